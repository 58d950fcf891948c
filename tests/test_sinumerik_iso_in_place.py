"""Sinumerik constructs ISO cannot hold (STRING variables and values, string functions such as
SPRINT/GETT, per-word AC/IC/DC on an axis, G500, DIAMON on a mill, indirect G, a computed D) in a
subprogram file converted to ISO: each is an alarm at its own line (NC412), the rest of the file
keeps its structure; never a whole-file refusal, never left out. In a main program G500 is lowered
to plain motion over its stretch (to the next settable offset), proven equivalent with offsets."""
from __future__ import annotations

from pathlib import Path

import pytest

from nctrans import api
from nctrans.dialects.base import get
from nctrans.dialects.iso_m.plan import NOT_CONVERTED_ALARM, stable_number
from nctrans.interp import interpret
from nctrans.machine import default_mill

ALARM = f"#3000={NOT_CONVERTED_ALARM} (NOT CONVERTED: "

# (source line inside a PROC, the alarm comment it becomes)
CONSTRUCTS = [
    ("DEF STRING[20] NAME", "DEF STRING NAME)"),
    ('R1=GETT("DRILL")', "GETT[..])"),
    ("G1 X10 C=IC(90) F100", "C=IC[..])"),
    ("G1 C=DC(180) F100", "C=AC/DC[..])"),
    ("G500", "G500)"),
    # more than the 500 common variables #500-#999 hold
    ("DEF REAL BIG[600]", "DEF BIG[..])"),
]


@pytest.mark.parametrize("line, alarm", CONSTRUCTS, ids=[c[0] for c in CONSTRUCTS])
def test_construct_is_an_alarm_at_its_own_line(line, alarm):
    src = f"PROC PART(REAL DEPTH)\nG1 Z=-DEPTH F100\n{line}\nG1 Z0\nRET\n"
    conv = api.transpile(src, read="sinumerik", write="iso-m")
    assert conv.ok, [d.message for d in conv.diagnostics if d.severity == "error"]
    lines = conv.text.splitlines()
    i = lines.index("G1 F100. Z[-#1]")
    j = lines.index("G1 Z0.", i)
    # the block's other words may stand before the alarm, but no axis word: nothing moves
    between = lines[i + 1:j]
    assert between[-1] == ALARM + alarm
    assert not [x for x in between[:-1] if any(a in x for a in "XYZABC")]
    assert lines[j + 1] == "M99"
    assert [(d.line, d.severity) for d in conv.diagnostics if d.rule == "NC412"] == [(3, "warning")]
    assert not [d for d in conv.diagnostics if d.rule == "NC402"]
    back = get("iso-m").parse(conv.text, "o.nc")
    assert not [d for d in back.diagnostics if d.severity == "error"]


def test_string_report_in_a_proc_file_keeps_the_rest():
    src = ("PROC LOG(INT PASS)\nDEF STRING[40] TEXT\nG0 X0 Y0\nTEXT=SPRINT(\"PASS %d\", PASS)\n"
           "G1 X=PASS*10 F200\nRET\n")
    conv = api.transpile(src, read="sinumerik", write="iso-m")
    assert conv.ok
    assert sorted(d.line for d in conv.diagnostics if d.rule == "NC412") == [2, 4]
    lines = conv.text.splitlines()
    assert ALARM + "DEF STRING TEXT)" in lines and ALARM + "SPRINT[..])" in lines
    assert any(x.startswith("G1 F200. X[") for x in lines)
    # called: the ISO subprogram stops at the first alarm (the DEF), before any motion
    number = stable_number("LOG", set())
    sub = "\n".join(x for x in lines if x != "%")
    prog = f"%\nO1\nG0 Z50.\nG65 P{number} A2.\nM30\n{sub}\n%\n"
    found: list = []
    records = list(interpret(get("iso-m").parse(prog, "t.nc").program, default_mill(), diagnostics=found))
    assert [r.end["Z"] for r in records if r.kind == "rapid"] == [50.0]
    assert [d.rule for d in found if d.severity == "error"] == ["NC221"]
    assert f"alarm {NOT_CONVERTED_ALARM}" in found[0].message


def test_strict_refuses_them():
    conv = api.transpile("PROC P\nDEF STRING[8] SS1\nG0 X1\nRET\n", read="sinumerik", write="iso-m",
                         strict=True)
    assert conv.text is None
    assert [d.severity for d in conv.diagnostics if d.rule == "NC412"] == ["error"]


OFFSETS = (Path(__file__).parent / "data" / "offsets-g54-g55.toml").read_text()


def test_g500_in_a_main_program_is_lowered_over_its_stretch(tmp_path):
    # G500 after G54 cancels the settable offset for every later block; lowering its block alone
    # left the next blocks under G54 (X10 ran at machine 110 instead of 10)
    machine = tmp_path / "m.toml"
    machine.write_text(OFFSETS)
    src = "G54\nG0 X0\nG500\nG1 X10 F100\nG1 X20\nG55\nG1 X5\nM30\n"
    conv = api.transpile(src, read="sinumerik", write="iso-m", machine=str(machine))
    assert conv.ok
    lines = conv.text.splitlines()
    # machine X10 and X20 under G54 (X=100): -90 and -80, hand-computed; G55 then as written
    assert any(x.endswith("X-90.") for x in lines) and "X-80." in lines
    assert lines[lines.index("X-80.") + 1:lines.index("X-80.") + 3] == ["G55", "G1 X5."]
    assert api.equiv(src, conv.text, read_a="sinumerik", read_b="iso-m", machine=str(machine)).equivalent


# Sinumerik functions with no motion effect, written on ISO as comments: NC413 where their own
# control does something the comment does not, NC401 where nothing is lost (rules/sinumerik.toml
# [options.no_motion_effect] harmless_elsewhere)
COMMENTED = [("STOPRE", "NC401"), ("DISPLOF", "NC401"), ("FNORM", "NC401"),
             ("SOFT", "NC413"), ("BRISK", "NC413"), ("SBLOF", "NC413"), ("SETPIECE(1)", "NC413"),
             ("FFWON", "NC413"), ("NEWCONF", "NC413")]


@pytest.mark.parametrize("word, rule", COMMENTED, ids=[c[0] for c in COMMENTED])
def test_no_effect_function_commented_with_its_rule(word, rule):
    src = f"G0 X0 Y0\n{word}\nG1 X10 F100\nM30\n"
    conv = api.transpile(src, read="sinumerik", write="iso-m")
    assert conv.ok
    at_2 = [d for d in conv.diagnostics if d.line == 2]
    assert [d.rule for d in at_2] == [rule]
    assert at_2[0].severity == ("warning" if rule == "NC413" else "info")
    lines = conv.text.splitlines()
    # a comment at its place, never a word; the path is the same
    flat = word.replace("(", "[").replace(")", "]")     # Fanuc/LinuxCNC comments do not nest
    assert lines[lines.index("G0 X0. Y0.") + 1] in (f"({flat})", f"(NC413 sinumerik: {flat})")
    assert api.equiv(src, conv.text, read_a="sinumerik", read_b="iso-m").equivalent


def test_a_return_ending_a_main_program_is_said_when_written_as_m99():
    # M17 ends a Sinumerik main program run on its own; ISO M99 there restarts it (NC406 says so)
    conv = api.transpile("G0 X1 Y2\nM17\n", read="sinumerik", write="iso-m")
    assert [(d.rule, d.line) for d in conv.diagnostics if d.severity == "warning"] == [("NC406", 2)]
    # a PROC's RET is a subprogram's return: nothing to say; nor for ISO's own M99
    proc = api.transpile("PROC FOO(REAL AA)\nG0 X=AA\nRET\n", read="sinumerik", write="iso-m")
    assert "NC406" not in {d.rule for d in proc.diagnostics}
    iso = api.transpile("O1\nG0 X1\nM99\n", read="iso-m", write="iso-m")
    assert "NC406" not in {d.rule for d in iso.diagnostics}


@pytest.mark.parametrize("target", ["iso-m", "iso-t"])
def test_a_main_program_file_ending_with_a_return_is_written_with_m30(target, tmp_path):
    # an .MPF (or a %_N_.._MPF header) is a main program: M17 ends it, so ISO M30, not M99 (which
    # restarts an ISO main program endlessly); an .SPF is a subprogram file: M17 is its M99
    text = "G0 X1 Y2\nG1 X5 F100\nM17\n"
    for name, header, end in (("PART.MPF", "", "M30"), ("PART.txt", "%_N_PART_MPF\n", "M30"),
                              ("PART.SPF", "", "M99")):
        src = tmp_path / name
        src.write_text(header + text)
        conv = api.transpile(src, read="sinumerik", write=target)
        ends = [ln for ln in conv.text.splitlines() if ln.startswith(("M30", "M99"))]
        assert ends == [end], (name, conv.text)
        assert "NC406" not in {d.rule for d in conv.diagnostics if d.severity == "warning"}
        if end == "M30":
            assert api.equiv(src, conv.text, read_a="sinumerik", read_b=target).equivalent


def test_diamon_is_written_as_radius_words():
    # DIAMON (diameter X, absolute and incremental) is no alarm: ISO X words carry the radius
    src = "PROC PART(REAL DD)\nG1 Z0 F100\nDIAMON\nG1 X=DD Z1\nG91 X2\nDIAMOF\nG90 X5\nRET\n"
    conv = api.transpile(src, read="sinumerik", write="iso-m")
    lines = [l for l in conv.text.splitlines() if l.startswith(("G1 X", "G91", "G90"))]
    assert lines == ["G1 X[#1/2] Z1.", "G91 X1.", "G90 X5."]
    assert "NC412" not in {d.rule for d in conv.diagnostics}
