"""Sinumerik CYCLE93, grooving (issue 8, nctrans/interp/grooving.py): hand-computed cases, the
refusals, a property over random grooves, conversion to ISO turning.

Expected values are worked out by hand from the model in the module docstring (facts [GK] of the
Siemens turning cycles manual, choices [NC]): the path is the first cutting edge's; plunges equally
spaced at most the tool width apart from the starting point's side, equal infeeds of at most IDEP
with a _VRT back-off, a dwell DTB at the bottom; then the profile from each edge to the middle."""
from __future__ import annotations

import math

import pytest
from hypothesis import given, settings, strategies as st

from nctrans import api, pipeline
from nctrans.interp.grooving import groove_passes, groove_steps
from nctrans.interp.milling_cycles import MillingError
from nctrans.machine import Tool, default_lathe
from nctrans.source import from_text


def _lathe(width: float | None = 3.0):
    m = default_lathe()
    m.tools = [Tool(1, width=width)]
    return m


def _text(call: str) -> str:
    return f"G18 G90 DIAMON T1 D1\nS500 M3 G95 F0.1\nG0 X50 Z10\n{call}\nG0 X60\nM30\n"


def _run(call: str, width: float | None = 3.0):
    text = _text(call)
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld, _lathe(width)) if r.line == 4]
    got = []
    for r in recs:
        if r.kind == "dwell":
            got.append(("dwell", r.dwell_s))
        elif r.kind in ("rapid", "linear", "arc"):
            got.append((r.kind, round(r.end["X"], 6), round(r.end["Z"], 6)))
    return got, ld.diagnostics, recs


def test_rectangular_groove_from_the_right_by_hand():
    # VARI 5: longitudinal, outside, starting point on the right: the groove runs from Z-10 to Z-18
    # at radius 20 (SPD 40 under DIAMON), 4 deep. Tool 3 wide, FAL1 0.2, FAL2 0.3, IDEP 2, DTB 0.5,
    # _VRT 1. Plunges (first edge) from 0.3 to 8 - 0.3 - 3 = 4.7 in ceil(4.4 / 3) = 2 steps: u 0.3,
    # 2.5, 4.7 (Z -10.3, -12.5, -14.7); depth 4 - 0.2 = 3.8 in two infeeds of 1.9 (radius 18.1, then
    # 16.2), backing off 1 between them. Finishing: the first edge down Z-10 to the base, along it to
    # the middle u 4 (Z-14); the second edge (3 behind: first edge at Z-15) down Z-18 to the middle
    # (first edge at u 4 - 3 = 1, Z-11); back to the start point (21, -10).
    got, diags, recs = _run("CYCLE93(40, -10, 8, 4, 0, 0, 0, 0, 0, 0, 0, 0.2, 0.3, 2, 0.5, 5, 1)")
    assert not [d for d in diags if d.severity != "info"]
    r, f = "rapid", "linear"
    want = [(r, 21, -10)]
    for z in (-10.3, -12.5, -14.7):
        want += [(r, 21, z), (f, 18.1, z), (r, 19.1, z), (f, 16.2, z), ("dwell", 0.5), (r, 21, z)]
    want += [(r, 21, -10), (f, 20, -10), (f, 16, -10), (f, 16, -14), (r, 21, -14),
             (r, 21, -15), (f, 20, -15), (f, 16, -15), (f, 16, -11), (r, 21, -11), (r, 21, -10)]
    want = [w for i, w in enumerate(want) if i == 0 or w != want[i - 1]]     # (no zero-length moves)
    assert got == [w if w[0] == "dwell" else (w[0], pytest.approx(w[1]), pytest.approx(w[2])) for w in want]
    assert all(rec.feed == 0.1 and rec.feed_mode == "per_rev" for rec in recs if rec.kind == "linear")


def test_chamfer_and_radius_corners_by_hand():
    # VARI 11: starting point left (groove from Z-20 towards +Z to Z-10), chamfers by leg (CHR).
    # RCO1 -1: a 1 x 1 chamfer on the outer corner at Z-20; RCI2 1: radius 1 at the base corner at
    # Z-10. Tool 4 wide, no allowances, IDEP 0 (one infeed), _VRT 0 (1 mm). Plunges at u 0, 3, 6;
    # the last spans u 6..10 and stops above the radius: depth 4 - 1 = 3 (radius 17).
    # Finishing, first edge: in at Z-21 (the chamfer's start), the chamfer to (19, -20), down to
    # the base (16), along it to the middle u 5 (Z-15). Second edge (first edge 4 behind it): in at
    # first-edge u 6 (Z-14), down to depth 3 (radius 17), the radius clockwise in the (Z, X) picture
    # to the base (16, -15) about (17, -15), along the base to u 5 - 4 = 1 (Z-19), out, back.
    got, diags, recs = _run("CYCLE93(40, -20, 10, 4, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 11, 0)", width=4.0)
    assert not [d for d in diags if d.severity != "info"]
    r, f = "rapid", "linear"
    want = [(r, 21, -20), (f, 16, -20), (r, 21, -20),
            (r, 21, -17), (f, 16, -17), (r, 21, -17),
            (r, 21, -14), (f, 17, -14), (r, 21, -14),
            (r, 21, -21), (f, 20, -21), (f, 19, -20), (f, 16, -20), (f, 16, -15), (r, 21, -15),
            (r, 21, -14), (f, 20, -14), (f, 17, -14), ("arc", 16, -15), (f, 16, -19), (r, 21, -19),
            (r, 21, -20)]
    assert got == [(k, pytest.approx(x), pytest.approx(z)) for k, x, z in want]
    arc = next(rec for rec in recs if rec.kind == "arc")
    assert (arc.center["X"], arc.center["Z"]) == (pytest.approx(17), pytest.approx(-15))
    assert arc.direction == "cw"


def test_inside_groove_cuts_away_from_the_axis():
    # VARI 3: inside, starting point left; bore radius 15 (SPD 30), 2 deep: base at radius 17, the
    # clearance 1 mm towards the axis (radius 14). Tool 3 = width 3: one plunge, then both edges.
    got, diags, _ = _run("CYCLE93(30, -5, 3, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 3, 0)")
    assert not [d for d in diags if d.severity != "info"]
    r, f = "rapid", "linear"
    want = [(r, 14, -5), (f, 17, -5), (r, 14, -5),
            (f, 15, -5), (f, 17, -5), (r, 14, -5)]          # first edge's finish: down the flank at u 0
    assert got[:len(want)] == [(k, pytest.approx(x), pytest.approx(z)) for k, x, z in want]
    assert max(x for k, x, z in got if k == "linear") == pytest.approx(17)
    assert got[-1] == ("rapid", pytest.approx(14), pytest.approx(-5))


@pytest.mark.parametrize("call, width, rule", [
    ("CYCLE93(40, -10, 8, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 5, 1)", None, "NC113"),    # no tool width
    ("CYCLE93(10, -10, 8, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 2, 1)", 3.0, "NC114"),     # face, past the axis
    ("CYCLE93(40, -10, 8, 4, 0, 0, 90, 0, 0, 0, 0, 0, 0, 2, 0, 6, 1)", 3.0, "NC114"),    # ANG2 90 (< 89.999)
    ("CYCLE93(40, -10, 8, 4, 5, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 5, 1)", 3.0, "NC113"),     # STA1
    ("CYCLE93(40, -10, 8, 4, 0, -10, 0, 0, 0, 0, 0, 0, 0, 2, 0, 5, 1)", 3.0, "NC114"),   # ANG1 < 0
    ("CYCLE93(40, -10, 8, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 9, 1)", 3.0, "NC114"),     # VARI 9
    ("CYCLE93(40, -10, 8, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 25, 1)", 3.0, "NC114"),    # VARI 25
    ("CYCLE93(40, -10, 2, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 5, 1)", 3.0, "NC114"),     # tool too wide
    ("CYCLE93(40, -10, 8, 4, 0, 0, 0, 0, 0, 3, 3, 0, 0, 2, 0, 5, 1)", 3.0, "NC114"),     # flat base < tool
    ("CYCLE93(40, -10, 8, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 5, 1)", 3.0, "NC114"),     # no depth
    ("CYCLE93(40, -10, 8, 4, 0, 0, 0, 0, 0, 0, 0, 4, 0, 2, 0, 5, 1)", 3.0, "NC114"),     # FAL1 = depth
    ("MCALL CYCLE93(40, -10, 8, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 5, 1)", 3.0, "NC113"),
])
def test_what_is_not_modelled_or_alarms_moves_nothing_and_says_so(call, width, rule):
    got, diags, _ = _run(call, width)
    assert got == []
    said = [d for d in diags if d.line == 4 and d.severity != "info"]
    assert [d.rule for d in said] == [rule] and "CYCLE93" in said[0].message


def test_face_groove_in_a_right_hand_face_by_hand():
    # VARI 6: face, outside, starting point on the right: the groove runs from radius 20 (SPD 40
    # under DIAMON) towards the axis to radius 14 (WIDG 6) and goes into the face Z0 towards -Z
    # (DIAG 3); _VRT 1 puts the start point at Z1. Tool 3 wide (its first edge on the outer side),
    # no allowances, IDEP 0: plunges at u 0 and 3 (radius 20 and 17) to Z-3. Finishing: the first
    # edge down the outer flank (radius 20) to the base and along it to the middle (radius 17); the
    # second edge (3 further in) down the inner flank at radius 14 (the first edge at 17) and along
    # the base until the first edge is back at radius 20; out, and the cycle ends at the start point.
    got, diags, _ = _run("CYCLE93(40, 0, 6, 3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 6, 1)")
    assert not [d for d in diags if d.severity != "info"]
    r, f = "rapid", "linear"
    want = [(r, 20, 1), (f, 20, -3), (r, 20, 1), (r, 17, 1), (f, 17, -3), (r, 17, 1),
            (r, 20, 1), (f, 20, 0), (f, 20, -3), (f, 17, -3), (r, 17, 1),
            (f, 17, 0), (f, 17, -3), (f, 20, -3), (r, 20, 1)]
    assert got == [(k, pytest.approx(x), pytest.approx(z)) for k, x, z in want]


def test_inside_face_groove_starting_left_goes_into_plus_z():
    # VARI 4: face, inside (the groove lies away from the axis, towards +X from SPD), starting point
    # on the left (the groove goes into the face Z-5 towards +Z): radius 10 (SPD 20) .. 13, 2 deep
    # (base at Z-3), start point at Z-6. Tool 3 = WIDG: one plunge, then both edges at radius 10.
    got, diags, _ = _run("CYCLE93(20, -5, 3, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 4, 0)")
    assert not [d for d in diags if d.severity != "info"]
    r, f = "rapid", "linear"
    want = [(r, 10, -6), (f, 10, -3), (r, 10, -6), (f, 10, -5), (f, 10, -3), (r, 10, -6),
            (f, 10, -5), (f, 10, -3), (r, 10, -6)]
    assert got == [(k, pytest.approx(x), pytest.approx(z)) for k, x, z in want]


def test_face_groove_with_corners_converted_to_iso_turning_is_equivalent():
    text = _text("CYCLE93(40, 0, 8, 3, 0, 0, 0, 0.5, -0.5, 0, 0.5, 0.1, 0.2, 1, 0.2, 16, 0)")
    conv = api.transpile(text, "sinumerik", "iso-t", machine=_lathe(3.0))
    assert conv.text is not None and "CYCLE93" not in conv.text
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-t", machine=_lathe(3.0))


def test_converted_to_iso_turning_is_equivalent():
    text = _text("CYCLE93(40, -20, 10, 4, 0, 0, 0, -1, 0, 0, 1, 0.1, 0.2, 1.5, 0.5, 11, 0)")
    conv = api.transpile(text, "sinumerik", "iso-t", machine=_lathe(4.0))
    assert conv.text is not None and "CYCLE93" not in conv.text
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-t", machine=_lathe(4.0))


def test_flank_angles_widen_the_groove_from_its_base_by_hand():
    # [GK] WIDG is the width at the base, the flanks open outwards by ANG1/ANG2 from the normal of
    # the contour, SPD/SPL is the edge where flank 1 meets the contour. VARI 5 (starting point
    # right: u runs towards -Z from Z-10), radius 20 (SPD 40), WIDG 4, DIAG 3, ANG1 = ANG2 = 45:
    # tan 45 = 1, so the base corners are at u 3 and 7 (depth 3), the other edge at u 10.
    # Roughing (tool 3, no allowances, IDEP 0): plunges from u 0 to 10 - 3 = 7 in ceil(7/3) = 3
    # steps: u 0, 7/3, 14/3, 7; each as deep as the tool's both ends may go: the floor is
    # min(u, 3, 10 - u): u 0 -> min(0, 3) = 0 (none), 7/3 -> min(7/3, 3) = 7/3,
    # 14/3 -> min(3, 10 - 23/3) = 7/3, 7 -> min(3, 0) = 0 (none). Radius 20 - 7/3 = 17.6667.
    # Finishing: first edge from (20, -10) down flank 1 to the base corner (17, -13), along the
    # base to the middle u 5 capped at 7 - 3 = 4 (Z-14), out. Second edge from the other edge u 10
    # (first edge at u 7, Z-17) down flank 2 to u 7 (first edge u 4: (17, -14)), along the base
    # until the second edge is at max(5, 3 + 3) = 6 (first edge u 3, Z-13), out, back to the start.
    got, diags, _ = _run("CYCLE93(40, -10, 4, 3, 0, 45, 45, 0, 0, 0, 0, 0, 0, 0, 0, 5, 1)")
    assert not [d for d in diags if d.severity != "info"]
    r, f, x = "rapid", "linear", 20 - 7 / 3
    want = [(r, 21, -10), (r, 21, -10 - 7 / 3), (f, x, -10 - 7 / 3), (r, 21, -10 - 7 / 3),
            (r, 21, -10 - 14 / 3), (f, x, -10 - 14 / 3), (r, 21, -10 - 14 / 3),
            (r, 21, -10), (f, 20, -10), (f, 17, -13), (f, 17, -14), (r, 21, -14),
            (r, 21, -17), (f, 20, -17), (f, 17, -14), (f, 17, -13), (r, 21, -13), (r, 21, -10)]
    assert got == [(k, pytest.approx(a), pytest.approx(b)) for k, a, b in want]


def test_corners_on_sloping_flanks_by_hand():
    # The groove above with VARI 15 (chamfers by their legs, CHR), RCO1 -1: a chamfer with legs 1
    # on the contour and on flank 1: from u -1 (Z-9) to (sin 45, cos 45) = (0.707107, 0.707107),
    # i.e. radius 20 - 0.707107 = 19.292893 at Z -10.707107. RCI2 1: a rounding at base corner 2
    # (u 7, depth 3), where flank and base turn by 45 degrees: its tangent points lie
    # tan(22.5) = 0.414214 from the corner: on flank 2 at (7.292893, 2.707107), on the base at
    # (6.585786, 3); centre (6.585786, 2). The flat base now ends at 6.585786: the first edge
    # stops at 6.585786 - 3 = 3.585786 (Z-13.585786). The second edge goes down flank 2 to the
    # tangent point (first edge at u 4.292893: radius 17.292893, Z-14.292893), round the corner
    # to (first edge) u 3.585786 at the base about u 3.585786, depth 2 (radius 18), along the base
    # to u 3 (Z-13). Roughing is that of the groove above (the plunges do not reach the corners).
    got, diags, recs = _run("CYCLE93(40, -10, 4, 3, 0, 45, 45, -1, 0, 0, 1, 0, 0, 0, 0, 15, 1)")
    assert not [d for d in diags if d.severity != "info"]
    r, f = "rapid", "linear"
    want = [(r, 21, -9), (f, 20, -9), (f, 19.292893, -10.707107), (f, 17, -13), (f, 17, -13.585786),
            (r, 21, -13.585786),
            (r, 21, -17), (f, 20, -17), (f, 17.292893, -14.292893), ("arc", 17, -13.585786), (f, 17, -13),
            (r, 21, -13), (r, 21, -10)]
    assert got[7:] == [(k, pytest.approx(a, abs=1e-6), pytest.approx(b, abs=1e-6)) for k, a, b in want]
    arc = next(rec for rec in recs if rec.kind == "arc")
    assert (arc.center["X"], arc.center["Z"]) == (pytest.approx(18), pytest.approx(-13.585786))
    # from lower left of the centre to straight below it, in the (Z right, X up) picture: ccw
    assert arc.direction == "ccw"


# ---------------------------------------------------------------------------------------------
# Property: random grooves. Local coordinates: u along the groove from the starting point's edge,
# w the depth. The finished groove is the trapezoid with its base (WIDG) from u D tan ANG1 to that
# + W at depth D and its flanks opening outwards to the contour (w 0), less the material its base
# corners keep, plus what its top corners take off the part. Corner geometry worked out here
# independently of the module: at each corner the two lines meet at 90 + ANG degrees (half angle
# h = 45 + ANG / 2): a rounding r touches them r / tan h from the corner, its centre on the
# bisector r / sin h from it; a chamfer's legs are L (CHR) or c / (2 sin h) (CHF, c its length).


def _inside(poly, p, tol=1e-9) -> bool:
    """p inside the convex polygon `poly` (either orientation)."""
    sides = [(b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
             for a, b in zip(poly, poly[1:] + poly[:1])]
    return all(x >= -tol for x in sides) or all(x <= tol for x in sides)


def _corner_shape(v: float, chr_: bool, corner, d1, d2, ang: float):
    """(kind, leg, zone): the corner element at `corner` between the unit directions d1, d2 of its
    two lines (pointing away from it); zone = the kite or triangle it cuts off."""
    if v == 0:
        return ("none", 0.0, None)
    h = math.radians(45 + ang / 2)
    if v > 0:
        leg = v / math.tan(h)
    else:
        leg = -v if chr_ else -v / (2 * math.sin(h))
    p1 = (corner[0] + leg * d1[0], corner[1] + leg * d1[1])
    p2 = (corner[0] + leg * d2[0], corner[1] + leg * d2[1])
    if v < 0:
        return ("chamfer", leg, (corner, p1, p2))
    bis = (d1[0] + d2[0], d1[1] + d2[1])
    nb = math.hypot(*bis)
    dist = v / math.sin(h)
    centre = (corner[0] + dist * bis[0] / nb, corner[1] + dist * bis[1] / nb)
    return ("radius", leg, (corner, p1, centre, p2), centre, v)


def _groove(W, D, a1, a2, rco1, rco2, rci1, rci2, chr_):
    t1, t2 = math.tan(math.radians(a1)), math.tan(math.radians(a2))
    b1, b2 = D * t1, D * t1 + W
    top2 = b2 + D * t2
    f1 = (math.sin(math.radians(a1)), math.cos(math.radians(a1)))     # flank 1 downwards
    f2 = (-math.sin(math.radians(a2)), math.cos(math.radians(a2)))    # flank 2 downwards
    return dict(W=W, D=D, t1=t1, t2=t2, b1=b1, b2=b2, top2=top2, a1=a1, a2=a2,
                o1=_corner_shape(rco1, chr_, (0.0, 0.0), (-1.0, 0.0), f1, a1),
                o2=_corner_shape(rco2, chr_, (top2, 0.0), (1.0, 0.0), f2, a2),
                i1=_corner_shape(rci1, chr_, (b1, D), (-f1[0], -f1[1]), (1.0, 0.0), a1),
                i2=_corner_shape(rci2, chr_, (b2, D), (-f2[0], -f2[1]), (-1.0, 0.0), a2))


def _in_zone(c, p, tol=1e-6) -> bool:
    """p in the part a corner element cuts off (between the sharp corner and the element)."""
    if c[0] == "none":
        return False
    if c[0] == "chamfer":
        return _inside(list(c[2]), p, -tol)
    return _inside(list(c[2]), p, -tol) and math.dist(p, c[3]) > c[4] + tol


def _air(u: float, w: float, g: dict, tol: float = 1e-6) -> bool:
    """True where no material is left once the groove is finished (outside the part included)."""
    if w <= tol:
        return True
    if w > g["D"] + tol:
        return False
    in_trapezoid = w * g["t1"] - tol <= u <= g["top2"] - w * g["t2"] + tol
    if not in_trapezoid:                            # the part, unless a top corner took it off
        return _in_zone(g["o1"], (u, w), -tol) or _in_zone(g["o2"], (u, w), -tol)
    return not (_in_zone(g["i1"], (u, w)) or _in_zone(g["i2"], (u, w)))


corner = st.one_of(st.just(0.0), st.floats(-2, -0.1), st.floats(0.1, 2))
angle = st.one_of(st.just(0.0), st.floats(0, 70))


@settings(max_examples=120, deadline=None)
@given(st.floats(2, 30), st.floats(0.5, 12), st.floats(0.3, 1.0), st.floats(0, 0.5), st.floats(0, 0.5),
       st.one_of(st.just(0.0), st.floats(0.2, 5)), st.sampled_from([1, 2, 3, 4, 5, 6, 7, 8, 11, 12, 13, 14, 15, 16, 17, 18]),
       corner, corner, corner, corner, st.floats(0, 2), st.floats(-50, 50), angle, angle)
def test_grooves_stay_in_the_outline_reach_the_depth_and_end_at_the_start(
        W, D, frac, fal1, fal2, idep, vari, rco1, rco2, rci1, rci2, vrt, spl, ang1, ang2):
    tw = W * frac
    p = dict(SPD=20.0, SPL=spl, WIDG=W, DIAG=D, ANG1=ang1, ANG2=ang2, RCO1=rco1, RCO2=rco2, RCI1=rci1,
             RCI2=rci2, FAL1=fal1, FAL2=fal2, IDEP=idep, VARI=vari, VRT=vrt, DTB=0.2)
    chr_ = vari > 10
    g = _groove(W, D, ang1, ang2, rco1, rco2, rci1, rci2, chr_)
    leg = {k: g[k][1] for k in ("o1", "o2", "i1", "i2")}
    c1, c2 = math.cos(math.radians(ang1)), math.cos(math.radians(ang2))
    face = vari % 2 == 0
    s = -1.0 if vari % 10 >= 5 else 1.0
    e = -1.0 if vari % 10 in (3, 4, 7, 8) else 1.0
    try:
        rough, finish = groove_passes(p, tw)
    except MillingError as err:                     # refused only where the groove cannot be cut so
        assert err.rule == "NC114"
        assert (leg["o1"] + leg["i1"] > D / c1 - 1e-9 or leg["o2"] + leg["i2"] > D / c2 - 1e-9
                or leg["i1"] + leg["i2"] > W - 1e-9 or tw > W - leg["i1"] - leg["i2"] - 1e-9
                or tw > W - fal2 / c1 - fal2 / c2 - 1e-9 or fal1 >= D - 1e-9
                or (face and e > 0 and g["top2"] + leg["o2"] > 20.0 - 1e-9))   # an outside face groove past the axis
        return
    v = vrt or 1.0

    def local(xz):
        if face:                                    # u along X away from the start point, w into Z
            return e * (20.0 - xz[0]), s * (xz[1] - spl)
        return s * (xz[1] - spl), e * (20.0 - xz[0])

    start = (20.0, spl - s * v) if face else (20.0 + e * v, spl)
    steps = groove_steps(p, tw)
    assert steps[0] == ("rapid", pytest.approx(start))     # the start point
    assert steps[-1] == ("rapid", pytest.approx(start))    # ... where it ends
    here = local(steps[0][1])
    deepest = 0.0
    for k, step in enumerate(steps):
        if step[0] == "dwell":
            continue
        end = local(step[1])
        if step[0] == "arc":
            cu, cw_ = local(step[2])
            a0 = math.atan2(here[1] - cw_, here[0] - cu)
            a1 = math.atan2(end[1] - cw_, end[0] - cu)
            da = (a1 - a0 + math.pi) % (2 * math.pi) - math.pi         # quarter arcs: the short way
            rad = math.dist(here, (cu, cw_))
            pts = [(cu + rad * math.cos(a0 + da * t / 8), cw_ + rad * math.sin(a0 + da * t / 8)) for t in range(9)]
        else:
            pts = [(here[0] + (end[0] - here[0]) * t / 8, here[1] + (end[1] - here[1]) * t / 8) for t in range(9)]
        for u, w in pts:                            # the tool's cutting line: the first edge .. + width
            for j in range(9):
                assert _air(u + tw * j / 8, w, g), (k, step, u + tw * j / 8, w)
        deepest = max(deepest, end[1])
        here = end
    assert deepest == pytest.approx(D)               # the finishing reaches the base
    # roughing: every plunge cuts at most IDEP deeper than it had reached, and leaves FAL1
    reached, x_here = 0.0, None
    for step in rough:
        if step[0] == "dwell":
            continue
        u, w = local(step[1])
        if step[0] == "rapid" and w < 0 and (x_here is None or abs(u - x_here) > 1e-9):
            reached, x_here = 0.0, u                 # a new plunge
        if step[0] == "linear":
            if idep > 0:
                assert w - reached <= idep + 1e-9
            assert w <= D - fal1 + 1e-9
            reached = max(reached, w)


def test_any_values_plan_or_refuse():
    base = dict(SPD=20.0, SPL=0.0, WIDG=8.0, DIAG=4.0, VARI=5.0, IDEP=1.0)
    assert groove_steps(base, 3.0)
    for bad in (dict(WIDG=float("nan")), dict(IDEP=1e-6), dict(VARI=0.5), dict(DIAG=100.0), dict(VRT=float("inf"))):
        with pytest.raises(MillingError):
            groove_steps(dict(base, **bad), 3.0)


def test_sloping_flanks_with_corners_converted_to_iso_turning_is_equivalent():
    text = _text("CYCLE93(40, -20, 6, 3, 0, 20, 35, 0.5, -0.5, 0.4, -0.3, 0.1, 0.2, 1, 0.2, 15, 0)")
    conv = api.transpile(text, "sinumerik", "iso-t", machine=_lathe(3.0))
    assert conv.text is not None and "CYCLE93" not in conv.text
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-t", machine=_lathe(3.0))


def test_sta1_zero_is_the_paraxial_groove_and_an_inclined_contour_stays_refused():
    # STA1 0 written out is the groove with STA1 omitted (a subprogram sees an omitted argument
    # as 0, seed L4722)
    given, _, _ = _run("CYCLE93(40, -10, 8, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 5, 1)")
    omitted, _, _ = _run("CYCLE93(40, -10, 8, 4, , 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 5, 1)")
    assert given and given == omitted
    # STA1 30 with a 3 mm tool: a base sloping at 30 degrees under a flat blade 3 wide leaves
    # 3 x tan 30 = 1.732 at one end: refused at its line, nothing moves
    got, diags, _ = _run("CYCLE93(40, -10, 8, 4, 30, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 5, 1)")
    assert got == []
    (d,) = [d for d in diags if d.line == 4 and d.severity != "info"]
    assert d.rule == "NC113" and "STA1 30" in d.message and "3 x tan 30" in d.message
