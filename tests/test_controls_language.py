"""Language the real programs use (issue 8): Sinumerik IF..GOTOF chains, DEF limit attributes, glued
words, string functions; Fanuc external output, G103, #3000 alarms and system variables read from
the machine model. Expected values are worked out by hand in the comments."""
from __future__ import annotations

from pathlib import Path

import pytest

from nctrans import pipeline
from nctrans.machine import load as load_machine
from nctrans.source import from_text


def run(text: str, dialect: str, machine=None):
    ld = pipeline.load_source(from_text(text, "t.nc"), "t.nc", dialect)
    recs = list(pipeline.toolpath_of(ld, machine))
    return recs, ld.diagnostics


def ends(recs, axis="X"):
    return [round(r.end[axis], 6) for r in recs if r.kind in ("rapid", "linear", "arc")]


def problems(diags):
    return [d.format_text() if hasattr(d, "format_text") else d for d in diags
            if d.severity in ("error", "warning")]


# --------------------------------------------------------------------------- Sinumerik

CHAIN = ("DEF REAL DPR, RTP, RFP\nDPR={dpr} RTP=1 RFP={rfp}\n"
         "IF DPR==0 GOTOF _MM1 IF RTP==RFP GOTOF _FEHL1\nG0 X1\n_MM1:\nG0 X2\n_FEHL1:\nM30\n")


@pytest.mark.parametrize("dpr,rfp,want", [(0, 1, [2.0]),        # first jump taken
                                          (1, 1, []),           # second jump taken
                                          (1, 2, [1.0, 2.0])])  # neither
def test_several_if_gotof_in_one_block(dpr, rfp, want):
    recs, diags = run(CHAIN.format(dpr=dpr, rfp=rfp), "sinumerik")
    assert ends(recs) == want
    assert problems(diags) == []


def test_def_limit_attributes_are_accepted():
    text = ("DEF CHAN INT lli 0 uli 4 NAME\nDEF CHAN REAL PHU 1 LLI -5.5 ULI 10 APR 7 APW 2 LEN=2\n"
            "DEF INT LLI=3\nNAME=3\nG0 X=NAME+LEN+LLI\nM30\n")
    recs, diags = run(text, "sinumerik")
    assert ends(recs) == [8.0]                     # 3 + 2 + 3
    assert [d.rule for d in diags if d.rule.startswith("NC0")] == []


def test_words_written_together():
    # G01G90X=R12F800: G1, G90, X = R12 (5), F800; then G0G91X1Y2 from there
    recs, diags = run("R12=5\nG01G90X=R12F800\nG0G91X1Y2\nM30\n", "sinumerik")
    moves = [r for r in recs if r.kind in ("rapid", "linear")]
    assert [(r.kind, r.end["X"], r.end["Y"], r.feed) for r in moves] == [
        ("linear", 5.0, 0.0, 800.0), ("rapid", 6.0, 2.0, None)]
    assert problems(diags) == []


def test_string_functions():
    text = ('DEF STRING[20] SA="ABCDEF"\nDEF STRING[20] SB\nDEF INT LL\n'
            "LL=STRLEN(SA)\nG0 X=LL\n"                      # 6
            'LL=INDEX(SA,"C")\nG0 X=LL\n'                   # 2
            'LL=RINDEX("ABCABC","B")\nG0 X=LL\n'           # 4
            "SB=SUBSTR(SA,1,2)\nLL=MATCH(SA,SB)\nG0 X=LL\n"  # "BC" at 1
            'LL=MINDEX("ABC","XC")\nG0 X=LL\n'             # 2
            'LL=INDEX(SA,"Z")\nG0 X=LL\n'                   # -1
            'SB=TOLOWER(SA)\nIF SB<>"abcdef" GOTOF BAD\n'
            'IF TOUPPER("ab")<>"AB" GOTOF BAD\n'
            'G0 X=NUMBER("12.5")\n'                       # 12.5
            'IF ISNUMBER("1.5EX2")==0 GOTOF BAD\nIF AXSTRING(X)<>"X" GOTOF BAD\n'
            "G0 X=SUBSTR(\"ABC\",1)==\"BC\"\n"           # TRUE -> 1
            "M30\nBAD:\nG0 X99\nM30\n")
    recs, diags = run(text, "sinumerik")
    assert ends(recs) == [6.0, 2.0, 4.0, 1.0, 2.0, -1.0, 12.5, 1.0]
    assert problems(diags) == []


def test_string_function_errors_are_reported():
    recs, diags = run('DEF REAL VV\nVV=NUMBER("1,5")\nVV=SUBSTR("A",-1)\nVV=STRLEN(5)\nM30\n', "sinumerik")
    assert [(d.rule, d.line) for d in diags if d.severity == "error"] == [
        ("NC104", 2), ("NC104", 3), ("NC104", 4)]


def test_setal_is_an_error_that_ends_the_run():
    recs, diags = run('G0 X1\nSETAL(61001, "bad")\nG0 X2\nM30\n', "sinumerik")
    assert ends(recs) == [1.0]
    (d,) = [d for d in diags if d.rule == "NC221"]
    assert d.severity == "error" and d.line == 2 and "61001" in d.message


# --------------------------------------------------------------------------- ISO / Fanuc

def test_external_output_and_g103_have_no_motion_effect():
    text = ("G0 X1\nPOPEN\nDPRNT[X#5041[44]*Y#5042[44]]\nBPRNT[A#1[3]]\nPCLOS\nG103 P1\nG103\n"
            "N10 POPEN\nG0 X2\nM30\n")
    recs, diags = run(text, "iso-m")
    assert ends(recs) == [1.0, 2.0]
    assert [d for d in diags if d.severity != "info"] == []


def test_3000_alarm_stops_with_its_message():
    recs, diags = run("G0 X1\n#3000=1 (TOOL BROKEN)\nG0 X2\nM30\n", "iso-m")
    assert ends(recs) == [1.0]
    (d,) = [d for d in diags if d.rule == "NC221"]
    assert d.severity == "error" and d.line == 2 and "TOOL BROKEN" in d.message


MACHINE = """
name = "m"
kind = "mill"
[axes.X]
kind = "linear"
min = -3000.0
max = 3000.0
[axes.Y]
kind = "linear"
min = -3000.0
max = 3000.0
[axes.Z]
kind = "linear"
min = -3000.0
max = 3000.0
[offsets.G54]
X = 10.0
Y = 20.0
Z = 30.0
[offsets.G55]
X = 1.0
Z = 7.0
[[tools]]
number = 2
length = 100.0
radius = 3.0
"""


def test_fanuc_system_variables_read_machine_and_state(tmp_path: Path):
    path = tmp_path / "m.toml"
    path.write_text(MACHINE)
    machine = load_machine(path)
    # G54 offset (10, 20, 30) adds to every work coordinate below
    text = ("G17 G90 G94 G21 G54 F250 S1200 T2\n"
            "G1 X#4001 Y#4002\n"                 # G1 -> 1, G17 -> 17: (11, 37)
            "G1 X#4003 Y#4005\n"                 # G90 -> 90, G94 -> 94: (100, 114)
            "G1 X#4006 Y#4014\n"                 # G21 -> 21, G54 -> 54: (31, 74)
            "G1 X#5221 Y#5222 Z#5263\n"          # G54 X 10, G54 Y 20, G56 Z 0: (20, 40, 30)
            "G1 X#5241 Z#5243\n"                 # G55 X 1, G55 Z 7: (11, 40, 37)
            "G1 X#2002 Y#2402 Z#2202\n"          # tool 2 length 100, radius 3, wear 0: (110, 23, 30)
            "G1 X#4109 Y#4119 Z#4120\n"          # F 250, S 1200, T 2: (260, 1220, 32)
            "M30\n")
    recs, diags = run(text, "iso-m", machine)
    pts = [(r.end["X"], r.end["Y"], r.end["Z"]) for r in recs if r.kind == "linear"]
    assert pts == [(11, 37, 0), (100, 114, 0), (31, 74, 0), (20, 40, 30), (11, 40, 37),
                   (110, 23, 30), (260, 1220, 32)]
    assert problems(diags) == []


def test_unknown_system_variables_say_so_where_they_matter():
    recs, diags = run("#1=#3001\n#2=#3901\nG0 X#1\nIF [#2 GT 5] GOTO 10\nN10 M30\n", "iso-m")
    assert [(d.rule, d.line) for d in diags] == [("NC107", 3), ("NC107", 4)]
