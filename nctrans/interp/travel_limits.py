"""Travel limits a program sets (IR TravelLimit), kept per scope and turned into the `limits`
records of the toolpath, which the machine check enforces.

Records are in machine coordinates, so the check needs no dialect knowledge. The scopes differ in
the point they bound (see ir.nodes.TravelLimit): "machine" limits are axis positions and go out
as written; "work_area" limits and the "zone" box bound the tool tip, so their Z is moved by the
tool-length compensation in force (and sent again when it changes).

Two kinds of record (see nctrans.toolpath): per-axis limits (`start` lower, `end` upper: the
tightest of the machine and the active work-area limits) and the forbidden zone (`zone`
"inside", `start`/`end` its corners; neither: no zone).
"""
from __future__ import annotations

from typing import Optional

Bounds = tuple[dict[str, float], dict[str, float]]


class ProgrammedLimits:
    """The programmed limits of one run. `apply` one statement, then `pending(tool_z)` gives the
    records (as keyword dicts for ToolpathRecord) that changed since last asked."""

    def __init__(self, machine_axes: Optional[dict] = None):
        # the machine's own soft limits: what an incremental Fagor G198/G199 counts from
        self.base = {a: (ax.min, ax.max) for a, ax in (machine_axes or {}).items()}
        self.machine: Bounds = ({}, {})
        self.work_area: Bounds = ({}, {})
        self.work_area_on = True                # Sinumerik WALIMON is the power-on state
        self.zone: Optional[Bounds] = None
        self.zone_on = False
        self._sent: dict[str, object] = {"axes": ({}, {}), "zone": None}

    @property
    def active(self) -> bool:
        return bool(self.machine[0] or self.machine[1] or self.work_area[0] or self.work_area[1]
                    or self.zone is not None)

    def apply(self, kind: str, scope: str, values: dict[str, float], corner: dict[str, float],
              incremental: bool) -> None:
        if scope == "zone":
            if kind == "box":
                lo = {a: min(v, corner.get(a, v)) for a, v in values.items()}
                hi = {a: max(v, corner.get(a, v)) for a, v in values.items()}
                self.zone = (lo, hi)
                self.zone_on = True
            elif kind in ("on", "off"):
                self.zone_on = kind == "on"
            return
        if kind in ("on", "off"):
            if scope == "work_area":
                self.work_area_on = kind == "on"
            return
        side = 0 if kind == "lower" else 1
        bounds = self.machine if scope == "machine" else self.work_area
        for a, v in values.items():
            if incremental:
                now = bounds[side].get(a)
                if now is None:
                    now = self.base.get(a, (None, None))[side]
                v = (now or 0.0) + v
            bounds[side][a] = v
            if scope == "machine" and bounds[0].get(a) == 0.0 and bounds[1].get(a) == 0.0:
                # Fagor: both limits 0 remove the axis's limits (spec fagor8065 11.2)
                del bounds[0][a], bounds[1][a]

    def pending(self, tool_z: float) -> list[dict]:
        """Records (ToolpathRecord keyword arguments) for what changed since the last call."""
        out = []
        lower, upper = dict(self.machine[0]), dict(self.machine[1])
        if self.work_area_on:
            for a, v in self.work_area[0].items():
                v += tool_z if a == "Z" else 0.0
                lower[a] = max(v, lower.get(a, v))
            for a, v in self.work_area[1].items():
                v += tool_z if a == "Z" else 0.0
                upper[a] = min(v, upper.get(a, v))
        if (lower, upper) != self._sent["axes"]:
            self._sent["axes"] = (lower, upper)
            out.append({"start": lower or None, "end": upper or None})
        zone = None
        if self.zone_on and self.zone is not None:
            zone = tuple({a: v + (tool_z if a == "Z" else 0.0) for a, v in side.items()}
                         for side in self.zone)
        if zone != self._sent["zone"]:
            self._sent["zone"] = zone
            out.append({"zone": "inside", "start": zone[0] if zone else None,
                        "end": zone[1] if zone else None})
        return out
