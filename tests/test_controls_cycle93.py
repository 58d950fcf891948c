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
    ("CYCLE93(40, -10, 8, 4, 0, 0, 10, 0, 0, 0, 0, 0, 0, 2, 0, 6, 1)", 3.0, "NC113"),    # ANG2 on a face groove
    ("CYCLE93(40, -10, 8, 4, 5, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 5, 1)", 3.0, "NC113"),     # STA1
    ("CYCLE93(40, -10, 8, 4, 0, 10, 0, 0, 0, 0, 0, 0, 0, 2, 0, 5, 1)", 3.0, "NC113"),    # ANG1
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


# ---------------------------------------------------------------------------------------------
# Property: random grooves. Local coordinates: u along the groove from the starting point's edge,
# w the depth (the finished groove is u in [0, W], w in [0, D] less its rounded/chamfered corners).

def _legs(v: float, chr_: bool) -> float:
    return 0.0 if v == 0 else v if v > 0 else (-v if chr_ else -v / math.sqrt(2))


def _air(u: float, w: float, W: float, D: float, c: dict, tol: float = 1e-6) -> bool:
    """True where no material is left once the groove is finished (outside the part included)."""
    if w <= tol:
        return True
    if w > D + tol:
        return False
    for side, v in ((1, -u), (2, u - W)):            # v > 0: beyond the groove's edge, on the contour
        kind, leg = c[f"o{side}"]
        if v > tol:
            if v > leg + tol or w > leg + tol:
                return False
            if kind == "radius":
                return math.hypot(leg - v, leg - w) >= leg - tol
            return w <= leg - v + tol
    floor = D
    for side, v in ((1, u), (2, W - u)):
        kind, leg = c[f"i{side}"]
        if v < leg:
            floor = D - leg + (math.sqrt(max(leg * leg - (leg - v) ** 2, 0)) if kind == "radius" else v)
    return w <= floor + tol


corner = st.one_of(st.just(0.0), st.floats(-2, -0.1), st.floats(0.1, 2))


@settings(max_examples=80, deadline=None)
@given(st.floats(2, 30), st.floats(0.5, 12), st.floats(0.3, 1.0), st.floats(0, 0.5), st.floats(0, 0.5),
       st.one_of(st.just(0.0), st.floats(0.2, 5)), st.sampled_from([1, 2, 3, 4, 5, 6, 7, 8, 11, 12, 13, 14, 15, 16, 17, 18]),
       corner, corner, corner, corner, st.floats(0, 2), st.floats(-50, 50))
def test_grooves_stay_in_the_outline_reach_the_depth_and_end_at_the_start(
        W, D, frac, fal1, fal2, idep, vari, rco1, rco2, rci1, rci2, vrt, spl):
    tw = W * frac
    p = dict(SPD=20.0, SPL=spl, WIDG=W, DIAG=D, RCO1=rco1, RCO2=rco2, RCI1=rci1, RCI2=rci2, FAL1=fal1,
             FAL2=fal2, IDEP=idep, VARI=vari, VRT=vrt, DTB=0.2)
    chr_ = vari > 10
    c = {}
    for name, v in (("o1", rco1), ("o2", rco2), ("i1", rci1), ("i2", rci2)):
        c[name] = ("radius" if v > 0 else "chamfer", _legs(v, chr_))
    face = vari % 2 == 0
    s = -1.0 if vari % 10 >= 5 else 1.0
    e = -1.0 if vari % 10 in (3, 4, 7, 8) else 1.0
    try:
        rough, finish = groove_passes(p, tw)
    except MillingError as err:                     # refused only where the groove cannot be cut so
        assert err.rule == "NC114"
        assert (c["o1"][1] + c["i1"][1] > D or c["o2"][1] + c["i2"][1] > D or c["i1"][1] + c["i2"][1] > W
                or tw > W - c["i1"][1] - c["i2"][1] - 1e-9 or tw > W - 2 * fal2 - 1e-9 or fal1 >= D - 1e-9
                or (face and e > 0 and W + c["o2"][1] > 20.0 - 1e-9))   # an outside face groove past the axis
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
                assert _air(u + tw * j / 8, w, W, D, c), (k, step, u + tw * j / 8, w)
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
