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
NC220 says so.

nctrans models one spindle, the master. Which spindle is the master is state: SETMS(n) makes
spindle n the master, SETMS alone gives the role back to the configured one, spindle 1 [GK:
machine data 20090 SPIND_DEF_MASTER_SPIND, 1 by default; the seeds do not describe SETMS]. A
spindle word written with its number reaches the master only where that number is the master's:
`S2=500` under master 1, `SPOS[1]=90` or `S1=300` after SETMS(2) are NC220 at their line, not
the master's speed or angle (`S2=500` used to set the master's speed). `SPOS[n]=` positions the
master where n is the master: `SPOS[1]=` under the configured master, `SPOS[2]=` after SETMS(2),
as `SPOS=` does; plain `S`, `SPOS=` address whichever spindle is the master. A writer spells only
the plain and spindle-1 forms as its own master positioning (`is_modelled`): whether n is the master
is known to the run, not to the text. The seed's SPOS[2] examples (L21470-21482) position a
following spindle under synchronised spindle coupling (COUPON), an overlay on the coupled motion
nctrans does not model either.
"""
from __future__ import annotations

import math
import re
from typing import Optional

from nctrans.ir import nodes as n

# the Passthrough reason of SPOS/SPOSA (rules/sinumerik.toml passthrough_words)
REASON = "spindle positioning"


def is_positioning(s: n.Passthrough) -> bool:
    """A SPOS/SPOSA word this module runs: plain, or with a constant spindle number (the front end
    gives it its address and value); the run positions the master, any other spindle is NC220."""
    return s.reason == REASON and bool(s.address) and s.value is not None


def is_modelled(s: n.Passthrough) -> bool:
    """A positioning word that names the master whatever SETMS says: plain (`SPOS=`), or spindle
    1's (`SPOS[1]=`, the configured master). What a writer may spell as its own dialect's
    master-spindle positioning; `SPOS[2]=` is the master's only after SETMS(2), which only the
    run knows."""
    return is_positioning(s) and spindle_number(s) in (None, 1)


_NUMBERED_WORD = re.compile(r"\s*[A-Za-z_]\w*\s*\[\s*(\d+)\s*\]\s*=")


def spindle_number(s: n.Passthrough) -> Optional[int]:
    """The spindle number a positioning word is written with (SPOS[2]=.. -> 2), else None."""
    m = _NUMBERED_WORD.match(s.text)
    return int(m.group(1)) if m else None


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
    number = spindle_number(s)
    if number is not None and number != it.master_spindle:
        _not_the_master(it, s, number)          # SPOS[2]= under master 1, SPOS[1]= after SETMS(2)
        return
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


# ---------------------------------------------------------------------------------------------
# The master spindle (SETMS) and speeds written with a spindle number

_SETMS = re.compile(r"\s*SETMS\s*(?:\(\s*([^)]*?)\s*\))?\s*$", re.IGNORECASE)


def is_setms(s: n.Passthrough) -> bool:
    """The dialect's master-spindle word (rules `[options] master_spindle_word`, Sinumerik SETMS)."""
    from nctrans.rules import option
    return option(s.dialect, "master_spindle_word") == "SETMS" and _SETMS.match(s.text) is not None


def set_master(d) -> None:
    """SETMS(n): spindle n is the master from here; SETMS: the configured master (1) again. A
    number that is not a constant leaves the master unknown (None): every numbered spindle word
    is then NC220 until the next SETMS."""
    it, s = d
    arg = (_SETMS.match(s.text).group(1) or "").strip()
    before = it.master_spindle
    if not arg:
        it.master_spindle = 1
    elif arg.isdigit() and int(arg) >= 1:
        it.master_spindle = int(arg)
    else:
        it.master_spindle = None
        it.diag("NC220", "warning", f"{s.text.strip()!r}: the master spindle is not a constant; spindle "
                "words written with a spindle number are not modelled until the next SETMS")
        return
    if it.master_spindle != before:
        # one spindle's state is kept (speed, direction, angle): it now belongs to another spindle
        it.diag("NC220", "warning", f"{s.text.strip()!r} makes spindle {it.master_spindle} the master: its "
                "speed, direction and angle are not known here; the analysed toolpath keeps those of "
                f"spindle {before} until S, M3/M4/M5 or SPOS set them")


def _not_the_master(it, s, number: int) -> None:
    master = it.master_spindle
    which = f"the master is spindle {master}" if master is not None else "the master is not known"
    text = s.text.strip() if isinstance(s, n.Passthrough) else f"S{number}="
    it.diag("NC220", "warning", f"{text!r} addresses spindle {number}, and {which} (SETMS): nctrans "
            "models the master spindle only; not modelled, the analysed toolpath leaves it out")


_NUMBERED_M = re.compile(r"M(\d+)=", re.IGNORECASE)


def numbered_mode(s: n.ModeChange) -> Optional[int]:
    """The spindle number of a spindle function written with it (Sinumerik M1=3), else None."""
    m = _NUMBERED_M.match(s.code)
    return int(m.group(1)) if m else None


def numbered_mode_change(d) -> None:
    """M<n>=3/4/5/19: the master's function where n is the master, else NC220 (never the master's
    direction: `M1=3` after SETMS(2) starts spindle 1, not the master)."""
    it, s = d
    number = numbered_mode(s)
    if number == it.master_spindle:
        it._h_mode(s)
    else:
        _not_the_master(it, n.Passthrough(s.code, "spindle function", it.program.dialect), number)


def numbered_speed(d) -> None:
    """S<n>=: the master's speed where n is the master, else NC220 (never the master's speed)."""
    it, s, f = d
    if s.spindle == it.master_spindle:
        it._h_speed(f)
    else:
        _not_the_master(it, s, s.spindle)
