"""The documented mapping between subprogram names and program numbers, for calls kept across
dialects.

A dialect that calls subprograms by number (ISO: M98/G65 P<n>, O<n>) and one that calls them by
name (Sinumerik: WARMUP_CYCLE, L1234) meet here:
- a name that is already a number (O1234, 1234, Sinumerik L1234) is that number;
- any other name becomes a number from O9000..O9999: 9000 + CRC-32 of the upper-case name mod 1000,
  so every file converts the same name to the same number without seeing the others (a clash
  within one program takes the next free number, and NC404 names the number used).
`call_keys` gives the identities one call may have, so `equiv` can tell that a kept call in the
conversion is the same call as in the source (an opaque event: same call, same evaluated
arguments, same point of the toolpath).
"""
from __future__ import annotations

import re
import zlib
from typing import Optional

NAMED_FIRST = 9000
NAMED_COUNT = 1000
_NUMBER = re.compile(r"^[OoLl]?0*(\d+)$")


def number_of(name: str) -> Optional[int]:
    """The program number a name already is ("O1000", "1000", "L1000"), or None for a name."""
    m = _NUMBER.match((name or "").strip())
    return int(m.group(1)) if m else None


def stable_number(name: str, taken: set[int] = frozenset()) -> int:
    """O9000..O9999 from the name alone (the same name gets the same number in every file that
    defines or calls it), the next free one on a clash with `taken`."""
    num = NAMED_FIRST + zlib.crc32(name.upper().encode()) % NAMED_COUNT
    while num in taken:
        num = NAMED_FIRST + (num - NAMED_FIRST + 1) % NAMED_COUNT
    return num


def call_keys(name: str) -> frozenset[str]:
    """Identities of a call of `name`: its upper-case name and the program number it is or
    converts to."""
    name = (name or "").strip()
    num = number_of(name)
    if num is None:
        num = stable_number(name)
        return frozenset((name.upper(), f"O{num}"))
    return frozenset((f"O{num}",))


def same_call(a: str, b: str) -> bool:
    return bool(call_keys(a) & call_keys(b))
