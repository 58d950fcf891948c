"""When a T word changes the tool: at once (a lathe's turret, a control set to change by T) or
only at M6 (a mill whose changer loads the preselected tool).

Data, not code: the dialect table's `[options] tool_change.by_t_word = { mill = .., lathe = .. }`
by the machine's kind, overridden by the machine file's `[tool_change] by_t_word` (Sinumerik
machine data 22550 TOOL_CHANGE_MODE: 0 = T changes, 1 = M6 changes). Where T changes the tool, an
M6 naming the tool already in place changes nothing (as a turret that stays), so `T1 M6` written
for either setting runs the same. ISO turning's T word is a turret change in its front end
(T0101: ToolSelect, ToolChange(turret), the offset)."""
from __future__ import annotations

from typing import Optional


def changes_on_t_word(machine, dialect: Optional[str]) -> bool:
    tc = getattr(machine, "tool_change", None)
    own = tc.get("by_t_word") if isinstance(tc, dict) else getattr(tc, "by_t_word", None)
    if own is not None:
        return bool(own)
    from nctrans.rules import option
    table = option(dialect, "tool_change", {}) or {}
    by_kind = table.get("by_t_word", {}) if isinstance(table, dict) else {}
    return bool(by_kind.get(getattr(machine, "kind", "mill"), False)) if isinstance(by_kind, dict) else False
