"""Cutter radius compensation against LinuxCNC's rs274, plus geometric properties.

Each case is a small contour written once as segments; the test turns it into an ISO program for
rs274 and into PlannedMoves for CutterCompensator, and compares the compensated canonical moves
(end points, arc centres and rotation) within 1e-4 (rs274 prints 4 decimals).
"""
from __future__ import annotations

import math
import shutil

import pytest
import rs274 as h
from hypothesis import assume, given, settings, strategies as st

from nctrans.interp.cutter_comp import CutterCompensator, PlannedMove

RS274 = shutil.which("rs274")
needs_rs274 = pytest.mark.skipif(RS274 is None, reason="LinuxCNC rs274 not installed")

PLANES = {"XY": ("G17", "X", "Y", "Z", "I", "J"), "ZX": ("G18", "Z", "X", "Y", "K", "I")}


def program(start, segs, side, radius, exit_pt, plane="XY"):
    g, a1, a2, a3, i1, i2 = PLANES[plane]
    lines = ["G21 G90 G40 G80", g, "T1 M6",
             f"G0 {a1}{start[0]} {a2}{start[1]} {a3}0", "(BEGIN)",
             f"{'G41' if side == 'left' else 'G42'} D1"]
    for s in segs:
        if s[0] in ("G0", "G1"):
            lines.append(f"{s[0]} {a1}{s[1]} {a2}{s[2]} F100")
        elif s[0] == "Z":
            lines.append(f"G1 {a3}{s[1]} F100")
        else:                                   # ("G2"/"G3", e1, e2, c1, c2) absolute centre
            prev = _prev_point(start, segs, s)
            lines.append(f"{s[0]} {a1}{s[1]} {a2}{s[2]} {i1}{s[3] - prev[0]} {i2}{s[4] - prev[1]} F100")
    if exit_pt is not None:
        lines.append(f"G40 G1 {a1}{exit_pt[0]} {a2}{exit_pt[1]}")
    lines += ["(END)", "M2"]
    return "\n".join(lines) + "\n"


def _prev_point(start, segs, upto):
    p = start
    for s in segs:
        if s is upto:
            return p
        if s[0] != "Z":
            p = (s[1], s[2])
    return p


def rs274_moves(tmp_path, text, radius, plane="XY"):
    # standalone rs274 reads the tool table in inches: diameter 2r mm
    calls, message = h.calls_between_markers(tmp_path, text, f"T1 P1 Z0 D{2 * radius / 25.4:.12f} ;\n")
    moves = []
    for name, args in calls:
        v = [float(x) for x in args.split(",")] if name in ("STRAIGHT_FEED", "STRAIGHT_TRAVERSE", "ARC_FEED") else []
        if name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            # straight moves print X, Y, Z; reorder to (first, second, third) of the plane like ARC_FEED
            xyz = (v[0], v[1], v[2]) if plane == "XY" else (v[2], v[0], v[1])
            moves.append(("rapid" if name == "STRAIGHT_TRAVERSE" else "linear", xyz, None, 0))
        elif name == "ARC_FEED":
            moves.append(("arc", (v[0], v[1], v[5]), (v[2], v[3]), int(v[4])))
    return moves, message


def run_comp(start, segs, side, radius, exit_pt, plane="XY"):
    """The same contour through CutterCompensator, as rs274-shaped tuples (plane coords + third axis)."""
    a1, a2 = {"XY": ("X", "Y"), "ZX": ("Z", "X")}[plane]
    a3 = {"XY": "Z", "ZX": "Y"}[plane]
    comp = CutterCompensator(side, radius, plane)
    pos = {a1: float(start[0]), a2: float(start[1]), a3: 0.0}
    out = []
    for n, s in enumerate(segs):
        end = dict(pos)
        if s[0] == "Z":
            end[a3] = float(s[1])
            mv = PlannedMove("linear", dict(pos), end, payload=n)
        else:
            end[a1], end[a2] = float(s[1]), float(s[2])
            if s[0] in ("G2", "G3"):
                mv = PlannedMove("arc", dict(pos), end, center={a1: s[3], a2: s[4]},
                                 direction="cw" if s[0] == "G2" else "ccw", payload=n)
            else:
                mv = PlannedMove("rapid" if s[0] == "G0" else "linear", dict(pos), end, payload=n)
        out += comp.push(mv)
        out += comp.push(("event", n))
        pos = end
    exit_mv = None
    if exit_pt is not None:
        end = dict(pos)
        end[a1], end[a2] = float(exit_pt[0]), float(exit_pt[1])
        exit_mv = PlannedMove("linear", dict(pos), end, payload="exit")
    out += comp.finish(exit_mv)
    return out, comp


def shaped(out, plane="XY"):
    a1, a2 = {"XY": ("X", "Y"), "ZX": ("Z", "X")}[plane]
    a3 = {"XY": "Z", "ZX": "Y"}[plane]
    res = []
    for m in out:
        if isinstance(m, PlannedMove):
            rot = 0
            if m.kind == "arc":
                rot = (m.turns + 1) * (1 if m.direction == "ccw" else -1)
            res.append((m.kind, (m.end[a1], m.end[a2], m.end[a3]),
                        (m.center[a1], m.center[a2]) if m.kind == "arc" else None, rot))
    return res


def assert_moves(got, want, tol=1e-4):
    assert [g[0] for g in got] == [w[0] for w in want], (got, want)
    for g, w in zip(got, want):
        assert all(abs(a - b) <= tol for a, b in zip(g[1], w[1])), (g, w)
        if w[2] is not None:
            assert all(abs(a - b) <= tol for a, b in zip(g[2], w[2])), (g, w)
            assert g[3] == w[3], (g, w)


def assert_continuous(out):
    prev = None
    for m in out:
        if isinstance(m, PlannedMove):
            if prev is not None:
                for ax, v in m.start.items():
                    assert math.isclose(v, prev.end.get(ax, v), abs_tol=1e-9), (prev, m)
            prev = m


SQUARE = [("G1", 0, 0), ("G1", 10, 0), ("G1", 10, 10), ("G1", 0, 10), ("G1", 0, 0)]
SQUARE_CW = [("G1", 0, 0), ("G1", 0, 10), ("G1", 10, 10), ("G1", 10, 0), ("G1", 0, 0)]

CASES = [
    # id, start, segments, side, radius, exit, plane
    ("square-ccw-left", (-5, -5), SQUARE, "left", 1, (-5, -5), "XY"),
    ("square-ccw-right", (-5, -5), SQUARE, "right", 1, (-5, -5), "XY"),
    ("square-cw-left", (-5, -5), SQUARE_CW, "left", 1, (-5, -5), "XY"),
    ("square-cw-right", (-5, -5), SQUARE_CW, "right", 1.5, (-5, -5), "XY"),
    ("line-arc-line-tangent", (-5, 0), [("G1", 0, 0), ("G1", 10, 0), ("G3", 15, 5, 10, 5),
                                        ("G1", 15, 15)], "left", 1, (20, 20), "XY"),
    ("line-arc-line-tangent-outside", (-5, 0), [("G1", 0, 0), ("G1", 10, 0), ("G3", 15, 5, 10, 5),
                                                ("G1", 15, 15)], "right", 1, (20, 20), "XY"),
    ("line-arc-nontangent", (-5, 0), [("G1", 0, 0), ("G1", 10, 0), ("G2", 20, 0, 15, -3),
                                      ("G1", 25, 5)], "left", 1, (30, 5), "XY"),
    ("line-arc-nontangent-right", (-5, 0), [("G1", 0, 0), ("G1", 10, 0), ("G2", 20, 0, 15, -3),
                                            ("G1", 25, 5)], "right", 1, (30, 5), "XY"),
    ("concave-arc", (-5, 0), [("G1", 0, 0), ("G1", 10, 0), ("G3", 20, 0, 15, 2),
                              ("G1", 30, 0)], "left", 1, (35, -5), "XY"),
    ("arc-arc", (-5, 0), [("G1", 0, 0), ("G2", 10, 0, 5, 0), ("G2", 20, 0, 15, 0),
                          ("G3", 30, 0, 25, 0)], "left", 1, (35, 0), "XY"),
    ("arc-arc-right", (-5, 0), [("G1", 0, 0), ("G3", 10, 0, 5, -1), ("G3", 20, 0, 15, 1),
                                ("G1", 20, 10)], "right", 0.5, (25, 10), "XY"),
    ("arc-line-concave", (-5, 0), [("G1", 0, 0), ("G3", 10, 0, 5, -4), ("G1", 10, 10)],
     "left", 1, (5, 15), "XY"),
    ("rapids-while-on", (-5, -5), [("G0", 0, 0), ("G0", 10, 0), ("G1", 10, 10), ("G0", 0, 10),
                                   ("G1", 0, 0)], "right", 1, (-5, -5), "XY"),
    ("z-moves-in-concave-corner", (-5, -5), [("G1", 0, 0), ("G1", 10, 0), ("Z", 5), ("Z", -1),
                                             ("G1", 10, 10)], "left", 1, (5, 15), "XY"),
    ("g18-zx", (-5, -5), [("G1", 0, 0), ("G1", 10, 0), ("G2", 15, 5, 10, 5), ("G1", 15, 15)],
     "left", 1, (20, 20), "ZX"),
    ("arc-entry", (-5, 0), [("G3", 5, 0, 0, 0), ("G1", 5, 10)], "left", 1, (0, 15), "XY"),
    ("collinear", (-5, 0), [("G1", 0, 0), ("G1", 5, 0), ("G1", 10, 0), ("G1", 10, 5)],
     "right", 1, (15, 5), "XY"),
]


@needs_rs274
@pytest.mark.rs274
@pytest.mark.parametrize("name,start,segs,side,radius,exit_pt,plane", CASES, ids=[c[0] for c in CASES])
def test_matches_rs274(tmp_path, name, start, segs, side, radius, exit_pt, plane):
    want, log = rs274_moves(tmp_path, program(start, segs, side, radius, exit_pt, plane), radius,
                             plane)
    assert want, log
    out, comp = run_comp(start, segs, side, radius, exit_pt, plane)
    assert not comp.problems
    assert_moves(shaped(out, plane), want)
    assert_continuous(out)


GOUGES = [
    ("inside-arc-too-small", (-5, 0), [("G1", 0, 0), ("G1", 10, 0), ("G3", 10, 1, 10, 0.5),
                                       ("G1", 0, 1)], "left", 1, None),
    ("concave-step-too-narrow", (-5, -5), [("G1", 0, 0), ("G1", 10, 0), ("G1", 10, 1),
                                           ("G1", 0, 1)], "left", 1, None),
    ("entry-too-short", (0, 0), [("G1", 0.5, 0), ("G1", 10, 0)], "left", 1, None),
]


@needs_rs274
@pytest.mark.rs274
@pytest.mark.parametrize("name,start,segs,side,radius,exit_pt", GOUGES, ids=[g[0] for g in GOUGES])
def test_rs274_errors_become_problems(tmp_path, name, start, segs, side, radius, exit_pt):
    """Where rs274 stops with an error, the filter records a problem instead and keeps going."""
    text = program(start, segs, side, radius, exit_pt)
    _, log = rs274_moves(tmp_path, text, radius)
    message, block = [line for line in log.splitlines() if line != "executing"][:2]
    out, comp = run_comp(start, segs, side, radius, exit_pt)
    assert [m for _, m in comp.problems] == [message]
    # the problem is attributed to the block rs274 stopped at
    n = comp.problems[0][1] and comp.problems[0][0]
    assert text.splitlines()[text.splitlines().index("G41 D1" if side == "left" else "G42 D1") + 1 + n] == block
    assert_continuous(out)


def test_events_keep_their_order():
    """Events pushed after a move come out after it, even though the move is held back."""
    out, _ = run_comp((-5, -5), SQUARE, "left", 1, (-5, -5))
    order = [("m", m.payload) if isinstance(m, PlannedMove) else m for m in out]
    seen_events = [o[1] for o in order if o[0] == "event"]
    assert seen_events == sorted(seen_events)
    # every move of segment n (including its corner arc) precedes the event pushed after segment n
    for n in range(len(SQUARE)):
        ev = order.index(("event", n))
        assert all(order.index(("m", k)) < ev for k in range(n + 1) if ("m", k) in order)


def test_finish_with_arc_exit_runs_the_arc():
    """An arc as the exit move still runs (uncompensated from the held end); the interpreter reports
    it as NC212 whether or not the radius is known, so the filter records no problem of its own."""
    comp = CutterCompensator("left", 1.0)
    comp.push(PlannedMove("linear", {"X": -5, "Y": 0}, {"X": 0, "Y": 0}, payload=1))
    out = comp.finish(PlannedMove("arc", {"X": 0, "Y": 0}, {"X": 2, "Y": 0}, center={"X": 1, "Y": 0},
                                  direction="cw", payload=2))
    assert [m.payload for m in out] == [1, 2]
    assert comp.problems == []


def test_negative_radius_swaps_side():
    a, _ = run_comp((-5, -5), SQUARE, "left", -1, (-5, -5))
    b, _ = run_comp((-5, -5), SQUARE, "right", 1, (-5, -5))
    assert_moves(shaped(a), shaped(b), tol=1e-12)


# --- properties --------------------------------------------------------------------------------

def _dist_to_segment(p, a, b):
    ax, ay = a
    bx, by = b
    dx, dy = bx - ax, by - ay
    t = max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / (dx * dx + dy * dy)))
    return math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy)


def _samples(m, n=12):
    sx, sy, ex, ey = m.start["X"], m.start["Y"], m.end["X"], m.end["Y"]
    if m.kind != "arc":
        return [(sx + (ex - sx) * k / n, sy + (ey - sy) * k / n) for k in range(n + 1)]
    cx, cy = m.center["X"], m.center["Y"]
    r = math.hypot(sx - cx, sy - cy)
    a0 = math.atan2(sy - cy, sx - cx)
    a1 = math.atan2(ey - cy, ex - cx)
    sweep = (a1 - a0) % (2 * math.pi) if m.direction == "ccw" else -((a0 - a1) % (2 * math.pi))
    return [(cx + r * math.cos(a0 + sweep * k / n), cy + r * math.sin(a0 + sweep * k / n))
            for k in range(n + 1)]


@st.composite
def convex_polygons(draw):
    """(CCW convex polygon, radius) where the inside offset fits: each edge outlasts its corner retreats."""
    n = draw(st.integers(3, 8))
    radius = draw(st.floats(0.1, 1.5))
    cuts = sorted(draw(st.lists(st.floats(0, 2 * math.pi, exclude_max=True), min_size=n, max_size=n,
                                unique=True)))
    rad = draw(st.floats(20, 100))
    cx, cy = draw(st.floats(-50, 50)), draw(st.floats(-50, 50))
    pts = [(round(cx + rad * math.cos(a), 6), round(cy + rad * math.sin(a), 6)) for a in cuts]
    edges = [math.dist(pts[i], pts[(i + 1) % n]) for i in range(n)]
    assume(min(edges) > 4.0)
    # keep corners away from LinuxCNC's 0.05 rad "straight enough" band
    for i in range(n):
        a, b, c = pts[i - 1], pts[i], pts[(i + 1) % n]
        t1 = math.atan2(b[1] - a[1], b[0] - a[0])
        t2 = math.atan2(c[1] - b[1], c[0] - b[0])
        assume(0.1 < (t2 - t1) % (2 * math.pi) < math.pi - 0.1)
    def retreat(i):
        a, b, c = pts[i - 1], pts[i], pts[(i + 1) % n]
        turn = (math.atan2(c[1] - b[1], c[0] - b[0]) - math.atan2(b[1] - a[1], b[0] - a[0])) % (2 * math.pi)
        return radius / math.tan((math.pi - turn) / 2)
    assume(all(retreat(i) + retreat((i + 1) % n) < edges[i] - 0.01 for i in range(n)))
    return pts, radius


@settings(max_examples=150, deadline=None)
@given(poly=convex_polygons())
def test_convex_polygon_offset_keeps_radius(poly):
    """A CCW convex polygon, G41 (inside: concave corners) and G42 (outside: corner arcs).

    After the entry move the compensated path stays at least r from every programmed edge and is
    exactly r from each edge's midpoint.
    """
    pts, radius = poly
    n = len(pts)
    # start outside the polygon, on the outward normal of the first edge's start
    (x0, y0), (x1, y1) = pts[0], pts[1]
    ln = math.hypot(x1 - x0, y1 - y0)
    nx, ny = (y1 - y0) / ln, -(x1 - x0) / ln                  # right of a CCW edge = outside
    start = (x0 + 10 * nx - 10 * (x1 - x0) / ln, y0 + 10 * ny - 10 * (y1 - y0) / ln)
    segs = [("G1", *pts[0])] + [("G1", *pts[(i + 1) % n]) for i in range(n)] + [("G1", *pts[1])]
    edges = [(pts[i], pts[(i + 1) % n]) for i in range(n)]
    for side in ("right", "left"):
        out, comp = run_comp(start, segs, side, radius, None)
        assert not comp.problems
        assert_continuous(out)
        # payload k runs along edge k-1. The entry (0), the first pass along edge 0 (1: starts at
        # the entry corner) and the repeated edge 0 (n+1: the path stops, so its end has no
        # corner and keeps the normal offset) only count for the midpoint check.
        moves = [m for m in out if isinstance(m, PlannedMove) and m.payload >= 2]
        for m in moves:
            if m.payload > n:
                continue
            for p in _samples(m):
                d = min(_dist_to_segment(p, a, b) for a, b in edges)
                assert d >= radius - 1e-7
        # each compensated edge runs on the edge's offset line
        for m in moves:
            if m.kind == "linear":
                a, b = edges[(m.payload - 1) % n]
                for p in ((m.start["X"], m.start["Y"]), (m.end["X"], m.end["Y"])):
                    assert abs(_dist_to_line(p, a, b) - radius) < 1e-9
        if side == "right":
            # outside: the whole offset edge is cut, so each edge midpoint is exactly r away
            for a, b in edges:
                mid = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
                best = min(_dist_to_segment(mid, (m.start["X"], m.start["Y"]), (m.end["X"], m.end["Y"]))
                           for m in moves if m.kind == "linear")
                assert abs(best - radius) < 1e-9


def _dist_to_line(p, a, b):
    return abs((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])) / math.dist(a, b)

