"""2D views of a scene: the projection, the page layout, and each move as a drawable shape.

Shared by the SVG and PNG renderers, so both draw exactly the same picture. An arc becomes a true
circular arc (the "arc" shape) when the view looks straight at the arc's plane (top: XY, front: ZX,
side: YZ) - a helix projects to a circle there too; in any other view it is a polyline whose chords
stay within a quarter of a pixel of the curve.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterator

from nctrans.backplot.scene import LINEAR_AXES, Move, Scene, arc_extremes
from nctrans.toolpath_io import arc_sweep

_S2, _S6 = math.sqrt(2.0), math.sqrt(6.0)
# view -> (screen right, screen up) as unit vectors in machine X, Y, Z
VIEWS: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "top": ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),        # looking down -Z
    "front": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),      # looking along +Y
    "side": ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),       # looking along -X (from the right)
    "iso": ((1 / _S2, 1 / _S2, 0.0), (-1 / _S6, 1 / _S6, 2 / _S6)),   # from +X -Y +Z
}
# the arc plane each view looks straight at
FACING_PLANE = {"top": "XY", "front": "ZX", "side": "YZ"}
_AXIS_INDEX = {a: i for i, a in enumerate(LINEAR_AXES)}

PAGE_WIDTH = 1200
MAX_PAGE_HEIGHT = 1200
MARGIN = 40          # around the drawing
FOOTER = 70          # below it: scale bar, axis triad, legend


@dataclass
class Layout:
    """Maps machine coordinates to page pixels for one view (y grows downwards on the page)."""
    view: str
    scale: float            # pixels per mm
    u0: float               # world u at the drawing's left edge
    v1: float               # world v at the drawing's top edge
    width: int
    height: int

    def uv(self, p) -> tuple[float, float]:
        r, u = VIEWS[self.view]
        return (r[0] * p[0] + r[1] * p[1] + r[2] * p[2], u[0] * p[0] + u[1] * p[1] + u[2] * p[2])

    def page(self, p) -> tuple[float, float]:
        u, v = self.uv(p)
        return (MARGIN + (u - self.u0) * self.scale, MARGIN + (self.v1 - v) * self.scale)

    @property
    def drawing_bottom(self) -> float:
        return self.height - FOOTER


def layout_for(scenes: list[Scene], view: str) -> Layout:
    """A page that fits every scene's bounding box (several scenes: --compare)."""
    if view not in VIEWS:
        raise ValueError(f"unknown view {view!r}")
    us: list[float] = []
    vs: list[float] = []
    probe = Layout(view, 1.0, 0.0, 0.0, 0, 0)
    for sc in scenes:
        for m in sc.moves:
            for p in (m.start, m.end):
                u, v = probe.uv(p)
                us.append(u)
                vs.append(v)
            if m.kind == "arc":     # the arc's extreme points in its plane bound it in every view
                for p in arc_extremes(m.record):
                    u, v = probe.uv(p)
                    us.append(u)
                    vs.append(v)
    if not us:
        us, vs = [0.0], [0.0]
    du, dv = max(us) - min(us), max(vs) - min(vs)
    span = max(du, dv, 1e-6)
    du, dv = max(du, span * 1e-3), max(dv, span * 1e-3)   # a flat view still gets a drawing area
    inner_w = PAGE_WIDTH - 2 * MARGIN
    scale = inner_w / du
    max_inner_h = MAX_PAGE_HEIGHT - 2 * MARGIN - FOOTER
    if dv * scale > max_inner_h:
        scale = max_inner_h / dv
    inner_h = max(dv * scale, 200.0)
    u0 = min(us) - (inner_w / scale - (max(us) - min(us))) / 2
    v1 = max(vs) + (inner_h / scale - (max(vs) - min(vs))) / 2
    return Layout(view, scale, u0, v1, PAGE_WIDTH, int(math.ceil(inner_h + 2 * MARGIN + FOOTER)))


@dataclass(slots=True)
class Arc:
    """A circular arc on the page: start point, then pieces (radius, sweep_positive, end point);
    sweep_positive means the page's positive-angle direction (clockwise on screen, y down).
    Every piece turns less than 180 degrees, so no large-arc flag is needed."""
    start: tuple[float, float]
    pieces: list[tuple[float, bool, tuple[float, float]]]


@dataclass(slots=True)
class Polyline:
    points: list[tuple[float, float]]


def _plane_orientation(view: str, plane: str) -> float:
    """+1 when the plane's (first, second) axes keep their turning sense on the page's (right, up)."""
    right, up = VIEWS[view]
    a1, a2 = plane[0], plane[1]
    i1, i2 = _AXIS_INDEX[a1], _AXIS_INDEX[a2]
    return right[i1] * up[i2] - up[i1] * right[i2]


def shape(move: Move, lay: Layout):
    """The page shape of a move: Arc for an arc facing the view, else Polyline."""
    r = move.record
    if r.kind != "arc":
        return Polyline([lay.page(move.start), lay.page(move.end)])
    plane = r.plane or "XY"
    if FACING_PLANE.get(lay.view) == plane:
        t0, sweep, radius, (a1, a2) = arc_sweep(r)
        if radius * lay.scale > 1e-3 and abs(sweep) > 1e-12:
            c = r.center or {}
            i1, i2 = _AXIS_INDEX[a1], _AXIS_INDEX[a2]
            n = max(1, math.ceil(abs(sweep) / (2 * math.pi / 3)))
            positive = sweep * _plane_orientation(lay.view, plane) < 0   # page y points down
            pieces = []
            base = list(move.start)
            for k in range(1, n + 1):
                if k == n:
                    p = move.end
                else:
                    ang = t0 + sweep * k / n
                    q = list(base)
                    q[i1] = c.get(a1, 0.0) + radius * math.cos(ang)
                    q[i2] = c.get(a2, 0.0) + radius * math.sin(ang)
                    p = tuple(q)
                pieces.append((radius * lay.scale, positive, lay.page(p)))
            return Arc(lay.page(move.start), pieces)
    return Polyline([lay.page(move.start)] + [lay.page(p) for p in arc_polyline(move, 0.25 / lay.scale)])


def arc_polyline(move: Move, tol: float) -> list[tuple[float, float, float]]:
    """Points along an arc move after its start (end included), chords within `tol` mm."""
    from nctrans.equivalence import arc_points
    return arc_points(move.record, LINEAR_AXES, max(tol, 1e-6))


def arc_tessellation(shp: Arc, max_err_px: float = 0.25) -> list[tuple[float, float]]:
    """Page points along an Arc shape (for rasterising): chords within max_err_px of the curve."""
    pts = [shp.start]
    x0, y0 = shp.start
    for radius, positive, end in shp.pieces:
        # centre of the circle through (x0, y0) and end with this radius, on the turning side
        mx, my = (x0 + end[0]) / 2, (y0 + end[1]) / 2
        dx, dy = end[0] - x0, end[1] - y0
        half = math.hypot(dx, dy) / 2
        if half < 1e-9 or radius < half:
            pts.append(end)
            x0, y0 = end
            continue
        h = math.sqrt(max(radius * radius - half * half, 0.0))
        nx, ny = -dy / (2 * half), dx / (2 * half)
        sign = 1.0 if positive else -1.0      # pieces turn < 180: the centre lies on the turning side
        cx, cy = mx + sign * nx * h, my + sign * ny * h
        a0 = math.atan2(y0 - cy, x0 - cx)
        a1 = math.atan2(end[1] - cy, end[0] - cx)
        sweep = a1 - a0
        if positive and sweep < 0:
            sweep += 2 * math.pi
        if not positive and sweep > 0:
            sweep -= 2 * math.pi
        step = 2 * math.acos(max(-1.0, 1 - max_err_px / radius)) if radius > max_err_px else math.pi
        n = max(1, math.ceil(abs(sweep) / step))
        for k in range(1, n):
            a = a0 + sweep * k / n
            pts.append((cx + radius * math.cos(a), cy + radius * math.sin(a)))
        pts.append(end)
        x0, y0 = end
    return pts


def shapes(scene: Scene, lay: Layout) -> Iterator[tuple[Move, object]]:
    for m in scene.moves:
        yield m, shape(m, lay)


def nice_length(target: float) -> float:
    """The 1, 2 or 5 times a power of ten closest below `target` (scale bar length in mm)."""
    if target <= 0:
        return 1.0
    exp = math.floor(math.log10(target))
    for f in (5.0, 2.0, 1.0):
        if f * 10 ** exp <= target:
            return f * 10 ** exp
    return 10 ** exp


def triad(view: str) -> list[tuple[str, float, float]]:
    """(axis name, page dx, page dy) of each machine axis's unit vector as seen in the view;
    axes seen end-on (shorter than a tenth) are left out."""
    right, up = VIEWS[view]
    out = []
    for i, a in enumerate(LINEAR_AXES):
        dx, dy = right[i], -up[i]
        if math.hypot(dx, dy) > 0.1:
            out.append((a, dx, dy))
    return out


# colours: one per tool in order of first use (Tableau 10, distinguishable and print-safe)
PALETTE = ("#1f77b4", "#2ca02c", "#a066c8", "#ff7f0e", "#8c564b", "#e377c2", "#17becf", "#bcbd22",
           "#7f7f7f", "#d62728")
COMPARE_COLOURS = ("#1f5fbf", "#e8590c")     # A, B in --compare
DIFF_COLOUR = "#d00000"
SEVERITY_COLOURS = {"error": "#d00000", "warning": "#e0a000", "info": "#2a80d0"}


def tool_colours(scene: Scene) -> dict:
    return {t: PALETTE[i % len(PALETTE)] for i, t in enumerate(scene.tools)}
