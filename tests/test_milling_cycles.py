"""Sinumerik milling cycles (issue 8, nctrans/interp/milling_cycles.py): hand-computed paths,
the errors the control stops with, properties over random calls, and conversion to ISO.

Expected values are worked out by hand from the model in the module docstring (facts [GK] of
the Siemens cycles manual, modelling choices [NC]): roughing rings 0.8 x the tool diameter apart
at most, equally spaced from the centre out; depth cuts equal and at most MID."""
from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from nctrans import api, pipeline
from nctrans.interp.milling_cycles import depth_levels, pocket_steps, rect_ring
from nctrans.machine import Machine, Tool
from nctrans.source import from_text


def _machine(radius: float) -> Machine:
    return Machine(name="t", tools=[Tool(number=1, radius=radius, length=50.0)])


def _run(body: str, radius: float | None = 3.0):
    text = f"G17 G90 G54 T1 D1 M6\nS2000 M3 F500\nG0 X50 Y50 Z20\n{body}\nM30\n"
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    machine = _machine(radius) if radius is not None else None
    recs = [r for r in pipeline.toolpath_of(ld, machine) if r.kind in ("rapid", "linear", "arc")]
    return recs, ld.diagnostics


def _ends(recs, line=4):
    out = []
    for r in recs:
        if r.line != line:
            continue
        e = (round(r.end["X"], 6), round(r.end["Y"], 6), round(r.end["Z"], 6))
        if r.kind == "arc":
            out.append(("arc", e, (round(r.center["X"], 6), round(r.center["Y"], 6)), r.direction))
        else:
            out.append((r.kind, e, r.feed))
    return out


def test_pocket1_rough_by_hand():
    # 40 x 20 pocket at (50, 50), corner radius 5, tool radius 3, allowance 0.5, two cuts of 3 mm.
    # Tool centre limit: 20-3.5 = 16.5 by 10-3.5 = 6.5; rings ceil(6.5 / 4.8) = 2, inset 3.25 and 0;
    # centre line +-(16.5-6.5) = +-10; ring 1: 13.25 x 3.25, sharp (5-3.5-3.25 < 0);
    # ring 2: 16.5 x 6.5, corner radius 5-3.5 = 1.5. CDIR 3: counterclockwise.
    recs, diags = _run("POCKET1(10, 0, 2, -6, , 40, 20, 5, 50, 50, 0, 100, 300, 3, 3, 0.5, 1)")
    assert not [d for d in diags if d.severity != "info"]

    def level(z):
        return [
            ("linear", (50, 50, z), 100),
            ("linear", (40, 50, z), 300), ("linear", (60, 50, z), 300),
            ("linear", (63.25, 50, z), 300), ("linear", (63.25, 53.25, z), 300),
            ("linear", (36.75, 53.25, z), 300), ("linear", (36.75, 46.75, z), 300),
            ("linear", (63.25, 46.75, z), 300), ("linear", (63.25, 50, z), 300),
            ("linear", (66.5, 50, z), 300), ("linear", (66.5, 55, z), 300),
            ("arc", (65, 56.5, z), (65, 55), "ccw"), ("linear", (35, 56.5, z), 300),
            ("arc", (33.5, 55, z), (35, 55), "ccw"), ("linear", (33.5, 45, z), 300),
            ("arc", (35, 43.5, z), (35, 45), "ccw"), ("linear", (65, 43.5, z), 300),
            ("arc", (66.5, 45, z), (65, 45), "ccw"), ("linear", (66.5, 50, z), 300),
            ("linear", (50, 50, z), 300)]
    want = [("rapid", (50, 50, 2), None)] + level(-3) + level(-6) + [("rapid", (50, 50, 10), None)]
    got = [(k, tuple(float(v) for v in e), *rest) for k, e, *rest in _ends(recs)]
    assert got == [(k, tuple(float(v) for v in e), *rest) for k, e, *rest in want]


def test_pocket2_complete_by_hand():
    # radius 15 pocket, tool 4, allowance 1, one cut (MID 5 = depth), clockwise (CDIR 2), VARI 0:
    # rough circles 10 / ceil(10 / 6.4) = 2 -> radii 5 and 10, then finish at 15-4 = 11 (FFP2 200).
    recs, diags = _run("POCKET2(10, 0, 2, -5, , 15, 50, 50, 100, 300, 5, 2, 1, 0, 0, 200)", radius=4.0)
    assert not [d for d in diags if d.severity != "info"]
    c = (50.0, 50.0)
    want = [("rapid", (50, 50, 2), None), ("linear", (50, 50, -5), 100),
            ("linear", (55, 50, -5), 300), ("arc", (45, 50, -5), c, "cw"), ("arc", (55, 50, -5), c, "cw"),
            ("linear", (60, 50, -5), 300), ("arc", (40, 50, -5), c, "cw"), ("arc", (60, 50, -5), c, "cw"),
            ("linear", (50, 50, -5), 300),
            ("linear", (61, 50, -5), 200), ("arc", (39, 50, -5), c, "cw"), ("arc", (61, 50, -5), c, "cw"),
            ("linear", (50, 50, -5), 200), ("rapid", (50, 50, 10), None)]
    got = _ends(recs)
    assert [g[0] for g in got] == [w[0] for w in want]
    for g, w in zip(got, want):
        assert g[1] == pytest.approx(tuple(map(float, w[1])))
        assert g[2:] == w[2:]


def test_dpr_wins_and_depth_is_split_evenly():
    # DP -99 is overridden by DPR 10 below RFP 0; MID 4 -> three equal cuts of 10/3
    assert depth_levels(0.0, -10.0, 4.0, 1.0) == pytest.approx([-10 / 3, -20 / 3, -10.0])
    recs, _ = _run("POCKET2(10, 0, 2, -99, 10, 15, 50, 50, 100, 300, 4, 3, 0, 1)")
    plunges = [r.end["Z"] for r in recs if r.line == 4 and r.kind == "linear" and r.feed == 100]
    assert plunges == pytest.approx([-10 / 3, -20 / 3, -10.0])


def test_finishing_only_goes_round_the_edge_once_per_finishing_cut():
    # VARI 2, MIDF 3 on a 6 mm deep 30 x 30 sharp pocket, tool 5: contour 10 x 10 half sizes, two cuts
    recs, _ = _run("POCKET1(10, 0, 2, -6, , 30, 30, 0, 50, 50, 0, 100, 300, 6, 3, 0, 2, 3, 150)", radius=5.0)
    cut = [r for r in recs if r.line == 4 and r.kind == "linear" and r.feed == 150]
    corners = {(r.end["X"], r.end["Y"]) for r in cut}
    assert {(60, 60), (40, 60), (40, 40), (60, 40)} <= corners
    assert sorted({r.end["Z"] for r in cut}) == [-6, -3]


def test_rotated_pocket_and_arc_directions():
    segs = rect_ring(2.0, 1.0, 0.0, ccw=True)
    assert [e for e, _ in segs] == [(2.0, 1.0), (-2.0, 1.0), (-2.0, -1.0), (2.0, -1.0), (2.0, 0.0)]
    assert [e for e, _ in rect_ring(2.0, 1.0, 0.0, ccw=False)] == [
        (2.0, -1.0), (-2.0, -1.0), (-2.0, 1.0), (2.0, 1.0), (2.0, 0.0)]
    # STA1 90: the length runs along Y; the finishing contour's far end is at Y 50 + 20 - 3
    recs, _ = _run("POCKET1(10, 0, 2, -2, , 40, 20, 0, 50, 50, 90, 100, 300, 0, 3, 0, 2)")
    ys = [r.end["Y"] for r in recs if r.line == 4]
    xs = [r.end["X"] for r in recs if r.line == 4]
    assert max(ys) == pytest.approx(67) and max(xs) == pytest.approx(57)


def test_no_tool_radius_moves_nothing_and_says_so():
    recs, diags = _run("POCKET1(10, 0, 2, -6, , 40, 20, 5, 50, 50, 0, 100, 300, 3, 3, 0.5, 1)", radius=None)
    assert not [r for r in recs if r.line == 4]
    assert [d.rule for d in diags if d.line == 4] == ["NC224"]


@pytest.mark.parametrize("call, words", [
    ("POCKET2(10, 0, 2, -5, , 3, 50, 50, 100, 300)", "too large"),
    ("POCKET1(10, 0, 2, -5, , 40, 6, 0, 50, 50)", "too large"),
    ("POCKET1(10, 0, 2, -5, , 40, 20, 0, 50, 50, 0, 100, 300, 0, 3, 7, 1)", "allowance"),
    ("POCKET1(10, 0, 2, , , 40, 20, 0, 50, 50)", "depth"),
    ("POCKET1(10, 0, 2, -5, , 0, 20, 0, 50, 50)", "LENG"),
    ("POCKET1(10, 0, 2, -5, , 40, 20, 0, 50, 50, 0, 100, 300, 0, 4)", "CDIR"),
    ("POCKET2(10, 0, 2, -5, , 15, 50, 50, 100, 300, 0, 3, 0, 7)", "VARI"),
])
def test_impossible_calls_stop_like_the_control(call, words):
    recs, diags = _run(call)
    assert not [r for r in recs if r.line == 4]
    said = [d for d in diags if d.line == 4 and d.severity == "error"]
    assert len(said) == 1 and words in said[0].message and "moves nothing" in said[0].message


def test_mcall_of_a_pocket_is_reported_not_run():
    recs, diags = _run("MCALL POCKET2(10, 0, 2, -5, , 15, 50, 50, 100, 300)\nG0 X80\nMCALL")
    assert [r.line for r in recs if r.line >= 4] == [5]
    assert [d.rule for d in diags if d.line == 4] == ["NC224"]


# ---------------------------------------------------------------------------------------------
# Properties over random pockets (pure planner, no interpreter)

def _points(steps, start):
    """Every end point, and points along each arc, in plane coordinates."""
    at = start
    for s in steps:
        if s[0] in ("rapid", "linear"):
            at = s[1]
            yield s[0], at
        elif s[0] == "arc":
            (x0, y0, _), (x1, y1, h), (cx, cy), cw = at, s[1], s[2], s[3]
            r = math.hypot(x0 - cx, y0 - cy)
            a0, a1 = math.atan2(y0 - cy, x0 - cx), math.atan2(y1 - cy, x1 - cx)
            sweep = (a0 - a1) % (2 * math.pi) if cw else (a1 - a0) % (2 * math.pi)
            sweep = sweep or 2 * math.pi
            for k in range(1, 9):
                a = a0 + (-1 if cw else 1) * sweep * k / 8
                yield "arc", (cx + r * math.cos(a), cy + r * math.sin(a), h)
            at = s[1]


pocket_calls = st.fixed_dictionaries({
    "rect": st.booleans(),
    "LENG": st.floats(10, 120), "WID": st.floats(10, 120), "crad_frac": st.floats(0, 1),
    "PRAD": st.floats(5, 60), "CPA": st.floats(-100, 100), "CPO": st.floats(-100, 100),
    "STA1": st.floats(-180, 180), "radius": st.floats(0.5, 4.5), "FAL": st.floats(0, 0.5),
    "depth": st.floats(0.5, 25), "MID": st.one_of(st.just(0.0), st.floats(0.3, 12)),
    "MIDF": st.one_of(st.just(0.0), st.floats(0.3, 12)), "VARI": st.sampled_from([0, 1, 2]),
    "CDIR": st.sampled_from([2, 3]), "RFP": st.floats(-20, 20),
})


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(pocket_calls)
def test_pocket_moves_stay_inside_reach_the_depth_and_end_at_rtp(c):
    rect, r, fal = c["rect"], c["radius"], c["FAL"]
    half = min(c["LENG"], c["WID"]) / 2 if rect else c["PRAD"]
    if half - r - fal < 0.1:
        return                               # the control refuses it (tested above)
    p = {k: c[k] for k in ("LENG", "WID", "CPA", "CPO", "STA1", "FAL", "MID", "MIDF", "VARI", "CDIR",
                           "PRAD", "RFP")}
    p.update(RTP=c["RFP"] + 15, SDIS=1.0, DP=c["RFP"] - c["depth"], FFD=50, FFP1=200, FFP2=100,
             CRAD=c["crad_frac"] * half)
    start = (0.0, 0.0, c["RFP"] + 40)
    steps = pocket_steps("rect_pocket" if rect else "circ_pocket", p, r, start, 300.0)
    a, b = (c["LENG"] / 2, c["WID"] / 2) if rect else (c["PRAD"], c["PRAD"])
    rc = max(p["CRAD"] - r, 0.0) if rect else a - r
    ang = math.radians(c["STA1"]) if rect else 0.0
    bottom, deepest = p["DP"], math.inf
    for kind, (x, y, h) in _points(steps, start):
        deepest = min(deepest, h)
        if h >= p["RFP"]:                     # above the material: the approach and the retract
            continue
        du, dv = x - c["CPA"], y - c["CPO"]
        u = abs(du * math.cos(ang) + dv * math.sin(ang))
        v = abs(-du * math.sin(ang) + dv * math.cos(ang))
        hu, hv = a - r, b - r
        assert u <= hu + 1e-6 and v <= hv + 1e-6
        if u > hu - rc and v > hv - rc:
            assert math.hypot(u - (hu - rc), v - (hv - rc)) <= rc + 1e-6
    assert deepest == pytest.approx(bottom) and deepest >= bottom - 1e-9
    assert steps[-1][0] == "rapid" and steps[-1][1] == pytest.approx((c["CPA"], c["CPO"], p["RTP"]))


# ---------------------------------------------------------------------------------------------
# Conversion: the call is lowered to plain motion for ISO and the two programs agree

@pytest.mark.parametrize("call", [
    "POCKET1(10, 0, 2, -6, , 40, 20, 5, 50, 50, 30, 100, 300, 3, 2, 0.5, 0, 2, 200)",
    "POCKET2(10, 0, 2, -5, , 15, 50, 50, 100, 300, 5, 3, 1, 0, 0, 200)",
])
def test_converted_to_iso_is_lowered_and_equivalent(call):
    text = f"G17 G90 G54 T1 D1 M6\nS2000 M3 F500\nG0 X50 Y50 Z20\n{call}\nG0 X0 Y0\nM30\n"
    machine = _machine(3.0)
    conv = api.transpile(text, "sinumerik", "iso-m", machine=machine)
    assert conv.text is not None and "POCKET" not in conv.text and "G65" not in conv.text
    assert any(d.rule == "NC401" and d.line == 4 for d in conv.diagnostics)
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m", machine=machine)
    again = api.transpile(text, "sinumerik", "sinumerik", machine=machine)
    assert "POCKET" in again.text
    assert api.equiv(text, again.text, read_a="sinumerik", read_b="sinumerik", machine=machine)


def test_converted_without_a_tool_radius_is_refused():
    text = "G17 G90 G0 X50 Y50 Z20 F100 S1000 M3\nPOCKET2(10, 0, 2, -5, , 15, 50, 50, 100, 300)\nM30\n"
    conv = api.transpile(text, "sinumerik", "iso-m")
    assert conv.text is None and any(d.rule == "NC402" and d.line == 2 for d in conv.diagnostics)


def test_inch_programs_scale_lengths_and_g70_keeps_feeds_in_mm():
    # G700: lengths and feeds in inch; G70: lengths in inch, feeds in the basic system (mm)
    for code, ffp1 in (("G700", 300 * 25.4), ("G70", 300)):
        text = (f"G17 G90 G54 T1 D1 M6\nS2000 M3 F500\nG0 X0 Y0 Z1\n{code}\n"
                "POCKET2(0.5, 0, 0.1, -0.2, , 1, 2, 2, 100, 300, 0, 3, 0, 1)\nM30\n")
        ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
        recs = [r for r in pipeline.toolpath_of(ld, _machine(3.0)) if r.line == 5]
        # pocket radius 25.4 mm, tool 3: one circle of 22.4 / ceil(22.4 / 4.8) = 5 rings -> first 4.48
        first = next(r for r in recs if r.kind == "linear" and r.end["Z"] == pytest.approx(-0.2 * 25.4)
                     and r.end["X"] != pytest.approx(50.8))
        assert first.end["X"] == pytest.approx(50.8 + 22.4 / 5) and first.feed == pytest.approx(ffp1)
        assert recs[-1].end["Z"] == pytest.approx(0.5 * 25.4)
