"""The toolpath: the flat stream of canonical motions the interpreter produces.

This is the seam (LinuxCNC's canonical calls): backplot, check, equiv and cycle time read these
records only, never the IR or the source. Units are mm and degrees, machine coordinates after every
offset, frame and tool-length compensation.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

KINDS = ("rapid", "linear", "arc", "dwell", "tool_change", "spindle", "coolant", "stop", "limits", "call")
# "limits": programmable travel limits from here on, in machine coordinates (Fagor G198/G199,
# Sinumerik G25/G26 under WALIMON, ISO G22), of two sorts that replace only their own sort:
# - without `zone`: `start` holds the lower limits, `end` the upper ones, by axis; an axis absent
#   from both is unbounded, and a record with neither lifts every programmable axis limit;
# - with zone "inside": the box from `start` to `end` is forbidden (neither: no zone any more);
# - with zone "unmodelled": limits are switched here that the interpreter does not model (Sinumerik
#   protection zones); the check reports that it cannot judge them.
# "call": a call of a subprogram that is neither in the program nor found (kept as a call when
# converting): an opaque event at its point of the toolpath, with the name as written (`call`)
# and the evaluated arguments in the order the callee binds them (`args`; None for one omitted).
# An extension of CONTRACT's toolpath section; `equiv` compares these events like tool changes.


@dataclass(slots=True)
class ToolpathRecord:
    seq: int
    file: str
    line: int
    kind: str
    start: Optional[dict[str, float]] = None
    end: Optional[dict[str, float]] = None
    center: Optional[dict[str, float]] = None
    direction: Optional[str] = None        # "cw" | "ccw"
    plane: Optional[str] = None            # "XY" | "ZX" | "YZ"
    turns: Optional[int] = None
    feed: Optional[float] = None
    feed_mode: Optional[str] = None        # "per_min" | "per_rev" | "inverse_time"
    spindle: Optional[float] = None
    tool: Optional[int] = None
    dwell_s: Optional[float] = None
    spindle_dir: Optional[str] = None      # spindle events: "cw" | "ccw" | "off" | "orient"
    coolant: Optional[str] = None          # coolant events: "mist" | "flood" | "off"
    stop_kind: Optional[str] = None        # stop events: "stop" | "optional" | "end"
    pitch: Optional[float] = None          # spindle-synchronised feed (tapping): lead in mm/rev
    # Constant surface speed, on moves while it is on: the surface speed (m/min), the programmed
    # spindle speed limit (rpm, G50 S / LIMS=; absent when none) and the machine X of the turning
    # axis (the radius is |X - css_axis|). `spindle` stays the speed the interpreter derived;
    # `check` works out what the surface speed demands at the move's smallest radius.
    css: Optional[float] = None
    spindle_limit: Optional[float] = None
    css_axis: Optional[float] = None
    zone: Optional[str] = None             # limits records: "inside" (a forbidden box), "unmodelled"
    call: Optional[str] = None
    args: Optional[list] = None
    # spindle events positioning the spindle (M19, Sinumerik SPOS/SPOSA): the angle in degrees, 0..360;
    # absent for M19, which positions at the control's setting (SD 43240 M19_SPOS, 0 by default)
    spindle_angle: Optional[float] = None
    # thread moves (pitch set) of a thread whose start is shifted: the spindle angle in degrees,
    # 0..360, at which the cut begins (Sinumerik SF=, ISO G33 Q, each start of a multi-start
    # CYCLE97/CYCLE98); absent when the start angle is 0 (the single-start thread)
    thread_start: Optional[float] = None

    def to_dict(self) -> dict:
        out = {}
        for name in self.__slots__:
            v = getattr(self, name)
            if v is not None:
                out[name] = v
        return out
