"""A programmable frame change under cutter radius compensation (nctrans/interp/episode_frame.py):
the move held before it keeps the frame it was programmed in, the next move's corner is computed on
the machine's path. Before, the held move was emitted in the new frame: TRANS X100 under G41 made
a record start at X110 after one ending at X10 (a 100 mm jump, no diagnostic); ROT RPL=90 one at
(-2, 10). A change that scales or mirrors is NC119 at its line.

Tool 1: length 10, radius 2; G41 (tool on the left). Expected values by hand."""
from __future__ import annotations

import pytest

import nctrans
from nctrans import pipeline
from nctrans.machine import Tool, default_mill
from nctrans.source import from_text

HEAD = "G17 G90 G40 T1 D1 M6\nG0 X0 Y-10 Z5\nG41 G1 X10 Y0 F100\nG1 X50\n"
TAIL = "G40 G1 X0 Y30\nM30\n"


def _mill():
    m = default_mill()
    m.tools = [Tool(1, length=10, radius=2)]
    return m


def run(text: str, dialect: str = "sinumerik"):
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", dialect)
    recs = [r for r in pipeline.toolpath_of(ld, _mill()) if r.kind in ("rapid", "linear", "arc")]
    got = [(r.line, r.kind, tuple(round(r.start[a], 4) for a in "XY"), tuple(round(r.end[a], 4) for a in "XY"))
           for r in recs]
    return got, [(d.line, d.rule) for d in ld.diagnostics if d.severity in ("warning", "error")]


# after the shift the tool (machine X50 Y0) is at program (-50, 0): Y20 goes up to (50, 20), X10
# to (110, 20). Left of +X is +Y (offset line Y2), left of +Y is -X (X48): a left turn, concave,
# the corner at the intersection (48, 2); from +Y to +X a right turn, convex: an arc about (50, 20)
# from (48, 20) to (50, 22); then along Y22 to X110 and the G40 exit to (100, 30)
SHIFTED = [
    (4, "linear", (10.0, 2.0), (48.0, 2.0)),
    (6, "linear", (48.0, 2.0), (48.0, 20.0)),
    (7, "arc", (48.0, 20.0), (50.0, 22.0)),
    (7, "linear", (50.0, 22.0), (110.0, 22.0)),
    (8, "linear", (110.0, 22.0), (100.0, 30.0)),
]


@pytest.mark.parametrize("dialect, shift", [("sinumerik", "TRANS X100"), ("sinumerik", "ATRANS X100"),
                                            ("iso-m", "G52 X100.")])
def test_a_shift_under_compensation(dialect, shift):
    text = HEAD + shift + "\nG1 Y20\nG1 X10\n" + TAIL
    if dialect == "iso-m":
        text = text.replace("T1 D1 M6", "T1 M6\nG43 H1 D1").replace("G41 G1", "G41 D1 G1")
    got, said = run(text, dialect)
    assert not [r for r in said if r[1] in ("NC119", "NC204")], said
    # (the ISO text has one line more: G43 H1 D1)
    assert [g[1:] for g in got[-5:]] == [s[1:] for s in SHIFTED], got


def test_a_rotation_under_compensation():
    # ROT RPL=90 about the zero: the tool (50, 0) is at program (0, -50). X20 -> program (20, -50)
    # -> work (50, 20): up +Y; X-10 -> (-10, -50) -> work (50, -10): back down, a reversal, convex
    # for the left side: an arc about (50, 20) from (48, 20) to (52, 20), then down X52 to Y-10;
    # G40 X0 Y30 -> work (-30, 0)
    got, said = run(HEAD + "ROT RPL=90\nG1 X20\nG1 X-10\n" + TAIL)
    assert said == []
    assert got[-5:] == [
        (4, "linear", (10.0, 2.0), (48.0, 2.0)),
        (6, "linear", (48.0, 2.0), (48.0, 20.0)),
        (7, "arc", (48.0, 20.0), (52.0, 20.0)),
        (7, "linear", (52.0, 20.0), (52.0, -10.0)),
        (8, "linear", (52.0, -10.0), (-30.0, 0.0)),
    ]


@pytest.mark.parametrize("change", ["MIRROR Y0", "SCALE X2 Y2", "AMIRROR X0"])
def test_a_scale_or_mirror_change_under_compensation_is_said_at_its_line(change):
    text = HEAD + change + "\nG1 Y20\nG1 X10\n" + TAIL
    _, said = run(text)
    assert (5, "NC119") in said
    # converted, the compensated stretch is never written as the analysed tool-centre path (which is
    # not the machine's): refused, or kept as the same construct under G41 for the control to run
    for target in ("iso-m", "fagor", "iso-t"):
        conv = nctrans.transpile(text, read="sinumerik", write=target, machine=_mill())
        assert conv.text is None or "G41" in conv.text, (target, conv.text)
        if conv.text is None:
            assert any(d.line == 5 and d.rule == "NC402" for d in conv.diagnostics), conv.diagnostics


def test_a_frame_set_before_the_compensation_is_no_change():
    # MIRROR before G41: in force for the whole episode, nothing to say (ISO seed L1712: G41/G42
    # swap under it, which compensating in program coordinates does)
    _, said = run("G17 G90 G40 T1 D1 M6\nMIRROR Y0\nG0 X0 Y-10 Z5\nG41 G1 X10 Y0 F100\nG1 X50\nG1 Y20\n" + TAIL)
    assert not [r for r in said if r[1] == "NC119"]


@pytest.mark.parametrize("target", ["iso-m", "sinumerik"])
def test_a_shift_under_compensation_converts_equivalent(target):
    text = HEAD + "TRANS X100\nG1 Y20\nG1 X10\n" + TAIL
    conv = nctrans.transpile(text, read="sinumerik", write=target, machine=_mill())
    assert conv.ok, conv.diagnostics
    assert nctrans.equiv(text, conv.text, read_a="sinumerik", read_b=target, machine=_mill()), conv.text
