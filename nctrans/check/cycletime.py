"""Cycle time from the toolpath and the machine: per tool and in total.

Rapids run at each axis's rapid rate (the slowest axis sets the time), feed moves at the programmed
feed, slowed to each axis's maximum feed. With `accel` on the axes, every move gets a trapezoidal
speed profile whose entry and exit speeds are set by the corner to its neighbours (full speed
through a tangent junction, a stop at a right angle or sharper), so a CAM program of many short
segments is not timed as if each ran at full feed. Dwells count; tool changes count
`tool_change_s` each when the machine gives it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional

from nctrans.check.limits import axis_travel, path_rate
from nctrans.machine import Machine
from nctrans.toolpath import ToolpathRecord
from nctrans.toolpath_io import motion_length

DEFAULT_RAPID = 10000.0     # mm/min when the machine gives no rapid rate


def _direction(r: ToolpathRecord, at_end: bool) -> Optional[tuple[float, float, float]]:
    """Unit tangent (XYZ) of a move at its start or end."""
    s, e = r.start, r.end
    if r.kind == "arc" and r.center is not None:
        from nctrans.toolpath_io import PLANE_AXES
        a1, a2 = PLANE_AXES.get(r.plane or "XY", ("X", "Y"))
        p = e if at_end else s
        c = r.center
        rx, ry = p.get(a1, 0.0) - c.get(a1, 0.0), p.get(a2, 0.0) - c.get(a2, 0.0)
        t = (-ry, rx) if r.direction == "ccw" else (ry, -rx)
        v = {a1: t[0], a2: t[1]}
    else:
        v = {a: e.get(a, 0.0) - s.get(a, 0.0) for a in "XYZ"}
    vec = (v.get("X", 0.0), v.get("Y", 0.0), v.get("Z", 0.0))
    n = math.sqrt(sum(c * c for c in vec))
    return None if n <= 1e-12 else tuple(c / n for c in vec)


def _profile_time(length: float, v: float, v0: float, v1: float, a: float) -> float:
    """Seconds to cover `length` mm with top speed v, entry v0, exit v1 (mm/s), acceleration a."""
    v0, v1 = min(v0, v), min(v1, v)
    d_acc = (v * v - v0 * v0) / (2 * a)
    d_dec = (v * v - v1 * v1) / (2 * a)
    if d_acc + d_dec <= length:
        return (v - v0) / a + (v - v1) / a + (length - d_acc - d_dec) / v
    peak = math.sqrt(max((2 * a * length + v0 * v0 + v1 * v1) / 2, 0.0))
    if peak < max(v0, v1):             # cannot even reach the exit speed: plain ramp
        return 2 * length / (v0 + v1) if v0 + v1 > 0 else 0.0
    return (peak - v0) / a + (peak - v1) / a


@dataclass
class CycleTime:
    machine: Machine
    per_tool: dict[Optional[int], float] = field(default_factory=dict)
    rapid_s: float = 0.0
    feed_s: float = 0.0
    dwell_s: float = 0.0
    change_s: float = 0.0
    untimed: int = 0                     # feed moves with no usable feed
    _pending: Optional[tuple] = None     # (record, length, speed mm/s, accel, entry speed)
    _tool: Optional[int] = None          # the tool in the spindle (a dwell record names none)

    def __post_init__(self) -> None:
        axes = self.machine.axes
        self._accel = {a: ax.accel for a, ax in axes.items() if ax.accel}
        self._rapid = {a: ax.rapid for a, ax in axes.items() if ax.rapid}
        self._max_feed = {a: ax.max_feed for a, ax in axes.items() if ax.max_feed}

    @property
    def total_s(self) -> float:
        return self.rapid_s + self.feed_s + self.dwell_s + self.change_s

    def _charge(self, tool, seconds: float, what: str) -> None:
        self.per_tool[tool] = self.per_tool.get(tool, 0.0) + seconds
        setattr(self, what, getattr(self, what) + seconds)

    def add(self, r: ToolpathRecord) -> None:
        kind = r.kind
        if r.tool is not None:
            self._tool = r.tool
        if kind in ("rapid", "linear", "arc") and r.start is not None and r.end is not None:
            self._move(r)
            return
        if kind == "dwell" and r.dwell_s:
            self._flush(None)
            self._charge(self._tool, r.dwell_s, "dwell_s")     # the tool that dwells
        elif kind == "tool_change":
            self._flush(None)
            if self.machine.tool_change_s:
                self._charge(r.tool, self.machine.tool_change_s, "change_s")
        elif kind == "stop":
            self._flush(None)

    def finish(self) -> "CycleTime":
        self._flush(None)
        return self

    def _move(self, r: ToolpathRecord) -> None:
        length = motion_length(r)
        travel = axis_travel(r)
        if length <= 1e-9:
            return
        if r.kind == "rapid":
            # every axis at its own rapid rate: the slowest one sets the speed along the path
            minutes = max((d / self._rapid.get(a, DEFAULT_RAPID) for a, d in travel.items() if a in "XYZ"),
                          default=0.0)
        else:
            rate = path_rate(r, length)
            if rate is None:
                self._flush(None)
                self.untimed += 1
                return
            minutes = length / rate
            for a, d in travel.items():
                if a in self._max_feed:
                    minutes = max(minutes, d / self._max_feed[a])
        speed = length / (minutes * 60.0) if minutes > 0 else 0.0      # mm/s
        if speed <= 0:
            return
        if not self._accel:
            self._charge(r.tool, length / speed, "rapid_s" if r.kind == "rapid" else "feed_s")
            return
        # the slowest axis's acceleration, scaled by its share of the direction, limits the path
        accel = min((self._accel[a] * length / d for a, d in travel.items()
                     if a in self._accel and d > 1e-9), default=math.inf)
        entry = self._flush(r, speed)
        self._pending = (r, length, speed, accel, entry)

    def _flush(self, following: Optional[ToolpathRecord], next_speed: float = 0.0) -> float:
        """Time the pending move now that its exit speed (the corner to `following`) is known;
        returns that speed, the next move's entry speed."""
        p = self._pending
        if p is None:
            return 0.0
        self._pending = None
        r, length, speed, accel, entry = p
        exit_speed = 0.0
        if following is not None and (following.kind == "rapid") == (r.kind == "rapid"):
            d0, d1 = _direction(r, True), _direction(following, False)
            if d0 is not None and d1 is not None:
                cos = sum(x * y for x, y in zip(d0, d1))
                exit_speed = min(speed, next_speed) * max(0.0, cos)
        t = length / speed if math.isinf(accel) else _profile_time(length, speed, entry, exit_speed, accel)
        self._charge(r.tool, t, "rapid_s" if r.kind == "rapid" else "feed_s")
        return exit_speed

    def report(self) -> str:
        lines = []
        for tool, s in self.per_tool.items():
            lines.append(f"  {'T' + str(tool) if tool is not None else 'no tool':<10} {hms(s)}")
        parts = [f"rapid {hms(self.rapid_s)}", f"feed {hms(self.feed_s)}"]
        if self.dwell_s:
            parts.append(f"dwell {hms(self.dwell_s)}")
        if self.change_s:
            parts.append(f"tool changes {hms(self.change_s)}")
        lines.append(f"  {'total':<10} {hms(self.total_s)} ({', '.join(parts)})")
        if self.untimed:
            lines.append(f"  ({self.untimed} feed moves without a usable feed are not counted)")
        return "\n".join(lines) + "\n"

    def to_dict(self) -> dict:
        return {"total_s": round(self.total_s, 3), "rapid_s": round(self.rapid_s, 3),
                "feed_s": round(self.feed_s, 3), "dwell_s": round(self.dwell_s, 3),
                "tool_change_s": round(self.change_s, 3), "untimed_moves": self.untimed,
                "per_tool": [{"tool": t, "seconds": round(s, 3)} for t, s in self.per_tool.items()]}


def hms(seconds: float) -> str:
    m, s = divmod(seconds, 60.0)
    h, m = divmod(int(m), 60)
    return f"{h}:{m:02d}:{s:04.1f}" if h else f"{m}:{s:04.1f}"
