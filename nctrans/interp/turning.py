"""Turning-cycle geometry: the passes of the ISO lathe cycles, as plain moves.

Everything here is two-dimensional and in radius: points are (d, p) pairs where `p` is the axis a
pass travels along and `d` the axis the passes step across (G71: d = X, p = Z; G72 swaps them), so
one function serves the turning and the facing form. The interpreter (nctrans.interp.lathe) turns
the program's words into these numbers and the moves back into toolpath records.

A move is (kind, end, center, cw): kind "rapid" | "linear" | "thread" | "arc"; center and cw only
for arcs (center in the same (d, p) order). A contour is a list of such moves from a start point.
"""
from __future__ import annotations

import math
from typing import Optional

EPS = 1e-9


def _sign(v: float) -> float:
    return -1.0 if v < 0 else 1.0


# ------------------------------------------------------------------------------ contours

def _arc_angles(start, end, center, cw):
    """Start angle and signed sweep of an arc in the (p, d) frame the interpreter uses for G18
    (first plane axis Z = p, second X = d): cw means the angle decreases."""
    a0 = math.atan2(start[0] - center[0], start[1] - center[1])
    a1 = math.atan2(end[0] - center[0], end[1] - center[1])
    sweep = (a0 - a1) if cw else (a1 - a0)
    sweep %= 2 * math.pi
    if sweep < 1e-12:
        sweep = 2 * math.pi
    return a0, (-sweep if cw else sweep)


def arc_points(start, end, center, cw, n: int = 16):
    """n+1 points along an arc (for monotonicity checks)."""
    a0, sw = _arc_angles(start, end, center, cw)
    r = math.hypot(start[0] - center[0], start[1] - center[1])
    return [(center[0] + r * math.sin(a0 + sw * i / n), center[1] + r * math.cos(a0 + sw * i / n))
            for i in range(n + 1)]


def hits(start, moves, level: float) -> list[float]:
    """p of every point where the contour crosses the line d = level."""
    out = []
    cur = start
    for kind, end, center, cw in moves:
        if kind == "arc" and center is not None:
            r = math.hypot(cur[0] - center[0], cur[1] - center[1])
            dd = level - center[0]
            if abs(dd) <= r + EPS:
                h = math.sqrt(max(r * r - dd * dd, 0.0))
                a0, sw = _arc_angles(cur, end, center, cw)
                for p in (center[1] + h, center[1] - h):
                    a = math.atan2(level - center[0], p - center[1])
                    rel = (a - a0) if sw > 0 else (a0 - a)
                    rel %= 2 * math.pi
                    if rel <= abs(sw) + 1e-9 or rel >= 2 * math.pi - 1e-9:
                        out.append(p)
        else:
            d1, d2 = cur[0], end[0]
            if abs(d2 - d1) < EPS:
                if abs(d1 - level) < EPS:
                    out.extend((cur[1], end[1]))
            elif (d1 - level) * (d2 - level) <= 0:
                t = (level - d1) / (d2 - d1)
                out.append(cur[1] + t * (end[1] - cur[1]))
        cur = end
    return out


def shifted(moves, dd: float, dp: float):
    """The contour moved by (dd, dp): end points and arc centres alike."""
    return [(k, (e[0] + dd, e[1] + dp), None if c is None else (c[0] + dd, c[1] + dp), cw)
            for k, e, c, cw in moves]


def first_non_monotonic(start, moves) -> Optional[int]:
    """Index of the first move where d turns back (type I stock removal needs d monotonic)."""
    direction = 0.0
    cur = start
    for i, (kind, end, center, cw) in enumerate(moves):
        pts = arc_points(cur, end, center, cw) if kind == "arc" and center is not None else [cur, end]
        for a, b in zip(pts, pts[1:]):
            step = b[0] - a[0]
            if abs(step) < 1e-7:
                continue
            if direction == 0.0:
                direction = _sign(step)
            elif _sign(step) != direction:
                return i
        cur = end
    return None


# ------------------------------------------------------------------------------ stock removal

def rough_levels(start, approach_end, contour, depth: float, retract: float):
    """G71/G72 roughing passes (type I) as moves from `start`.

    start: the cycle start point A (d0, p0). approach_end: A', the end of the first contour block
    (already shifted by the finishing allowance). contour: the shifted moves A' -> B.
    The material is bounded by A', the contour, and the line from B back across to d0, so a level
    above the contour's last point still cuts to B's p (as the control does). Levels step from d0
    towards A' by `depth`; a level reaching A' is left to the final contour pass. Each level:
    rapid across to the level, cut along p to the contour, retract 45 degrees by `retract`, rapid
    back along p to p0."""
    d0, p0 = start
    if not contour or depth <= 0:
        return []
    sd = _sign(approach_end[0] - d0)
    b = contour[-1][1]
    sp = _sign(b[1] - p0)
    bounded = list(contour) + [("linear", (d0, b[1]), None, None)]
    out = []
    k = 1
    while True:
        level = d0 + sd * k * depth
        if sd * (level - approach_end[0]) >= -1e-9:
            break
        k += 1
        ahead = [p for p in hits(approach_end, bounded, level) if sp * (p - p0) > 1e-9]
        if not ahead:
            continue
        stop = min(ahead, key=lambda p: sp * (p - p0))
        out.append(("rapid", (level, p0), None, None))
        out.append(("linear", (level, stop), None, None))
        out.append(("rapid", (level - sd * retract, stop - sp * retract), None, None))
        out.append(("rapid", (level - sd * retract, p0), None, None))
    return out


def swapped(moves):
    """The moves with d and p exchanged (a mirror: arcs turn the other way)."""
    return [(k, (e[1], e[0]), None if c is None else (c[1], c[0]), None if cw is None else not cw)
            for k, e, c, cw in moves]


def _extreme(start, moves, sd: float) -> float:
    """The d furthest in direction sd along the moves (arcs sampled)."""
    best = start[0]
    cur = start
    for kind, end, center, cw in moves:
        pts = arc_points(cur, end, center, cw, 64) if kind == "arc" and center is not None else [end]
        for d, _ in pts:
            if sd * (d - best) > 0:
                best = d
        cur = end
    return best


def inside_stock(start, approach_end, moves) -> list:
    """The contour without its trailing moves that run on or outside the start side d = d0 (a
    return along the stock line, as CAM output writes before Q): they bound no material."""
    d0 = start[0]
    sd = _sign(approach_end[0] - d0)
    out = list(moves)
    while len(out) > 1:
        before = out[-2][1]
        if sd * (out[-1][1][0] - d0) > 1e-9 or sd * (before[0] - d0) > 1e-9:
            break
        out.pop()
    return out


def material_intervals(start, boundary, level: float, sd: float) -> list[tuple[float, float]]:
    """The p intervals where a pass along d = level stays out of the part: the boundary (approach +
    contour, monotonic in p) is at the level or beyond it, from the start's p to the contour's end.
    A level that runs along a shoulder or a pocket floor passes over it."""
    p0 = start[1]
    pb = boundary[-1][1][1]
    sp = _sign(pb - p0)
    cuts = {p0, pb}
    cuts.update(p for p in hits(start, boundary, level) if sp * (p - p0) > EPS and sp * (pb - p) > EPS)
    ordered = sorted(cuts, key=lambda p: sp * (p - p0))
    across = swapped(boundary)
    flipped = (start[1], start[0])
    out: list[tuple[float, float]] = []
    for u, v in zip(ordered, ordered[1:]):
        if abs(v - u) < 1e-7:
            continue
        ds = hits(flipped, across, (u + v) / 2)
        if not ds or sd * (ds[0] - level) < -1e-7:     # the part stands above the level here
            continue
        if out and abs(out[-1][1] - u) < 1e-7:
            out[-1] = (out[-1][0], v)
        else:
            out.append((u, v))
    return out


def rough_pockets(start, approach_end, contour, depth: float, retract: float):
    """G71/G72 type II roughing: a contour monotonic in p that may turn back in d (pockets).

    Levels step from d0 by `depth` down to the contour's deepest point. At each level the material
    is a set of p intervals (material_intervals); an interval at one level lies inside one interval
    of the level before, so they form a tree. First the intervals that start at the start point's p
    are cut level after level, exactly as type I. Then each pocket, nearest the start first: from
    d0 down over its entry side to the level above it (cut air), plunge at the entry wall, cut to
    the exit wall, retract 45 degrees by `retract`, and so on into the deeper intervals inside it,
    each reached at the height of the retract above them (air just cut); back out to d0 between
    pockets and finally to the start point. The approach and link moves are nctrans's model: the
    cutting levels are the control's, its moves between them vary by make and parameter."""
    d0, p0 = start
    if not contour or depth <= 0:
        return []
    boundary = [("linear", approach_end, None, None)] + list(contour)
    sd = _sign(approach_end[0] - d0)
    sp = _sign(contour[-1][1][1] - p0)
    bottom = _extreme(start, boundary, sd)
    levels = []
    k = 1
    while sd * (d0 + sd * k * depth - bottom) < -1e-9:
        level = d0 + sd * k * depth
        levels.append((level, material_intervals(start, boundary, level, sd)))
        k += 1

    def height(i):                      # just above level i (i = -1: the start side d0)
        return d0 if i < 0 else levels[i][0] - sd * retract

    out: list = []

    def rapid(pt):
        here = out[-1][1] if out else start
        if abs(here[0] - pt[0]) > EPS or abs(here[1] - pt[1]) > EPS:
            out.append(("rapid", pt, None, None))

    def cut(i, u, v):
        level = levels[i][0]
        out.append(("linear", (level, u), None, None))
        out.append(("linear", (level, v), None, None))
        back = min(retract, abs(v - u))          # the retract stays over the slab just cut
        rapid((level - sd * retract, v - sp * back))

    def inside(i, u, v):
        return [iv for iv in levels[i][1] if sp * (iv[0] - u) > -1e-7 and sp * (v - iv[1]) > -1e-7]

    main = []                           # (level index, end) of the intervals at the start side
    for i, (level, ivs) in enumerate(levels):
        if ivs and abs(ivs[0][0] - p0) < 1e-7:
            main.append((i, ivs[0][1]))
    for i, v in main:
        rapid((levels[i][0], p0))
        out.append(("linear", (levels[i][0], v), None, None))
        rapid((levels[i][0] - sd * retract, v - sp * retract))
        rapid((levels[i][0] - sd * retract, p0))

    def descend(i, u, v):
        for cu, cv in (inside(i + 1, u, v) if i + 1 < len(levels) else []):
            rapid((height(i), out[-1][1][1]))
            rapid((height(i), cu))
            cut(i + 1, cu, cv)
            descend(i + 1, cu, cv)

    mains = dict(main)
    roots = []
    for i, (level, ivs) in enumerate(levels):
        for u, v in ivs:
            if abs(u - p0) < 1e-7:
                continue
            parent_main = i == 0 or (i - 1 in mains and sp * (mains[i - 1] - v) > -1e-7)
            if parent_main:
                roots.append((u, i, v))
    for u, i, v in sorted(roots, key=lambda r: (sp * (r[0] - p0), r[1])):
        here = out[-1][1] if out else start
        rapid((d0, here[1]))
        rapid((d0, u))
        rapid((height(i - 1), u))
        cut(i, u, v)
        descend(i, u, v)
    if roots:
        rapid((d0, out[-1][1][1]))
        rapid((d0, p0))
    return out


def return_to(point, current):
    """Back to the cycle start: across in d first (away from the part), then along p."""
    out = []
    if abs(current[0] - point[0]) > EPS:
        out.append(("rapid", (point[0], current[1]), None, None))
    if abs(current[1] - point[1]) > EPS:
        out.append(("rapid", point, None, None))
    return out


# ------------------------------------------------------------------------------ box cycles

def box_turn(start, target, taper: float):
    """G90 (d = X, p = Z) and, with axes swapped, G94: plunge (rapid), cut to the target (with the
    taper: d at the start side is target + taper), cut back across to d0, rapid back along p."""
    (d0, p0), (dt, pt) = start, target
    return [("rapid", (dt + taper, p0), None, None), ("linear", (dt, pt), None, None),
            ("linear", (d0, pt), None, None), ("rapid", (d0, p0), None, None)]


def box_thread(start, target, taper: float):
    """G92: plunge (rapid), thread to the target, rapid out across, rapid back along p."""
    (d0, p0), (dt, pt) = start, target
    return [("rapid", (dt + taper, p0), None, None), ("thread", (dt, pt), None, None),
            ("rapid", (d0, pt), None, None), ("rapid", (d0, p0), None, None)]


# ------------------------------------------------------------------------------ threading

def thread_depths(height: float, first: float, min_step: float = 0.0, finish_allow: float = 0.0,
                  finish_passes: int = 0) -> list[float]:
    """G76 infeed depths from the crest, constant chip area: first * sqrt(n), each step at least
    `min_step`, the roughing passes ending at height - finish_allow, then `finish_passes` passes
    at the full height."""
    if height <= 0 or first <= 0:
        return [max(height, 0.0)] * max(finish_passes, 1)
    rough_end = height - finish_allow
    out: list[float] = []
    prev = 0.0
    n = 1
    while True:
        d = first * math.sqrt(n)
        if d - prev < min_step:
            d = prev + min_step
        if d >= rough_end - 1e-12:
            out.append(rough_end)
            break
        out.append(d)
        prev = d
        n += 1
    if finish_allow > 0 and finish_passes == 0:
        finish_passes = 1
    out.extend([height] * finish_passes)
    return out


def thread_passes(start, target, height: float, depths: list[float], taper: float, angle: float,
                  chamfer: float = 0.0, chamfer_rise: float = 1.0):
    """G76 passes (d = X, p = Z). The root is the target; the crest lies `height` outside it (on the
    start side). Each pass: rapid along p to the flank-shifted start (single-edge infeed at half
    the tool angle), rapid across to the depth, thread to the end, rapid out to d0, rapid to p0.
    With a chamfer (pull-out) the thread leaves the root `chamfer` before the end and reaches the
    end `chamfer * chamfer_rise` further out (rise = tan of the pull-out angle, 1 at 45 degrees)."""
    (d0, p0), (dt, pt) = start, target
    sd = _sign(dt - d0)
    sp = _sign(pt - p0)
    crest = dt - sd * height
    half = math.tan(math.radians(angle) / 2) if angle else 0.0
    out = []
    for depth in depths:
        shift = -sp * (height - depth) * half if half else 0.0
        d_cut = crest + sd * depth
        ps = p0 + shift
        if abs(shift) > EPS:
            out.append(("rapid", (d0, ps), None, None))
        out.append(("rapid", (d_cut + taper, ps), None, None))
        if chamfer > EPS:
            out.append(("thread", (d_cut, pt + shift - sp * chamfer), None, None))
            out.append(("thread", (d_cut - sd * chamfer * chamfer_rise, pt + shift), None, None))
        else:
            out.append(("thread", (d_cut, pt + shift), None, None))
        if abs(out[-1][1][0] - d0) > EPS:           # a pull-out may end on the start line
            out.append(("rapid", (d0, pt + shift), None, None))
        out.append(("rapid", (d0, p0), None, None))
    return out


# ------------------------------------------------------------------------------ peck cycles

def peck_passes(start, target, peck: float, shift: float, retract: float):
    """G75 (d = X pecks, p = Z columns) and, swapped, G74. Each column: peck towards the target d
    by `peck` (all at once when 0), rapid back by `retract` between pecks, rapid out to d0; the
    next column is `shift` further along p (the last one exactly at the target p); finally rapid
    back to p0."""
    (d0, p0), (dt, pt) = start, target
    sd = _sign(dt - d0)
    sp = _sign(pt - p0)
    columns = [p0]
    if shift > EPS and abs(pt - p0) > EPS:
        c = p0
        while sp * (pt - c) > EPS:
            c = c + sp * shift
            if sp * (c - pt) > -EPS:
                c = pt
            columns.append(c)
    elif abs(pt - p0) > EPS:
        columns.append(pt)
    out = []
    for i, pc in enumerate(columns):
        if i:
            out.append(("rapid", (d0, pc), None, None))
        cur = d0
        while True:
            nxt = cur + sd * peck if peck > EPS else dt
            if sd * (nxt - dt) >= -EPS:
                nxt = dt
            out.append(("linear", (nxt, pc), None, None))
            if nxt == dt:
                break
            out.append(("rapid", (nxt - sd * retract, pc), None, None))
            cur = nxt
        out.append(("rapid", (d0, pc), None, None))
    if abs(columns[-1] - p0) > EPS:
        out.append(("rapid", (d0, p0), None, None))
    return out
