"""Sinumerik CYCLE94 (undercut form E/F, DIN 509) and CYCLE96 (thread undercut, DIN 76), issue 8
(nctrans/interp/undercuts.py): hand-computed cases, refusals, a property over random undercuts,
conversion to ISO turning.

Expected values are worked out by hand from the tables in rules/cycles.toml [undercut] and the
model in the module docstring: one pass from the clearance point (1 mm beyond the undercut and
outside the surface) onto the surface, down the run-out flank, along the base, round the radius,
up the face, off it by 1 mm, back to the start with G0."""
from __future__ import annotations

import math

import pytest
from hypothesis import given, settings, strategies as st

from nctrans import api, pipeline
from nctrans.interp.undercuts import din509, din76, din76_internal, undercut_steps
from nctrans.machine import Tool, default_lathe
from nctrans.source import from_text

TAN15, TAN30, TAN8 = math.tan(math.radians(15)), math.tan(math.radians(30)), math.tan(math.radians(8))


def _lathe(tip=None):
    m = default_lathe()
    m.tools = [Tool(1, tip=tip)]
    return m


def _text(call: str) -> str:
    return f"G18 G90 DIAMON T1 D1\nS800 M3 G95 F0.1\nG0 X40 Z5\n{call}\nG0 X60\nM30\n"


def _run(call: str, tip=None):
    ld = pipeline.load_source(from_text(_text(call), "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld, _lathe(tip)) if r.line == 4]
    got = [(r.kind, round(r.end["X"], 6), round(r.end["Z"], 6)) for r in recs
           if r.kind in ("rapid", "linear", "arc")]
    return got, ld.diagnostics, recs


def _approx(want):
    return [(k, pytest.approx(x, abs=1e-6), pytest.approx(z, abs=1e-6)) for k, x, z in want]


def test_form_e_outside_shoulder_towards_minus_z_by_hand():
    # d 30 lies in the DIN 509 row 18..80: t1 0.3, f 2.5, r 0.6. VARI 3 (tip -X -Z): outside, the
    # shoulder at Z-20 towards -Z, the undercut from Z-20 to Z-17.5 below radius 15.
    # start (1 beyond, 1 out): X16 Z-16.5; onto the surface X15 Z-17.5; run-out 0.3 / tan 15 =
    # 1.119615 long to Z-18.619615 at radius 14.7; base to Z-19.4 (r from the face); the radius about
    # (15.3, -19.4) clockwise (bottom to the face, seen with Z right, X up) to X15.3 Z-20 (t1 < r:
    # the radius meets the face 0.3 above the surface); up the face by 1 to X16.3; G0 back.
    got, diags, recs = _run('CYCLE94(30, -20, "E", 3)')
    assert [d for d in diags if d.severity != "info"] == []
    assert got == _approx([("rapid", 16, -16.5), ("linear", 15, -17.5), ("linear", 14.7, -20 + 2.5 - 0.3 / TAN15),
                           ("linear", 14.7, -19.4), ("arc", 15.3, -20), ("linear", 16.3, -20),
                           ("rapid", 16.3, -16.5), ("rapid", 16, -16.5)])
    (arc,) = [r for r in recs if r.kind == "arc"]
    assert arc.direction == "cw" and arc.center["X"] == pytest.approx(15.3) and arc.center["Z"] == pytest.approx(-19.4)
    assert all(r.feed == 0.1 and r.feed_mode == "per_rev" for r in recs if r.kind in ("linear", "arc"))


def test_form_f_recesses_the_face_by_hand():
    # Form F adds t2 0.2 into the face with its wall at 8 degrees: the base runs to Z-19.6 (r - t2
    # from the face), the radius about (15.3, -19.6) to X15.3 Z-20.2, the wall up to the face at
    # 0.3 - 0.6 - 0.2 / tan 8 = -1.723074 (radius 16.723074), off the face by 1, back.
    got, diags, _ = _run('CYCLE94(30, -20, "F", 3)')
    assert [d for d in diags if d.severity != "info"] == []
    top = 15 + 0.3 + 0.2 / TAN8
    assert got == _approx([("rapid", 16, -16.5), ("linear", 15, -17.5), ("linear", 14.7, -20 + 2.5 - 0.3 / TAN15),
                           ("linear", 14.7, -19.6), ("arc", 15.3, -20.2), ("linear", top, -20),
                           ("linear", top + 1, -20), ("rapid", top + 1, -16.5), ("rapid", 16, -16.5)])


def test_form_e_shoulder_towards_plus_z_small_diameter_by_hand():
    # d 8 (DIAMON): the row 3..10: t1 0.2, f 2, r 0.2. VARI 4 (tip -X +Z): outside, the shoulder at
    # Z0 towards +Z, the undercut from Z0 to Z-2 below radius 4. t1 = r: the radius ends on the face
    # exactly at the surface (X4 Z0). Start X5 Z-3.
    got, diags, recs = _run('CYCLE94(8, 0, "E", 4)')
    assert [d for d in diags if d.severity != "info"] == []
    assert got == _approx([("rapid", 5, -3), ("linear", 4, -2), ("linear", 3.8, -2 + 0.2 / TAN15),
                           ("linear", 3.8, -0.2), ("arc", 4, 0), ("linear", 5, 0), ("rapid", 5, -3)])
    (arc,) = [r for r in recs if r.kind == "arc"]
    assert arc.direction == "ccw"                   # the mirror image of the VARI 3 case


def test_thread_undercut_form_a_and_b_by_hand():
    # M24: coarse pitch 3; DIN 76 row 3: dg = d - 4.4 (t 2.2), g2 10.5 (A) / 7.5 (B), r 1.6.
    # VARI 3, shoulder at Z-30: start X13 Z-18.5 (A); onto the thread X12 Z-19.5; run-out at 30
    # degrees, 2.2 / tan 30 = 3.810512 long, to X9.8 Z-23.310512; base to Z-28.4; the radius about
    # (11.4, -28.4) to X11.4 Z-30; up the face to X12, off by 1 to X13; G0 back.
    got, diags, _ = _run('CYCLE96(24, -30, "A", 3)')
    assert [d for d in diags if d.severity != "info"] == []
    assert got == _approx([("rapid", 13, -18.5), ("linear", 12, -19.5), ("linear", 9.8, -19.5 - 2.2 / TAN30),
                           ("linear", 9.8, -28.4), ("arc", 11.4, -30), ("linear", 12, -30), ("linear", 13, -30),
                           ("rapid", 13, -18.5)])
    got, diags, _ = _run('CYCLE96(24, -30, "B", 3)')
    assert got[:3] == _approx([("rapid", 13, -21.5), ("linear", 12, -22.5), ("linear", 9.8, -22.5 - 2.2 / TAN30)])


def test_internal_thread_undercut_forms_c_and_d_by_hand():
    # M20 internal: coarse pitch 2.5; DIN 76 internal row 2.5 [GK]: dg = d + 0.5 = 20.5 (radius
    # 10.25), g2 13 (C) / 9.3 (D), r 1.2. Cut into the core hole at the minor diameter D1 = 20 -
    # 1.082532 x 2.5 = 17.29367 (radius 8.646835): depth t = (20.5 - 17.29367) / 2 = 1.603165.
    # VARI 2 (tip +X -Z): inside, the shoulder at Z-30 towards -Z. Start 1 inside the hole and 1
    # beyond: X7.646835 Z-30+13+1 = -16; onto the hole X8.646835 Z-17; the run-out at 30 degrees,
    # 1.603165 / tan 30 = 2.776763 long, to X10.25 Z-19.776763; base to Z-28.8 (r from the face);
    # the radius about (8.646835 + 1.603165 - 1.2, -28.8) = (9.05, -28.8) to X9.05 Z-30; down the
    # face to the hole X8.646835, off by 1 to X7.646835; G0 back.
    r1 = (20 - 1.082532 * 2.5) / 2
    got, diags, recs = _run('CYCLE96(20, -30, "C", 2)')
    # started at X40 Z5 (radius 20), outside the core hole: the G0 to (7.646835, -16) crosses the
    # hole's radius 8.646835 at Z = 5 - 21 x (20 - 8.646835) / (20 - 7.646835) = -14.30003
    assert [(d.rule, d.line) for d in diags if d.severity != "info"] == [("NC418", 4)]
    assert "at Z-14.3," in next(d.message for d in diags if d.rule == "NC418")
    assert got == _approx([("rapid", r1 - 1, -16), ("linear", r1, -17), ("linear", 10.25, -17 - 2.776763),
                           ("linear", 10.25, -28.8), ("arc", 9.05, -30), ("linear", r1, -30),
                           ("linear", r1 - 1, -30), ("rapid", r1 - 1, -16)])
    (arc,) = [r for r in recs if r.kind == "arc"]
    assert arc.center["X"] == pytest.approx(9.05) and arc.center["Z"] == pytest.approx(-28.8)
    # form D: g2 9.3: start at Z-30+9.3+1 = -19.7, onto the hole at Z-20.7
    got, diags, _ = _run('CYCLE96(20, -30, "D", 2)')
    assert got[:3] == _approx([("rapid", r1 - 1, -19.7), ("linear", r1, -20.7),
                               ("linear", 10.25, -20.7 - 2.776763)])
    # M8 (P 1.25) with the shoulder towards +Z (VARI 1): dg 8.5, D1 = 8 - 1.353165 = 6.646835,
    # t = (8.5 - 6.646835) / 2 = 0.926583; g2 (C) 6.7: the undercut from Z0 to Z-6.7 going -Z
    got, diags, _ = _run('CYCLE96(8, 0, "C", 1)')
    r1 = (8 - 1.082532 * 1.25) / 2
    assert got[:3] == _approx([("rapid", r1 - 1, -7.7), ("linear", r1, -6.7),
                               ("linear", 4.25, -6.7 + 0.926583 / TAN30)])


def test_internal_undercut_converts_to_iso_turning():
    text = _text('CYCLE96(20, -30, "C", 2)\nG0 Z5\nCYCLE96(20, -30, "D", 2)')
    conv = api.transpile(text, "sinumerik", "iso-t", machine=_lathe())
    assert conv.text is not None and "CYCLE96" not in conv.text
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-t", machine=_lathe())


def test_inside_undercut_cuts_away_from_the_axis():
    # VARI 2 (tip +X -Z): a bore of diameter 40 with the shoulder at Z-20 towards -Z; the undercut
    # goes outwards to radius 20.3 (row 18..80); the start is 1 inside the bore (radius 19).
    got, diags, _ = _run('CYCLE94(40, -20, "E", 2)')
    assert [d for d in diags if d.severity != "info"] == []
    assert got[:4] == _approx([("rapid", 19, -16.5), ("linear", 20, -17.5),
                               ("linear", 20.3, -20 + 2.5 - 0.3 / TAN15), ("linear", 20.3, -19.4)])


def test_vari_0_takes_the_tools_cutting_edge_position():
    got3, _, _ = _run('CYCLE94(30, -20, "E", 3)')
    got0, diags, _ = _run('CYCLE94(30, -20, "E", 0)', tip=3)
    assert got0 == got3 and [d for d in diags if d.severity != "info"] == []


@pytest.mark.parametrize("call,tip,rule", [
    ('CYCLE94(30, -20, "E", 0)', None, "NC115"),   # no tip direction for VARI 0
    ('CYCLE94(30, -20, "E", 6)', None, "NC115"),   # a tip along an axis names no corner
    ('CYCLE96(24, -30, "C", 3)', None, "NC116"),   # an internal undercut at an outside position
    ('CYCLE96(24, -30, "A", 2)', None, "NC116"),   # an external undercut at an inside position
    ('MCALL CYCLE94(30, -20, "E", 3)', None, "NC115"),
    ('CYCLE94(30, -20, "G", 3)', None, "NC116"),   # no such form
    ('CYCLE94(30, -20, "E", 9)', None, "NC116"),
    ('CYCLE96(25, -30, "A", 3)', None, "NC116"),   # M25 is no metric coarse thread
    ('CYCLE94(, -20, "E", 3)', None, "NC116"),     # no diameter
])
def test_what_is_not_modelled_or_alarms_moves_nothing_and_says_so(call, tip, rule):
    got, diags, _ = _run(call, tip)
    said = [d for d in diags if d.rule in ("NC115", "NC116")]
    assert [d.rule for d in said] == [rule] and said[0].line == 4
    assert got == []


def test_converted_to_iso_turning_is_equivalent():
    text = _text('CYCLE94(30, -20, "F", 3)\nG0 X40 Z5\nCYCLE96(24, -30, "A", 3)')
    conv = api.transpile(text, "sinumerik", "iso-t", machine=_lathe())
    assert conv.text is not None and "CYCLE94" not in conv.text and "CYCLE96" not in conv.text
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-t", machine=_lathe())


# ---------------------------------------------------------------------------------------------
# Property: u along the axis away from the shoulder face (u = 0), w the depth below the surface.

def _material(u, w, t, W, r, t2, run, tol=1e-6):
    """True where the finished part has material (the shoulder at u < 0, the body below w = 0),
    written from the DIN outline: run-out flank at `run` degrees, base at t, radius r at the face,
    form F's recess t2 with its wall at 8 degrees."""
    if u < -tol:
        if t2 <= 0:
            return True
        top = t - r - t2 / TAN8
        if w < top - tol or w > t + tol:
            return True
        if w <= t - r:
            return u < -t2 * (w - top) / (t - r - top) - tol
        return math.hypot(u - (r - t2), w - (t - r)) > r + tol
    if w <= tol:
        return False
    if u >= W:
        floor = 0.0
    elif u >= W - t / math.tan(math.radians(run)):
        floor = (W - u) * math.tan(math.radians(run))
    elif u >= r - t2:
        floor = t
    else:
        floor = t - r + math.sqrt(max(r * r - (u - (r - t2)) ** 2, 0.0))
    return w > floor + tol


@settings(max_examples=120, deadline=None)
@given(st.floats(1, 200), st.floats(-100, 100), st.sampled_from(["E", "F", "A", "B", "C", "D"]),
       st.sampled_from([1, 2, 3, 4]))
def test_undercuts_never_cut_outside_the_outline_and_end_where_they_start(diameter, spl, form, pos):
    if form in "EF":
        cut, run = din509(diameter, form), 15.0
    else:
        sizes = [3, 4, 5, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 27, 30, 33, 36, 39, 42, 45, 48]
        d = min(sizes, key=lambda s: abs(s - diameter / 4))
        pitch = {3: .5, 4: .7, 5: .8, 6: 1, 8: 1.25, 10: 1.5, 12: 1.75, 14: 2, 16: 2, 18: 2.5, 20: 2.5,
                 22: 2.5, 24: 3, 27: 3, 30: 3.5, 33: 3.5, 36: 4, 39: 4, 42: 4.5, 45: 4.5, 48: 5}[d]
        cut, run, diameter = din76(pitch, form) if form in "AB" else None, 30.0, float(d)
    inside, plus_z = pos in (1, 2), pos in (1, 4)
    r0 = diameter / 2
    if form in "CD":                 # internal: cut into the core hole, from inside it
        cut, r0 = din76_internal(pitch, form, diameter)
        inside = True
    steps = undercut_steps(cut, r0, spl, inside, plus_z, 1.0)
    e, s = (-1 if inside else 1), (-1 if plus_z else 1)

    def local(p):
        return s * (p[1] - spl), e * (r0 - p[0])

    here = local(steps[0][1])
    assert here == pytest.approx((cut.width + 1, -1))    # starts at the clearance point
    deepest = -1.0
    for step in steps[1:]:
        end = local(step[1])
        if step[0] == "arc":
            cu, cw_ = local(step[2])
            a0, a1 = math.atan2(here[1] - cw_, here[0] - cu), math.atan2(end[1] - cw_, end[0] - cu)
            da = (a1 - a0 + math.pi) % (2 * math.pi) - math.pi
            rad = math.dist(here, (cu, cw_))
            assert math.dist(end, (cu, cw_)) == pytest.approx(rad)
            pts = [(cu + rad * math.cos(a0 + da * k / 16), cw_ + rad * math.sin(a0 + da * k / 16)) for k in range(17)]
        else:
            pts = [(here[0] + (end[0] - here[0]) * k / 16, here[1] + (end[1] - here[1]) * k / 16) for k in range(17)]
        for u, w in pts:
            assert not _material(u, w, cut.depth, cut.width, cut.radius, cut.face_depth, run), (step, u, w)
            deepest = max(deepest, w)
        here = end
    assert here == pytest.approx(local(steps[0][1]))      # ends where it started
    assert deepest == pytest.approx(cut.depth)             # reaches the undercut's base


def test_an_approach_from_inside_the_bore_is_not_warned():
    # positioned inside the core hole first (radius 5 < 8.646835, at Z5): the G0 to the clearance
    # point stays inside the hole: no NC418; the same call from X40 Z5 is NC418 (above)
    text = _text('G0 X10\nCYCLE96(20, -30, "C", 2)')
    diags = api.lint(text, "sinumerik", _lathe())
    assert not [d for d in diags if d.rule == "NC418"]


def test_an_external_undercut_started_outside_is_not_warned():
    got, diags, _ = _run('CYCLE96(24, -30, "A", 3)')
    assert not [d for d in diags if d.rule == "NC418"]
