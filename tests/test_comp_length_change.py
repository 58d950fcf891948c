"""An offset change under cutter radius compensation (issue 9): a tool length (G43 H), a work
offset (G55) or G92. The compensated move held before it (its end waits for the next move's corner)
keeps the offsets it was programmed with, the next move takes the new ones, and the corner between
them is computed on the path the machine runs. Before, the held move was emitted with the new
offsets (a 20 mm jump in Z inside it; 100 mm in X for G55) and the program point was reset to the
last emitted, compensated machine point, so every later move of the episode went to the wrong
place (the length change said NC220 "not modelled"; G55 and G92 said nothing).

Expected values by hand: tool 1 length 10, tool 2 length 30, both radius 2, G41 (tool on the left).
"""
from __future__ import annotations

import pytest

from nctrans import api, pipeline, plainrun
from nctrans.machine import Tool, default_mill
from nctrans.source import from_text

PROGRAM = """G21 G17 G90 G40 G49
T1 M6
G0 X0 Y-10 Z5
G43 H1 Z5
G41 D1 G1 X10 Y0 F100
G1 X50
G43 H2
G1 Y20{z}
G1 X10
G40 G1 X0 Y30
M30
"""


def _mill():
    m = default_mill()
    m.tools = [Tool(1, length=10, radius=2), Tool(2, length=30, radius=2)]
    return m


def _moves(text: str, kernel: bool = True):
    saved = plainrun.native
    if not kernel:
        plainrun.native = None
    try:
        ld = pipeline.load_source(from_text(text, "t.ngc"), "t.ngc", "iso-m")
        recs = [r for r in pipeline.toolpath_of(ld, _mill()) if r.kind in ("rapid", "linear", "arc")]
    finally:
        plainrun.native = saved
    got = [(r.line, r.kind, tuple(round(r.start[a], 6) for a in "XYZ"), tuple(round(r.end[a], 6) for a in "XYZ"))
           for r in recs]
    return got, [(d.rule, d.severity, d.line) for d in ld.diagnostics]


def test_held_move_keeps_the_length_it_was_programmed_with():
    # Line 6 (X50, offset to Y2) is held when line 7 changes the length: its end is the concave
    # corner with line 8 (offset line X48): (48, 2) at Z5 + 10 = 15, not 5 + 30 = 35. G43 H2 moves
    # nothing (the program Z becomes 15 - 30 = -15); line 8 runs along X48 to the corner with line
    # 9 (Y18) at machine Z15, line 9 keeps its offset end (10, 18) at G40, the exit runs to (0, 30).
    got, diags = _moves(PROGRAM.format(z=""))
    assert got[-5:] == [
        (6, "arc", (8.585786, 1.414214, 15.0), (10.0, 2.0, 15.0)),
        (6, "linear", (10.0, 2.0, 15.0), (48.0, 2.0, 15.0)),
        (8, "linear", (48.0, 2.0, 15.0), (48.0, 18.0, 15.0)),
        (9, "linear", (48.0, 18.0, 15.0), (10.0, 18.0, 15.0)),
        (10, "linear", (10.0, 18.0, 15.0), (0.0, 30.0, 15.0)),
    ]
    # no longer "not modelled"; iso-m says LinuxCNC refuses the change (rs274: "Cannot change tool
    # offset with cutter radius compensation on")
    assert ("NC220", "warning", 7) not in diags
    assert ("NC122", "info", 7) in diags


def test_the_next_move_takes_the_new_length():
    # Line 8 programs Z2: it ends at 2 + 30 = 32 and starts where the held move ended (Z15).
    got, _ = _moves(PROGRAM.format(z=" Z2"))
    assert got[-4:-2] == [
        (6, "linear", (10.0, 2.0, 15.0), (48.0, 2.0, 15.0)),
        (8, "linear", (48.0, 2.0, 15.0), (48.0, 18.0, 32.0)),
    ]
    assert got[-1][3] == (0.0, 30.0, 32.0)


@pytest.mark.parametrize("text", [PROGRAM.format(z=""), PROGRAM.format(z=" Z2"),
                                  PROGRAM.format(z="").replace("G43 H2", "G92 X0")])
def test_same_with_and_without_the_native_kernel(text):
    assert _moves(text, kernel=True) == _moves(text, kernel=False)


def test_converted_and_flattened_stay_equivalent():
    text = PROGRAM.format(z=" Z2")
    for target, kw in (("sinumerik", {}), ("iso-m", {"flatten": True})):
        conv = api.transpile(text, "iso-m", target, machine=_mill(), **kw)
        assert conv.text is not None
        assert api.equiv(text, conv.text, read_a="iso-m", read_b=target, machine=_mill())


def test_work_offset_change_under_compensation_by_hand():
    # G55 shifts X by 100 between line 5 (X50, held) and line 7 (Y20, now X-50 in G55 = machine
    # X50). Line 5 ends at the concave corner with line 7 (offset line X48): (48, 2). Line 7 turns
    # right into line 8 (+X): a convex corner, the arc about (50, 20) from (48, 20) to (50, 22).
    # Line 8 (X10 in G55 = machine 110) keeps its offset end (110, 22) at G40; the exit runs to
    # X0 Y30 in G55 = machine (100, 30).
    text = PROGRAM.format(z="").replace("G43 H2", "G55").replace("G43 H1 Z5", "G43 H1 Z5 G54")
    m = _mill()
    m.offsets["G55"] = {"X": 100.0, "Y": 0.0, "Z": 0.0}
    ld = pipeline.load_source(from_text(text, "t.ngc"), "t.ngc", "iso-m")
    got = [(r.line, r.kind, tuple(round(r.end[a], 6) for a in "XY"))
           for r in pipeline.toolpath_of(ld, m) if r.kind in ("linear", "arc")]
    assert got[-5:] == [(6, "linear", (48.0, 2.0)), (8, "linear", (48.0, 20.0)), (9, "arc", (50.0, 22.0)),
                        (9, "linear", (110.0, 22.0)), (10, "linear", (100.0, 30.0))]
    assert ("NC122", 7) in [(d.rule, d.line) for d in ld.diagnostics]


def test_g92_under_compensation_by_hand():
    # G92 X0 at program X50 (held end): the program X becomes 0 there, so line 8's X10 is machine
    # X60. Line 6 ends at the corner with line 8 (X48, Y2), line 8 runs up X48 to Y20, the corner
    # with line 9 (+X: convex, the arc about (50, 20) to (50, 22)), line 9 keeps its offset end
    # (60, 22) at G40, the exit runs to X0 Y30 = machine (50, 30).
    text = PROGRAM.format(z="").replace("G43 H2", "G92 X0")
    got, diags = _moves(text)
    assert [(ln, k, e[:2]) for ln, k, s, e in got[-5:]] == [
        (6, "linear", (48.0, 2.0)), (8, "linear", (48.0, 20.0)), (9, "arc", (50.0, 22.0)),
        (9, "linear", (60.0, 22.0)), (10, "linear", (50.0, 30.0))]
    assert ("NC122", "info", 7) in diags
