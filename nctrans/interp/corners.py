"""Geometry of a contour corner element: the rounding arc or chamfer line a control inserts between
two contour elements (Sinumerik RND/RNDM/CHF/CHR, ISO `,R`/`,C`).

Pure plane geometry on (abscissa, ordinate) pairs; the interpreter's corner stage
(corner_elements.py) takes the moves apart and back. An element is a line or an arc (centre,
direction) from `start` to `end`; the corner is the first element's end = the second's start.

- Rounding of radius r: the circle of radius r tangent to both elements on the inside of the
  corner: the elements offset by r towards the turn meet in its centre; its feet on the elements
  are the tangent points (seed ISO L3960-3967; Sinumerik RND, spec 9.3).
- Chamfer CHR (ISO `,C`): the line between the points at distance `leg` from the corner along each
  element (straight distance from the corner, which on a line is the length along it).
- Chamfer CHF: the same line, the legs chosen so that the chamfer itself is `length` long.
- A corner whose elements meet at less than ANGLE_TOLERANCE_DEG (tangent, or nearly) gets no
  element: its length would be zero (seed ISO L4014-4018).
An element that does not fit (radius or legs longer than the elements allow) gives None with why.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

Point = tuple[float, float]

# the seed's "travel distance zero" rule: elements meeting within 1 degree get no corner element
ANGLE_TOLERANCE_DEG = 1.0
_EPS = 1e-9


@dataclass(frozen=True)
class Element:
    """A contour element in the plane: a line, or an arc about `center` (cw or ccw, under a turn)."""
    kind: str                       # "linear" or "arc"
    start: Point
    end: Point
    center: Optional[Point] = None
    cw: Optional[bool] = None

    @property
    def radius(self) -> float:
        return math.dist(self.center, self.start)


@dataclass(frozen=True)
class Corner:
    """What goes between the two trimmed elements: a line (chamfer) or an arc (rounding)."""
    first_end: Point                # the first element now ends here
    second_start: Point             # the second element now starts here
    kind: str                       # "linear" or "arc"
    center: Optional[Point] = None
    cw: Optional[bool] = None


def _sub(a: Point, b: Point) -> Point:
    return (a[0] - b[0], a[1] - b[1])


def _unit(v: Point) -> Point:
    length = math.hypot(*v)
    return (v[0] / length, v[1] / length)


def _cross(a: Point, b: Point) -> float:
    return a[0] * b[1] - a[1] * b[0]


def _dot(a: Point, b: Point) -> float:
    return a[0] * b[0] + a[1] * b[1]


def tangent(e: Element, p: Point) -> Point:
    """Unit direction of travel of `e` at its point `p`."""
    if e.kind == "linear":
        return _unit(_sub(e.end, e.start))
    rx, ry = _unit(_sub(p, e.center))
    return (ry, -rx) if e.cw else (-ry, rx)


def _sweep(e: Element) -> float:
    """Angle an arc turns through from start to end in its direction (0, 2 pi]."""
    a0 = math.atan2(e.start[1] - e.center[1], e.start[0] - e.center[0])
    a1 = math.atan2(e.end[1] - e.center[1], e.end[0] - e.center[0])
    d = (a0 - a1) if e.cw else (a1 - a0)
    d %= 2 * math.pi
    return d if d > _EPS else 2 * math.pi


def _along(e: Element, p: Point) -> Optional[float]:
    """Where the point `p` of e's carrier lies along `e`: 0 at start, 1 at end; None off it."""
    if e.kind == "linear":
        d = _sub(e.end, e.start)
        length2 = _dot(d, d)
        t = _dot(_sub(p, e.start), d) / length2
    else:
        a0 = math.atan2(e.start[1] - e.center[1], e.start[0] - e.center[0])
        ap = math.atan2(p[1] - e.center[1], p[0] - e.center[0])
        turn = ((a0 - ap) if e.cw else (ap - a0)) % (2 * math.pi)
        if turn > 2 * math.pi - 1e-7:
            turn = 0.0
        t = turn / _sweep(e)
    return t if -1e-7 <= t <= 1 + 1e-7 else None


def degenerate(e: Element) -> bool:
    """Whether `e` has no direction to round or chamfer: a line of no length in the plane, an arc
    of no radius (a zero-length or an out-of-plane move beside the corner)."""
    if e.kind == "linear":
        return not math.hypot(*_sub(e.end, e.start)) > _EPS
    return e.center is None or not e.radius > _EPS


def deflection(first: Element, second: Element) -> float:
    """Signed turn at the corner, radians in (-pi, pi): > 0 to the left (ccw)."""
    t1 = tangent(first, first.end)
    t2 = tangent(second, second.start)
    return math.atan2(_cross(t1, t2), _dot(t1, t2))


def is_tangent(first: Element, second: Element) -> bool:
    return abs(math.degrees(deflection(first, second))) < ANGLE_TOLERANCE_DEG


def _at_distance(e: Element, corner: Point, dist: float, backwards: bool) -> Optional[Point]:
    """The point of `e` at straight distance `dist` from `corner` (its end when `backwards`, else
    its start), or None when `e` is not that long."""
    if e.kind == "linear":
        d = _unit(_sub(e.end, e.start))
        s = -1.0 if backwards else 1.0
        p = (corner[0] + s * dist * d[0], corner[1] + s * dist * d[1])
    else:
        r = e.radius
        if dist > 2 * r:
            return None
        theta = 2 * math.asin(dist / (2 * r))
        # along the arc's direction (ccw: +) forwards, against it backwards
        s = (-1.0 if e.cw else 1.0) * (-1.0 if backwards else 1.0)
        a = math.atan2(corner[1] - e.center[1], corner[0] - e.center[0]) + s * theta
        p = (e.center[0] + r * math.cos(a), e.center[1] + r * math.sin(a))
    return p if _along(e, p) is not None else None


def _max_leg(e: Element) -> float:
    """The longest straight distance from an end of `e` that _at_distance reaches on it."""
    if e.kind == "linear":
        return math.dist(e.start, e.end)
    return math.dist(e.start, e.end) if _sweep(e) <= math.pi else 2 * e.radius


def chamfer_legs(first: Element, second: Element, leg: float) -> tuple[Optional[Corner], str]:
    """Chamfer whose ends lie `leg` from the corner on each element (Sinumerik CHR, ISO `,C`)."""
    c = first.end
    p1 = _at_distance(first, c, leg, True)
    p2 = _at_distance(second, c, leg, False)
    if p1 is None or p2 is None:
        return None, f"the chamfer's legs ({leg:g}) are longer than the contour elements allow"
    return Corner(p1, p2, "linear"), ""


def chamfer_length(first: Element, second: Element, length: float) -> tuple[Optional[Corner], str]:
    """Chamfer `length` long, its ends equally far from the corner (Sinumerik CHF)."""
    c = first.end

    def span(leg: float) -> Optional[float]:
        p1 = _at_distance(first, c, leg, True)
        p2 = _at_distance(second, c, leg, False)
        return None if p1 is None or p2 is None else math.dist(p1, p2)

    # the chamfer grows with its legs: bisect on the leg between 0 and the longest that fits
    hi = min(_max_leg(first), _max_leg(second)) * (1 - 1e-12)
    if hi <= 1e-9 or (span(hi) or 0.0) < length - 1e-9:
        return None, f"a chamfer {length:g} long does not fit on the contour elements"
    lo = 0.0
    for _ in range(80):
        mid = (lo + hi) / 2
        if span(mid) < length:
            lo = mid
        else:
            hi = mid
    return chamfer_legs(first, second, (lo + hi) / 2)


def _offset(e: Element, side: float, r: float):
    """e's carrier moved by r to the left (side +1) or right (-1) of its travel:
    ("line", point, direction) or ("circle", centre, radius); None when a circle vanishes."""
    if e.kind == "linear":
        d = _unit(_sub(e.end, e.start))
        n = (-d[1] * side * r, d[0] * side * r)
        return ("line", (e.start[0] + n[0], e.start[1] + n[1]), d)
    # left of a ccw arc is towards its centre
    rad = e.radius + (side * r if e.cw else -side * r)
    return None if rad <= _EPS else ("circle", e.center, rad)


def _intersect(a, b) -> list[Point]:
    if a[0] == "line" and b[0] == "line":
        (_, p, d), (_, q, f) = a, b
        den = _cross(d, f)
        if abs(den) < _EPS:
            return []
        t = _cross(_sub(q, p), f) / den
        return [(p[0] + t * d[0], p[1] + t * d[1])]
    if a[0] == "circle" and b[0] == "line":
        a, b = b, a
    if a[0] == "line":
        (_, p, d), (_, c, r) = a, b
        # |p + t d - c| = r
        w = _sub(p, c)
        bq = _dot(w, d)
        disc = bq * bq - (_dot(w, w) - r * r)
        if disc < -_EPS:
            return []
        s = math.sqrt(max(disc, 0.0))
        return [(p[0] + t * d[0], p[1] + t * d[1]) for t in (-bq - s, -bq + s)]
    (_, c1, r1), (_, c2, r2) = a, b
    dist = math.dist(c1, c2)
    if dist < _EPS or dist > r1 + r2 + _EPS or dist < abs(r1 - r2) - _EPS:
        return []
    x = (dist * dist + r1 * r1 - r2 * r2) / (2 * dist)
    h = math.sqrt(max(r1 * r1 - x * x, 0.0))
    u = _unit(_sub(c2, c1))
    m = (c1[0] + x * u[0], c1[1] + x * u[1])
    return [(m[0] - h * u[1], m[1] + h * u[0]), (m[0] + h * u[1], m[1] - h * u[0])]


def _foot(e: Element, p: Point) -> Point:
    """The point of e's carrier nearest to p."""
    if e.kind == "linear":
        d = _unit(_sub(e.end, e.start))
        t = _dot(_sub(p, e.start), d)
        return (e.start[0] + t * d[0], e.start[1] + t * d[1])
    u = _unit(_sub(p, e.center))
    r = e.radius
    return (e.center[0] + r * u[0], e.center[1] + r * u[1])


def rounding(first: Element, second: Element, r: float) -> tuple[Optional[Corner], str]:
    """The arc of radius r tangent to both elements inside the corner, or None with why."""
    turn = deflection(first, second)
    side = 1.0 if turn > 0 else -1.0
    o1, o2 = _offset(first, side, r), _offset(second, side, r)
    why = f"the rounding radius {r:g} is larger than the contour elements allow"
    if o1 is None or o2 is None:
        return None, why
    c = first.end
    best = None
    for centre in _intersect(o1, o2):
        p1, p2 = _foot(first, centre), _foot(second, centre)
        if _along(first, p1) is None or _along(second, p2) is None:
            continue
        # tangent with the travel: the fillet continues the first element's direction at p1
        if _dot(tangent(first, p1), tangent(Element("arc", p1, p2, centre, side < 0), p1)) < 0.999:
            continue
        d = math.dist(centre, c)
        if best is None or d < best[0]:
            best = (d, Corner(p1, p2, "arc", centre, side < 0))
    return (best[1], "") if best else (None, why)
