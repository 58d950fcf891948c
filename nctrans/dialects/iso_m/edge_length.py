"""The tool length of a cutting edge (Sinumerik D) written as ISO G43 H / G49.

A source whose D selects a cutting edge (rules table option `edge_offsets`) applies the edge's
length with the D, or with a tool change, which brings edge D1 (`default_cutting_edge`); D0
switches it off (nctrans.interp.tool_edges). An ISO D is only the radius register, so without a
G43 H the ISO program would run without the length. This writes, after the block's own words:

- D0 -> G49;
- D<d>, d >= 2 -> G43 H<d>: an edge without data of its own is the machine's offset register of
  its number, which ISO H<d> reads (the same equivalence as ISO T0102 <-> Sinumerik T1 D2);
- D1 (or a tool change without D) -> G43 H<t>, t the active tool: edge 1 is the tool's own length,
  which ISO reads as the length register of the tool number; no tool changed yet: H1, the
  register the source reads too.

The edge's radius goes to ISO as the D word of the block that starts cutter compensation (G41/G42),
the only block LinuxCNC takes a D in ("D word with no G41 ... to use it"): edge d >= 2 as D<d>, D1
as the tool's register D<t>, D0 as D0. A D that changes the edge while compensation is on is
refused at its line (ISO would need G40 and a new G41 there).

What ISO cannot express is said at its line: a computed D or tool number (NC402, the length is
left out), a length under G18/G19 (NC401: ISO G43 acts along Z, the source edge along the axis
normal to the plane). Edge data a program writes ($TC_DP3[t,d]) is refused where it is written.
"""
from __future__ import annotations

from typing import Optional

from nctrans.ir import nodes as n


def edge_offsets(dialect: str) -> bool:
    """Whether a source dialect's D selects a cutting edge (length and radius)."""
    from nctrans.rules import option
    return bool(option(dialect, "edge_offsets"))


def _const(e) -> Optional[int]:
    if type(e) is n.Num and float(e.value).is_integer():
        return int(e.value)
    return None


class EdgeLengths:
    """Which tool is active in the emitted text, and the G43/G49 words a block's D needs."""

    def __init__(self, emitter) -> None:
        self.em = emitter
        self.selected = None            # the last T word's expression (None: no T yet)
        self.tool: Optional[int] = 0    # the active tool; 0: none changed yet; None: unknown
        # the length words in effect in the text ("G49" or the H word; None: not known here), so
        # a D that keeps the length writes none (LinuxCNC refuses G43 while G41/G42 is on)
        self.written: Optional[str] = "G49"
        self.edge = None                # the source's active edge expression (None: no D yet)
        self.comp = "off"               # cutter compensation in the source: off | on | None (unknown)

    def unknown(self) -> None:
        """A subprogram body: the active tool is the caller's."""
        self.tool = None
        self.written = None
        self.edge = self.comp = None

    def reached_from_elsewhere(self) -> None:
        """A jump target or structure: the length in effect may be another path's."""
        self.written = None

    def block_words(self, body) -> list[tuple[str, str]]:
        """The words that give the block's edge selection its length (none when it selects none)."""
        d_expr = None
        changed = False
        comp_before, comp_start = self.comp, False
        for s in body:
            t = type(s)
            if t is n.ToolSelect:
                self.selected = s.tool
            elif t is n.ToolChange:
                changed = True
            elif t is n.OffsetSelect and s.kind == "radius":
                d_expr = s.index
            elif t is n.ModeChange and s.group == "cutter_comp":
                self.comp = "off" if s.value == "off" else "on"
                comp_start = comp_start or s.value != "off"
        if changed:
            self.tool = _const(self.selected) if self.selected is not None else None
        if d_expr is not None or changed:
            self.edge = d_expr if d_expr is not None else n.Num(1.0)
        radius = self._radius_word(comp_start, comp_before, d_expr is not None or changed)
        if d_expr is None and not changed:
            return radius
        return self._length_words(d_expr) + radius

    def _radius_word(self, comp_start: bool, comp_before, edge_changed: bool) -> list[tuple[str, str]]:
        """The D word of a block that starts compensation: the active edge's radius register."""
        em = self.em
        if not comp_start:
            if edge_changed and comp_before == "on" and self.comp == "on":
                em.refuse("a cutting edge D changed while cutter compensation is on (ISO takes D "
                          "only with G41/G42)")
            return []
        if self.edge is None:
            return []                   # no D yet: as the source, compensation by no radius
        d = _const(self.edge)
        if d is None:
            return [("D", em.addr("D", self.edge))]
        from nctrans.dialects.emit import flat_radius_number
        if self.tool == 0 and d and not flat_radius_number(d):
            # no tool change before it: the edge of the tool the machine holds (the source's
            # analysis: NC123), which no ISO register names (register d is another radius)
            em.refuse(f"the radius of cutting edge D{d} with no tool change before it: an edge of "
                      "the tool the machine holds from before, which the program does not say and "
                      "no ISO register names")
            return []
        if d == 1:
            if self.tool is None:
                em.refuse("the radius of edge D1 of a tool not known here")
                return []
            d = self.tool or 1
        return [("D", f"D{d}")]

    def _length_words(self, d_expr) -> list[tuple[str, str]]:
        em = self.em
        d = _const(d_expr) if d_expr is not None else 1
        if d is None:
            what = "the tool length of a computed cutting edge D (G43 H left out)"
            if em.in_place:
                from .emitter import NotConvertible
                raise NotConvertible(what, "D=..")
            em.refuse(what)
            return []
        if d == 0:
            if self.written == "G49":
                return []
            self.written = "G49"
            return [em.code_word("tool_length", "off")]
        if d == 1:
            if self.tool is None:
                em.refuse("the tool length of edge D1 of a tool not known here (G43 H left out)")
                return []
            h = self.tool or 1
        else:
            h = d
        if self.written == f"H{h}":
            return []
        self.written = f"H{h}"
        if em.plane != "XY":
            em.lowered(f"tool length of edge D{d} written as G43 H{h}, which acts along Z; the "
                       f"source applies it along the axis normal to plane {em.plane}")
        else:
            em.lowered("tool length of a cutting edge D written as G43 H (D1: the tool's register)",
                       once="edge-length")
        return [em.code_word("tool_length", "plus"), ("H", f"H{h}")]
