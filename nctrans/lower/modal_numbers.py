"""A numbered modal-state variable of one dialect (ISO #4001 motion, #4007 cutter compensation,
#4014 work offset ...: the G code number in force) as an expression over another dialect's G-group
index variable (Sinumerik `$P_GG[n]`: the position of the code in force inside G group n).

Both are data: the source table's `[[options.numbered_variables]]` entry (source "modal": the
neutral group and the number each neutral value reads as), the target table's
`options.g_group_index` (each G group's codes in index order) and its codes' neutral meanings. The
mapping exists when one G group holds the codes of every value the program can be in and the
number is the index plus one constant for all of them (#4007 = $P_GG[7]+39: G40/G41/G42 are 40/41/42
and indexes 1/2/3). The values the program can be in are its power-on value and those it selects;
a value with no number on the source side, or no code on the target side, or off the line, and
there is no mapping (the caller refuses the read at its line).
"""
from __future__ import annotations

from typing import Optional

from nctrans.ir import nodes as ir
from nctrans.ir import walk


def selected_values(program: ir.Program) -> Optional[dict[str, set[str]]]:
    """Neutral group -> the values the program can be in (power-on and selected); None when the
    body is streamed (not all of it can be seen)."""
    out: dict[str, set[str]] = {}
    for group, value in ((program.meta or {}).get("defaults") or {}).items():
        out.setdefault(group, set()).add(value)
    for body in [program.body, *(s.body for s in program.subprograms.values())]:
        if type(body) is not list:
            return None
        for b in walk.blocks(body):
            for s in b.body:
                if type(s) is ir.ModeChange:
                    out.setdefault(s.group, set()).add(s.value)
                elif type(s) is ir.CycleParams or type(s) is ir.CycleCall:
                    out.setdefault("motion", set()).add("none")   # a cycle holds group 1 itself
    return out


def as_group_index(entry: dict, values: set[str], target) -> Optional[tuple[str, int, int]]:
    """(index variable, G group number, constant) with number = variable[group] + constant for
    every value in `values`, or None. `entry` is the source's numbered-variable entry, `target`
    the target's rules table."""
    variable = target.options.get("g_group_index_variable")
    lists = target.options.get("g_group_index") or {}
    numbers = entry.get("values") or {}
    if entry.get("source") != "modal" or not variable or not values:
        return None
    group_of = {code.upper(): (int(g), i + 1) for g, codes in lists.items()
                for i, code in enumerate(codes) if code}
    found = set()
    for value in values:
        rule = target.code_for(entry["group"], value)
        if value not in numbers or rule is None or rule.code.upper() not in group_of:
            return None
        g, index = group_of[rule.code.upper()]
        found.add((g, float(numbers[value]) - index))
    if len(found) != 1:
        return None
    (g, constant), = found
    return (variable, g, int(constant)) if constant == int(constant) else None
