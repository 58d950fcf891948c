"""Contour corner elements as motion (interp/corner_elements.py, interp/corners.py): Sinumerik
RND/RNDM/CHF/CHR with FRC/FRCM, ISO `,R`/`,C`. Expected points are computed by hand in the
comments (a 10 x 10 square from the origin unless said otherwise)."""
from __future__ import annotations

import math

import pytest
from hypothesis import assume, given, settings, strategies as st

import nctrans
from nctrans import api
from nctrans.machine import Axis, Machine, Tool

import rs274 as h

HEAD = "G17 G90 G0 X0 Y0 Z0 F1000\n"


def run(text: str, dialect: str = "sinumerik"):
    tp = nctrans.toolpath(text, dialect)
    recs = list(tp)
    return recs, tp.diagnostics


def moves(recs):
    return [r for r in recs if r.kind in ("rapid", "linear", "arc")]


def pt(p, nd=4):
    return (round(p["X"], nd), round(p["Y"], nd))


def path(recs, nd=4):
    """(kind, end X, end Y, centre or None) of each move after the first rapid."""
    return [(r.kind, *pt(r.end, nd), pt(r.center, nd) if r.kind == "arc" else None)
            for r in moves(recs)[1:]]


def bad(diags):
    return [(d.rule, d.line) for d in diags if d.severity in ("warning", "error")]


# ------------------------------------------------------------------ hand-computed line/line cases

def test_rnd_between_two_lines_is_the_tangent_arc():
    # +X then +Y, a left turn: the radius-2 arc is tangent to y=0 at (8,0) and to x=10 at (10,2),
    # centre (8,2), counter-clockwise; the second line starts at its end
    recs, diags = run(HEAD + "G1 X10 RND=2\nY10\nM30\n")
    assert path(recs) == [("linear", 8.0, 0.0, None), ("arc", 10.0, 2.0, (8.0, 2.0)),
                          ("linear", 10.0, 10.0, None)]
    arc = moves(recs)[2]
    assert arc.direction == "ccw" and arc.line == 2 and arc.feed == 1000.0
    assert bad(diags) == []


def test_rnd_on_a_right_turn_is_clockwise():
    # +X then -Y: the arc's centre is below the first line, (8,-2), clockwise, ends at (10,-2)
    recs, _ = run(HEAD + "G1 X10 RND=2\nY-10\nM30\n")
    assert path(recs)[:2] == [("linear", 8.0, 0.0, None), ("arc", 10.0, -2.0, (8.0, -2.0))]
    assert moves(recs)[2].direction == "cw"


def test_rnd_on_an_obtuse_corner():
    # +X then 45 degrees up-left... here up-right at 45 deg: deflection 45 deg, the tangent points
    # lie r*tan(22.5 deg) = 2 * 0.414214 = 0.828427 from the corner (10,0) on each line
    recs, _ = run(HEAD + "G1 X10 RND=2\nX20 Y10\nM30\n")
    d = 2 * math.tan(math.radians(22.5))
    (k1, x1, y1, _), (k2, x2, y2, c), _ = path(recs, 6)
    assert (k1, k2) == ("linear", "arc")
    assert (x1, y1) == (round(10 - d, 6), 0.0)
    assert (x2, y2) == (round(10 + d / math.sqrt(2), 6), round(d / math.sqrt(2), 6))
    assert c == (round(10 - d, 6), 2.0)


def test_chr_is_the_leg_and_chf_the_chamfer_length():
    # CHR=1: the chamfer from (9,0) to (10,1); CHF=2 at a right angle: legs 2/sqrt(2) = 1.414214
    recs, _ = run(HEAD + "G1 X10 CHR=1\nY10\nM30\n")
    assert path(recs) == [("linear", 9.0, 0.0, None), ("linear", 10.0, 1.0, None),
                          ("linear", 10.0, 10.0, None)]
    recs, _ = run(HEAD + "G1 X10 CHF=2\nY10\nM30\n")
    leg = round(2 / math.sqrt(2), 6)
    assert path(recs, 6)[:2] == [("linear", round(10 - leg, 6), 0.0, None), ("linear", 10.0, leg, None)]
    a, b = moves(recs)[2].start, moves(recs)[2].end
    assert math.dist(pt(a, 9), pt(b, 9)) == pytest.approx(2.0, abs=1e-9)


def test_line_into_an_arc_rounding():
    # line (0,0)->(10,0), then G2 from (10,0) to (20,0) about (15,0) (R5, up through (15,5)):
    # a left turn of 90 deg. Fillet r=1: the line offset to y=1 meets the arc offset to R6
    # (cw arc, left side = outside): (x-15)^2 + 1 = 36, x = 15 - sqrt(35) = 9.083920; the foot on
    # the arc is (15,0) + 5 * (-sqrt(35), 1) / 6 = (10.069934, 0.833333)
    recs, diags = run(HEAD + "G1 X10 RND=1\nG2 X20 Y0 I5 J0\nM30\n")
    x = 15 - math.sqrt(35)
    foot = (15 - 5 * math.sqrt(35) / 6, 5 / 6)
    got = path(recs, 6)
    assert got[0] == ("linear", round(x, 6), 0.0, None)
    assert got[1] == ("arc", round(foot[0], 6), round(foot[1], 6), (round(x, 6), 1.0))
    assert got[2] == ("arc", 20.0, 0.0, (15.0, 0.0))
    assert moves(recs)[2].direction == "ccw" and moves(recs)[3].direction == "cw"
    assert bad(diags) == []


def test_chamfer_between_two_arcs_lies_on_both():
    # two ccw quarter circles R10 about (0,0) then about (20,0)... here: G3 from (10,0) to (0,10)
    # about the origin, then G2 from (0,10) to (-10,20) about (-10,10) (a right turn at (0,10)).
    # CHR=2: the chamfer's ends are 2 from the corner, on each circle
    text = ("G17 G90 G0 X10 Y0 Z0 F1000\nG3 X0 Y10 I-10 J0 CHR=2\nG2 X-10 Y20 I-10 J0\nM30\n")
    recs, _ = run(text)
    first, chamfer, second = moves(recs)[1:4]
    p1, p2 = pt(chamfer.start, 9), pt(chamfer.end, 9)
    assert math.dist(p1, (0, 10)) == pytest.approx(2) and math.dist(p2, (0, 10)) == pytest.approx(2)
    assert math.hypot(*p1) == pytest.approx(10)                      # on the first circle
    assert math.dist(p2, (-10, 10)) == pytest.approx(10)             # on the second
    assert pt(first.end, 9) == p1 and pt(second.start, 9) == p2


# ------------------------------------------------------------------ modal, feeds, ISO

def test_rndm_rounds_every_corner_until_rndm0():
    # square with RNDM=1 from the first side: corners (10,0), (10,10) rounded; RNDM=0 in the block
    # to (0,10) leaves its end (the corner at (0,10)) sharp
    recs, _ = run(HEAD + "G1 X10 RNDM=1\nY10\nX0 RNDM=0\nY0\nM30\n")
    assert [r.kind for r in moves(recs)[1:]] == ["linear", "arc", "linear", "arc", "linear", "linear"]
    assert [pt(r.end) for r in moves(recs)[1:]] == [(9, 0), (10, 1), (10, 9), (9, 10), (0, 10), (0, 0)]


def test_frc_frcm_and_the_next_blocks_feed():
    # no FRC: the element runs at the F of the block leading away (F500 on line 3)
    recs, _ = run(HEAD + "G1 X10 RND=2\nY10 F500\nM30\n")
    assert [r.feed for r in moves(recs)[1:]] == [1000.0, 500.0, 500.0]
    # FRC: this element only; FRCM: every element until FRCM=0
    recs, _ = run(HEAD + "G1 X10 RND=2 FRC=50\nY10\nX0 RND=1 FRCM=70\nY0 CHR=1\nX5 RND=1 FRCM=0\nY5\nM30\n")
    # the element is the second record of the block that leads to it
    by_line: dict = {}
    for r in moves(recs)[1:]:
        by_line.setdefault(r.line, []).append(r)
    elements = [(line, rs[1].kind, rs[1].feed) for line, rs in by_line.items() if len(rs) == 2]
    assert elements == [(2, "arc", 50.0), (4, "arc", 70.0), (5, "linear", 70.0), (6, "arc", 1000.0)]
    assert [r.feed for r in by_line[3]] == [1000.0]


def test_iso_comma_r_and_comma_c():
    text = "G17 G90 G00 X0 Y0 Z0\nG01 X10. F1000. ,R2.\nY10. ,C1.\nX0.\nM30\n"
    recs, diags = run(text, "iso-m")
    assert path(recs) == [("linear", 8.0, 0.0, None), ("arc", 10.0, 2.0, (8.0, 2.0)),
                          ("linear", 10.0, 9.0, None), ("linear", 9.0, 10.0, None),
                          ("linear", 0.0, 10.0, None)]
    assert bad(diags) == []


def test_iso_t_comma_r_on_the_lathe_plane():
    # G18 (ZX), X in diameter: down -Z at X radius 10 to Z-10, then out +X to radius 20: the R2
    # arc is tangent at (X10, Z-8) and (X12, Z-10), centre (X12, Z-8)
    text = "G18 G21 G99\nT0101\nG00 X20. Z2.\nG01 Z-10. F0.2 ,R2.\nX40.\nM30\n"
    recs, diags = run(text, "iso-t")
    arc = [r for r in recs if r.kind == "arc"][0]
    assert (arc.start["X"], arc.start["Z"], arc.end["X"], arc.end["Z"]) == (10.0, -8.0, 12.0, -10.0)
    assert (arc.center["X"], arc.center["Z"]) == (12.0, -8.0)
    assert bad(diags) == []


# ------------------------------------------------------------------ not inserted: said

def test_next_block_not_a_contour_move():
    recs, diags = run(HEAD + "G1 X10 RND=2\nG0 Z20\nM30\n")
    assert pt(moves(recs)[1].end) == (10, 0)
    assert bad(diags) == [("NC217", 2)]
    recs, diags = run("G17 G90 G00 X0 Y0 Z0\nG01 X10. F100. ,R2.\nG00 Z20.\nM30\n", "iso-m")
    assert pt(moves(recs)[1].end) == (10, 0)
    assert bad(diags) == [("NC218", 2)] and diags[-1].severity == "error" or \
        ("NC218", 2) in bad(diags)


def test_blocks_without_motion_between():
    # Sinumerik: up to three blocks without motion may stand between; their records come after
    # the element, before the next contour move
    recs, diags = run(HEAD + "G1 X10 RND=2\nM8\nY10\nM30\n")
    assert [r.kind for r in recs[1:5]] == ["linear", "arc", "coolant", "linear"]
    assert bad(diags) == []
    recs, diags = run(HEAD + "G1 X10 RND=2\nM8\nM9\nM8\nM9\nY10\nM30\n")
    assert [r.kind for r in recs[1:3]] == ["linear", "coolant"] and pt(recs[1].end) == (10, 0)
    assert bad(diags) == [("NC217", 2)]
    # ISO: the next block must move (seed L4000-4004)
    recs, diags = run("G17 G90 G00 X0 Y0 Z0\nG01 X10. F100. ,R2.\nM08\nY10.\nM30\n", "iso-m")
    assert ("NC218", 2) in bad(diags) and pt(moves(recs)[1].end) == (10, 0)


def test_too_large_and_negative_values():
    # RND=20 at the 90 degree corner of a 10 mm and a 5 mm line: a rounding r touches each line r
    # from the corner, so it fits up to r = min(10, 5) = 5: the control reduces it [GK], nctrans
    # to the largest that fits (NC229): from (5, 0) about (5, 5) to (10, 5), ccw
    recs, diags = run(HEAD + "G1 X10 RND=20\nY5\nM30\n")
    ms = moves(recs)[1:]
    assert [pt(r.end) for r in ms if r.kind != "linear" or pt(r.start) != pt(r.end)] == [(5, 0), (10, 5)]
    arc = next(r for r in ms if r.kind == "arc")
    assert pt(arc.center) == (5, 5) and arc.direction == "ccw"
    (d,) = [d for d in diags if d.rule == "NC229"]
    assert d.line == 2 and d.severity == "warning" and "RND=20" in d.message and "at 5 " in d.message
    assert not [d for d in diags if d.rule in ("NC217", "NC219")]
    # CHF=20 (the chamfer's own length): equal legs L make a chamfer L * sqrt 2 long; L fits up to
    # 5, so the chamfer is 5 * sqrt 2 = 7.0710678, taken at the control's 0.001 mm: 7.071
    # (legs 7.071 / sqrt 2 = 4.99995 from the corner)
    recs, diags = run(HEAD + "G1 X10 CHF=20\nY5\nM30\n")
    (d,) = [d for d in diags if d.rule == "NC229"]
    assert "CHF=20" in d.message and "at 7.071 " in d.message
    ends = [pt(r.end, 6) for r in moves(recs)[1:]]
    assert ends[:2] == [(round(10 - 7.071 / math.sqrt(2), 6), 0), (10, round(7.071 / math.sqrt(2), 6))]
    # lines meeting at 45 degrees (turning by 135): (0, 0) -> (10, 0) -> (0, 10); a rounding r
    # touches them r / tan(22.5) = 2.414214 r from the corner, so r fits up to 10 tan(22.5) =
    # 4.1421356 (the first line is the shorter, 10 against 14.14): 4.142
    _, diags = run(HEAD + "G1 X10 RND=20\nX0 Y10\nM30\n")
    (d,) = [d for d in diags if d.rule == "NC229"]
    assert "at 4.142 " in d.message
    recs, diags = run(HEAD + "G1 X10 RND=-2\nY5\nM30\n")
    assert [pt(r.end) for r in moves(recs)[1:]] == [(10, 0), (10, 5)]
    assert ("NC120", 2) in bad(diags)


def test_out_of_plane_and_word_without_move():
    recs, diags = run(HEAD + "G1 X10 RND=2\nY10 Z-1\nM30\n")
    assert pt(moves(recs)[1].end) == (10, 0) and bad(diags) == [("NC217", 2)]
    recs, diags = run(HEAD + "RND=2\nG1 X10\nY10\nM30\n")
    assert ("NC217", 2) in bad(diags) and len(moves(recs)) == 3


def test_rounding_under_cutter_compensation_rounds_the_programmed_contour():
    # G41 with a radius-1 tool: the offset path of the R3 rounding is
    # an arc of radius 3 - 1 = 2 on the inside of a left turn, about the same centre (7,3)
    ax = Axis(min=-500.0, max=500.0)
    machine = Machine(name="m", kind="mill", axes={"X": ax, "Y": ax, "Z": ax},
                      tools=[Tool(number=1, length=0.0, radius=1.0)])
    text = "G17 G90 G0 X-10 Y0 Z0 F1000 T1 M6 D1\nG41 G1 X0 Y0\nX10 RND=3\nY10\nG40 X20 Y20\nM30\n"
    recs = list(nctrans.toolpath(text, "sinumerik", machine))
    arcs = [r for r in recs if r.kind == "arc" and r.line == 3]
    assert arcs, [r.kind for r in recs]
    a = arcs[-1]
    assert pt(a.center) == (7.0, 3.0)
    assert math.dist(pt(a.start, 9), (7, 3)) == pytest.approx(2.0)
    assert math.dist(pt(a.end, 9), (7, 3)) == pytest.approx(2.0)


# ------------------------------------------------------------------ property

@settings(max_examples=60, deadline=None)
@given(st.floats(-170, 170).filter(lambda a: abs(a) > 5), st.floats(5, 40), st.floats(5, 40),
       st.floats(0.1, 4), st.booleans())
def test_rounded_corner_is_continuous_tangent_and_inside_the_corner(turn, a, b, r, chamfer):
    """Two lines meeting at (a, 0) with a turn of `turn` degrees: the rounded (or chamfered)
    path is continuous, the arc is tangent to both lines, and the element stays in the triangle
    of the corner and its two tangent points."""
    a, r = round(a, 6), round(r, 4)
    t = math.radians(turn)
    end = (round(a + b * math.cos(t), 6), round(b * math.sin(t), 6))
    t = math.atan2(end[1], end[0] - a)          # the turn as written
    word = f"CHR={r}" if chamfer else f"RND={r}"
    text = f"G17 G90 G0 X0 Y0 Z0 F1000\nG1 X{a} {word}\nX{end[0]} Y{end[1]}\nM30\n"
    recs, diags = run(text)
    assume(not bad(diags))
    ms = moves(recs)[1:]
    assert len(ms) == 3
    for prev, nxt in zip(ms, ms[1:]):                     # continuous
        assert math.dist(pt(prev.end, 9), pt(nxt.start, 9)) < 1e-9
    p1, p2 = pt(ms[1].start, 9), pt(ms[1].end, 9)
    corner = (a, 0.0)
    assert p1[1] == pytest.approx(0, abs=1e-9) and 0 <= p1[0] <= a + 1e-9
    if chamfer:
        assert ms[1].kind == "linear"
        assert math.dist(p1, corner) == pytest.approx(r, abs=1e-6)
        assert math.dist(p2, corner) == pytest.approx(r, abs=1e-6)
        return
    arc = ms[1]
    c = pt(arc.center, 9)
    assert math.dist(c, p1) == pytest.approx(r, abs=1e-6) and math.dist(c, p2) == pytest.approx(r, abs=1e-6)
    # tangent: the radius at each end is perpendicular to its line
    d1 = (1.0, 0.0)
    d2 = (math.cos(t), math.sin(t))
    assert abs((p1[0] - c[0]) * d1[0] + (p1[1] - c[1]) * d1[1]) < 1e-6
    assert abs((p2[0] - c[0]) * d2[0] + (p2[1] - c[1]) * d2[1]) < 1e-6
    # inside the corner: the arc's middle lies in the triangle p1, corner, p2
    ang1 = math.atan2(p1[1] - c[1], p1[0] - c[0])
    ang2 = math.atan2(p2[1] - c[1], p2[0] - c[0])
    da = (ang2 - ang1 + math.pi) % (2 * math.pi) - math.pi
    mid = (c[0] + r * math.cos(ang1 + da / 2), c[1] + r * math.sin(ang1 + da / 2))

    def side(o, p, q):
        return (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0])
    s = [side(p1, corner, mid), side(corner, p2, mid), side(p2, p1, mid)]
    assert all(x >= -1e-9 for x in s) or all(x <= 1e-9 for x in s)


# ------------------------------------------------------------------ conversions

SIN = (HEAD + "G1 X10 RND=2\nY10 CHR=1\nG3 X0 Y10 CR=5 RND=1\nG1 Y0\nM30\n")


def test_sinumerik_rnd_chr_to_iso_comma_words_equivalent():
    conv = api.transpile(SIN, "sinumerik", "iso-m")
    assert conv.text is not None
    body = conv.text
    assert "X10. ,R2." in body and "Y10. ,C1." in body and ",R1." in body
    assert conv.lowered == []
    assert api.equiv(SIN, body, read_a="sinumerik", read_b="iso-m")


def test_iso_comma_words_to_sinumerik_equivalent():
    iso = "G17 G90 G00 X0 Y0 Z0\nG01 X10. F1000. ,R2.\nY10. ,C1.\nX0.\nM30\n"
    conv = api.transpile(iso, "iso-m", "sinumerik")
    assert "RND=2" in conv.text and "CHR=1" in conv.text
    assert api.equiv(iso, conv.text, read_a="iso-m", read_b="sinumerik")


def test_chf_and_rndm_to_iso_are_lowered_with_their_partner_blocks():
    text = HEAD + "G1 X10 RND=2\nY10 CHF=1.5\nX0 RNDM=1\nY0\nX5 RNDM=0\nG0 Z10\nM30\n"
    conv = api.transpile(text, "sinumerik", "iso-m")
    assert conv.text is not None and "CHF" not in conv.text and "RNDM" not in conv.text
    assert any(d.rule == "NC401" for d in conv.lowered)
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m")


@pytest.mark.rs274
def test_flattened_corners_run_in_rs274(rs274, tmp_path):
    """LinuxCNC has no ,R: --flatten writes the elements as arcs and lines it runs as nctrans
    means them."""
    text = HEAD + "G1 X10 RND=2\nY10 CHF=1.5\nG3 X0 Y10 CR=5 RND=1\nG1 Y0 CHR=1\nX5\nM30\n"
    out = api.transpile(text, "sinumerik", "iso-m", flatten=True).text
    prog = tmp_path / "corners.ngc"
    prog.write_text(out)
    run_ = h.run_rs274(prog, h.write_tool_table(tmp_path / "t.tbl", [(1, 0.0, 0.0)]), tmp_path / "o.out")
    assert run_.completed, run_.message
    ours = [r for r in nctrans.toolpath(text, "sinumerik") if r.kind in ("linear", "arc", "rapid")
            and r.start != r.end]
    theirs = [m for m in run_.moves if not h.is_zero_move(m)]
    assert len(theirs) == len(ours)
    for r, m in zip(ours, theirs):
        assert m.kind == r.kind
        assert math.dist(pt(r.end, 6), (m.end["X"], m.end["Y"])) < 1e-3


@settings(max_examples=60, deadline=None)
@given(st.floats(-150, 150).filter(lambda a: abs(a) > 5), st.floats(5, 30), st.booleans(),
       st.floats(40, 150), st.floats(0.2, 3))
def test_rounding_into_an_arc_is_tangent_to_both(turn, radius, cw, sweep, r):
    """A line along +X to (20, 0), then an arc leaving at `turn` degrees: the rounding starts on
    the line with its centre straight above or below, ends on the circle, touching it (the two
    centres and the touching point in one line), and the path is continuous."""
    radius, sweep, r = round(radius, 3), round(sweep, 3), round(r, 3)
    t = math.radians(turn)
    u = (math.cos(t), math.sin(t))
    left = (-u[1], u[0])
    side = -1.0 if cw else 1.0
    centre = (20 + side * radius * left[0], side * radius * left[1])
    a0 = math.atan2(-centre[1], 20 - centre[0])
    a1 = a0 + math.radians(sweep) * (-1.0 if cw else 1.0)
    end = (round(centre[0] + radius * math.cos(a1), 6), round(centre[1] + radius * math.sin(a1), 6))
    i, j = round(centre[0] - 20, 6), round(centre[1], 6)
    text = (f"G17 G90 G0 X0 Y0 Z0 F1000\nG1 X20 RND={r}\n{'G2' if cw else 'G3'} X{end[0]} Y{end[1]} "
            f"I{i} J{j}\nM30\n")
    recs, diags = run(text)
    assume(not bad(diags))
    ms = moves(recs)[1:]
    assert [m.kind for m in ms] == ["linear", "arc", "arc"]
    for prev, nxt in zip(ms, ms[1:]):
        assert math.dist(pt(prev.end, 9), pt(nxt.start, 9)) < 1e-9
    fillet, arc = ms[1], ms[2]
    fc, p1, p2 = pt(fillet.center, 9), pt(fillet.start, 9), pt(fillet.end, 9)
    ac = pt(arc.center, 9)
    assert p1[1] == pytest.approx(0, abs=1e-9) and 0 < p1[0] <= 20 + 1e-9
    assert fc[0] == pytest.approx(p1[0], abs=1e-6) and abs(fc[1]) == pytest.approx(r, abs=1e-6)
    assert math.dist(fc, p2) == pytest.approx(r, abs=1e-6)
    assert math.dist(ac, p2) == pytest.approx(math.dist(ac, (20, 0)), abs=1e-6)
    cross = (p2[0] - fc[0]) * (p2[1] - ac[1]) - (p2[1] - fc[1]) * (p2[0] - ac[0])
    assert abs(cross) < 1e-6 * max(1.0, radius)
    # the fillet turns the same way as the corner
    assert fillet.direction == ("ccw" if turn > 0 else "cw")


def test_blocks_between_lower_the_pair_for_iso():
    # Sinumerik allows an M8 block between; ISO needs the contour move in the very next block, so
    # the rounding and both blocks become the arc and lines it inserts
    text = HEAD + "G1 X10 RND=2\nM8\nY10\nM30\n"
    conv = api.transpile(text, "sinumerik", "iso-m")
    assert ",R" not in conv.text and "G3 X10. Y2. I0. J2." in conv.text
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m")


LATHE = Machine(name="lathe", kind="lathe",
                axes={"X": Axis(min=-300.0, max=300.0), "Z": Axis(min=-400.0, max=300.0)},
                tools=[Tool(number=1, length=0.0, radius=0.0)])


def test_corners_of_a_turning_cycle_contour_are_machined():
    # CYCLE95 contour (X diameter): X20 Z0 -> Z-20 RND=2 -> X40 CHR=1 -> Z-40. In radius the
    # rounding runs (10,-18) -> (12,-20) about (12,-18), the chamfer (19,-20) -> (20,-21); the
    # roughing passes keep FALZ 0.2 along Z and FALX 0.1 in X: +0.1 in X, +0.2 in Z
    text = ("G18 G90 G95 DIAMON\nT1 D1\nG0 X60 Z5 S1000 M3\n"
            "CYCLE95(\"KONT:KONTE\", 2, 0.2, 0.1, , 0.3, 0.2, 0.1, 1, , , 1)\nG0 X100 Z100\nM30\n"
            "KONT:\nG1 X20 Z0\nZ-20 RND=2\nX40 CHR=1\nZ-40\nKONTE:\n")
    tp = nctrans.toolpath(text, "sinumerik", LATHE)
    recs = list(tp)
    assert [d for d in tp.diagnostics if d.severity != "info"] == []

    def xz(p):
        return (round(p["X"], 6), round(p["Z"], 6))
    arcs = [(xz(r.start), xz(r.end), xz(r.center)) for r in recs if r.kind == "arc"]
    assert ((10.1, -17.8), (12.1, -19.8), (12.1, -17.8)) in arcs
    lines = [(xz(r.start), xz(r.end)) for r in recs if r.kind == "linear"]
    assert ((19.1, -19.8), (20.1, -20.8)) in lines
