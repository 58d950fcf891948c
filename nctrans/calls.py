"""The documented mapping between subprogram names and program numbers, for calls kept across
dialects.

A dialect that calls subprograms by number (ISO: M98/G65 P<n>, O<n>) and one that calls them by
name (Sinumerik: WARMUP_CYCLE, L1234) meet here:
- a name that is already a number (O1234, 1234, Sinumerik L1234) is that number;
- any other name becomes a number from O9000..O9999: 9000 + CRC-32 of the upper-case name mod 1000,
  so every file converts the same name to the same number without seeing the others (a clash
  within one program takes the next free number, and NC404 names the number used).
A string argument of a kept call (ISO passes numbers only) becomes its *string number*: CRC-32
of its UTF-8 text mod 10^7 (the empty string is 0), so a converted caller and the subprogram the
target control provides agree on it without seeing each other; the output names each in a comment.
A kept call's arguments, as `equiv` compares them, are positional: a G65's letters count in the
order a PROC's parameters are passed as letters (A B C D E F H M Q R S T U V W X Y Z, then I J K),
a letter not passed is an omitted argument, so `CALL(1,,3)` and `G65 P.. A1. C3.` are one call.
An argument passed by reference (a VAR parameter of the call's declaration, Sinumerik EXTERN, or a
whole array) is no part of the event: a G65 passes it in memory (the spill slots of
nctrans.dialects.iso_m.plan), not as a letter, and what the unknown callee does with it is not
modelled on either side, so `FOO(ARR, 2)` with FOO(VAR REAL[3], REAL) and `G65 P.. A2.` are one call.
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


# the locals of the G65 letters in the order a PROC's parameters take them (nctrans.dialects.iso_m
# plan.ARG_LETTERS), then I J K (#4-#6)
LETTER_LOCALS = (1, 2, 3, 7, 8, 9, 11, 13, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 4, 5, 6)
# a converted call's parameters past the 18 letters, passed in spill slots, follow them in its event
SPILLED_AFTER = 18


def call_arguments(call) -> list:
    """The argument expressions of a kept call in the order equiv compares them (None: not
    passed): positional ones as written; G65 letters by LETTER_LOCALS, gaps left as None; other
    named arguments after the positional ones, by the local they bind."""
    bound = {name: getattr(call.bindings.get(name), "key", None) for name in call.named_args}
    if call.named_args and not call.args and all(k in LETTER_LOCALS for k in bound.values()):
        by_local = {bound[name]: e for name, e in call.named_args.items()}
        out = [by_local.get(k) for k in LETTER_LOCALS]
        while out and out[-1] is None:
            out.pop()
        return out
    named = sorted(call.named_args.items(), key=lambda kv: (
        bound[kv[0]] if isinstance(bound[kv[0]], int) else 1000, kv[0]))
    return list(call.args) + [e for _, e in named]


def by_reference(declared: Optional[list], count: int) -> Optional[list[bool]]:
    """Per positional argument of a call: passed by reference as the declaration says (the
    `extern_params` signature: dicts with by_ref and dims), or None when there is no usable one."""
    if declared is None or len(declared) < count:
        return None
    return [bool(p.get("by_ref")) or bool(p.get("dims")) for p in declared[:count]]


STRING_NUMBERS = 10_000_000


def string_number(text: str) -> int:
    """The number a string argument of a kept call is passed as (0..9999999; "" is 0)."""
    return zlib.crc32(text.encode("utf-8")) % STRING_NUMBERS


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
