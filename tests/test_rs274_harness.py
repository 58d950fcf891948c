"""The rs274 harness itself: its reading of canonical output, and the conventions it relies on.

Canned-text tests pin the parser; the live tests run rs274 on small programs and check the machine
coordinates against values computed by hand, so a wrong assumption about offset order, units or the
ARC_FEED layout shows up here and not as a mysterious corpus mismatch.
"""
from __future__ import annotations

import math

import pytest

import rs274 as h
from nctrans.toolpath import ToolpathRecord

IN = 25.4

CANNED = """\
    1 N..... USE_LENGTH_UNITS(CANON_UNITS_MM)
    2 N..... SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    3 N..... SET_G92_OFFSET(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    4 N..... SET_XY_ROTATION(0.0000)
    5 N..... ON_RESET()
    6 N10    COMMENT("T1 (1/2 EM) with (nested) parens")
    7 N10    USE_LENGTH_UNITS(CANON_UNITS_INCHES)
    8 N20    STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)
    9 N30    SET_FEED_RATE(10.0000)
   10 N30    STRAIGHT_FEED(1.0000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)
   11 N40    SELECT_PLANE(CANON_PLANE_XZ)
   12 N40    ARC_FEED(4.0000, 5.0000, 4.0000, 3.0000, 1, 2.0000, 0.0000, 0.0000, 0.0000)
   13 N50    SELECT_PLANE(CANON_PLANE_YZ)
   14 N50    ARC_FEED(3.0000, 3.0000, 2.0000, 3.0000, -3, 4.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
   15 N60    USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 2.0000, 0.0000 0.0000 0.0000, 0.0000 0.0000 0.0000)
   16 N60    SET_G5X_OFFSET(2, 1.0000, -1.0000, 0.5000, 0.0000, 0.0000, 0.0000)
   17 N70    STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 90.0000)
   18 N80    DWELL(1.5000)
   19 N110795PROGRAM_END()
   20 N90    ON_RESET()
"""


def _close(d: dict, ref: dict, tol=1e-9):
    assert set(ref) <= set(d)
    for k, v in ref.items():
        assert d[k] == pytest.approx(v, abs=tol), (k, d[k], v)


def test_canned_output_units_planes_and_offsets():
    run = h.parse(CANNED)
    assert run.completed
    kinds = [m.kind for m in run.moves]
    assert kinds == ["rapid", "linear", "arc", "arc", "rapid"]
    r, l, zx, yz, last = run.moves
    _close(r.start, {"X": 0, "Y": 0, "Z": 0})
    _close(r.end, {"X": IN, "Y": 2 * IN, "Z": 3 * IN})
    assert r.n_word == "N20" and r.out_line == 8 and r.text.startswith("STRAIGHT_TRAVERSE(")
    assert l.feed == pytest.approx(10 * IN)
    # XZ plane: first axis Z, second X, helix axis Y
    _close(zx.end, {"Z": 4 * IN, "X": 5 * IN, "Y": 2 * IN})
    _close(zx.center, {"Z": 4 * IN, "X": 3 * IN})
    assert (zx.plane, zx.direction, zx.turns) == ("ZX", "ccw", 0)
    # YZ plane: first Y, second Z, helix X; rotation -3 = cw with two extra turns; 12 values accepted
    _close(yz.end, {"Y": 3 * IN, "Z": 3 * IN, "X": 4 * IN})
    _close(yz.center, {"Y": 2 * IN, "Z": 3 * IN})
    assert (yz.plane, yz.direction, yz.turns) == ("YZ", "cw", 2)
    assert yz.start == zx.end
    # offsets printed in inches at the time: G5x (1,-1,0.5) in + tool length 2 in on Z; rotary in degrees
    _close(last.end, {"X": IN, "Y": -IN, "Z": 2.5 * IN, "C": 90.0})
    assert [e.name for e in run.events] == ["DWELL", "PROGRAM_END"]


def test_tolerance_follows_printed_rounding():
    run = h.parse(CANNED)
    # inch program without offsets: half a printed digit is 1.27 µm, more than the 1 µm floor
    assert run.moves[0].tol == pytest.approx(0.00005 * IN)
    # plus the rounding of the two nonzero printed offsets (G5x and tool length)
    assert run.moves[-1].tol == pytest.approx(3 * 0.00005 * IN)
    mm = h.parse("1 N..... USE_LENGTH_UNITS(CANON_UNITS_MM)\n"
                 "2 N..... STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n")
    assert mm.moves[0].tol == h.BASE_TOL_MM
    assert not mm.completed


def test_rotation_applies_to_program_plus_g92_not_to_g5x():
    run = h.parse("1 N..... SET_G5X_OFFSET(1, 10.0000, 20.0000, 30.0000, 0.0000, 0.0000, 0.0000)\n"
                  "2 N..... SET_XY_ROTATION(90.0000)\n"
                  "3 N..... SET_G92_OFFSET(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
                  "4 N..... STRAIGHT_TRAVERSE(1.0000, 1.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n")
    # (1,1)+(1,0) = (2,1) -> rotated 90 deg -> (-1,2) -> + (10,20,30)
    _close(run.moves[0].end, {"X": 9.0, "Y": 22.0, "Z": 30.0})


def _rec(kind, start, end, line=1, **kw):
    return ToolpathRecord(seq=line, file="t.nc", line=line, kind=kind, start=start, end=end, **kw)


def _moves(text):
    return h.parse(text).moves


SIMPLE = ("1 N..... STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"   # zero move
          "2 N..... STRAIGHT_TRAVERSE(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
          "3 N..... ARC_FEED(1.0000, 0.0000, 0.5000, 0.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)\n")


def test_compare_agrees_and_drops_zero_moves_on_both_sides():
    o = {"X": 0.0, "Y": 0.0, "Z": 0.0}
    p = {"X": 1.0, "Y": 0.0, "Z": 0.0}
    mine = [h.Motion.of(_rec("rapid", p, dict(p), 1)),                # zero-length: dropped
            h.Motion.of(_rec("rapid", o, {"X": 1.0004, "Y": 0.0, "Z": 0.0}, 2)),
            h.Motion.of(_rec("arc", p, p, 3, center={"X": 0.5, "Y": 0.0}, direction="cw",
                             plane="XY", turns=0))]
    assert h.compare(_moves(SIMPLE), mine, "t.nc") is None


def test_compare_reports_first_difference_with_both_sources():
    o = {"X": 0.0, "Y": 0.0, "Z": 0.0}
    p = {"X": 1.0, "Y": 0.0, "Z": 0.0}
    mine = [h.Motion.of(_rec("rapid", o, p, 2)),
            h.Motion.of(_rec("arc", p, p, 7, center={"X": 0.5, "Y": 0.0}, direction="ccw",
                             plane="XY", turns=0))]
    msg = h.compare(_moves(SIMPLE), mine, "t.nc")
    assert "motion #1" in msg and "direction ccw != cw" in msg
    assert "rs274 out #3" in msg and "ARC_FEED(" in msg and "t.nc:7" in msg
    # a full circle (start == end) is not a zero-length move, so dropping it would be a difference
    msg = h.compare(_moves(SIMPLE), mine[:1], "t.nc")
    assert "rs274 has 2 motions, nctrans 1" in msg and "ARC_FEED" in msg
    far = [h.Motion.of(_rec("rapid", o, {"X": 1.002, "Y": 0.0, "Z": 0.0}, 2))]
    msg = h.compare(_moves(SIMPLE)[:2], far, "t.nc")
    assert "end.X differs by 0.002000 mm" in msg


def test_tool_table_is_written_in_inches(tmp_path):
    path = h.write_tool_table(tmp_path / "t.tbl", [(1, 50.8, 0.254), (12, 0.0, 0.0)])
    lines = path.read_text().splitlines()
    assert lines[0].split()[:4] == ["T1", "P1", "Z2.000000000", "D0.020000000"]
    assert lines[1].startswith("T12 P12 Z0.000000000 D0.000000000")


# ------------------------------------------------------------------ live rs274 on small programs

def _live(tmp_path, text, tools=((1, 0.0, 0.0),)):
    prog = tmp_path / "p.ngc"
    prog.write_text(text)
    tbl = h.write_tool_table(tmp_path / "t.tbl", tools)
    run = h.run_rs274(prog, tbl, tmp_path / "p.out")
    assert run.completed, run.message
    return run


@pytest.mark.rs274
def test_live_g10_rotation_g92_g53_inch(rs274, tmp_path):
    run = _live(tmp_path, """G20 G90 G17
G10 L2 P1 X1 Y2 Z-3 R90
G54
G0 X1 Y0 Z0
G92 X0 Y0
G0 X1 Y1
G53 G0 X0.5 Y0.25 Z0
G92.1
G0 X0 Y0 Z0
M30
""")
    ends = [m.end for m in run.moves]
    _close(ends[0], {"X": 1 * IN, "Y": 3 * IN, "Z": -3 * IN}, 1e-6)      # rot90(1,0)+(1,2,-3)
    _close(ends[1], {"X": 0.0, "Y": 4 * IN, "Z": -3 * IN}, 1e-6)         # rot90((1,1)+(1,0))+(1,2)
    _close(ends[2], {"X": 0.5 * IN, "Y": 0.25 * IN, "Z": 0.0}, 0.00006 * IN * 3)  # G53 round trip
    _close(ends[3], {"X": 1 * IN, "Y": 2 * IN, "Z": -3 * IN}, 1e-6)      # G92 cleared
    assert run.moves[1].start == run.moves[0].end


@pytest.mark.rs274
def test_live_tool_length_g52_g53_mm(rs274, tmp_path):
    run = _live(tmp_path, """G21 G90 G17
T3 M6
G43 H3
G0 X0 Y0 Z10
G91 G1 Z-5 F100
G90 G49
G0 Z10
G52 X5 Y6 Z7
G0 X0 Y0 Z0
G53 G0 X1 Y2 Z3
M2
""", tools=((3, 12.7, 1.27),))
    zs = [m.end["Z"] for m in run.moves]
    assert zs == pytest.approx([22.7, 17.7, 10.0, 7.0, 3.0], abs=1e-6)
    _close(run.moves[3].end, {"X": 5.0, "Y": 6.0}, 1e-6)
    _close(run.moves[4].end, {"X": 1.0, "Y": 2.0}, 1e-6)
    # G43 itself does not move the machine: the next move starts where the last one ended
    assert run.moves[0].start == {"X": 0.0, "Y": 0.0, "Z": 0.0, "A": 0.0, "B": 0.0, "C": 0.0}


@pytest.mark.rs274
def test_live_arcs_in_three_planes_and_helix(rs274, tmp_path):
    run = _live(tmp_path, """G21 G90 G17 F100
G10 L2 P2 X100 Y200 Z300
G55
G0 X0 Y0 Z0
G2 X10 Y0 I5 J0
G18 G3 X20 Z0 I5 K0
G19 G2 Y10 Z0 J5 K0
G17 G3 X20 Y10 Z-5 I-5 J0 P2
M2
""")
    rapid, xy, zx, yz, helix = run.moves
    _close(rapid.end, {"X": 100, "Y": 200, "Z": 300}, 1e-6)
    assert (xy.plane, xy.direction, xy.turns) == ("XY", "cw", 0)
    _close(xy.end, {"X": 110, "Y": 200, "Z": 300}, 1e-6)
    _close(xy.center, {"X": 105, "Y": 200}, 1e-6)
    assert (zx.plane, zx.direction, zx.turns) == ("ZX", "ccw", 0)
    _close(zx.end, {"X": 120, "Y": 200, "Z": 300}, 1e-6)
    _close(zx.center, {"X": 115, "Z": 300}, 1e-6)
    assert (yz.plane, yz.direction, yz.turns) == ("YZ", "cw", 0)
    _close(yz.end, {"X": 120, "Y": 210, "Z": 300}, 1e-6)
    _close(yz.center, {"Y": 205, "Z": 300}, 1e-6)
    assert (helix.plane, helix.direction, helix.turns) == ("XY", "ccw", 1)
    _close(helix.end, {"X": 120, "Y": 210, "Z": 295}, 1e-6)
    _close(helix.center, {"X": 115, "Y": 210}, 1e-6)
    assert helix.start == yz.end


@pytest.mark.rs274
def test_live_units_switch_keeps_offsets_in_mm(rs274, tmp_path):
    # offsets set in mm stay put when the program switches to inches (rs274 does not reprint them)
    run = _live(tmp_path, """G21 G90
G10 L2 P1 X25.4 Y50.8
G54
G0 X0 Y0
G20
G0 X1 Y0
G92 X0
G0 X1
G21
G0 X0
M2
""")
    xs = [m.end["X"] for m in run.moves]
    assert xs == pytest.approx([25.4, 50.8, 76.2, 50.8], abs=1e-6)
    assert all(m.end["Y"] == pytest.approx(50.8, abs=1e-6) for m in run.moves)


@pytest.mark.rs274
def test_live_cutter_comp_uses_table_radius(rs274, tmp_path):
    # D0.5 in the table is a diameter in inches: radius 0.25 in = 6.35 mm, left of a +X move
    run = _live(tmp_path, """G20 G90 G17
T2 M6
G0 X-1 Y-1 Z1
G41 D2 G1 X0 Y0 F10
G1 X2
G40 G1 X3 Y-1
M2
""", tools=((2, 0.0, 6.35),))
    ys = [round(m.end["Y"], 4) for m in run.moves if m.kind == "linear" and abs(m.end["X"] - 2 * IN) < 1e-6]
    assert 6.35 in ys


def test_rotation_math_sanity():
    st = h._State()
    st.rotation = 30.0
    p = st.to_machine({"X": 1.0, "Y": 0.0, "Z": 0.0, "A": 0.0, "B": 0.0, "C": 0.0})
    assert (p["X"], p["Y"]) == pytest.approx((math.cos(math.pi / 6), 0.5))
