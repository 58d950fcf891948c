"""Which number an alarm the program raises gets in a target dialect.

A program's own (user) alarm is numbered in its control's user band: ISO `#3000=n` raises n, a
Sinumerik program raises `SETAL(66000+n)` (its cycle alarms are 60000..69999; SETAL(86) is no user
alarm there). The author's n is what a conversion keeps: moved into the target's band, never written
as the raw number. A number of the source control's own alarm list (a Sinumerik cycle alarm 61000, a
Fagor error-list number) means nothing on another control: it is kept where the target's SETAL-like
range takes it, else written as the target's "alarm of the source program" number with the source's
number in the text. The bands are data: rules/<dialect>.toml `[options] alarms`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from nctrans.ir import nodes as n
from nctrans.rules import option


@dataclass(frozen=True)
class Band:
    user_base: Optional[int]        # the number of the program's own alarm 0; None: no numbered band
    user_count: int                 # own alarms 0 .. user_count-1 fit
    own_range: Optional[tuple]      # control-list numbers a program may raise as they are
    foreign: Optional[int]          # the number a foreign alarm is raised with (None: text only)


def band(dialect: Optional[str]) -> Band:
    t = option(dialect, "alarms", None) or {}
    rng = t.get("range")
    return Band(t.get("user_base"), int(t.get("user_count", 0)),
                tuple(rng) if rng else None, t.get("foreign"))


def constant(e) -> Optional[float]:
    return float(e.value) if type(e) is n.Num else None


@dataclass
class Written:
    number: Optional[n.Expr]    # the number to write (None: the target writes the text form)
    text: Optional[n.Expr]      # the text to write with it
    note: Optional[str]         # what moved, for the info at the line (None: written as it is)


def written(a: n.Alarm, target: Optional[str], source: Optional[str] = None) -> Written:
    """The number and text `a` is written with in `target`'s numbering (`source`: the dialect the
    program was read in; its own control's alarm list holds in that dialect)."""
    b = band(target)
    num = a.number
    if a.own_base is None and source == target and num is not None:
        return Written(num, a.text, None)
    if a.own_base is not None and num is not None and b.user_base is not None:
        k = constant(num)
        if k is None:            # a computed own alarm: the same offset applied by the control
            shift = b.user_base - a.own_base
            if shift == 0:
                return Written(num, a.text, None)
            op = "+" if shift > 0 else "-"
            return Written(n.Binary(op, num, n.Num(float(abs(shift)), str(abs(shift)))), a.text,
                           f"the program's own alarm (computed) raised as {b.user_base} + (number - "
                           f"{a.own_base}): the user alarm band of the target")
        own = int(k) - a.own_base
        if 0 <= own < b.user_count and k == int(k):
            out = b.user_base + own
            note = None if out == int(k) else (
                f"the program's own alarm {int(k)} raised as {out} (its user alarm {own}: the "
                f"target's user alarms are {b.user_base}..{b.user_base + b.user_count - 1})")
            return Written(n.Num(float(out), str(out)), a.text, note)
    k = constant(num) if num is not None else None
    if a.own_base is None and k is not None and b.own_range and b.own_range[0] <= k <= b.own_range[1]:
        return Written(num, a.text, None)
    # a number this target has no place for: the alarm still stops there, its number in the text
    # (an own alarm by the author's number: ISO 86 and Sinumerik 66086 are both "ALARM 86")
    if k is not None and a.own_base is not None:
        k -= a.own_base
    whole = k is not None and k == int(k)
    shown = str(int(k)) if whole else None
    what = (f"alarm {shown}" if whole else "an alarm with no number" if num is None
            else "a computed alarm number")
    text = a.text if a.text is not None else (n.Str(f"ALARM {shown}") if whole else None)
    if b.foreign is None:       # a target that raises by text alone
        return Written(None if text is not None else num, text, None)
    kept = "its text kept" if num is None else "its number kept in the text"
    return Written(n.Num(float(b.foreign), str(b.foreign)), text,
                   f"{what} of the source program raised as {b.foreign} (the target's alarm for an "
                   f"alarm it has no number for), {kept}: the program stops here")
