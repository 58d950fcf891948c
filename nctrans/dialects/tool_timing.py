"""Where a converted program changes the tool: where its source does.

A T word changes the tool at once on one control (a lathe's turret, a Sinumerik or Fagor set to
change by T) and only preselects on another (a mill's changer loads it at M6): rules data
`tool_change.by_t_word`, read for the machine the conversion is for (nctrans.interp.tool_change).
Written word for word, a mill's preselecting `T2` ... `M6` became ISO turning's `T0202` at the T,
and tool 2 cut the blocks the source still cut with tool 1 (exit 0). `ToolTiming.retime` moves
the tool words of each block to where the target's words change the tool as the source did:

- source preselects, target changes by T: a T alone is held and written at the next M6 (the
  block then selects and changes, as the source's M6 does); a T never followed by an M6 changes
  nothing and is not written; an M6 where the tool held is not known (a place reached from
  elsewhere) is refused at its line (NC402: the construct is lowered to plain motion);
- source changes by T, target preselects: a T alone is followed by a turret change (a tool
  already in place changes nothing, as in the source), and an M6 after it, which changes nothing
  in the source (the tool selected is the tool in place), is not written;
- both change by T: an M6 after a T of the tool in place is left out (a Fagor M06 brings D1), and
  a change that brings the source's default edge (Sinumerik D1) says it where the target's T
  keeps the D number (Fagor);
- a lathe's turret that stays (ISO turning T0102 after T0101) is no change on a target whose M6
  would change the tool again.
Said at the line: a repeated M6 of the loaded tool a T-changing target cannot make (NC401), an M6
after a T that already changed the tool with moves between (NC124: the program reads as written
for an M6 changer, the conversion's machine changes by T).
"""
from __future__ import annotations

from typing import Optional

from nctrans.ir import nodes as n

_UNKNOWN = object()             # the tool held is not known here (a place reached from elsewhere)


def t_word_changes(dialect: Optional[str]) -> bool:
    """Whether `dialect`'s T word changes the tool on the machine of the conversion running (the
    built-in mill outside one)."""
    from nctrans.dialects.emit import CONVERSION_MACHINE
    from nctrans.interp.tool_change import changes_on_t_word
    get = CONVERSION_MACHINE.get()
    machine = get() if get is not None else None
    return changes_on_t_word(machine, dialect)


def _default_edge(dialect: Optional[str]) -> int:
    from nctrans.rules import option
    return int(option(dialect, "default_cutting_edge", 0) or 0) if dialect else 0


class ToolTiming:
    """Per emitter: `source` and `target` dialect names; `target_turret`: the target's T word
    always changes the tool (ISO turning's T<tool><offset>)."""

    def __init__(self, source: Optional[str], target: str, target_turret: bool = False):
        same = source == target
        self.source_changes = not same and t_word_changes(source)
        self.target_changes = not same and (target_turret or t_word_changes(target))
        self.target_turret = target_turret
        self.converting = not same
        self.held = None                # the tool a source T preselected and no M6 loaded yet
        self.t_seen = False             # a T was written on this path (source changes by T)
        self.in_place: Optional[float] = None   # the tool a turret change put in place, if known
        self.loaded: Optional[float] = None     # the tool the last M6 loaded, if known
        self.notes: list[str] = []      # NC401 notes of the last block retimed
        self.warnings: list[str] = []   # NC124 of the last block retimed
        self.src_tool = None            # the tool the source's T put in place (both change by T)
        # the edge a change brings in the source where the target's change brings none (rules
        # default_cutting_edge: Sinumerik D1; a Fagor T keeps the D number)
        self.edge_on_change = (_default_edge(source) if not same and not _default_edge(target)
                               and not target_turret else 0)
        self.same = False               # ... and the last T named the tool already there
        self.t_alone = False            # a source T changed the tool in a block of its own ...
        self.cut_since = False          # ... and a move followed it before any M6

    @property
    def active(self) -> bool:
        return self.source_changes != self.target_changes

    def forget(self) -> None:
        """A place reached from elsewhere: the tool held there depends on the path."""
        self.held = _UNKNOWN
        self.t_seen = False
        self.in_place = None
        self.loaded = None
        self.t_alone = self.cut_since = False
        self.src_tool, self.same = None, False

    def apply(self, emitter, body: list) -> list:
        """The block's statements retimed for `emitter`, its refusal (NC402), notes (NC401) and
        warnings (NC124) reported there."""
        body, why = self.retime(body)
        if why is not None:
            emitter.refuse(why)
        for note in self.notes:
            emitter.lowered(note)
        if self.warnings:
            from nctrans.diagnostics import at_span
            for text in self.warnings:
                emitter.diags.append(at_span("NC124", "warning", text, emitter._where()))
        return body

    def retime(self, body: list) -> tuple[list, Optional[str]]:
        """(the block's statements with its tool words where the target needs them, the reason an
        M6 cannot be written or None)."""
        self.notes = []
        self.warnings = []
        if self.source_changes:
            self._watch_preselect(body)
        if not self.converting or not any(type(s) in (n.ToolSelect, n.ToolChange) for s in body):
            return body, None
        if not self.target_turret:
            body = self._turret_stays(body)
        if not self.active:
            return (self._m6_changes_nothing(body) if self.source_changes else body), None
        if self.target_changes:
            return self._hold_until_change(body)
        return self._change_at_t(body), None

    def _watch_preselect(self, body: list) -> None:
        """NC124 at an M6 that follows, after moves, a T of its own block where the source's T
        changes the tool (the machine of the conversion): the T changed it there and the moves
        between were cut with the new tool, which the conversion keeps; a program that writes the
        M6 was likely written for a changer that loads at M6, where the old tool cuts them."""
        sel = chg = False
        for s in body:
            t = type(s)
            if t is n.ToolSelect:
                sel = True
            elif t is n.ToolChange and not s.turret:
                chg = True
            elif t is n.Motion and self.t_alone:
                self.cut_since = True
        if chg and not sel and self.t_alone and self.cut_since:
            self.warnings.append(
                "this M6 changes nothing on the machine the conversion is for: there the T word "
                "before it changed the tool (rules tool_change.by_t_word: a lathe's turret, or a "
                "control set to change by T), and the moves between are cut with the new tool, as "
                "written here; "
                "on a changer that loads at M6 the old tool cuts them: convert with that machine "
                "(--machine; its [tool_change] by_t_word = false)")
        if sel or chg:
            self.t_alone, self.cut_since = sel and not chg, False

    def _turret_stays(self, body: list) -> list:
        """A lathe's T word naming the tool at the cutting position (ISO turning T0102 after
        T0101) changes only the offset: written without its T and change, where an M6 would
        change the tool again (and stop the spindle)."""
        sel = next((s for s in body if type(s) is n.ToolSelect), None)
        turns = [s for s in body if type(s) is n.ToolChange]
        if not turns:
            return body
        tool = sel.tool.value if sel is not None and type(sel.tool) is n.Num else None
        if not all(s.turret for s in turns) or tool is None:
            self.in_place = None if tool is None else tool
            return body
        if tool != self.in_place:
            self.in_place = tool
            return body
        return [s for s in body if type(s) not in (n.ToolSelect, n.ToolChange)]

    def _hold_until_change(self, body: list) -> tuple[list, Optional[str]]:
        out: list = []
        why = None
        for i, s in enumerate(body):
            t = type(s)
            if t is n.ToolSelect:
                if any(type(x) is n.ToolChange for x in body[i + 1:]):
                    out.append(s)                # selected and changed in one block: as written
                self.held = s.tool               # else preselected: written at the M6 that loads it
                continue
            if t is not n.ToolChange or s.turret:
                out.append(s)
                continue
            if not any(type(x) is n.ToolSelect for x in out):
                if self.held is _UNKNOWN:
                    why = ("an M6 whose tool is not known here: it loads the tool preselected before "
                           "it on the path taken (this place is reached from elsewhere), and this "
                           "control changes the tool where its T word is written")
                elif self.held is None:
                    if self.target_turret:      # else: the change alone, as the source's
                        why = ("an M6 with no tool selected before it: this control changes the "
                               "tool with a T word, which names the tool it changes to")
                else:
                    out.append(n.ToolSelect(self.held))
            tool = self.held.value if type(self.held) is n.Num else None
            if tool is not None and tool == self.loaded:
                self.notes.append(
                    f"an M6 of tool {tool:g}, already loaded: the source's changer puts it away and "
                    "loads it again; this control's T word changes nothing for the tool in place "
                    "(the path is the same, the change cycle is not made)")
            self.loaded = tool
            out.append(s)
        return out, why

    def _m6_changes_nothing(self, body: list) -> list:
        """Both change the tool by T: an M6 after a T naming the tool already in place changes
        nothing in the source (nor its edge), and is left out where the target's M6 would do
        something (a Fagor M06 brings D1 of the tool). After a T that changed the tool it is kept
        (the target's M6 then brings what the source's change did)."""
        out: list = []
        edge = self.edge_on_change and not any(type(x) in (n.OffsetSelect, n.ToolChange) for x in body)
        for s in body:
            t = type(s)
            if t is n.ToolSelect:
                k = s.tool.value if type(s.tool) is n.Num else None
                self.same = k is not None and k == self.src_tool
                self.src_tool = k
                if edge and not self.same:
                    # the source's change brings its default edge (Sinumerik D1); the target's T
                    # keeps the D number in force (Fagor): said with the T
                    out.extend((s, n.OffsetSelect("radius", n.Num(float(self.edge_on_change)))))
                    continue
            elif t is n.ToolChange and not s.turret:
                if self.same:
                    continue
                self.same = True
            out.append(s)
        return out

    def _change_at_t(self, body: list) -> list:
        out: list = []
        for i, s in enumerate(body):
            t = type(s)
            if t is n.ToolSelect:
                out.append(s)
                self.t_seen = True
                if not any(type(x) is n.ToolChange for x in body[i + 1:]):
                    out.append(n.ToolChange(turret=True))
            elif t is n.ToolChange and not s.turret:
                if any(type(x) is n.ToolSelect for x in out):
                    out.append(n.ToolChange(turret=True))   # T2 M6: the T changed, the M6 nothing
                elif not self.t_seen:
                    out.append(s)        # before any T: the source's change of no tool selected
            else:
                out.append(s)
        return out
