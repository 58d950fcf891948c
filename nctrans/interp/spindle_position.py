"""Sinumerik spindle positioning SPOS / SPOSA (and M19): the spindle stops and turns to an angle.

`SPOS=90`, `SPOSA=AC(90)`, `SPOS=DC(0)`, `SPOS=ACP(..)`/`ACN(..)` position the master spindle at an
absolute angle; `SPOS=IC(-90)` turns it by an angle from where it stands. Either way the spindle
leaves speed control and stands at the angle afterwards (seed, advanced manual: "Positioning
SPOS", L21200-21208, and the SPOS[2]=IC(..) examples L21470-21482); M3/M4 start it again. SPOSA does
not wait for the spindle at the block's end; that changes no path. M19 positions at setting data
43240 M19_SPOS, "also effective in Siemens mode" (ISO seed D.3), 0 degrees by default.

What nctrans records: a `spindle` event with `spindle_dir` "orient" and `spindle_angle` (0..360),
at the line. A feed move after it is not NC209 (as after M5): a positioned spindle is what probing
and measuring programs feed with (corpus mojimould-O80000001-main: M19, then G1 with a touch
probe). An
IC angle from a spindle that was turning (or whose angle is not known) leaves the angle unknown:
the event's angle is NaN (left out of the JSON record, compared as unknown by equiv, refused by
--flatten) and
NC220 says so. Spindles other than the master (`SPOS[2]=`) stay NC220,
not modelled (nctrans models one spindle).
"""
from __future__ import annotations

import math

from nctrans.ir import nodes as n

# the Passthrough reason of SPOS/SPOSA (rules/sinumerik.toml passthrough_words)
REASON = "spindle positioning"


def is_modelled(s: n.Passthrough) -> bool:
    """A SPOS/SPOSA word of the master spindle, which this module runs (the front end gives it its
    address and value; other spindles' SPOS[n]= come without and stay NC220)."""
    return s.reason == REASON and bool(s.address) and s.value is not None


# Siemens position modes: absolute (direction by the shortest way or as written) and incremental
_ABSOLUTE = ("AC", "DC", "ACP", "ACN")


def compile_position(it, s: n.Passthrough):
    """The handler data for one SPOS/SPOSA word: (interpreter, passthrough, incremental, value fn)."""
    v = s.value
    incremental = False
    if type(v) is n.Func and v.name.upper() in (*_ABSOLUTE, "IC") and len(v.args) == 1:
        incremental = v.name.upper() == "IC"
        v = v.args[0]
    return (it, s, incremental, it.ev.compile(v))


def position(d) -> None:
    """Run one SPOS/SPOSA: stop the spindle at the angle and record the event."""
    it, s, incremental, value = d
    angle = it._value(value, s.address)
    if angle is None:
        return                                  # _value reported why
    before = it.spindle_angle if it.st.spindle_dir == "orient" else None
    if incremental:
        if before is None:
            it.diag("NC220", "warning", f"{s.text.strip()!r} turns the spindle from an angle nctrans does "
                    "not know (it was turning, or never positioned): the spindle stops, its angle is "
                    "unknown in the analysed toolpath")
            angle = math.nan
        else:
            angle = before + angle
    stop_at(it, angle % 360.0)


def stop_at(it, angle: float) -> None:
    """The spindle stands positioned at `angle` degrees (NaN: unknown)."""
    from nctrans.interp import rigid_tap
    it.st.set("spindle", "orient")
    it.spindle_stopped = False         # positioned on purpose: probing moves at feed (NC209 is M5's)
    it.spindle_reported = False
    it.spindle_angle = None if math.isnan(angle) else angle
    rigid_tap.spindle_programmed(it)
    it._record("spindle", spindle_dir="orient", spindle=it.st.spindle_speed, spindle_angle=angle)
