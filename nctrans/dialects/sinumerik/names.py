"""Which names a Sinumerik program may give its own variables and PROC parameters.

The seed (sinumerik-840d-advanced-programming, "Variable names", L839) says a name's first two
characters are letters or `_`: `S`, `F`, `X1` or `R5` cannot name a variable, since `S=5` is the
spindle speed and `X1=5` an axis. A name the language already gives a meaning as an extended
address (an axis, an arc or polar word such as CR= or AP=, SPOS=, RND= ...) cannot either: in a
block `NAME=value` would program that address. The control refuses such a DEF or PROC; nctrans says
so at the name (NC126) instead of reading the later assignments as addresses without a word.
"""
from __future__ import annotations

from typing import Optional

_FIRST_TWO = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZ_")


def refused(name: str, options: dict) -> Optional[str]:
    """Why `name` (upper case) cannot be declared, or None. `options` is the table's [options]."""
    if len(name) < 2 or name[0] not in _FIRST_TWO or name[1] not in _FIRST_TWO:
        return (f"'{name}' cannot name a variable: the first two characters of a name must be "
                f"letters or '_' (`{name}=` programs the address {name[0]})")
    if name in options.get("axes", ()):
        return f"'{name}' cannot name a variable: it is an axis (`{name}=` moves it)"
    for section in ("centre_words", "via_words", "motion_words", "passthrough_words"):
        meaning = options.get(section, {}).get(name)
        if meaning is not None:
            what = meaning if section != "centre_words" else "arc centre"
            what = what if section != "via_words" else "intermediate point"
            return (f"'{name}' cannot name a variable: `{name}=` is the control's "
                    f"{what.replace('polar.', 'polar ')} word")
    if name == "LIMS":
        return "'LIMS' cannot name a variable: `LIMS=` is the control's spindle speed limit word"
    return None
