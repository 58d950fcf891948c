"""Geometry of toolpath moves shared by the checks: points along a move, an arc's extreme points
and its chords. Arcs come from the toolpath record (start, end, centre, plane, direction, turns)."""
from __future__ import annotations

import math
from typing import Iterator

from nctrans.toolpath import ToolpathRecord
from nctrans.toolpath_io import arc_sweep


def arc_point(r: ToolpathRecord, frac: float, geo=None) -> dict[str, float]:
    """The point at fraction `frac` of an arc (helical axis and other axes linear in frac)."""
    t0, sweep, radius, (a1, a2) = geo or arc_sweep(r)
    s, e, c = r.start, r.end, r.center or {}
    p = {a: s[a] + (e.get(a, s[a]) - s[a]) * frac for a in s}
    ang = t0 + sweep * frac
    p[a1] = c.get(a1, 0.0) + radius * math.cos(ang)
    p[a2] = c.get(a2, 0.0) + radius * math.sin(ang)
    return p


def arc_extremes(r: ToolpathRecord) -> Iterator[tuple[dict[str, float], float]]:
    """(point, fraction) where the arc crosses a quadrant boundary of its plane: with the end
    points, these bound every axis along the arc (a helix's axial motion is linear)."""
    geo = arc_sweep(r)
    t0, sweep, radius, _axes = geo
    if radius <= 0 or sweep == 0:
        return
    quarter = math.pi / 2
    lo, hi = min(t0, t0 + sweep), max(t0, t0 + sweep)
    k = math.floor(lo / quarter) + 1
    seen = 0
    while k * quarter < hi and seen < 4:
        frac = (k * quarter - t0) / sweep
        if 0.0 < frac < 1.0:
            yield arc_point(r, frac, geo), frac
            seen += 1
        k += 1


def arc_chords(r: ToolpathRecord, tol: float) -> tuple[list[dict[str, float]], float]:
    """Points along an arc whose chords stay within `tol` of it, and the largest chord-to-arc
    distance (the sagitta), which callers add to a radius to stay on the safe side."""
    geo = arc_sweep(r)
    t0, sweep, radius, _axes = geo
    if radius <= tol:
        return [dict(r.start), dict(r.end)], radius
    step = 2.0 * math.acos(max(-1.0, 1.0 - tol / radius))
    n = max(1, min(10_000, math.ceil(abs(sweep) / step)))
    sagitta = radius * (1.0 - math.cos(abs(sweep) / n / 2.0))
    return [arc_point(r, i / n, geo) for i in range(n + 1)], sagitta


def is_motion(r: ToolpathRecord) -> bool:
    return r.kind in ("rapid", "linear", "arc") and r.start is not None and r.end is not None
