"""G71/G72 type II roughing (nctrans.interp.turning.rough_pockets) on random profiles: properties
that hold whatever the profile, as a control's roughing must.

Profiles are OD turning in radius: start (d0 = 20, p0 = 2), a contour monotonic in p (Z falling)
whose d wanders between 5 and 19.5 (pockets), ending across at d0. The stock lies below d0 and
beyond p0; a feed move along a level clears everything outside that level over its p range."""
from __future__ import annotations

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from nctrans.interp import turning

D0, P0 = 20.0, 2.0
TOL = 1e-6


@st.composite
def profiles(draw):
    n = draw(st.integers(2, 7))
    pts = [(draw(st.integers(20, 78)) / 4.0, P0)]        # A': d 5..19.5
    p = P0
    for _ in range(n):
        step = draw(st.sampled_from([0.0, 0.5, 1.0, 2.5, 4.0, 6.0]))
        d = draw(st.integers(20, 78)) / 4.0
        if step == 0.0 and d == pts[-1][0]:
            step = 1.0
        p -= step
        pts.append((d, p))
    if pts[-1][1] == P0:
        pts.append((pts[-1][0], P0 - 3.0))
    pts.append((D0, pts[-1][1]))
    depth = draw(st.sampled_from([0.7, 1.0, 1.5, 2.0, 3.0]))
    retract = draw(st.sampled_from([0.2, 0.5, 1.0]))
    return pts, depth, retract


def surface(pts, p):
    """Lowest d of the part boundary at p (a wall counts with its lower end); d0 past the end;
    nothing before the start (p above p0 is in front of the stock)."""
    if p > P0 + 1e-9:
        return float("-inf")
    best = None
    for (d1, p1), (d2, p2) in zip(pts, pts[1:]):
        lo, hi = min(p1, p2), max(p1, p2)
        if not lo - 1e-9 <= p <= hi + 1e-9:
            continue
        d = min(d1, d2) if abs(p2 - p1) < 1e-12 else d1 + (d2 - d1) * (p - p1) / (p2 - p1)
        best = d if best is None else min(best, d)
    return D0 if best is None else best


def along(a, b, n=24):
    return [(a[0] + (b[0] - a[0]) * i / n, a[1] + (b[1] - a[1]) * i / n) for i in range(n + 1)]


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(profiles())
def test_type2_roughing_never_enters_the_part_nor_rapids_into_stock_and_leaves_at_most_a_depth(case):
    pts, depth, retract = case
    contour = [("linear", pt, None, None) for pt in pts[1:]]
    moves = turning.rough_pockets((D0, P0), pts[0], contour, depth, retract)
    cleared: list[tuple[float, float, float]] = []          # (level, p from, p to) cut so far
    here = (D0, P0)
    for kind, end, _, _ in moves:
        for d, p in along(here, end):
            assert d >= surface(pts, p) - TOL, (kind, here, end, (d, p))
            if kind == "rapid":
                air = d >= D0 - TOL or p >= P0 - TOL or any(lo - TOL <= p <= hi + TOL and d >= lv - TOL
                                           for lv, lo, hi in cleared)
                assert air, ("rapid into uncut stock", here, end, (d, p))
        if kind == "linear" and abs(end[0] - here[0]) < 1e-12:
            cleared.append((end[0], min(here[1], end[1]), max(here[1], end[1])))
        here = end
    assert here == (D0, P0) or not moves or moves[-1][0] == "rapid"
    p_end = pts[-1][1]
    for i in range(1, 200):
        p = P0 + (p_end - P0) * (i + 0.37) / 200.5
        lowest = min([lv for lv, lo, hi in cleared if lo - TOL <= p <= hi + TOL], default=D0)
        assert lowest - surface(pts, p) <= depth + 1e-6, (p, lowest, surface(pts, p))
