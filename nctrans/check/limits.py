"""Limits a move can break without touching anything: axis travel (end points and the extreme
points of an arc's sweep, so an arc that bulges past a limit between two legal end points is
caught), programmable limits carried by the toolpath (`limits` records, e.g. Fagor G198/G199),
feed against each axis's maximum, and spindle speed against the spindle's maximum (also the speed
constant surface speed reaches at the smallest radius of a move).

Everything is in machine coordinates, as the toolpath gives it. One finding per block, axis and
side, with the largest excess the block reaches.
"""
from __future__ import annotations

import math
from typing import Optional

from nctrans.check.findings import Finding
from nctrans.check.geometry import arc_extremes
from nctrans.machine import Machine
from nctrans.toolpath import ToolpathRecord
from nctrans.toolpath_io import arc_sweep, motion_length

EPS = 1e-6      # mm: a point on a limit is inside it


class LimitCheck:
    """Feed records in order (`add`); `findings()` afterwards."""

    def __init__(self, machine: Machine):
        self.machine = machine
        self.travel = {a: (ax.min, ax.max) for a, ax in machine.axes.items()
                       if ax.min is not None or ax.max is not None}
        self.max_feed = {a: ax.max_feed for a, ax in machine.axes.items() if ax.max_feed}
        self.max_rpm = machine.spindle.max_rpm
        self.known_axes = set(machine.axes)
        self.programmed: tuple[dict, dict] = ({}, {})     # programmable (lower, upper) limits
        self.zone: Optional[tuple[dict, dict]] = None       # programmed forbidden box (min, max)
        self._found: dict[tuple, Finding] = {}
        self._unknown_axes: set[str] = set()
        self._speed: Optional[float] = None     # last spindle speed seen (reported where it changes)
        self._css_over = False                  # inside a run of moves whose CSS is over the limit
        self._placed = False                    # has a move put the machine somewhere known?

    def findings(self) -> list[Finding]:
        return list(self._found.values())

    # ------------------------------------------------------------------ per record
    def add(self, r: ToolpathRecord) -> None:
        kind = r.kind
        if kind == "limits":
            if r.zone == "unmodelled":
                self._found[(r.file, r.line, "unmodelled")] = Finding(
                    "NC307", r.file, r.line, "limits",
                    "travel limits or protection zones switched here are not modelled (NC220 names "
                    "the construct): the check cannot tell whether the program respects them")
            elif r.zone is not None:
                self.zone = (dict(r.start), dict(r.end)) if r.start and r.end else None
            else:
                self.programmed = (dict(r.start or {}), dict(r.end or {}))
            return
        if r.spindle is not None and r.spindle != self._speed:
            self._speed = r.spindle
            self._spindle(r, r.spindle, None)
        if kind not in ("rapid", "linear", "arc") or r.end is None:
            return
        self._axes_known(r)
        self._point(r, r.end, None)
        if kind == "arc" and r.center is not None:
            for p, _frac in arc_extremes(r):
                self._point(r, p, "in the arc's sweep")
        if self.zone is not None:
            self._zone(r)
        self._placed = True
        if kind != "rapid":
            self._feed(r)
        css = getattr(r, "css", None)
        if css:
            self._css_over = self._css(r, css)
        else:
            self._css_over = False

    def _keep(self, key: tuple, f: Finding) -> None:
        old = self._found.get(key)
        if old is None or (f.amount or 0.0) > (old.amount or 0.0):
            self._found[key] = f

    def _axes_known(self, r: ToolpathRecord) -> None:
        for a, v in r.end.items():
            if a in self.known_axes or a in self._unknown_axes:
                continue
            if v != 0.0 or (r.start or {}).get(a, 0.0) != 0.0:
                self._unknown_axes.add(a)
                self._found[("axis", a)] = Finding(
                    "NC305", r.file, r.line, a,
                    f"axis {a} moves (to {a}{v:.3f}) but the machine {self.machine.name!r} has no axis {a}: "
                    "its travel and collisions along it are not checked", dict(r.end))

    def _point(self, r: ToolpathRecord, p: dict[str, float], where: Optional[str]) -> None:
        suffix = f" {where}" if where else ""
        for a, (lo, hi) in self.travel.items():
            v = p.get(a)
            if v is None:
                continue
            if hi is not None and v > hi + EPS:
                self._keep((r.file, r.line, "travel", a, "max"), Finding(
                    "NC301", r.file, r.line, a,
                    f"{a} overtravel{suffix}: {a}{v:.3f} is {v - hi:.3f} mm beyond the maximum {hi:g} "
                    f"(machine coordinates)", dict(p), v - hi))
            if lo is not None and v < lo - EPS:
                self._keep((r.file, r.line, "travel", a, "min"), Finding(
                    "NC301", r.file, r.line, a,
                    f"{a} overtravel{suffix}: {a}{v:.3f} is {lo - v:.3f} mm beyond the minimum {lo:g} "
                    f"(machine coordinates)", dict(p), lo - v))
        lower, upper = self.programmed
        for a, hi in upper.items():
            v = p.get(a)
            if v is not None and v > hi + EPS:
                self._keep((r.file, r.line, "prog", a, "max"), Finding(
                    "NC302", r.file, r.line, a,
                    f"{a} beyond the programmed upper limit{suffix}: {a}{v:.3f} is {v - hi:.3f} mm above {hi:g}",
                    dict(p), v - hi))
        for a, lo in lower.items():
            v = p.get(a)
            if v is not None and v < lo - EPS:
                self._keep((r.file, r.line, "prog", a, "min"), Finding(
                    "NC302", r.file, r.line, a,
                    f"{a} beyond the programmed lower limit{suffix}: {a}{v:.3f} is {lo - v:.3f} mm below {lo:g}",
                    dict(p), lo - v))

    # ------------------------------------------------------------------ forbidden zone
    def _zone(self, r: ToolpathRecord) -> None:
        """A move whose path enters the programmed forbidden box (not only its end: a straight
        move is clipped against the box, an arc as chords of at most 1 degree)."""
        lo, hi = self.zone
        axes = [a for a in lo if a in hi]
        if not axes:
            return
        if not self._placed:        # the first move starts where the machine is assumed to be
            pts = [r.end, r.end]
        else:
            pts = [r.start or r.end] + [p for p, _ in arc_points(r)] if r.kind == "arc" and r.center \
                else [r.start or r.end, r.end]
        deepest, depth = None, 0.0
        for p, q in zip(pts, pts[1:]):
            hit = segment_in_box(p, q, lo, hi, axes)
            if hit is not None:
                d = min(min(hit[a] - lo[a], hi[a] - hit[a]) for a in axes)
                if deepest is None or d > depth:
                    deepest, depth = hit, d
        if deepest is not None:
            box = " ".join(f"{a}{lo[a]:g}..{hi[a]:g}" for a in axes)
            self._keep((r.file, r.line, "zone"), Finding(
                "NC302", r.file, r.line, "zone",
                f"the move enters the programmed protection zone {box} (machine coordinates), "
                f"{depth:.3f} mm deep at " + " ".join(f"{a}{deepest[a]:.3f}" for a in axes),
                dict(deepest), depth))

    # ------------------------------------------------------------------ feed
    def _feed(self, r: ToolpathRecord) -> None:
        if not self.max_feed or not r.feed or r.feed <= 0:
            return
        length = motion_length(r)
        s, e = r.start, r.end
        rate = path_rate(r, length)        # mm/min along the path (None: unknown)
        if rate is None:
            return
        if length <= 1e-9:                 # a rotary-only move: the feed is in deg/min
            length = max((abs(e.get(a, 0.0) - s.get(a, 0.0)) for a in e), default=0.0)
            if length <= 1e-9:
                return
        minutes = length / rate
        per_axis = axis_travel(r)
        for a, limit in self.max_feed.items():
            d = per_axis.get(a, 0.0)
            if d <= 1e-9:
                continue
            v = d / minutes
            if v > limit * (1 + 1e-9):
                self._keep((r.file, r.line, "feed", a), Finding(
                    "NC303", r.file, r.line, a,
                    f"feed on {a} reaches {v:.0f} mm/min, {v - limit:.0f} over its maximum {limit:g} "
                    f"(the control will slow the move down)", dict(e), v - limit))

    # ------------------------------------------------------------------ spindle
    def _spindle(self, r: ToolpathRecord, rpm: float, how: Optional[str]) -> bool:
        top = self.max_rpm
        if top is None or rpm <= top * (1 + 1e-9):
            return False
        how = f" {how}" if how else ""
        self._keep((r.file, r.line, "spindle"), Finding(
            "NC304", r.file, r.line, "spindle",
            f"spindle speed{how} {rpm:.0f} rpm is {rpm - top:.0f} over the maximum {top:g} rpm",
            dict(r.end) if r.end else None, rpm - top))
        return True

    def _css(self, r: ToolpathRecord, css: float) -> bool:
        """Constant surface speed css (m/min) at the smallest radius (|X|) the move passes; True
        while over the limit (a run of such moves is reported at its first block)."""
        rmin = smallest_radius(r)
        rpm = math.inf if rmin <= 1e-9 else css * 1000.0 / (2 * math.pi * rmin)
        clamp = getattr(r, "spindle_limit", None)
        if clamp:
            rpm = min(rpm, clamp)
        if self._css_over:
            return math.isinf(rpm) or (self.max_rpm is not None and rpm > self.max_rpm)
        if math.isinf(rpm):
            self._keep((r.file, r.line, "spindle"), Finding(
                "NC304", r.file, r.line, "spindle",
                f"constant surface speed {css:g} m/min at X0 with no spindle speed limit: "
                f"the spindle would run away (limit it, e.g. G50 S / LIMS)", dict(r.end), math.inf))
            return True
        return self._spindle(r, rpm, f"reached by constant surface speed {css:g} m/min at radius {rmin:.3f}")


def path_rate(r: ToolpathRecord, length: float) -> Optional[float]:
    """Programmed speed along the path in mm/min (per-minute, per-revolution or inverse-time)."""
    f = r.feed
    if not f or f <= 0:
        return None
    if r.feed_mode == "per_rev":
        return f * r.spindle if r.spindle else None
    if r.feed_mode == "inverse_time":
        return f * length if length > 0 else None
    return f


def axis_travel(r: ToolpathRecord) -> dict[str, float]:
    """Distance each axis covers in the move (an arc's plane axes: the radius times the swept
    angle, an upper bound of their speed share)."""
    s, e = r.start, r.end
    out = {a: abs(e.get(a, s.get(a, 0.0)) - s.get(a, 0.0)) for a in set(s) | set(e)}
    if r.kind == "arc" and r.center is not None:
        _t0, sweep, radius, (a1, a2) = arc_sweep(r)
        out[a1] = out[a2] = abs(sweep) * radius
    return out


def smallest_radius(r: ToolpathRecord) -> float:
    """Smallest distance |X - css_axis| along a move: the turning radius where constant surface
    speed peaks."""
    axis = getattr(r, "css_axis", None) or 0.0
    s, e = r.start or {}, r.end or {}
    x0, x1 = s.get("X", 0.0) - axis, e.get("X", 0.0) - axis
    xs = [abs(x0), abs(x1)]
    if r.kind == "arc" and r.center is not None:
        xs += [abs(p.get("X", 0.0) - axis) for p, _ in arc_extremes(r)]
    elif (x0 > 0) != (x1 > 0):
        xs.append(0.0)                     # the move crosses the spindle axis
    return min(xs)


def arc_points(r: ToolpathRecord, step_deg: float = 1.0):
    """Points along an arc (machine coordinates) no more than `step_deg` apart, its end last, each
    with its fraction of the sweep."""
    t0, sweep, radius, (a1, a2) = arc_sweep(r)
    n = max(1, int(math.ceil(abs(math.degrees(sweep)) / step_deg)))
    s, e, c = r.start, r.end, r.center
    out = []
    for i in range(1, n + 1):
        f = i / n
        t = t0 + sweep * f
        p = {a: s.get(a, 0.0) + (e.get(a, 0.0) - s.get(a, 0.0)) * f for a in set(s) | set(e)}
        p[a1] = c[a1] + radius * math.cos(t)
        p[a2] = c[a2] + radius * math.sin(t)
        out.append((p, f))
    out[-1] = (dict(e), 1.0)
    return out


def segment_in_box(p: dict, q: dict, lo: dict, hi: dict, axes) -> Optional[dict]:
    """The deepest point of the straight move p -> q strictly inside the box (slab clipping), or
    None when it stays outside or only touches the faces."""
    t0, t1 = 0.0, 1.0
    for a in axes:
        a0, a1 = p.get(a, 0.0), q.get(a, 0.0)
        d = a1 - a0
        if abs(d) < 1e-12:
            if a0 <= lo[a] + EPS or a0 >= hi[a] - EPS:
                return None
            continue
        u, v = (lo[a] + EPS - a0) / d, (hi[a] - EPS - a0) / d
        if u > v:
            u, v = v, u
        t0, t1 = max(t0, u), min(t1, v)
        if t0 > t1:
            return None
    # the depth (distance to the nearest face) is the least of linear functions of t: its
    # maximum is at an end of the clipped span or where two of them cross
    lines = []
    for a in axes:
        a0, d = p.get(a, 0.0), q.get(a, 0.0) - p.get(a, 0.0)
        lines += [(a0 - lo[a], d), (hi[a] - a0, -d)]
    ts = {t0, t1}
    for i, (c1, s1) in enumerate(lines):
        for c2, s2 in lines[i + 1:]:
            if abs(s1 - s2) > 1e-12:
                t = (c2 - c1) / (s1 - s2)
                if t0 < t < t1:
                    ts.add(t)
    t = max(ts, key=lambda t: min(c + s * t for c, s in lines))
    return {a: p.get(a, 0.0) + (q.get(a, 0.0) - p.get(a, 0.0)) * t for a in set(p) | set(q)}
