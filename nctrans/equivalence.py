"""Are two toolpaths the same machining? (`nctrans equiv`)

Two record streams are cut into the same shape of sequence: *runs* of consecutive motion of one
class (rapid or feed), separated by *gaps* holding what changed in between (tool changes, spindle
speed and direction, coolant, dwells, stops) and by feed-rate changes. Runs compare geometrically:
arcs are discretised into chords (sag well under the tolerance), and each run's points must lie
within `tol` mm of the other run's polyline, in order, both ways, with matching end points. So an
arc in one program equals the same arc written as short lines in the other. Gaps compare by order
and value of their events, after dropping events that change nothing (S1000 M3 on one line equals
S1000 then M3). Zero-length moves are ignored. The first difference is returned with both sides'
file:line.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterable, Iterator, Optional

from nctrans.toolpath import ToolpathRecord
from nctrans.toolpath_io import PLANE_AXES, arc_sweep

DEFAULT_TOL = 0.001
_ZERO = 1e-9
_MAX_CHORDS = 20000
_REL = 1e-6       # relative tolerance for event values (feed, speed, dwell)


@dataclass
class Difference:
    message: str
    a: Optional[ToolpathRecord]
    b: Optional[ToolpathRecord]

    def where(self, rec: Optional[ToolpathRecord], label: str) -> str:
        return f"{rec.file}:{rec.line}" if rec is not None else f"{label}: (end of toolpath)"

    def format(self) -> str:
        return f"{self.where(self.a, 'A')}: {self.where(self.b, 'B')}: {self.message}"


@dataclass
class _Run:
    cls: str                                  # "rapid" | "feed"
    axes: tuple[str, ...]
    points: list[tuple[float, ...]]
    recs: list[ToolpathRecord]                # the record each point came from
    feed: Optional[tuple] = None              # (feed, feed_mode) for feed runs


@dataclass
class _Gap:
    events: list[tuple[str, object, ToolpathRecord]] = field(default_factory=list)


# --------------------------------------------------------------------------- discretisation

def _point(d: Optional[dict], axes: tuple[str, ...]) -> tuple[float, ...]:
    d = d or {}
    return tuple(float(d.get(a, 0.0)) for a in axes)


def arc_points(r: ToolpathRecord, axes: tuple[str, ...], tol: float) -> list[tuple[float, ...]]:
    """Points along an arc (excluding its start, including its end) whose chords deviate from the
    arc by at most tol/4. Non-plane axes (helix, rotaries) move linearly with the angle; a radius
    that differs between start and end (rounding) is interpolated like a spiral."""
    t0, sweep, r0, (a1, a2) = arc_sweep(r)
    s, e, c = r.start or {}, r.end or {}, r.center or {}
    r1 = math.hypot(e.get(a1, 0.0) - c.get(a1, 0.0), e.get(a2, 0.0) - c.get(a2, 0.0))
    rmax = max(r0, r1)
    sag = tol / 4
    if rmax <= sag:
        n = 1
    else:
        step = 2 * math.acos(max(-1.0, 1 - sag / rmax))
        n = max(1, min(_MAX_CHORDS, math.ceil(abs(sweep) / step)))
    start = _point(s, axes)
    end = _point(e, axes)
    i1, i2 = axes.index(a1), axes.index(a2)
    c1, c2 = c.get(a1, 0.0), c.get(a2, 0.0)
    pts = []
    for k in range(1, n + 1):
        f = k / n
        if k == n:
            pts.append(end)
            break
        ang = t0 + sweep * f
        rad = r0 + (r1 - r0) * f
        p = [sv + (ev - sv) * f for sv, ev in zip(start, end)]
        p[i1] = c1 + rad * math.cos(ang)
        p[i2] = c2 + rad * math.sin(ang)
        pts.append(tuple(p))
    return pts


# --------------------------------------------------------------------------- sequence building

def _close(a, b) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        if a is None or b is None:
            return False
        return abs(a - b) <= max(1e-9, _REL * max(abs(a), abs(b)))
    return a == b


def _axes_of(records: list[ToolpathRecord]) -> tuple[str, ...]:
    seen: dict[str, None] = {}
    for r in records:
        for pt in (r.start, r.end):
            if pt:
                for a in pt:
                    seen.setdefault(a, None)
    order = "XYZABCUVW"
    return tuple(sorted(seen, key=lambda a: (order.find(a) if a in order else 99, a)))


def _is_zero_move(r: ToolpathRecord, axes: tuple[str, ...]) -> bool:
    s, e = _point(r.start, axes), _point(r.end, axes)
    if any(abs(x - y) > _ZERO for x, y in zip(s, e)):
        return False
    if r.kind == "arc":       # start == end: a full circle unless the radius is nil
        t0, sweep, radius, _ = arc_sweep(r)
        return radius <= _ZERO
    return True


def build_sequence(records: Iterable[ToolpathRecord], axes: tuple[str, ...], tol: float) -> list:
    """Records -> alternating list of _Gap and _Run (a gap before every run, one at the end)."""
    seq: list = []
    gap = _Gap()
    run: Optional[_Run] = None
    # state that events are compared against: only real changes become events
    state: dict[str, object] = {}

    def event(key: str, value, rec: ToolpathRecord) -> None:
        nonlocal gap, run
        if key in state and _close(state[key], value) and key not in ("dwell", "stop", "tool_change"):
            return
        state[key] = value
        if run is not None:
            seq.append(run)
            run = None
        gap.events.append((key, value, rec))

    for r in records:
        k = r.kind
        if k in ("rapid", "linear", "arc"):
            if _is_zero_move(r, axes):
                continue
            cls = "rapid" if k == "rapid" else "feed"
            if cls == "feed":
                feed = (r.feed, r.feed_mode or "per_min")
                if state.get("feed") is None or not (_close(state["feed"][0], feed[0])
                                                      and state["feed"][1] == feed[1]):
                    event("feed", feed, r)
            if run is None or run.cls != cls:
                if run is not None:
                    seq.append(run)
                seq.append(gap)
                gap = _Gap()
                run = _Run(cls, axes, [_point(r.start, axes)], [r])
            pts = arc_points(r, axes, tol) if k == "arc" else [_point(r.end, axes)]
            run.points.extend(pts)
            run.recs.extend([r] * len(pts))
        elif k == "tool_change":
            event("tool_change", r.tool, r)
        elif k == "spindle":
            if r.spindle is not None:
                event("spindle_speed", r.spindle, r)
            if r.spindle_dir is not None:
                event("spindle_dir", r.spindle_dir, r)
        elif k == "coolant":
            event("coolant", r.coolant, r)
        elif k == "dwell":
            event("dwell", r.dwell_s, r)
        elif k == "stop":
            event("stop", r.stop_kind, r)
    if run is not None:
        seq.append(run)
    seq.append(gap)
    return seq


# --------------------------------------------------------------------------- geometry

def _dist_point_segment(p, a, b) -> float:
    ab = [y - x for x, y in zip(a, b)]
    ap = [y - x for x, y in zip(a, p)]
    L2 = sum(v * v for v in ab)
    t = 0.0 if L2 == 0 else max(0.0, min(1.0, sum(u * v for u, v in zip(ab, ap)) / L2))
    return math.sqrt(sum((pv - (av + t * bv)) ** 2 for pv, av, bv in zip(p, a, ab)))


def _walk(P: list, Q: list, tol: float) -> tuple[Optional[int], int]:
    """Walk P's points along polyline Q, visiting Q's segments in order. Returns (index of the first
    point of P farther than tol from Q, or None; index of the segment of Q reached)."""
    if len(Q) == 1:
        for i, p in enumerate(P):
            if math.dist(p, Q[0]) > tol:
                return i, 0
        return None, 0
    j = 0
    last = len(Q) - 2
    for i, p in enumerate(P):
        while _dist_point_segment(p, Q[j], Q[j + 1]) > tol:
            if j == last:
                return i, j
            j += 1
    return None, j


def _beyond(Q: list, j: int, p, tol: float) -> int:
    """Index of the first point of Q after segment j that is farther than tol from p."""
    for k in range(j + 1, len(Q)):
        if math.dist(Q[k], p) > tol:
            return k
    return len(Q) - 1


def _compare_runs(ra: _Run, rb: _Run, tol: float, next_a: str = "", next_b: str = "") -> Optional[Difference]:
    """First difference between two runs; next_a/next_b say what follows each (for messages)."""
    cls = ra.cls
    if ra.cls != rb.cls:
        return Difference(f"{ra.cls} motion in A where B has {rb.cls} motion", ra.recs[0], rb.recs[0])
    A, B = ra.points, rb.points
    if math.dist(A[0], B[0]) > tol:
        return Difference(f"{cls} motion starts at {_fmt(A[0], ra.axes)} in A, "
                          f"{_fmt(B[0], rb.axes)} in B", ra.recs[0], rb.recs[0])
    fa, ja = _walk(A, B, tol)
    fb, jb = _walk(B, A, tol)
    ends_apart = math.dist(A[-1], B[-1]) > tol
    if fa is None and ends_apart:           # A stops where B goes on
        k = _beyond(B, ja, A[-1], tol)
        return Difference(f"A's {cls} motion ends at {_fmt(A[-1], ra.axes)}"
                          f"{' and ' + next_a + ' follows' if next_a else ''}; "
                          f"B's goes on to {_fmt(B[k], rb.axes)}", ra.recs[-1], rb.recs[k])
    if fb is None and ends_apart:           # B stops where A goes on
        k = _beyond(A, jb, B[-1], tol)
        return Difference(f"B's {cls} motion ends at {_fmt(B[-1], rb.axes)}"
                          f"{' and ' + next_b + ' follows' if next_b else ''}; "
                          f"A's goes on to {_fmt(A[k], ra.axes)}", ra.recs[k], rb.recs[-1])
    if fa is not None:
        k = min(ja + 1, len(B) - 1)
        return Difference(f"path leaves tolerance {tol:g} mm: A passes {_fmt(A[fa], ra.axes)}, "
                          f"B is near {_fmt(B[k], rb.axes)}", ra.recs[fa], rb.recs[k])
    if fb is not None:
        k = min(jb + 1, len(A) - 1)
        return Difference(f"path leaves tolerance {tol:g} mm: B passes {_fmt(B[fb], rb.axes)}, "
                          f"A is near {_fmt(A[k], ra.axes)}", ra.recs[k], rb.recs[fb])
    if ends_apart:
        return Difference(f"{cls} motion ends at {_fmt(A[-1], ra.axes)} in A, "
                          f"{_fmt(B[-1], rb.axes)} in B", ra.recs[-1], rb.recs[-1])
    return None


def _fmt(p, axes) -> str:
    return " ".join(f"{a}{v:.4f}" if len(a) == 1 else f"{a}={v:.4f}" for a, v in zip(axes, p))


def _fmt_event(key: str, value) -> str:
    if key == "feed":
        f, mode = value
        return f"feed {f:g} {mode}" if f is not None else f"feed unset {mode}"
    return f"{key.replace('_', ' ')} {value}"


def _compare_gaps(ga: _Gap, gb: _Gap, ra: Optional[ToolpathRecord], rb: Optional[ToolpathRecord]
                  ) -> Optional[Difference]:
    for (ka, va, reca), (kb, vb, recb) in zip(ga.events, gb.events):
        same = ka == kb and (_close(va[0], vb[0]) and va[1] == vb[1] if ka == "feed" else _close(va, vb))
        if not same:
            return Difference(f"{_fmt_event(ka, va)} in A, {_fmt_event(kb, vb)} in B", reca, recb)
    na, nb = len(ga.events), len(gb.events)
    if na > nb:
        k, v, rec = ga.events[nb]
        return Difference(f"{_fmt_event(k, v)} in A has no counterpart in B", rec, gb.events[-1][2] if nb else rb)
    if nb > na:
        k, v, rec = gb.events[na]
        return Difference(f"{_fmt_event(k, v)} in B has no counterpart in A", ga.events[-1][2] if na else ra, rec)
    return None


def _what_next(seq: list, n: int) -> str:
    """What follows item n of a sequence, in words (for messages)."""
    for item in seq[n + 1:]:
        if isinstance(item, _Run):
            return f"{item.cls} motion"
    for item in seq[n + 1:]:
        if item.events:
            return _fmt_event(*item.events[0][:2])
    return "the end of the toolpath"


def compare(a: Iterable[ToolpathRecord], b: Iterable[ToolpathRecord], tol: float = DEFAULT_TOL
            ) -> Optional[Difference]:
    """The first difference between toolpaths a and b, or None when they are equivalent."""
    for d in differences(a, b, tol):
        return d
    return None


def differences(a: Iterable[ToolpathRecord], b: Iterable[ToolpathRecord], tol: float = DEFAULT_TOL
                ) -> Iterator[Difference]:
    """Every difference between the pieces (runs of motion, gaps of events) of a and b paired in
    order; the first is compare's answer. Pairing is by position, so once the two have gone out of
    step (a missing run), later differences may follow from the first (backplot --compare marks
    them all)."""
    la, lb = list(a), list(b)
    axes = _axes_of(la + lb)
    sa, sb = build_sequence(la, axes, tol), build_sequence(lb, axes, tol)
    last_a = last_b = None
    for n, (ia, ib) in enumerate(zip(sa, sb)):
        if isinstance(ia, _Run) and isinstance(ib, _Run):
            d = _compare_runs(ia, ib, tol, _what_next(sa, n), _what_next(sb, n))
            last_a, last_b = ia.recs[-1], ib.recs[-1]
        elif isinstance(ia, _Gap) and isinstance(ib, _Gap):
            d = _compare_gaps(ia, ib, last_a, last_b)
            if ia.events:
                last_a = ia.events[-1][2]
            if ib.events:
                last_b = ib.events[-1][2]
        else:  # cannot happen: both sequences alternate gap/run from a gap
            d = Difference("toolpaths differ in structure", last_a, last_b)
        if d is not None:
            yield d
    if len(sa) != len(sb):
        longer, name = (sa, "A") if len(sa) > len(sb) else (sb, "B")
        extra = longer[min(len(sa), len(sb))]
        rec = extra.recs[0] if isinstance(extra, _Run) else (extra.events[0][2] if extra.events else None)
        what = f"{extra.cls} motion" if isinstance(extra, _Run) else "events"
        if name == "A":
            yield Difference(f"A continues with {what}; B has ended", rec, last_b)
        else:
            yield Difference(f"B continues with {what}; A has ended", last_a, rec)
