"""Sinumerik program section repetition (REPEAT label P=n, REPEAT start end, REPEATB, ENDLABEL).

[GK] Siemens Fundamentals programming manual, "program section repetition" (the advanced seed only
lists REPEATB in its keyword table, L24650, "repeat a program line nnn times"):
- `REPEATB label P=n`: the block carrying `label` runs n more times; the label is searched towards
  the program start first, then towards its end.
- `REPEAT label P=n`: the blocks from `label` (searched towards the start only) up to the block
  before the REPEAT run n more times; when an `ENDLABEL:` block comes between them the section ends
  with it.
- `REPEAT start end P=n`: the blocks from `start` to `end`, both included (searched towards the
  start first, then towards the end).
- P defaults to 1. Execution then goes on after the REPEAT statement.

The interpreter runs a section as a call of a unit that holds a copy of the section's compiled
instructions (jump targets rebased), sharing the caller's variables. A section that cuts a
control structure (a jump leaving or entering it) cannot be run that way: `section_code` says so.
"""
from __future__ import annotations

from typing import Any, Callable, Optional

from nctrans.ir import nodes as n

ENDLABEL = "ENDLABEL"


def find_before_then_after(pcs: Optional[list[int]], pc: int) -> Optional[int]:
    """The nearest of `pcs` at or before `pc`, else the first after it."""
    if not pcs:
        return None
    before = [p for p in pcs if p <= pc]
    if before:
        return before[-1]
    after = [p for p in pcs if p > pc]
    return after[0] if after else None


def section_bounds(s: n.SectionRepeat, labels: dict, key: Callable[[Any], Any],
                   pc: int) -> tuple[Optional[int], Optional[int], str]:
    """(first pc, last pc, problem) of the section `s` as seen from the REPEAT at `pc`."""
    start_pcs = labels.get(key(s.start))
    if s.line_only or s.end is not None:
        first = find_before_then_after(start_pcs, pc)
    else:
        first = max((p for p in start_pcs or () if p < pc), default=None)
    if first is None:
        where = "before the REPEAT" if not (s.line_only or s.end) else "in this program"
        return None, None, f"jump label {s.start} of the repeated section not found {where}"
    if s.line_only:
        return first, first, ""
    if s.end is not None:
        last = min((p for p in labels.get(key(s.end)) or () if p >= first), default=None)
        if last is None:
            return None, None, f"end label {s.end} of the repeated section not found after {s.start}"
        return first, last, ""
    last = min((p for p in labels.get(key(ENDLABEL)) or () if first <= p < pc), default=None)
    return first, (pc - 1 if last is None else last), ""


def section_code(code: list, labels: dict, first: int, last: int,
                 jump_ops: tuple[int, int]) -> tuple[Optional[list], dict, str]:
    """(instructions, labels, problem): a copy of code[first:last+1] with jumps rebased, or a
    problem when a jump in it leaves the section (it cuts a control structure)."""
    jump, jfalse = jump_ops
    out = []
    for ins in code[first:last + 1]:
        op = ins[0]
        if op == jump or op == jfalse:
            slot = 1 if op == jump else 2
            target = ins[slot]
            if not first <= target <= last + 1:
                return None, {}, "the repeated section cuts a control structure (IF/loop)"
            ins = ins[:slot] + (target - first,) + ins[slot + 1:]
        out.append(ins)
    sub_labels = {}
    for k, pcs in labels.items():
        inside = [p - first for p in pcs if first <= p <= last]
        if inside:
            sub_labels[k] = inside
    return out, sub_labels, ""
