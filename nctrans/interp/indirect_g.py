"""Indirect G code programming: a G code chosen by its number inside a modal group as the program
runs (Sinumerik `G[8]=INT_VAR`, spec 3.6, seed L1536-1552: `INT_VAR=2` selects G54).

The front end reads the group's codes from the rules table (`[options.g_group_index]`, the same
"index as PLC interface" numbering `$P_GG[n]` returns) into an IR ModeSelect; here the number is
evaluated and the code it names is selected as if it had been written. A number the group does not
have is the control's alarm 12475 (NC105); a value the analysis cannot know (NC107) leaves the
group as it was, and says so at the line.
"""
from __future__ import annotations

from nctrans.ir import nodes as n


def select_mode(it, data) -> None:
    """Interpreter handler of a ModeSelect; `data` is (statement, compiled index)."""
    s, index = data
    v = it._value(index, f"G[{s.family}]")
    if v is None:
        it.diag("NC107", "warning", f"G[{s.family}]: the G code number is unknown to the analysis; "
                "the G group is left as it was")
        return
    number = int(v) if v == int(v) else None
    choice = s.choices[number - 1] if number is not None and 1 <= number <= len(s.choices) else None
    if choice is None:
        it.diag("NC105", "error", f"G[{s.family}]={v:g}: G group {s.family} has no G code number {v:g} "
                f"that nctrans models (1-{len(s.choices)}; the control stops with alarm 12475 on an "
                "invalid number)")
        return
    group, value, code = choice
    it._h_mode(n.ModeChange(group, value, code))
