"""Modal state: what stays in force from block to block.

Seeded from the dialect's defaults (`program.meta["defaults"]`, {group: value}); the interpreter
never asks which dialect it runs. Groups the hot path reads are plain attributes; every group is
also kept in `groups` so unknown/neutral groups (path_mode, spindle_mode ...) are remembered.
"""
from __future__ import annotations

from typing import Any, Optional

INCH = 25.4
LINEAR_AXES = frozenset("XYZUVW")
ROTARY_AXES = frozenset("ABC")
BASE_AXES = ("X", "Y", "Z")


class ModalState:
    __slots__ = ("groups", "motion", "plane", "incremental", "arc_absolute", "scale", "feed_scale", "feed_mode",
                 "feed", "spindle_speed", "spindle_dir", "tool", "tool_selected", "length_mode",
                 "length_index", "comp_side", "radius_index", "work_offset", "cycle",
                 "cycle_retract", "coolant", "diameter", "polar")

    def __init__(self, defaults: Optional[dict[str, Any]] = None):
        self.groups: dict[str, str] = {}
        self.motion = "rapid"
        self.plane = "XY"
        self.incremental = False
        self.arc_absolute = False
        self.scale = 1.0                  # program length unit -> mm
        self.feed_scale = 1.0             # program feed unit -> mm (Sinumerik G70: feeds stay mm)
        self.feed_mode = "per_min"
        self.feed: Optional[float] = None         # mm/min (or mm/rev, or 1/min inverse time)
        self.spindle_speed: Optional[float] = None
        self.spindle_dir: Optional[str] = None
        self.tool: Optional[int] = None           # tool in the spindle
        self.tool_selected: Optional[int] = None  # last T word
        self.length_mode = "off"
        self.length_index: Optional[int] = None
        self.comp_side = "off"
        self.radius_index: Optional[int] = None
        self.work_offset: Optional[str] = None
        self.cycle = "off"
        self.cycle_retract = "initial"
        self.coolant = "off"
        self.diameter = False             # lathe: X words are diameters (ISO-T, Sinumerik DIAMON)
        self.polar = False                # plane words are radius and angle (polar_input.py)
        for g, v in (defaults or {}).items():
            self.set(str(g), str(v))

    def set(self, group: str, value: str) -> None:
        """Record a modal change; mirror the groups the hot path reads into attributes."""
        self.groups[group] = value
        if group == "motion":
            self.motion = value
        elif group == "plane":
            self.plane = value
        elif group == "distance":
            self.incremental = value == "incremental"
        elif group == "arc_distance":
            self.arc_absolute = value == "absolute"
        elif group == "units":
            self.scale = INCH if value in ("inch", "inch_geometry") else 1.0
            self.feed_scale = INCH if value == "inch" else 1.0
        elif group == "feed_mode":
            self.feed_mode = value
        elif group == "tool_length":
            self.length_mode = value
        elif group == "cutter_comp":
            self.comp_side = value
        elif group == "work_offset":
            self.work_offset = value
        elif group == "cycle":
            self.cycle = value
        elif group == "cycle_retract":
            self.cycle_retract = value
        elif group == "spindle":
            self.spindle_dir = value
        elif group == "coolant":
            self.coolant = value
        elif group == "diameter":
            self.diameter = value == "diameter"
        elif group == "polar":
            self.polar = value == "on"
