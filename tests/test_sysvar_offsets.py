"""Writes to ISO offset system variables change the offsets the later moves use, as G10 does
(rules/iso-m.toml [[options.numbered_variables]], nctrans.interp.sysvars). Before, `#2402=.5` was
kept as a plain variable and a following G41 D2 ran with the old radius: silently wrong."""
from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

import nctrans


def _moves(src: str):
    return [r for r in nctrans.toolpath(src, dialect="iso-m") if r.kind in ("linear", "rapid")]


def test_radius_write_is_the_compensation_of_the_next_g41():
    # Haas layout: #2401.. radius geometry of D1..; G41 left of a +X move shifts the path to +Y
    moves = _moves("G90 G17 G21\n#2402=.5\nG1 G41 D2 X10 Y0 F100\nX20\nG40 X30\nM30\n")
    assert [round(m.end["Y"], 6) for m in moves] == [0.5, 0.5, 0.0]


def test_length_geometry_and_wear_add_up():
    moves = _moves("G90 G21\n#2003=10.\n#2203=-.25\nG43 H3 G0 Z0\n#100=#2003\n#101=#2203\n"
                   "G0 Z#100\nZ#101\nM30\n")
    # Z0 with length 10 - 0.25 = 9.75; reading the numbers back gives geometry and wear apart
    assert [round(m.end["Z"], 6) for m in moves] == [9.75, 19.75, 9.5]


def test_work_offset_write_moves_the_active_system_at_once():
    moves = _moves("G90 G21 G54\nG0 X0 Y0\n#5221=7.\n#5222=-2.\nG0 X1 Y1\n#5241=100.\nG0 X0\nM30\n")
    # G55 (#5241) is not active: the last move still uses G54's offset
    assert [(m.end["X"], m.end["Y"]) for m in moves] == [(0.0, 0.0), (8.0, -1.0), (7.0, -1.0)]


def test_inch_program_writes_in_inches():
    moves = _moves("G90 G20\n#2401=.1\nG1 G41 D1 X1. Y0 F10.\nM30\n")
    assert round(moves[0].end["Y"], 6) == pytest.approx(2.54)


@settings(max_examples=30, deadline=None)
@given(value=st.integers(-500, 500).map(lambda v: v / 100), axis=st.sampled_from("XYZ"))
def test_a_work_offset_write_and_g10_move_the_same(value, axis):
    number = 5221 + "XYZ".index(axis)
    by_var = _moves(f"G90 G21 G54\n#{number}={value}\nG0 X1 Y2 Z3\nM30\n")
    by_g10 = _moves(f"G90 G21 G54\nG10 L2 P1 {axis}{value}\nG0 X1 Y2 Z3\nM30\n")
    assert [m.end for m in by_var] == [m.end for m in by_g10]
