"""A tool length change under cutter radius compensation (issue 9): the compensated move held
before it (its end waits for the next move's corner) keeps the length it was programmed with, and
the next move starts where it ended. Before, the held move was emitted with the new length (a 20 mm
jump in Z inside it) and the program point was reset to the last emitted, compensated machine
point, so every later move of the episode went to the wrong place (NC220 said "not modelled").

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


@pytest.mark.parametrize("z", ["", " Z2"])
def test_same_with_and_without_the_native_kernel(z):
    assert _moves(PROGRAM.format(z=z), kernel=True) == _moves(PROGRAM.format(z=z), kernel=False)


def test_converted_and_flattened_stay_equivalent():
    text = PROGRAM.format(z=" Z2")
    for target, kw in (("sinumerik", {}), ("iso-m", {"flatten": True})):
        conv = api.transpile(text, "iso-m", target, machine=_mill(), **kw)
        assert conv.text is not None
        assert api.equiv(text, conv.text, read_a="iso-m", read_b=target, machine=_mill())
