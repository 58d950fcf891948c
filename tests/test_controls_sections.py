"""Sinumerik program section repetition (issue 8): REPEAT label P=n, REPEAT start end, ENDLABEL,
REPEATB. Every expected toolpath is worked out by hand in the comments (G91 steps make each run of
a block visible as one more increment)."""
from __future__ import annotations

import pytest

from nctrans import pipeline
from nctrans.source import from_text


def run(text: str, dialect: str = "sinumerik"):
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", dialect)
    recs = list(pipeline.toolpath_of(ld, None))
    return recs, ld.diagnostics


def moves(recs):
    return [(r.kind, round(r.end["X"], 6), round(r.end["Y"], 6), round(r.end["Z"], 6))
            for r in recs if r.kind in ("rapid", "linear", "arc")]


def codes(diags, severity=("error", "warning")):
    return [d.rule for d in diags if d.severity in severity]


START = "G0 X0 Y0 Z0\nG91 F100\n"


def test_repeat_section_back_to_label_runs_p_more_times():
    # LBL1..Y1 runs once normally, then twice more: X +10 and Y +1 three times in all
    recs, diags = run(START + "LBL1: G1 X10\nY1\nREPEAT LBL1 P=2\nG90\nM30\n")
    assert codes(diags) == []
    assert moves(recs)[1:] == [("linear", 10, 0, 0), ("linear", 10, 1, 0),
                               ("linear", 20, 1, 0), ("linear", 20, 2, 0),
                               ("linear", 30, 2, 0), ("linear", 30, 3, 0)]


def test_repeat_without_p_repeats_once():
    recs, diags = run(START + "LBL1: G1 X10\nREPEAT LBL1\nM30\n")
    assert codes(diags) == []
    assert [m[1] for m in moves(recs)] == [0, 10, 20]


def test_repeatb_repeats_the_labelled_line_only_and_also_searches_forward():
    # REPEATB BB finds BB before it (X+1 block): 3 more runs; later REPEATB AFTER finds the
    # block after it: 2 runs there, then the block runs once more when reached normally
    text = START + "BB: G1 X1\nY5\nREPEATB BB P=3\nREPEATB AFTER P=2\nAFTER: Z-1\nM30\n"
    recs, diags = run(text)
    assert codes(diags) == []
    assert moves(recs)[1:] == [("linear", 1, 0, 0), ("linear", 1, 5, 0),
                               ("linear", 2, 5, 0), ("linear", 3, 5, 0), ("linear", 4, 5, 0),
                               ("linear", 4, 5, -1), ("linear", 4, 5, -2), ("linear", 4, 5, -3)]


def test_repeat_between_two_labels_includes_the_end_label_block():
    # S..E (X+1, Y+1) again once; the block after E (Z-1) is not part of it
    text = START + "S: G1 X1\nE: Y1\nZ-1\nREPEAT S E P=1\nM30\n"
    recs, diags = run(text)
    assert codes(diags) == []
    assert moves(recs)[1:] == [("linear", 1, 0, 0), ("linear", 1, 1, 0), ("linear", 1, 1, -1),
                               ("linear", 2, 1, -1), ("linear", 2, 2, -1)]


def test_repeat_label_ends_at_endlabel():
    # the section A..ENDLABEL is X+1, Y+1; X+100 after ENDLABEL is not repeated
    text = START + "A: G1 X1\nENDLABEL: Y1\nX100\nREPEAT A P=2\nM30\n"
    recs, diags = run(text)
    assert codes(diags) == []
    assert [m[1:3] for m in moves(recs)[1:]] == [(1, 0), (1, 1), (101, 1),
                                                 (102, 1), (102, 2), (103, 2), (103, 3)]


def test_nested_repetition_runs_inside_the_section():
    # section I..REPEATB: X+1 then REPEATB I (X+1 again): 2 per run; REPEAT O runs it once more
    text = START + "O: G1 Y1\nI: X1\nREPEATB I P=1\nREPEAT O P=1\nM30\n"
    recs, diags = run(text)
    assert codes(diags) == []
    assert [m[1:3] for m in moves(recs)[1:]] == [(0, 1), (1, 1), (2, 1), (2, 2), (3, 2), (4, 2)]


def test_modal_cycle_drills_again_at_repeated_positions():
    # drill at the two positions with CYCLE81 (to Z-5), then the same positions again with a
    # CYCLE82 modal call (DPR=8 -> Z-8, dwell 1 s): the REPEAT is not a call level, MCALL applies
    text = ("G17 G90 G0 X0 Y0 Z50 F100 S1000 M3\nMCALL CYCLE81(10, 0, 2, -5)\n"
            "POS1: X10 Y0\nPOS2: X20 Y0\nMCALL\nMCALL CYCLE82(10, 0, 2, , 8, 1)\n"
            "REPEAT POS1 POS2\nMCALL\nM30\n")
    recs, diags = run(text)
    assert codes(diags) == []
    bottoms = [(r.end["X"], r.end["Z"]) for r in recs if r.kind == "linear"]
    assert bottoms == [(10, -5), (20, -5), (10, -8), (20, -8)]
    assert [r.dwell_s for r in recs if r.kind == "dwell"] == [1.0, 1.0]


def test_repeat_count_from_an_expression():
    recs, diags = run(START + "R1=1\nL: G1 X2\nREPEAT L P=R1+2\nM30\n")
    assert codes(diags) == []
    assert [m[1] for m in moves(recs)] == [0, 2, 4, 6, 8]


@pytest.mark.parametrize("text,why", [
    (START + "REPEAT LATER P=2\nLATER: G1 X10\nM30\n", "not found before"),
    (START + "S: G1 X1\nREPEAT S NOEND\nM30\n", "end label NOEND"),
    (START + "R1=0\nS: G1 X1\nIF R1==0\nY1\nENDIF\nREPEAT S P=1\nM30\n", None),
    (START + "S: IF 1\nG1 X1\nREPEAT S P=1\nENDIF\nM30\n", "cuts a control structure"),
])
def test_unrunnable_repetition_is_reported_at_its_line(text, why):
    recs, diags = run(text)
    if why is None:        # the IF is wholly inside the section: it runs again (X+1, Y+1 twice)
        assert codes(diags) == []
        assert [m[1:3] for m in moves(recs)[1:]] == [(1, 0), (1, 1), (2, 1), (2, 2)]
        return
    bad = [d for d in diags if d.rule == "NC222"]
    assert bad and why in bad[0].message and bad[0].severity == "error"
    assert bad[0].line == next(i for i, l in enumerate(text.splitlines(), 1) if "REPEAT" in l)


def test_jump_out_of_a_section_is_reported():
    # first pass: R1=1, no jump; in the repetition R1=2 jumps to OUT outside the section:
    # NC222, the repetition ends and the program goes on after the REPEAT (OUT: Y1)
    text = START + "R1=0\nS: G1 X1\nR1=R1+1\nIF R1>1 GOTOF OUT\nREPEAT S P=3\nOUT: Y1\nM30\n"
    recs, diags = run(text)
    assert codes(diags) == ["NC222"]
    assert [m[1:3] for m in moves(recs)[1:]] == [(1, 0), (2, 0), (2, 1)]


def test_huge_repeat_count_stops_at_the_step_budget():
    from nctrans.interp import interpret
    ld = pipeline.load_source(from_text(START + "L: G1 X1\nREPEAT L P=100000000\nM30\n", "t.mpf"),
                              "t.mpf", "sinumerik")
    diags: list = []
    recs = list(interpret(ld.program, diagnostics=diags, max_steps=1000))
    assert [d.rule for d in diags] == ["NC205"] and len(recs) < 1100


@pytest.mark.parametrize("text", ["REPEAT A B C\n", "REPEATB\n", "REPEAT A P=2 X1\n"])
def test_malformed_repetition_is_a_syntax_error(text):
    _, diags = run("A: G0 X1\nB: X2\n" + text + "M30\n")
    assert [(d.rule, d.line) for d in diags if d.severity == "error"] == [("NC002", 3)]


def test_bare_repeat_is_still_the_repeat_until_loop():
    recs, diags = run("R1=0\nREPEAT\nR1=R1+1\nG0 X=R1\nUNTIL R1>=3\nM30\n")
    assert codes(diags) == [] and [m[1] for m in moves(recs)] == [1, 2, 3]


def test_sinumerik_writes_the_repetition_back_and_iso_lowers_it_to_plain_moves():
    from nctrans import api
    text = START + "LBL1: G1 X10\nREPEATB LBL1 P=2\nREPEAT LBL1 P=1\nM30\n"
    same = api.transpile(text, "sinumerik", "sinumerik")
    assert "REPEATB LBL1 P=2" in same.text and "REPEAT LBL1 P=1" in same.text
    # X10 once and twice more by REPEATB (X30); the REPEAT section is LBL1 up to the block before
    # it, so it holds the REPEATB too: X+10 and two more, X60 at the end
    iso = api.transpile(text, "sinumerik", "iso-m")
    xs = [float(w[1:]) for ln in iso.text.splitlines() for w in ln.split() if w.startswith("X")]
    assert xs[1:] == [10.0, 20.0, 30.0, 40.0, 50.0, 60.0], iso.text
