"""Sinumerik OFFN (interp/contour_offset.py): the allowance normal to the contour that cutter
compensation adds to the tool radius (seed L12466-12492). Expected points by hand."""
from __future__ import annotations

import nctrans
from nctrans import api
from nctrans.machine import Axis, Machine, Tool

_AX = Axis(min=-500.0, max=500.0)
MACHINE = Machine(name="m", kind="mill", axes={"X": _AX, "Y": _AX, "Z": _AX},
                  tools=[Tool(number=1, length=0.0, radius=2.0)])

# the seed's square (L12474-12480) without TRANSMIT: 20 x 20 about the origin, run counter-
# clockwise with G41, so the tool is left of the path: inside the square, where the corners are
# plain intersections of the offset sides
SQUARE = ("G17 G90 G0 X30 Y-10 Z0 T1 M6 D1 F1000\nG1 X10 Y-10 G41 OFFN={offn}\nX10 Y10\nX-10\n"
          "Y-10\nX10\nG0 X30 G40 OFFN=0\nM30\n")


def end_of_line(offn: str, line: int):
    recs = [r for r in nctrans.toolpath(SQUARE.format(offn=offn), "sinumerik", MACHINE)
            if r.kind == "linear" and r.line == line]
    return (round(recs[-1].end["X"], 6), round(recs[-1].end["Y"], 6))


def test_offn_adds_to_the_tool_radius():
    # radius 2 + OFFN 1 = 3 inside: the corner (10,10) is run at (7,7), (-10,10) at (-7,7);
    # without OFFN at (8,8)
    assert end_of_line("1", 3) == (7.0, 7.0)
    assert end_of_line("1", 4) == (-7.0, 7.0)
    assert end_of_line("0", 3) == (8.0, 8.0)
    assert end_of_line("-0.5", 3) == (8.5, 8.5)      # a negative allowance: closer to the contour


def test_offn_without_compensation_moves_nothing_and_is_not_unmodelled():
    tp = nctrans.toolpath("G0 X0 Y0 Z0 F100\nOFFN=2\nG1 X10\nM30\n", "sinumerik")
    recs = [r for r in tp if r.kind == "linear"]
    assert [(r.end["X"], r.end["Y"]) for r in recs] == [(10.0, 0.0)]
    assert [d for d in tp.diagnostics if d.severity != "info"] == []


def test_offn_change_under_compensation_is_said():
    text = SQUARE.format(offn="1").replace("X-10\n", "X-10 OFFN=2\n")
    tp = nctrans.toolpath(text, "sinumerik", MACHINE)
    list(tp)
    assert [(d.rule, d.line) for d in tp.diagnostics if d.severity == "warning"] == [("NC220", 4)]


def test_offn_flattened_is_in_the_coordinates():
    conv = api.transpile(SQUARE.format(offn="1"), "sinumerik", "iso-m", flatten=True, machine=MACHINE)
    assert conv.text is not None and "OFFN" not in conv.text
    assert "G1 Y7.\nX-7.\nY-7.\n" in conv.text          # the sides at radius 2 + OFFN 1 inside
