"""ISO turning front end: the ISO-family front end (iso_m.frontend) with the lathe's table and words.

What differs from milling, and nothing else:
- G codes are looked up through the table's G-code system (A by default; B and C rename codes);
- U, W, H are incremental X, Z, C (system A);
- T0101 selects tool 01 with offset 01 and changes to it at once (no M06);
- G50 sets the coordinate system (X Z) and the maximum spindle speed (S);
- G70-G76 and the modal box cycles G90/G92/G94 become CycleCall nodes, their words named by the
  table's [options.cycle_words]; a G71/G72/G73/G74/G75/G76 block without P Q (or X Z) is the
  parameter block of the Fanuc two-block form.
"""
from __future__ import annotations

import re
from typing import Any, Optional

from nctrans.diagnostics import Diagnostic
from nctrans.dialects.iso_m import frontend as iso
from nctrans.ir.nodes import (AxisValue, CycleCall, HomeReturn, Motion, Num, OffsetSelect,
                              SetPosition, SpindleLimit, ToolChange, ToolSelect)
from nctrans.rules import normalise_code

INCREMENTAL = {"U": "X", "W": "Z", "H": "C"}
BOX_CYCLES = frozenset(("box_turn", "box_thread", "box_face"))
# the first block of a two-block cycle is told apart by what it lacks
_SECOND_BLOCK = {"rough_turn": "PQ", "rough_face": "PQ", "pattern_repeat": "PQ",
                 "face_peck": "XZUW", "groove_peck": "XZUW", "thread_multi": "XZUW"}
_KEEP = frozenset("FSTMN")


class TurningLowering(iso.Lowering):
    dialect = "iso-t"
    table_name = "iso-t"
    code_kind = "an ISO turning code"

    def __init__(self, file: str, diags: list[Diagnostic]):
        super().__init__(file, diags)
        opts = self.table.options
        self.system = str(opts.get("gcode_system", "A"))
        self.renames = dict(opts.get("gcode_systems", {}).get(self.system, {}))
        self.cycle_words = opts.get("cycle_words", {})
        self.increment_words = opts.get("cycle_increment_words", {})
        self.box: Optional[str] = None          # modal G90/G92/G94 as written
        self.box_params: dict = {}              # its last words: a repeat block changes some
        self.repeat = False
        self._line = 0
        self.g_handlers["turning_cycle"] = self._g_turning
        self.nonmodal_handlers["coordinate_setting"] = self._nm_g50

    def code(self, letter: str, text: str):
        if letter == "G" and self.renames:
            try:
                target = self.renames.get(normalise_code("G", text.lstrip("+")))
            except ValueError:
                target = None
            if target is not None:
                return self.table.lookup(target)
        return super().code(letter, text)

    plain_runs = False              # U/W are increments, T0101 selects and changes: no line is plain

    @classmethod
    def program_defaults(cls, table) -> dict:
        """The family's power-on modes; the program starts in diameter mode when X is the
        diameter axis (the table's diameter_axis)."""
        defaults = super().program_defaults(table)
        if table.options.get("diameter_axis", "X") == "X":
            defaults["diameter"] = "diameter"
        return defaults

    def hot(self, words: list):
        return None                 # every block goes through lower(): U/W, T and modal cycles

    # ------------------------------------------------------------------ blocks
    def lower(self, items: list, line: int):
        self._line = line
        items = self._modal_box(items)
        number, body, structure, unknown = super().lower(items, line)
        if body:
            body = self._lathe_statements(body, line)
        return number, body, structure, unknown

    def _modal_box(self, items: list) -> list:
        """G90/G92/G94 are modal (group 01): a later block of axis words repeats the cycle."""
        written = False
        axes = False
        for it in items:
            if it[0] == "G" and len(it) == 2 and type(it[1]) is str:
                rule = self.code("G", it[1])
                if rule is None:
                    continue
                if rule.group == "turning_cycle" and rule.value in BOX_CYCLES:
                    self.box = it[1]
                    written = True
                elif rule.group == "motion":
                    self.box = None
                    written = True
                elif rule.group in ("turning_cycle", "nonmodal"):
                    written = True
            elif it[0] in "XZUW":
                axes = True
        self.repeat = False
        if self.box is None or written or not axes:
            return items
        self.repeat = True
        at = 1 if items and items[0][0] == "N" else 0
        return items[:at] + [("G", self.box)] + items[at:]

    def _lathe_statements(self, body: list, line: int) -> list:
        out = []
        for s in body:
            t = type(s)
            if t is Motion:
                s.target = self._axes(s.target, line)
            elif t is SetPosition:
                s.target = self._axes(s.target, line)
            elif t is HomeReturn:
                s.via = self._axes(s.via, line)
            elif t is ToolSelect:
                out.extend(self._tool(s, line))
                continue
            out.append(s)
        return out

    def _axes(self, target: dict, line: int) -> dict:
        """U/W/H -> incremental X/Z/C (system A; B and C program increments with G91)."""
        if self.system != "A" or not (target.keys() & INCREMENTAL.keys()):
            return target
        out = {}
        for k, av in target.items():
            axis = INCREMENTAL.get(k)
            if axis is None:
                if k in out:
                    continue
                out[k] = av
                continue
            if axis in target:
                self.diags.append(Diagnostic("NC131", "error", f"{axis} and {k} in one block: the "
                                             f"axis is programmed twice", self.file, line))
                continue
            out[axis] = AxisValue(av.value, "inc")
        return out

    def _tool(self, s: ToolSelect, line: int) -> list:
        """T0101: tool 01, offset 01; T1212 likewise; a change happens at once on a turret."""
        v = s.tool
        if type(v) is not Num or v.text is None or not v.text.lstrip("+").isdigit():
            self.warn_once("t-expr", "NC232", "warning", "T word by expression: taken as the tool "
                           "number, with no offset split", line)
            return [s, ToolChange(turret=True)]
        digits = v.text.lstrip("+")
        num = int(digits)
        if len(digits) <= 2:
            tool, offset = num, num
        else:
            tool, offset = divmod(num, 100)
        return [ToolSelect(Num(float(tool), None)), ToolChange(turret=True),
                OffsetSelect("radius", Num(float(offset), None))]

    # ------------------------------------------------------------------ G handlers
    def _nm_g50(self, b, rule, text: str) -> None:
        s = b.vals.pop("S", None)
        if s is not None:
            b.out.append((iso.B_SPEED, SpindleLimit(self.num("S", s))))
        if any(k in b.vals for k in "XZUWC"):      # G50 S alone sets no position
            b.owner = "set_position"
            b.owner_rule = rule

    def _g_turning(self, b, rule, text: str) -> None:
        """A turning cycle block: its words become the CycleCall's parameters."""
        kind = rule.value
        vals = b.vals
        need = _SECOND_BLOCK.get(kind)
        form = kind
        if need is not None and not any(k in vals for k in need):
            form = kind + "_first"
        names = self.cycle_words.get(form, {})
        scaled = set(self.increment_words.get(form, ()))
        inc = float(self.table.options.get(
            "least_increment_inch" if self.units == "inch" else "least_increment_mm", 0.001))
        params: dict[str, Any] = {}
        for letter in [k for k in vals if k not in _KEEP]:
            v = vals.pop(letter)
            key = names.get(letter)
            if key is None:
                self.warn_once(f"cycle-word:{form}:{letter}", "NC232", "warning",
                               f"G{text}: word {letter} has no meaning in this cycle; ignored",
                               self._line)
                continue
            value = self.num(letter, v)
            if letter in scaled and type(v) is str and "." not in v:
                value = Num(value.value * inc, v)
            params[key] = value
        if kind in BOX_CYCLES:
            if self.repeat:                     # X36. after G90 X40. Z-30.: the rest as before
                for a, b_ in (("x", "x_inc"), ("z", "z_inc")):
                    if a in params or b_ in params:
                        self.box_params.pop(a, None)
                        self.box_params.pop(b_, None)
                params = {**self.box_params, **params}
            self.box_params = dict(params)
        b.out.append((iso.B_MOTION, CycleCall(kind, params, False,
                                              "parameters" if form != kind else "")))


# G70-G73 (G72-G75 in G-code system C) read their contour blocks N<P>..N<Q> from the whole body
# (nctrans.interp.lathe): a program with any G7x word is parsed whole. Matches in comments only
# cost the streaming.
_WHOLE_BODY = re.compile(r"G[ \t]*0*7[ \t]*\d", re.IGNORECASE)


def parse_program(text: str, file: str = "<stdin>"):
    """Parse ISO turning text; the program starts in diameter mode (the table's diameter_axis,
    TurningLowering.program_defaults)."""
    return iso.parse_program(text, file, TurningLowering)


def parse_stream(text: str, file: str = "<stdin>"):
    """The ISO family's lazy parse (iso_m.frontend.parse_stream) for turning programs that run
    straight through; None when a contour cycle needs the whole body."""
    if _WHOLE_BODY.search(text) is not None:
        return None
    return iso.parse_stream(text, file, TurningLowering)
