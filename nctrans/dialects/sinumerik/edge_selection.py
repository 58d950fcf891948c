"""ISO tool length and radius registers written as the Sinumerik cutting edge D (issue 9).

An ISO mill applies a length register H (G43 plus, G44 minus, G49 off) and, under G41/G42, a radius
register D; a Sinumerik control takes both from one cutting edge D of the active tool, and a tool
change (M6) brings edge D1. The analysis of both dialects (nctrans.interp.tool_edges) reads a flat
D number d >= 2 as offset register d (length and radius: ISO T0102 <-> Sinumerik T1 D2), D1 as the
active tool's own data (ISO register t of tool t, the convention the Sinumerik -> ISO writer keeps
too: D1 -> G43 H<t>), D0 as no length and no radius.

So the Sinumerik D that gives what an ISO program has in force is:
- G49: D0, but only while cutter compensation is off (D0 also drops the radius);
- G43 with register k: D<k> for k >= 2, or D1 where k is the active tool's number;
- under G41/G42 the same edge must also carry the ISO radius register d: k and d must name one edge;
- G44 (negative length) has no edge: refused at its line.

`EdgeSelection` follows the ISO state block by block in source order and says which D word a block
needs. The divergence a Sinumerik M6 makes (it brings D1 while the ISO length stays what it was) is
left alone until a block could see it (a move along Z or another axis than X/Y, a cycle, a call, a
jump, a control structure, anything not known to be harmless): most ISO programs select G43 H<t>
before the first Z move, so `T3 M6 ... G43 Z95 H3` stays `T3 M6 ... Z95` with no D word at all.
Where no edge gives what the ISO program has, the block that needs it is refused (NC402) at its
line; a state the emitter cannot know statically (inside loops that change it, after a call or a
jump target) is only trusted while nothing changes it.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Optional, Union

from nctrans.dialects.emit import CONVERSION_MACHINE as _MACHINE
from nctrans.ir import nodes as ir

UNKNOWN = "unknown"
Known = Union[int, str, None]           # a number, UNKNOWN, or None (never set)

# statements that never let a control see the tool length (a Motion is judged by its axes)
_HARMLESS = (ir.ToolSelect, ir.ToolChange, ir.OffsetSelect, ir.Feed, ir.SpindleSpeed,
             ir.SpindleLimit, ir.Dwell, ir.Stop, ir.Message, ir.VarDecl)
# mode groups whose change lets a later block see the length differently: none but the canned cycle
_SEEING_GROUPS = frozenset(("cycle",))


class NoEdge(Exception):
    """No Sinumerik D gives the ISO state: the message says why."""


@dataclass
class _Iso:
    """What the ISO program has in force (UNKNOWN where the emitter cannot know it)."""
    tool: Known = 0                     # the tool in the spindle (0: none)
    selected: Known = None              # T of the next M6
    length: str = "off"                 # off | plus | minus | UNKNOWN
    register: Known = None              # the length register G43 applies (fixed when it acts)
    h: Known = None                     # the last H word
    radius: Known = None                # the last D word
    comp: str = "off"                   # off | on | UNKNOWN


def _number(e) -> Known:
    if isinstance(e, ir.Num) and float(e.value).is_integer():
        return int(e.value)
    return UNKNOWN


class EdgeSelection:
    """The ISO length / radius state and the Sinumerik edge written for it, one block at a time:
    feed the block's statements to `statement`, then ask `block_end` for the D word it needs."""

    def __init__(self, writes_radius: bool = False) -> None:
        self.iso = _Iso()
        # the program writes radius offset data itself (G10, #2401..): its registers are its own
        # (written as the flat $TC_DP6 of the D), not the held tool's unknown edge
        self.writes_radius = writes_radius
        self.edge: Known = 0            # the Sinumerik D in force (no D: nothing at power-on)
        self.in_step = True             # the edge gives what the ISO program has
        self.assumed: Optional[str] = None  # set when an edge was chosen by the machine's data
        self._machine = None
        self._reset_block()

    def _reset_block(self) -> None:
        self.explicit = False           # this block programs G43/G44/G49/H or G41/G42 with D
        self.length_word = False        # this block programs G43/G44 or H
        self.changed_tool = False
        self.sees = False

    # -------------------------------------------------------------- state the emitter cannot know
    def forget(self) -> None:
        """A subprogram's start, the point after a call, or a jump target: the ISO state is the
        caller's / the path's, and the edge written for it (every path keeps them in step)."""
        self.iso = _Iso(UNKNOWN, UNKNOWN, UNKNOWN, UNKNOWN, UNKNOWN, UNKNOWN, UNKNOWN)
        self.edge = UNKNOWN
        self.in_step = True

    def forget_changed_by(self, nodes: list, callee=None) -> None:
        """Entering a loop body (or leaving a structure, a call) whose statements change what is
        followed: those values depend on the path, the rest stays known. `callee(name)`: a
        called subprogram's body, or None when it is not known (it may change anything)."""
        self.forget_fields(touches(nodes, callee))

    def forget_fields(self, touched: set[str]) -> None:
        """Forget the followed values named ("tool", "length", "radius", "comp"); in step."""
        if not touched:
            return
        iso = self.iso
        if "tool" in touched:
            iso.tool = iso.selected = UNKNOWN
        if "length" in touched:
            iso.length, iso.register, iso.h = UNKNOWN, UNKNOWN, UNKNOWN
        if "radius" in touched:
            iso.radius = UNKNOWN
        if "comp" in touched:
            iso.comp = UNKNOWN
        self.edge = UNKNOWN
        self.in_step = True

    # -------------------------------------------------------------- one block
    def statement(self, s, cycle_active: bool) -> None:
        """Follow one ISO statement of the block being written."""
        iso = self.iso
        t = type(s)
        if t is ir.ToolSelect:
            iso.selected = _number(s.tool)
        elif t is ir.ToolChange:
            iso.tool = iso.selected
            self.changed_tool = True
        elif t is ir.OffsetSelect:
            if s.kind == "length":
                iso.h = _number(s.index)
                self.length_word = self.explicit = True
            else:
                iso.radius = _number(s.index)
                self.explicit = self.explicit or iso.comp != "off"
        elif t is ir.ModeChange and s.group == "tool_length":
            iso.length = s.value
            self.length_word = self.explicit = True
        elif t is ir.ModeChange and s.group == "cutter_comp":
            iso.comp = "off" if s.value == "off" else "on"
            self.explicit = self.explicit or s.value != "off"
        elif t is ir.ModeChange:
            self.sees = self.sees or s.group in _SEEING_GROUPS
        elif t is ir.Motion:
            self.sees = self.sees or cycle_active or _sees_length(s)
        elif t is ir.ProgramEnd and s.kind != "restart":
            pass                        # nothing runs after it
        elif not isinstance(s, _HARMLESS):
            self.sees = True

    def computed_g(self, codes: Optional[tuple]) -> None:
        """A computed G word (ISO G#143) that selects one of `codes` (None: not known): a cutter
        compensation code is that mode, a tool-length code makes the length unknown."""
        numbers = set()
        for c in codes or ():
            try:
                numbers.add(int(float(str(c).upper().lstrip("G"))))
            except ValueError:
                numbers.add(None)
        if codes is None or None in numbers:
            self.iso.comp = self.iso.length = UNKNOWN
        elif numbers & {40, 41, 42}:
            self.iso.comp = ("on" if numbers <= {41, 42} else "off" if numbers == {40} else UNKNOWN)
        if numbers & {43, 44, 49}:
            self.iso.length = UNKNOWN
        self.explicit = self.sees = True

    def block_end(self, sees: bool = False) -> Optional[int]:
        """The D number this block must write (None: none), after its statements were fed;
        raises NoEdge when the block needs an edge that no D gives. `sees`: the block is a jump
        target or otherwise lets the control see the length whatever it holds."""
        iso = self.iso
        explicit, sees = self.explicit, self.sees or sees
        if self.length_word and iso.length == "plus":
            # G43 fixes its register when it acts: H, else the tool in the spindle
            iso.register = iso.h if iso.h is not None else iso.tool
        if self.changed_tool:
            self.edge, self.in_step = 1, False      # M6 brings D1 of the new tool
        elif explicit:
            self.in_step = False
        self._reset_block()
        if self.in_step or not (explicit or sees):
            return None                 # in step, or a divergence nothing sees yet
        wanted = self.wanted()          # raises NoEdge
        if self.edge in wanted:
            self.in_step = True
            return None
        self.edge = 1 if 1 in wanted else min(wanted)
        self.in_step = True
        return self.edge

    def wanted(self) -> set[int]:
        """The D numbers that give the ISO state (at least one), or NoEdge saying why. By the edge
        numbering first (true on any machine); else by the values of the machine the conversion
        is for (`assumed` says so: the NC405 warning)."""
        self.no_tool_radius()           # no machine data makes that edge's radius known
        try:
            return self.by_numbering()
        except NoEdge as why:
            found = self.by_data()
            if not found:
                raise
            self.assumed = str(why)
            return found

    def by_data(self) -> set[int]:
        """The edges whose length (and, under compensation, radius) on the conversion's machine
        equal what the ISO program applies; empty when none does or the state is not known."""
        iso = self.iso
        get = _MACHINE.get()
        if iso.length not in ("off", "plus") or iso.comp == UNKNOWN or get is None:
            return set()
        if iso.length == "plus" and not isinstance(iso.register, int):
            return set()
        if iso.comp == "on" and not isinstance(iso.radius, (int, type(None))):
            return set()
        m = self._conversion_machine()
        if m is None:
            return set()
        length = m.length_offset(iso.register) if iso.length == "plus" else 0.0
        radius = m.radius_offset(iso.radius) if iso.comp == "on" and iso.radius else 0.0
        tool = self.iso.tool
        edges = {0, 1} | {x for x in (iso.register, iso.radius) if isinstance(x, int) and x >= 2}
        found = set()
        for e in edges:
            if e == 1 and (tool == UNKNOWN or tool is None):
                continue
            if iso.comp == "on" and e and tool in (0, None) and e not in m.radius_offsets:
                continue                # the radius of an edge of no tool changed: not known
            el, er = _edge_values(m, tool, e)
            if abs(el - length) < 1e-9 and (iso.comp != "on" or abs(er - radius) < 1e-9):
                found.add(e)
        return found

    def _conversion_machine(self):
        """The machine the conversion is for (None outside one, or where its file does not load:
        said where it is used)."""
        get = _MACHINE.get()
        if self._machine is None and get is not None:
            try:
                self._machine = get()
            except Exception:
                return None
        return self._machine

    def no_tool_radius(self) -> None:
        """NoEdge where compensation is on by an ISO radius register d and no tool change
        precedes it: a Sinumerik D<d> is an edge of the tool the machine holds from before, whose
        radius the program does not say (the analysis: NC123, radius 0), unless the machine file
        gives d as a flat offset number (radius_offsets)."""
        iso = self.iso
        if iso.comp != "on" or iso.tool not in (0, None) or iso.radius in (0, None, UNKNOWN) \
                or self.writes_radius:
            return
        m = self._conversion_machine()
        if m is not None and iso.radius in m.radius_offsets:
            return
        raise NoEdge(f"cutter radius compensation by ISO radius register D{iso.radius} with no tool "
                     f"change before it: register {iso.radius} holds its radius whatever tool is in "
                     f"the spindle, but a Sinumerik D{iso.radius} is an edge of the active tool, here "
                     "the one the machine holds from before, which the program does not say")

    def by_numbering(self) -> set[int]:
        iso = self.iso
        if iso.length == "minus":
            raise NoEdge("negative tool length compensation (G44) has no Sinumerik cutting edge: "
                         "a D edge only adds its length")
        if iso.length == UNKNOWN:
            raise NoEdge("the tool length compensation in force here is not known where the "
                         "block is written (set inside a loop, a branch or before a call)")
        if iso.length == "off":
            if iso.comp == "off" or (iso.comp == "on" and iso.radius in (0, None)):
                return {0}
            if iso.comp == "on":
                raise NoEdge(f"cutter radius compensation by radius register D{iso.radius} with no "
                             f"tool length on (G49): a Sinumerik cutting edge D{iso.radius} also "
                             f"applies length register {iso.radius}")
            raise NoEdge("G49 is written as D0, which on Sinumerik also ends cutter radius "
                         "compensation (not known to be off here)")
        length = self._edges(iso.register, "length")
        if iso.comp == "off":
            return length
        if iso.comp == UNKNOWN:
            # on or off, an edge that carries both registers gives what the ISO program has
            try:
                both = length & self._edges(iso.radius, "radius")
            except NoEdge:
                both = set()
            if both:
                return both
            raise NoEdge("whether cutter radius compensation is on is not known where the block "
                         "is written, so the cutting edge cannot be chosen")
        both = length & self._edges(iso.radius, "radius")
        if not both:
            raise NoEdge(f"length register H{iso.register} and radius register "
                         f"D{iso.radius if iso.radius is not None else 0} are different Sinumerik "
                         "cutting edges: one D gives both")
        return both

    def _edges(self, register: Known, what: str) -> set[int]:
        tool = self.iso.tool
        if register is None and what == "radius":
            register = 0                # G41/G42 with no D yet: compensation by no radius
        if register is None:
            raise NoEdge(f"no {what} offset register is selected")
        if register == UNKNOWN:
            raise NoEdge(f"the {what} offset register is computed or not known where the block "
                         "is written")
        found = {register} if register >= 2 or register == 0 else set()
        if tool != UNKNOWN and (register == tool or (register == 1 and tool in (0, None))):
            found.add(1)
        if not found:
            raise NoEdge(f"{what} register {register} is edge D1 of tool {register} only, and "
                         f"tool {tool if tool != UNKNOWN else '(not known)'} is in the spindle")
        return found

    def snapshot(self) -> "EdgeSelection":
        copy = EdgeSelection.__new__(EdgeSelection)
        copy.__dict__.update(self.__dict__)
        copy.iso = replace(self.iso)
        return copy


def _edge_values(m, tool, e: int) -> tuple[float, float]:
    """(length, radius) of Sinumerik edge D<e> of `tool` on machine `m`, as the analysis reads it
    (nctrans.interp.tool_edges: D1 the tool's own data unless a flat register 1 is given)."""
    if e == 0:
        return 0.0, 0.0
    own = m.tool(tool) if e == 1 and isinstance(tool, int) and tool else None
    length = (m.length_offsets[e] if e in m.length_offsets else
              float(own.length or 0.0) if own is not None else m.length_offset(e))
    radius = (m.radius_offsets[e] if e in m.radius_offsets else
              float(own.radius or 0.0) if own is not None else m.radius_offset(e))
    return float(length), float(radius)


def _sees_length(m: ir.Motion) -> bool:
    """A move that can show the tool length: one with a tool-axis (or any non-X/Y) word, machine
    coordinates, polar or indirect axes."""
    return (m.machine_coords or m.polar is not None or m.indirect is not None
            or any(a not in ("X", "Y") for a in m.target))


def touches(nodes: list, callee=None, seen: Optional[set] = None) -> set[str]:
    """Which followed values ("tool", "length", "radius", "comp") the statements of `nodes` change, with
    those of the subprograms they call (`callee(name)` -> body, None when unknown: everything)."""
    from nctrans.interp.computed_g import is_computed_g
    from nctrans.ir.walk import walk
    found: set[str] = set()
    seen = set() if seen is None else seen
    for node in walk(nodes):
        if type(node) is not ir.Block:
            continue
        for s in node.body:
            t = type(s)
            if t in (ir.ToolSelect, ir.ToolChange):
                found.add("tool")
            elif t is ir.OffsetSelect:
                found.add("length" if s.kind == "length" else "radius")
            elif t is ir.ModeChange and s.group == "tool_length":
                found.add("length")
            elif t is ir.ModeChange and s.group == "cutter_comp":
                found.add("comp")
            elif t is ir.Passthrough and is_computed_g(s):
                # G#143: written only where it names codes of one Sinumerik group, which holds
                # no tool length code (nctrans.lower.computed_g); else refused at its line
                found.add("comp")
            elif t is ir.SubCall:
                # a program this file does not hold is an opaque event, to the analysis of
                # either dialect as to equiv: the state it leaves is the one it found
                body = callee(s.name) if callee is not None and s.name and s.target is None else None
                if body is not None and s.name.upper() not in seen:
                    seen.add(s.name.upper())
                    found |= touches(body, callee, seen)
    return found


def _label(x) -> str:
    t = str(x).upper()
    return str(int(t)) if t.isdigit() else t


def jump_regions(nodes: list, callee=None) -> dict[str, set[str]]:
    """Label / block number -> the followed values a path that jumps to it may have changed
    differently from the path falling through: what the nodes between each jump and its target
    change (a forward jump skips them, a backward jump repeats them). A computed jump may land on
    any numbered block: everything the unit changes."""
    from nctrans.ir.walk import walk
    where: dict[str, int] = {}
    jumps: list[tuple[int, str]] = []
    for i, top in enumerate(nodes):
        for x in walk([top]):
            if type(x) is not ir.Block:
                continue
            for lab in (x.label, x.number):
                if lab is not None:
                    where.setdefault(_label(lab), i)
            for st in x.body:
                if type(st) is ir.Goto:
                    jumps.append((i, "*" if st.computed is not None else _label(st.target)))
    out: dict[str, set[str]] = {}
    everything = None
    for i, target in jumps:
        if target == "*":
            everything = everything if everything is not None else touches(nodes, callee)
            for lab in where:
                out.setdefault(lab, set()).update(everything)
            continue
        j = where.get(target)
        if j is None:
            continue
        out.setdefault(target, set()).update(touches(nodes[min(i, j):max(i, j) + 1], callee))
    return out


def writes_radius_data(program) -> bool:
    """Whether `program` writes tool radius offset data anywhere: G10 (a DataSetting of a radius
    kind) or a numbered variable of its dialect's radius registers (rules numbered_variables with
    source "tool_radius" or wear_of "radius")."""
    from nctrans.interp.sysvars import entries
    from nctrans.ir.walk import walk
    from nctrans.plainrun import RUNS
    spans = [(int(e["first"]), int(e["last"])) for e in entries(program.dialect)
             if e.get("source") == "tool_radius" or e.get("wear_of") == "radius"]
    units = [program.body, *(sub.body for sub in program.subprograms.values())]
    for body in units:
        # a compact body's runs of plain blocks are text not walked here: what they write is not
        # seen (an ISO register with no tool change is then refused, never guessed)
        body = [x for x in getattr(body, "items", body) if type(x) not in RUNS]
        for node in walk(body):
            if type(node) is not ir.Block:
                continue
            for s in node.body:
                t = type(s)
                if t is ir.DataSetting and "radius" in str(s.kind):
                    return True
                if t is ir.Assign and type(s.target) is ir.Var and isinstance(s.target.key, int) \
                        and any(a <= s.target.key <= b for a, b in spans):
                    return True
    return False
