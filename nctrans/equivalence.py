"""Are two toolpaths the same machining? (`nctrans equiv`)

Two record streams are cut into the same shape of sequence: *runs* of consecutive motion of one
class (rapid or feed), separated by *gaps* holding what changed in between (tool changes, spindle
speed and direction, coolant, dwells, stops) and by feed-rate changes. Runs compare geometrically:
arcs are discretised into chords (sag well under the tolerance), and each run's points must lie
within `tol` mm of the other run's polyline, in order (each found no earlier along the other
polyline than the one before it: a move back along its own line is a difference), both ways,
with matching end points. Where a move stops along a straight line is not compared: two
collinear moves in one direction (Z110 -> Z105 -> Z54) are the path of one (Z110 -> Z55 -> Z54). So an
arc in one program equals the same arc written as short lines in the other. Gaps compare by order
and value of their events, after dropping events that change nothing (S1000 M3 on one line equals
S1000 then M3). Zero-length moves are ignored. The first difference is returned with both sides'
file:line.

Both toolpaths are consumed as streams, in lockstep: the two walks along a pair of runs (A's
points over B's polyline and B's over A's) advance one step each in turn, and only the window of
points between where each walk stands is held. Memory is flat in program length. Two runs that
fall more than LOOKAHEAD points out of step (one path wanders where the other does not follow) are
reported as a difference at the point where the walk got stuck.
"""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import Iterable, Iterator, Optional

from nctrans.toolpath import ToolpathRecord
from nctrans.toolpath_io import arc_sweep

DEFAULT_TOL = 0.001
_ZERO = 1e-9
_MAX_CHORDS = 20000
_REL = 1e-6       # relative tolerance for event values (feed, speed, dwell)
# Points of one run held beyond where the slower walk stands; past it the runs are out of step.
LOOKAHEAD = 50_000
# Tokens looked at past a run's end to say what follows it (messages only).
_PEEK = 1000
_AXIS_ORDER = "XYZABCUVW"


@dataclass
class Difference:
    message: str
    a: Optional[ToolpathRecord]
    b: Optional[ToolpathRecord]
    at_end: bool = False        # one toolpath ended where the other goes on (all before agreed)

    def where(self, rec: Optional[ToolpathRecord], label: str) -> str:
        return f"{rec.file}:{rec.line}" if rec is not None else f"{label}: (end of toolpath)"

    def format(self) -> str:
        return f"{self.where(self.a, 'A')}: {self.where(self.b, 'B')}: {self.message}"


# --------------------------------------------------------------------------- axes and points

class _Axes:
    """The axes seen so far in either toolpath, in order of first appearance. Points are tuples
    over these; a point made before an axis appeared is shorter and reads 0 there (as every
    record reads 0 on an axis it does not name)."""

    def __init__(self) -> None:
        self.names: list[str] = []
        self.index: dict[str, int] = {}

    def add(self, d: Optional[dict]) -> None:
        if d:
            for a in d:
                if a not in self.index:
                    self.index[a] = len(self.names)
                    self.names.append(a)

    def point(self, d: Optional[dict]) -> tuple[float, ...]:
        d = d or {}
        return tuple(float(d.get(a, 0.0)) for a in self.names)

    def pad(self, p: tuple[float, ...]) -> tuple[float, ...]:
        n = len(self.names)
        return p if len(p) == n else p + (0.0,) * (n - len(p))

    def fmt(self, p: tuple[float, ...]) -> str:
        pairs = sorted(zip(self.names, p), key=lambda av: (_AXIS_ORDER.find(av[0]) % 99, av[0]))
        return " ".join(f"{a}{v:.4f}" if len(a) == 1 else f"{a}={v:.4f}" for a, v in pairs)


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
    along = [(sv, ev - sv) for sv, ev in zip(start, end)]
    dr = r1 - r0
    cos, sin = math.cos, math.sin
    for k in range(1, n):
        f = k / n
        ang = t0 + sweep * f
        rad = r0 + dr * f
        p = [sv + dv * f for sv, dv in along]
        p[i1] = c1 + rad * cos(ang)
        p[i2] = c2 + rad * sin(ang)
        pts.append(tuple(p))
    pts.append(end)
    return pts


# --------------------------------------------------------------------------- token stream

def _close(a, b) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        if a is None or b is None:
            return False
        return abs(a - b) <= max(1e-9, _REL * max(abs(a), abs(b)))
    return a == b


def _is_zero_move(r: ToolpathRecord) -> bool:
    s, e = r.start or {}, r.end or {}
    if any(abs(e.get(a, 0.0) - s.get(a, 0.0)) > _ZERO for a in {*s, *e}):
        return False
    if r.kind == "arc":       # start == end: a full circle unless the radius is nil
        t0, sweep, radius, _ = arc_sweep(r)
        return radius <= _ZERO
    return True


# Tokens: ("E", key, value, record) an event of a gap; ("R", class, first point, record) a run
# starts; ("P", point, record) the run's next point. A toolpath is gap (run gap)*.

def _tokens(records: Iterable[ToolpathRecord], axes: _Axes, tol: float) -> Iterator[tuple]:
    """A toolpath's records as the tokens of its gaps and runs, one at a time."""
    # both runs start at power-on, spindle and coolant off (every dialect's defaults): an M5 or
    # M9 before anything started them changes nothing, and is no event (a flattened conversion
    # writes state changes only, so it has no such M5)
    state: dict[str, object] = {"spindle_dir": "off", "coolant": "off"}
    run: Optional[str] = None              # class of the run being produced

    def changed(key: str, value) -> bool:
        nonlocal run
        if key in state and _close(state[key], value) and key not in ("dwell", "stop", "tool_change", "call"):
            return False
        state[key] = value
        run = None
        return True

    for r in records:
        k = r.kind
        if k in ("rapid", "linear", "arc"):
            if _is_zero_move(r):
                continue
            axes.add(r.start)
            axes.add(r.end)
            cls = "rapid" if k == "rapid" else "feed"
            if cls == "feed":
                feed = (r.feed, r.feed_mode or "per_min")
                speed = r.spindle if r.spindle is not None else state.get("spindle_speed")
                if feed[1] == "per_rev" and r.feed is not None \
                        and isinstance(speed, (int, float)) and speed > 0:
                    # a feed per revolution is that feed x the move's spindle speed per minute:
                    # one motion, whichever way a dialect programs it (G95 vs CYCLE84; a constant
                    # surface speed marked on one side, written out as S words on the other)
                    feed = (r.feed * speed, "per_min")
                last = state.get("feed")
                if last is None or not (_close(last[0], feed[0]) and last[1] == feed[1]):
                    state["feed"] = feed
                    run = None
                    yield ("E", "feed", feed, r)
                # a thread (a feed synchronised with the spindle, its lead as pitch) is another
                # motion than a feed at the same speed: the pitch compares as an event
                pitch = r.pitch or 0.0
                if not _close(state.get("pitch", 0.0), pitch):
                    state["pitch"] = pitch
                    run = None
                    yield ("E", "pitch", pitch, r)
                if r.pitch:
                    # a thread's start angle (its start of several): the same path cut at another
                    # spindle phase is another thread; no key reads 0, as a single start has
                    start = (r.thread_start or 0.0) % 360.0
                    if not _close(state.get("thread_start", 0.0), start):
                        state["thread_start"] = start
                        run = None
                        yield ("E", "thread_start", start, r)
            if run != cls:
                run = cls
                yield ("R", cls, axes.point(r.start), r)
            if k == "arc":
                a1, a2 = arc_sweep(r)[3]
                axes.add({a1: 0.0, a2: 0.0})
                for p in arc_points(r, tuple(axes.names), tol):
                    yield ("P", p, r)
            else:
                yield ("P", axes.point(r.end), r)
        elif k == "tool_change":
            if changed("tool_change", r.tool):
                yield ("E", "tool_change", r.tool, r)
        elif k == "spindle":
            # a positioned spindle compares with its angle: M19 (no angle) positions at the
            # control's setting, 0 degrees by default (SD 43240 M19_SPOS), as SPOS=0 does
            where = r.spindle_dir
            if where == "orient" and r.spindle_angle:          # (NaN: unknown, equal to nothing known)
                where = f"orient {r.spindle_angle:.3f}"
            # the speed of a spindle that does not turn is no event: it compares when it turns
            # (an M5 record carries the S in force, which one side may never have started); an S
            # set while stopped is the speed the next start compares (S1000, then M3 = S1000 M3)
            if r.spindle is not None:
                state["spindle_speed_set"] = r.spindle
            turns = (where if r.spindle_dir is not None else state["spindle_dir"]) in ("cw", "ccw")
            speed = state.get("spindle_speed_set")
            if turns and speed is not None and changed("spindle_speed", speed):
                yield ("E", "spindle_speed", speed, r)
            if r.spindle_dir is not None and changed("spindle_dir", where):
                yield ("E", "spindle_dir", where, r)
        elif k == "coolant":
            if changed("coolant", r.coolant):
                yield ("E", "coolant", r.coolant, r)
        elif k == "dwell":
            if changed("dwell", r.dwell_s):
                yield ("E", "dwell", r.dwell_s, r)
        elif k == "stop":
            if changed("stop", r.stop_kind):
                yield ("E", "stop", r.stop_kind, r)
        elif k == "call":
            call = KeptCall(r.call or "", tuple(r.args or ()))
            if changed("call", call):
                yield ("E", "call", call, r)


class _Stream:
    """A token stream with a look-ahead queue."""

    def __init__(self, tokens: Iterator[tuple]):
        self.tokens = tokens
        self.ahead: deque = deque()

    def peek(self, k: int = 0) -> Optional[tuple]:
        while len(self.ahead) <= k:
            t = next(self.tokens, None)
            if t is None:
                return None
            self.ahead.append(t)
        return self.ahead[k]

    def take(self) -> Optional[tuple]:
        if self.ahead:
            return self.ahead.popleft()
        return next(self.tokens, None)

    def take_point(self) -> Optional[tuple]:
        """The next token when it is a run's point ("P"), taken; else None, nothing taken
        (peek + take in one: equiv pulls every point of every run through here)."""
        ahead = self.ahead
        if ahead:
            if ahead[0][0] != "P":
                return None
            return ahead.popleft()
        t = next(self.tokens, None)
        if t is not None and t[0] != "P":
            ahead.append(t)
            return None
        return t

    def what_next(self) -> str:
        """What follows the current position, in words (for messages): the class of the next
        run, else the first event, else the end."""
        first_event = None
        for k in range(_PEEK):
            t = self.peek(k)
            if t is None:
                break
            if t[0] == "R":
                return f"{t[1]} motion"
            if t[0] == "E" and first_event is None:
                first_event = t
        if first_event is not None:
            return _fmt_event(first_event[1], first_event[2])
        return "the end of the toolpath"


class _Run:
    """The points of one run of one toolpath, pulled from its stream as the walks need them; only
    the window from `base` on is held."""

    def __init__(self, stream: _Stream, axes: _Axes, head: tuple):
        _, self.cls, p0, r0 = head
        self.stream = stream
        self.axes = axes
        self.buf: list = [(p0, r0)]
        self.base = 0
        self.low = 0
        self.count = 1
        self.ended = False
        self.first = (p0, r0)
        self.last = (p0, r0)

    def _pull(self, keep: bool = True) -> bool:
        if self.ended:
            return False
        t = self.stream.take_point()
        if t is None:
            self.ended = True
            return False
        item = (t[1], t[2])
        if keep:
            self.buf.append(item)
        self.count += 1
        self.last = item
        return True

    def has(self, k: int) -> bool:
        """Whether point k is held (pulling up to it); False past the run's end."""
        while k >= self.count:                 # count == base + len(buf) while the walks read
            if not self._pull():
                return False
        return True

    def point(self, k: int) -> tuple[float, ...]:
        i = k - self.base
        p, r = self.buf[i]
        if len(p) != len(self.axes.names):
            p = self.axes.pad(p)
            self.buf[i] = (p, r)
        return p

    def rec(self, k: int) -> ToolpathRecord:
        return self.buf[k - self.base][1]

    def trim(self, k: int) -> None:
        """Points before k are no longer needed (they are dropped in batches)."""
        self.low = k
        drop = k - self.base
        if drop > 1024 and drop * 2 > len(self.buf):
            del self.buf[:drop]
            self.base = k

    @property
    def window(self) -> int:
        """Points held that are still needed."""
        return self.count - self.low

    def drain(self) -> None:
        """Read to the run's end, keeping only its last point."""
        while self._pull(keep=False):
            pass

    def last_point(self) -> tuple[float, ...]:
        return self.axes.pad(self.last[0])


# --------------------------------------------------------------------------- geometry

def _dist_point_segment(p, a, b) -> float:
    ab = [y - x for x, y in zip(a, b)]
    L2 = math.fsum(v * v for v in ab)
    if L2 == 0:
        return math.dist(p, a)
    t = max(0.0, min(1.0, math.fsum(u * (y - x) for u, x, y in zip(ab, a, p)) / L2))
    return math.dist(p, [x + t * u for x, u in zip(a, ab)])


# Rounding allowance of the triangle-inequality bound in _Walk.step (relative to the lengths): any
# point x of a segment q0-q1 has |p-x| >= (|p-q0| + |p-q1| - |q0-q1|) / 2, so where that bound clears
# tol the segment is farther than tol from p without the projection.
_BOUND_SLACK = 1e-9


def _earliest_along(p, a, b, t: float, tol: float) -> Optional[float]:
    """The first position s >= t along segment a->b (0 at a, 1 at b) within tol of p, or None.
    Matching each point at the first place it fits, never behind the last one matched, makes the
    walk follow the path in order: a move back along its own line (Z110 -> Z40 -> Z54) is not the
    straight Z110 -> Z54, while two collinear moves one way are the one path they cover."""
    d = [y - x for x, y in zip(a, b)]
    L2 = sum(v * v for v in d)
    ap = [y - x for x, y in zip(a, p)]
    tol2 = tol * tol
    if L2 <= _ZERO * _ZERO:
        return t if sum(v * v for v in ap) <= tol2 else None
    u = sum(v * w for v, w in zip(d, ap)) / L2          # p projected on the line (unclamped)
    h2 = max(0.0, sum(v * v for v in ap) - u * u * L2)  # squared distance from the line
    if h2 > tol2:
        return None
    w = math.sqrt((tol2 - h2) / L2)                     # half the stretch of the line within tol
    if u + w < t or u - w > 1.0:
        return None
    return max(t, u - w)


class _Walk:
    """P's points walked along Q's polyline in order: `failed` is the index of the first point of
    P farther than tol from Q past where the previous point was found (None while none is), `j`
    the segment of Q reached and `t` the position on it (0..1). One step is one distance test."""

    def __init__(self, P: _Run, Q: _Run):
        self.P, self.Q = P, Q
        self.i = 0
        self.j = 0
        self.t = 0.0                # position on segment j (0..1) where P's last point was found
        self.failed: Optional[int] = None
        self.finished = False
        self.stuck = 0              # steps since P's point last advanced

    def step(self, tol: float) -> None:
        P, Q = self.P, self.Q
        i = self.i
        if i >= P.count and not P.has(i):
            self.finished = True
            return
        n = len(P.axes.names)
        p = P.buf[i - P.base][0]                # P.point(i), Q.point(j), read inline: once per step
        if len(p) != n:
            p = P.point(i)
        if Q.count < 2 and not Q.has(1):        # Q is one point
            if math.dist(p, Q.point(0)) > tol:
                self.failed, self.finished = i, True
            else:
                self.i = i + 1
            return
        j = self.j
        k = j - Q.base
        q0, q1 = Q.buf[k][0], Q.buf[k + 1][0]
        if len(q0) != n or len(q1) != n:
            q0, q1 = Q.point(j), Q.point(j + 1)
        # the triangle-inequality bound rejects a segment far from p without the projection
        d0, d1 = math.dist(p, q0), math.dist(p, q1)
        length = math.dist(q0, q1)
        far = d0 + d1 - length > 2 * tol + _BOUND_SLACK * (d0 + d1 + length)
        at = None if far else _earliest_along(p, q0, q1, self.t, tol)
        if at is not None:
            self.i = i + 1
            self.t = at
            self.stuck = 0
        elif j + 2 >= Q.count and not Q.has(j + 2):     # j is Q's last segment
            self.failed, self.finished = self.i, True
        else:
            self.j = j + 1
            self.t = 0.0
            self.stuck += 1


def _beyond(Q: _Run, j: int, p, tol: float) -> tuple:
    """(point, record) of the first point of Q after segment j that is farther than tol from p
    (Q's last point when none is, or when the window runs out)."""
    k = j + 1
    while Q.has(k) and k - j < LOOKAHEAD:
        q = Q.point(k)
        if math.dist(q, p) > tol:
            return q, Q.rec(k)
        k += 1
    return Q.last_point(), Q.last[1]


def _near(Q: _Run, j: int) -> tuple:
    """(point, record) of the end of Q's segment j (of the first segment still held)."""
    k = max(j + 1, Q.base)
    return (Q.point(k), Q.rec(k)) if Q.has(k) else (Q.last_point(), Q.last[1])


def _compare_runs(A: _Run, B: _Run, sa: _Stream, sb: _Stream, tol: float) -> Optional[Difference]:
    """First difference between two runs, read in lockstep; both are left where the comparison
    stopped (the caller drains them)."""
    cls, fmt = A.cls, A.axes.fmt
    if A.cls != B.cls:
        return Difference(f"{A.cls} motion in A where B has {B.cls} motion", A.first[1], B.first[1])
    a0, b0 = A.axes.pad(A.first[0]), B.axes.pad(B.first[0])
    if math.dist(a0, b0) > tol:
        return Difference(f"{cls} motion starts at {fmt(a0)} in A, {fmt(b0)} in B", A.first[1], B.first[1])
    ab, ba = _Walk(A, B), _Walk(B, A)
    while not (ab.finished and ba.finished):
        if not ab.finished:
            ab.step(tol)
        if not ba.finished:
            ba.step(tol)
        A.trim(ab.i if ab.i < ba.j else ba.j)
        B.trim(ba.i if ba.i < ab.j else ab.j)
        if A.count - A.low > LOOKAHEAD or B.count - B.low > LOOKAHEAD:     # the windows
            return _out_of_step(A, B, ab, ba, tol)
    fa, fb = ab.failed, ba.failed
    # each lies along the other and B's toolpath ends with this motion while A's goes on: B
    # stopped on A's path (a prefix of it, even where A then turns back a little), said as B's end
    b_stops_on_a = fb is None and sb.peek() is None and sa.peek() is not None
    if fa is None and not b_stops_on_a:     # all of A lies along B: does B stop where A does?
        q, beyond = _beyond(B, ab.j, A.last_point(), tol)
        B.drain()
        if math.dist(A.last_point(), B.last_point()) > tol:
            follows = sa.what_next()
            return Difference(f"A's {cls} motion ends at {fmt(A.last_point())}"
                              f"{' and ' + follows + ' follows' if follows else ''}; "
                              f"B's goes on to {fmt(q)}", A.last[1], beyond, at_end=sa.peek() is None)
    if fb is None:
        q, beyond = _beyond(A, ba.j, B.last_point(), tol)
        A.drain()
        # B stopped on A's path and A goes on, though it comes back to where B stopped (a full
        # circle from there): still B's end, not a path that leaves A's
        if math.dist(A.last_point(), B.last_point()) > tol or (b_stops_on_a and fa is not None):
            follows = sb.what_next()
            return Difference(f"B's {cls} motion ends at {fmt(B.last_point())}"
                              f"{' and ' + follows + ' follows' if follows else ''}; "
                              f"A's goes on to {fmt(q)}", beyond, B.last[1], at_end=sb.peek() is None)
    if fa is not None:
        q, near = _near(B, ab.j)
        return Difference(f"path leaves tolerance {tol:g} mm: A passes {fmt(A.point(fa))}, "
                          f"B is near {fmt(q)}", A.rec(fa), near)
    if fb is not None:
        q, near = _near(A, ba.j)
        return Difference(f"path leaves tolerance {tol:g} mm: B passes {fmt(B.point(fb))}, "
                          f"A is near {fmt(q)}", near, B.rec(fb))
    return None


def _out_of_step(A: _Run, B: _Run, ab: _Walk, ba: _Walk, tol: float) -> Difference:
    """The walks fell LOOKAHEAD points apart: the one stuck longest has a point the other path
    does not come back to within that window."""
    fmt = A.axes.fmt
    why = f"(not found within {LOOKAHEAD} points of the other path)"
    if ba.finished or (not ab.finished and ab.stuck >= ba.stuck):
        q, near = _near(B, ab.j - ab.stuck)
        return Difference(f"path leaves tolerance {tol:g} mm: A passes {fmt(A.point(ab.i))}, "
                          f"B is near {fmt(q)} {why}", A.rec(ab.i), near)
    q, near = _near(A, ba.j - ba.stuck)
    return Difference(f"path leaves tolerance {tol:g} mm: B passes {fmt(B.point(ba.i))}, "
                      f"A is near {fmt(q)} {why}", near, B.rec(ba.i))


# --------------------------------------------------------------------------- gaps

class KeptCall:
    """A call event: the same call (nctrans.calls: WARMUP_CYCLE and its O number are one) with the
    same evaluated arguments."""
    __slots__ = ("name", "args")

    def __init__(self, name: str, args: tuple):
        # omitted trailing arguments are not passed at all (an ISO G65 has no letter for them)
        while args and args[-1] is None:
            args = args[:-1]
        self.name, self.args = name, args

    def __eq__(self, other) -> bool:
        from nctrans.calls import same_call
        return (isinstance(other, KeptCall) and same_call(self.name, other.name)
                and len(self.args) == len(other.args)
                and all((a is None) == (b is None) and (a is None or _close(float(a), float(b)))
                        for a, b in zip(self.args, other.args)))

    def __repr__(self) -> str:
        return f"{self.name}({', '.join('' if a is None else f'{a:g}' for a in self.args)})"


def _fmt_event(key: str, value) -> str:
    if key == "feed":
        f, mode = value
        return f"feed {f:g} {mode}" if f is not None else f"feed unset {mode}"
    return f"{key.replace('_', ' ')} {value}"


def _same_event(ea: tuple, eb: tuple) -> bool:
    _, ka, va, _ = ea
    _, kb, vb, _ = eb
    if ka != kb:
        return False
    return _close(va[0], vb[0]) and va[1] == vb[1] if ka == "feed" else _close(va, vb)


# --------------------------------------------------------------------------- comparison

def compare(a: Iterable[ToolpathRecord], b: Iterable[ToolpathRecord], tol: float = DEFAULT_TOL
            ) -> Optional[Difference]:
    """The first difference between toolpaths a and b, or None when they are equivalent. Both are
    read as streams and only as far as the first difference."""
    for d in differences(a, b, tol):
        return d
    return None


def differences(a: Iterable[ToolpathRecord], b: Iterable[ToolpathRecord], tol: float = DEFAULT_TOL
                ) -> Iterator[Difference]:
    """Every difference between the pieces (runs of motion, gaps of events) of a and b paired in
    order; the first is compare's answer. Pairing is by position, so once the two have gone out of
    step (a missing run), later differences may follow from the first (backplot --compare marks
    them all). Memory stays flat: each toolpath is read once, in step with the other."""
    axes = _Axes()
    sa, sb = _Stream(_tokens(a, axes, tol)), _Stream(_tokens(b, axes, tol))
    last_a: Optional[ToolpathRecord] = None
    last_b: Optional[ToolpathRecord] = None
    while True:
        # a gap: events paired in order; one difference per gap
        found: Optional[Difference] = None
        while True:
            ta, tb = sa.peek(), sb.peek()
            a_event = ta is not None and ta[0] == "E"
            b_event = tb is not None and tb[0] == "E"
            if a_event and b_event:
                sa.take(), sb.take()
                if found is None and not _same_event(ta, tb):
                    found = Difference(f"{_fmt_event(ta[1], ta[2])} in A, {_fmt_event(tb[1], tb[2])} in B",
                                       ta[3], tb[3])
                last_a, last_b = ta[3], tb[3]
            elif a_event or b_event:
                if found is None:
                    side, t = ("A", ta) if a_event else ("B", tb)
                    other = "B" if side == "A" else "A"
                    msg = f"{_fmt_event(t[1], t[2])} in {side} has no counterpart in {other}"
                    ended = (tb if side == "A" else ta) is None       # the other toolpath is over
                    found = (Difference(msg, t[3], last_b, at_end=ended) if side == "A"
                             else Difference(msg, last_a, t[3], at_end=ended))
                s = sa if a_event else sb
                t = s.take()
                if a_event:
                    last_a = t[3]
                else:
                    last_b = t[3]
            else:
                break
        if found is not None:
            yield found
        ta, tb = sa.peek(), sb.peek()
        if ta is None and tb is None:
            return
        if ta is None or tb is None:
            name, t, other = ("A", ta, last_b) if tb is None else ("B", tb, last_a)
            what = f"{t[1]} motion"
            if name == "A":
                yield Difference(f"A continues with {what}; B has ended", t[3], other, at_end=True)
            else:
                yield Difference(f"B continues with {what}; A has ended", other, t[3], at_end=True)
            return
        A, B = _Run(sa, axes, sa.take()), _Run(sb, axes, sb.take())
        d = _compare_runs(A, B, sa, sb, tol)
        if d is not None:
            yield d                     # before reading the rest: compare() stops here
        A.drain()
        B.drain()
        last_a, last_b = A.last[1], B.last[1]
