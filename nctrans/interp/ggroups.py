"""Sinumerik $P_GG[n]: the active G code of G group n, as its index inside the group.

The index lists are data (rules/sinumerik.toml `[options.g_group_index]`, with their sources); the
codes' meanings come from the same table's [[codes]]. The interpreter keeps neutral modal state
(group "units" = "mm" for both G71 and G710), so it also remembers the code spelt last per neutral
group: that code wins when it still means the state, else the first code of the list that does.
A group without a list, or a state none of its codes means (a motion the interpreter does not
model), reads as UNKNOWN: the caller says NC107 where the value matters.
"""
from __future__ import annotations

from typing import Any, Callable, Optional

from nctrans.interp.evaluate import UNKNOWN


def index_reader(dialect: str, groups: dict, spelt: dict,
                 unmodelled_motion: Callable[[], Optional[str]]
                 ) -> Optional[tuple[str, Callable[[tuple], Any]]]:
    """(the variable's spelling, a reader of it) for the dialect's G-group index variable
    (Sinumerik `$P_GG[n]`, named by options.g_group_index_variable) over the live modal `groups` (neutral group -> value), `spelt`
    (neutral group -> the code spelt last) and `unmodelled_motion()` (the motion code in force that
    the interpreter does not model, such as G331, or None), or None when the dialect has no index
    table."""
    try:
        from nctrans.rules import load_table
        table = load_table(dialect)
    except Exception:            # no table for this dialect
        return None
    lists = table.options.get("g_group_index")
    variable = table.options.get("g_group_index_variable")
    if not isinstance(lists, dict) or not variable:
        return None
    # per G group: [(code, neutral group, neutral value)] in index order (None: not in the table)
    meaning: dict[int, list] = {}
    for number, codes in lists.items():
        entries = []
        for code in codes:
            rule = table.lookup(code) if code else None
            entries.append((code.upper(), rule.group, rule.value) if rule else None)
        meaning[int(number)] = entries

    def read(idx: Optional[tuple]) -> Any:
        if not idx or len(idx) != 1:
            return UNKNOWN
        try:
            entries = meaning.get(int(idx[0]))
        except (TypeError, ValueError):
            return UNKNOWN
        if not entries:
            return UNKNOWN
        if any(e is not None and e[1] == "motion" for e in entries):
            code = unmodelled_motion()
            if code is not None:          # G331 in force: the state still holds the motion before
                names = [c.upper() for c in lists.get(str(int(idx[0]))) or ()]
                return float(names.index(code.upper()) + 1) if code.upper() in names else UNKNOWN
        first = None
        for i, e in enumerate(entries, 1):
            if e is None:
                continue
            code, group, value = e
            if groups.get(group) != value:
                continue
            if spelt.get(group) == code:
                return float(i)
            if first is None:
                first = float(i)
        return UNKNOWN if first is None else first
    return str(variable), read
