"""ISO milling emitter: IR Program -> normalised ISO text.

Normal form: `%`, the O number, N numbers kept, comments in parentheses, one G per modal group,
a decimal point on every address of the conversion list (X Y Z U V W A B C I J K Q R F, spec §2.3)
so the text means the same under every decimal-notation profile, macro B expressions and control
flow re-emitted, Passthrough text verbatim. parse(emit(parse(x))) == parse(x) up to spans and
number spellings (tests/test_iso_roundtrip.py).

Constructs from other dialects get an ISO equivalent where one exists, reported as NC401 (info):
named variables and R parameters -> common variables, FOR/REPEAT/LOOP/CASE -> WHILE/IF..GOTO,
messages -> `(MSG, ...)` comments, labels -> fresh N numbers, named subprograms -> O numbers
(O9000..O9999 from the name, written after the main program as O blocks ending M99), PROC
parameters -> G65 Type I arguments read as #1..#26 in the body (the subprogram's DEF scalars take
the locals left over, so such subprograms are always called with G65: their own local level),
numeric arrays with constant dimensions -> a row-major block of common variables above the
R parameters, R[expr] -> #[500+expr], three-point arcs with constant points -> G2/G3 with the
centre computed here, additive translations (ATRANS) with constant values and no rotation, scale or
mirror active -> G52 with the accumulated shift. Where none exists the construct is reported as
NC402 (error) naming it and its source line, and left out of the text as a comment.

Not lowered, on purpose: Sinumerik G500 (work_offset "G53", no settable offset) -- ISO has no
modal "no work offset" (G53 is one-shot machine coordinates, and G54 is only the same when its
offset happens to be zero); additive rotation/scale/mirror (G68/G51 replace, they do not add);
calls of subprograms that are not in the program (the ISO text would call an O number nothing
defines); by-reference (VAR) and array parameters (G65 passes values only).
"""
from __future__ import annotations

import itertools
import math
from typing import Any, Optional

from nctrans import spilled
from nctrans import alarm_numbers
from nctrans.diagnostics import at_span
from nctrans.interp import corner_elements
from nctrans.interp.frames import PLANE_AXES
from nctrans.dialects.emit import (Emitter, NotExpressible, Spelling, flat_forms, flat_radius_number,
                                   format_number, rewrites)
from nctrans.ir import nodes as n
from nctrans.dialects.tool_timing import ToolTiming
from nctrans.ir import walk
from nctrans.ir.walk import constant
from nctrans.plainrun import RUNS, PlainRun, run_blocks

from . import per_word
from . import plan as pl
from .edge_length import EdgeLengths, edge_offsets
from .cycles import CycleRefused, IsoCycle, iso_cycle, pattern_positions

__all__ = ["IsoEmitter", "IsoSpelling", "NotExpressible", "format_number", "format_expr",
           "format_value", "emit_program"]

POINT_LETTERS = frozenset("XYZUVWABCIJKQRF")
AXES = "XYZABCUVW"


class IsoSpelling(Spelling):
    """Macro B expressions (operators and functions from rules/iso-m.toml [expressions]); without
    an emitter only #n variables can be written."""
    syntax_table = "iso-m"

    def var_text(self, v: n.Var) -> str:
        if v.space == "num":
            if v.key is None and v.indices:
                return f"#[{self.expr(v.indices[0])}]"
            return f"#{v.key}"
        return self.named_var(v)

    def named_var(self, v: n.Var) -> str:
        raise NotExpressible(f"variable {v.space}:{v.key}")

    def value(self, e: Any) -> str:
        """An address value: numbers and variables as they are, anything else in brackets."""
        if type(e) is n.Num:
            return format_number(e.value)
        if type(e) is n.Var:
            return self.var_text(e)
        return f"[{self.expr(e)}]"

    @rewrites(n.Binary, "pow")
    def _pow(self, e: n.Binary) -> tuple[str, int]:
        return self.expr(n.Func("pow", [e.left, e.right])), self.syntax.atom

    @rewrites(n.Binary, "div")
    def _div(self, e: n.Binary) -> tuple[str, int]:
        return self.expr(n.Func("fix", [n.Binary("/", e.left, e.right)])), self.syntax.atom

    @rewrites(n.Unary, "not")
    def _not(self, e: n.Unary) -> tuple[str, int]:
        return f"[{self.expr(e.operand)}]{self.syntax.binary['=='].text}0", self.syntax.binary["=="].prec

    @rewrites(n.Func, "atan2", "atan")
    def _atan(self, e: n.Func) -> tuple[str, int]:
        atan = self.syntax.functions["atan"]
        if e.name.lower() == "atan2":
            if len(e.args) != 2:
                raise NotExpressible(f"function {e.name.upper()}")
            return f"{atan}[{self.expr(e.args[0])}]/[{self.expr(e.args[1])}]", self.syntax.atom
        # bracketed, so a following "/[" is not read as ATAN[a]/[b]
        return f"[{self.call(e)}]", self.syntax.atom

    @rewrites(n.Func, "minval", "maxval")
    def _min_max(self, e: n.Func) -> tuple[str, int]:
        name = e.name.lower()
        if len(e.args) != 2:
            raise NotExpressible(f"function {e.name.upper()}")
        a, b = e.args
        total = n.Binary("-" if name == "minval" else "+", n.Binary("+", a, b),
                         n.Func("abs", [n.Binary("-", a, b)]))
        self.lowered(f"{name.upper()} written as an ABS expression")
        return self.term(n.Binary("/", total, n.Num(2.0)))


_BARE = IsoSpelling()


def format_expr(e: Any, ctx: Optional[IsoSpelling] = None) -> str:
    """An IR expression in macro B syntax (brackets only where precedence needs them)."""
    return (ctx or _BARE).expr(e)


def format_value(e: Any, ctx: Optional[IsoSpelling] = None) -> str:
    """An address value: numbers and variables as they are, anything else in brackets."""
    return (ctx or _BARE).value(e)


class _Line:
    """Words of one output line, with the letters already used (a repeated letter starts a new line)."""
    __slots__ = ("words", "used")

    def __init__(self):
        self.words: list[str] = []
        self.used: set[str] = set()


class _Lines(list):
    """Words a statement writes on lines of their own (one list of words per line)."""


def _const_int(e) -> Optional[int]:
    """A constant whole number (a tool or offset number), else None."""
    if type(e) is n.Num and float(e.value).is_integer():
        return int(e.value)
    return None


class NotConvertible(NotExpressible):
    """A facility of the source control ISO has no counterpart for (text the IR keeps verbatim:
    synchronized actions, interrupts, cam tables; a system variable with no ISO number). In a
    subprogram file, which cannot be lowered to plain motion, it is refused at its place only: an
    alarm stops the ISO control there (NC412) and the rest of the file keeps its structure."""

    def __init__(self, reason: str, construct: str):
        super().__init__(reason)
        self.construct = construct


class IsoEmitter(IsoSpelling, Emitter):
    """IR -> text for a dialect of the ISO family. dialect: the name of programs (and passthrough
    text) that are already this dialect's own; table: the rules table G/M codes are spelled from.
    ISO-family dialects subclass it with their names and override what they spell differently."""
    dialect = "iso-m"
    table_name = "iso-m"
    target_text = "ISO milling"          # NC402 wording: "<target_text> cannot express ..."
    lowered_for = "ISO"
    # a milling control applies a tool length along Z (G43 H); a lathe's is not (iso-t)
    writes_edge_lengths: bool = True
    # a turret T word naming the tool already in place (ISO turning T0111 after T0101) changes only
    # the offset: written without T.. M6, which would change the tool (and stop the spindle) here
    drops_staying_turret: bool = True
    turret_tool: Optional[int] = None
    # its T word changes the tool wherever it is written (ISO turning's turret), whatever the
    # machine's tool_change.by_t_word (nctrans.dialects.tool_timing)
    t_word_is_turret: bool = False
    # power-on modes a program from another control relies on, written out where ours differ
    power_on_groups: tuple[str, ...] = ("feed_mode", "plane")

    def __init__(self, program: n.Program):
        super().__init__(program)
        self.out = spilled.output_lines()      # to a temporary file once many (spilled.OutputLines)
        self.var_map: dict = {}
        self.next_common = 100
        self.next_label = 90000
        self.used_numbers = set()
        self.unread_runs: list[PlainRun] = []     # runs whose block numbers are not in used_numbers yet
        self.depth = 0
        # distance mode in source order, so a one-block G91 (incremental reference-point
        # approach from other dialects) can be followed by the G90 that restores it
        self.restore_absolute = False
        self.restore_arc_incremental = False
        # per-word AC/IC (nctrans.dialects.iso_m.per_word): whether the G90/G91 in force is known
        # here on every path (a main program starts under G90; a place reached from elsewhere
        # forgets it), and the mode a one-block switch must restore after its block
        self.distance_known = per_word.starts_as_main(program)
        self.restore_distance: Optional[str] = None
        self.rotation_plane: Optional[str] = None     # the plane a rotation about a named axis holds
        self.arc_distance = "incremental"
        # the plan: labels, locals and O numbers per unit (None = the main program)
        self.unit: Optional[str] = None
        self.plans: dict[Optional[str], pl.UnitPlan] = {}
        self.targets: dict[Optional[str], set[str]] = {}
        self.sub_numbers: dict[str, int] = {}
        self.arrays: dict[tuple, pl.ArrayPlan] = {}
        self.undeclared: set[str] = set()      # arrays used but not declared (NC410 once each)
        self.in_place = False                  # a subprogram file: NotConvertible refused in place
        self.strings: dict[int, str] = {}       # string number -> the string argument it stands for
        # (unit, array parameter) -> its dimensions
        self._slot_dims: dict[tuple, list[int]] = {
            (key, prm.name.upper()): list(prm.dims)
            for key, sub in program.subprograms.items() for prm in sub.params if prm.dims}
        top_r, dynamic_r = pl.max_r_used(program)
        self.next_array = 900 if dynamic_r else 500 + top_r + 1
        # undeclared (GUD) arrays indexed at run time: a row-major block each, laid out here
        self.global_arrays: dict[str, pl.ArrayPlan] = {}
        self.guards: list[str] = []         # index checks the next line written must run first
        if program.dialect != self.dialect:
            self._lay_out_globals(program)
        # plane and three-point mode, for arcs computed from the constant points (self.pos)
        self.plane = "XY"
        # X words of the source are diameters (ISO-T, Sinumerik DIAMON): a milling X is a radius
        self.diameter = False
        self.cip_mode = False
        # G33: ISO writes the thread lead as F, which is then the modal feed; the feed the source
        # programmed last is written again on the next feed move after the thread
        self.thread_mode = False
        # ... except in plain motion for LinuxCNC (--flatten --profile linuxcnc: rules iso-m
        # [options.flat_motion]): its G33 takes the lead as K and refuses F; see _thread
        self.lead_as_k = bool((program.meta or {}).get("flattened_from")) \
            and flat_forms(self.dialect).get("thread_lead") == "K"
        self.last_feed: Optional[str] = None
        self.feed_clobbered = False
        # the thread start angle (Sinumerik SF=, ISO Q): a start angle written outside a thread
        # block waits for the next one; a constant one is written again on each later thread
        # block (a Fanuc's G32 Q holds for its block only), see _thread_start
        self.start_pending: Optional[n.Expr] = None
        self.start_repeat: Optional[float] = None
        # named cycles written as ISO canned cycles (nctrans.dialects.iso_m.cycles): the modal one
        # (MCALL) and whether its G8x mode is on; motion mode, units and feed as programmed
        self.named_cycle: Optional[IsoCycle] = None
        self.named_active = False
        self.motion_mode: Optional[str] = None
        self.units_mm = True
        self.feed_expr = None
        # a source's cutting-edge D (Sinumerik) applies a tool length: written as G43 H / G49
        # (not in a flattened program: its coordinates hold the length already)
        self.edge_lengths = (EdgeLengths(self) if self.writes_edge_lengths
                             and program.dialect != self.dialect and edge_offsets(program.dialect)
                             and not (program.meta or {}).get("flattened_from") else None)
        # the tool in the spindle as the text has it (0: none changed yet; None: not known here)
        # and the last T word, for a source that switches the length on without naming a
        # register (Fagor D: the active tool's offset), see _length_register
        self.spindle_tool: Optional[int] = 0
        self.selected_tool = None
        # a source whose D is a corrector of the active tool with no edge model of its own (Fagor):
        # its D1 is the tool's own radius, ISO register D<t> of tool t (the machine file's
        # convention); the tool is followed through T and M6 (0: none changed yet, None: unknown)
        from nctrans.interp.comp_radius import offsets_of_active_tool
        self.tool_relative = (self.edge_lengths is None and program.dialect != self.dialect
                              and offsets_of_active_tool(program.dialect)
                              and not (program.meta or {}).get("flattened_from"))
        self.rel_selected: Optional[int] = None
        self.rel_tool: Optional[int] = 0
        # the tool words moved to where this control's words change the tool as the source's do
        self.tool_timing = ToolTiming(program.dialect, self.dialect, self.t_word_is_turret)
        # this control's M6 stops the spindle (rules tool_change.stops_spindle: Haas, LinuxCNC)
        # where the source's change does not: the direction in force is written again after it
        self.respin = self.writes_m6_stop(program.dialect)
        self.spindle_turning: Optional[str] = None       # "cw" / "ccw" where known to turn

    def writes_m6_stop(self, source: Optional[str]) -> bool:
        """Whether this control's tool change stops the spindle and the source's does not, on the
        conversion's machine (nctrans.interp.run_checks.tool_change_rules)."""
        if source == self.dialect or (self.program.meta or {}).get("flattened_from"):
            return False        # (plain motion writes the direction again itself: lower/flatten)
        from nctrans.dialects.emit import CONVERSION_MACHINE
        from nctrans.interp.run_checks import tool_change_rules
        from nctrans.rules import load_table
        get = CONVERSION_MACHINE.get()
        try:
            machine = get() if get is not None else None
            ours = tool_change_rules(machine, dict(load_table(self.table_name).options))[1]
            theirs = tool_change_rules(machine, dict(load_table(source).options))[1] if source else True
        except Exception:       # no table of that name (a test dialect) or a machine that fails
            return False
        return ours and not theirs

    def forget(self) -> None:
        super().forget()
        self.spindle_turning = None
        self.distance_known = False
        self.spindle_tool = None
        self.turret_tool = None
        if getattr(self, "tool_timing", None) is not None:
            self.tool_timing.forget()
        if getattr(self, "edge_lengths", None) is not None:
            self.edge_lengths.reached_from_elsewhere()

    # A string or a function ISO has no counterpart for (SPRINT, GETT, ...) is another control's
    # facility, not a spelling gap: in a subprogram file it is refused at its place (NC412).
    def string(self, e: n.Str) -> str:
        raise NotConvertible(f"the string value {e.value!r} (ISO variables hold numbers only)",
                             f'"{e.value}"')

    def call(self, e: n.Func) -> str:
        if e.name.lower() not in self.syntax.functions:
            raise NotConvertible(f"function {e.name.upper()}", f"{e.name.upper()}(..)")
        return super().call(e)

    def _lay_out_globals(self, program: n.Program) -> None:
        uses = pl.undeclared_arrays(program)
        declared = sum(math.prod(s.dims) for b in walk.blocks(program.body) for s in b.body
                       if type(s) is n.VarDecl and s.dims and all(isinstance(d, int) for d in s.dims))
        declared += sum(math.prod(s.dims) for sub in program.subprograms.values()
                        for b in walk.blocks(sub.body) for s in b.body
                        if type(s) is n.VarDecl and s.dims and all(isinstance(d, int) for d in s.dims))
        reserved = declared + sum(len(u.elements) for u in uses.values() if not u.computed)
        self.global_arrays = pl.global_layout(uses, self.next_array, reserved)
        if self.global_arrays:
            self.next_array = max(a.base + a.size for a in self.global_arrays.values())

    def _global_element(self, key: str, v: n.Var) -> str:
        """An element of an undeclared array indexed at run time: its place in the array's block
        (laid out by plan.global_layout), each computed index checked first (alarm when outside)."""
        arr = self.global_arrays[key]
        text = self._element(arr, v)
        for e, dim in zip(v.indices, arr.dims):
            if constant(e) is None:
                half = format_number((dim - 1) / 2)
                guard = (f"IF[ABS[[{self.expr(e)}]-{half}]GT{half}]THEN#3000={pl.ARRAY_INDEX_ALARM}"
                         f"({key[:20]} INDEX OUT OF RANGE)")
                if guard not in self.guards:
                    self.guards.append(guard)
        if key not in self.undeclared:
            self.undeclared.add(key)
            dims = ",".join(map(str, arr.dims))
            self.diags.append(at_span(
                "NC410", "warning", f"{v.key} is not declared in the program (a global of the control's "
                f"definition files) and is indexed at run time: it is laid out row-major as "
                f"{key}[{dims}] in #{arr.base}..#{arr.base + arr.size - 1} (assumed extents: 1 + the "
                f"largest constant index, at least {pl.GLOBAL_MIN_EXTENT}, the first dimension sharing "
                f"out the room left; the table at the top names it); an index outside stops the program "
                f"with alarm #3000={pl.ARRAY_INDEX_ALARM}, and the values the control kept in the array "
                "must be loaded there", self._where()))
        return text

    def _flush_guards(self, prefix: str = "") -> None:
        """Write the index checks gathered for the line about to be written, before it."""
        if self.guards:
            self.out.extend(prefix + g for g in self.guards)
            self.guards.clear()

    def named_var(self, v: n.Var) -> str:
        if v.space == "system":
            return self._system_var(v)
        if v.space == "name":
            key = str(v.key).upper()
            arr = self.arrays.get((self.unit, key)) or self.arrays.get((None, key))
            if arr is not None:
                return self._element(arr, v)
            plan = self.plans.get(self.unit)
            local = plan.locals.get(key) if plan is not None else None
            if local is not None:
                if v.indices:
                    raise NotExpressible(f"indexing the scalar {v.key}")
                return f"#{local}"
            if plan is not None and key in plan.slots:
                return self._slot_var(plan, key, v)
            if v.indices and key in self.global_arrays:
                return self._global_element(key, v)
            if v.indices:
                return self._undeclared_element(key, v)
        if v.space == "R" and v.key is None and v.indices and len(v.indices) == 1:
            self.lowered("R[expr] written as #[500+expr]")
            return f"#[500+{self.expr(v.indices[0])}]"
        return f"#{self.map_var(v)}"

    def _system_var(self, v: n.Var) -> str:
        """Another dialect's system variable as the ISO number of the same neutral meaning
        (rules/<dialect>.toml [system_variables]; $AA_IM[X] -> #5021)."""
        from nctrans.rules import system_spelling
        axis = None
        if v.indices:
            idx = v.indices[0]
            if len(v.indices) != 1 or type(idx) is not n.Var or idx.space != "name" \
                    or str(idx.key).upper() not in AXES:
                raise NotConvertible(f"system variable {v.key} with this index", f"{v.key}[..]")
            axis = str(idx.key).upper()
        found = system_spelling(self.table_name, str(v.key), axis)
        if found is None or found[1] is not None or not found[0][1:].isdigit():
            raise NotConvertible(f"system variable {v.key}{f'[{axis}]' if axis else ''} (no ISO "
                                 "number of the same meaning)", str(v.key))
        self.lowered(f"system variable {v.key}{f'[{axis}]' if axis else ''} written as {found[0]}")
        return found[0]

    def _slot_var(self, plan: pl.UnitPlan, key: str, v: n.Var) -> str:
        """A spilled parameter or local: its slot of the unit's spill frame (an array parameter
        takes consecutive slots, indexed row-major by its declared dimensions)."""
        offset, size = plan.slots[key]
        base = pl.SPILL_BASE - plan.frame + offset
        if not v.indices:
            if size != 1:
                raise NotExpressible(f"the array parameter {v.key} used without its indices")
            return plan.slot_text(offset)
        dims = self._slot_dims.get((self.unit, key))
        if dims is None:
            raise NotExpressible(f"indexing the scalar {v.key}")
        if len(v.indices) != len(dims):
            raise NotExpressible(f"the array parameter {v.key} used without all {len(dims)} indices")
        flat = v.indices[0]
        for e, dim in zip(v.indices[1:], dims[1:]):
            flat = n.Binary("+", n.Binary("*", flat, n.Num(float(dim))), e)
        c = constant(flat)
        if c is not None:
            if c != int(c) or not 0 <= c < size:
                raise NotExpressible(f"index {format_number(c)} of the parameter {v.key} (size {size})")
            return plan.slot_text(offset + int(c))
        return f"#[#{pl.SPILL_POINTER}+{base}+{self.expr(flat)}]"

    def _element(self, arr: pl.ArrayPlan, v: n.Var) -> str:
        idx = v.indices or []
        if len(idx) != len(arr.dims):
            raise NotExpressible(f"the array {v.key} used without all {len(arr.dims)} indices")
        for e, dim in zip(idx, arr.dims):
            c = constant(e)
            if c is not None and (c != int(c) or not 0 <= c < dim):
                raise NotExpressible(f"index {format_number(c)} of the array {v.key} (size {dim})")
        offset = idx[0]
        for e, dim in zip(idx[1:], arr.dims[1:]):
            offset = n.Binary("+", n.Binary("*", offset, n.Num(float(dim))), e)
        c = constant(offset)
        if c is not None:
            return f"#{arr.base + int(c)}"
        return f"#[{self.expr(n.Binary('+', n.Num(float(arr.base)), offset))}]"

    def _undeclared_element(self, key: str, v: n.Var) -> str:
        """An element of an array the program uses but does not declare (a GUD of the control's
        definition files): with constant indices, the element gets a common variable of its own
        in the #500 block, named in the table; its dimensions are unknown here, so an index
        computed at run time has no place to go."""
        idx = [constant(e) for e in v.indices]
        if any(c is None or c != int(c) or c < 0 for c in idx):
            raise NotConvertible(f"the array {v.key} indexed by an expression: it is not declared in "
                                 "this program, so its dimensions (the element's place) are unknown",
                                 f"{v.key}[..]")
        element = f"{key}[{','.join(str(int(c)) for c in idx)}]"
        number = self.var_map.get(("element", element))
        if number is None:
            if self.next_array > pl.COMMON_END:
                raise NotConvertible(f"the array element {element}: no room left in #500-#{pl.COMMON_END}",
                                     element)
            number = self.var_map[("element", element)] = self.next_array
            self.next_array += 1
            if key not in self.undeclared:
                self.undeclared.add(key)
                self.diags.append(at_span(
                    "NC410", "warning", f"{v.key} is not declared in the program (a global of the "
                    f"control's definition files): each element used is mapped to a common variable "
                    f"of its own for this program only ({element} = #{number}; the table at the top "
                    "names them); a program converted on its own that shares it may place it "
                    "elsewhere, and its values must be loaded there", self._where()))
        return f"#{number}"

    def map_var(self, v: n.Var) -> int:
        key = (v.space, v.key)
        if key not in self.var_map:
            if v.space == "R" and isinstance(v.key, int) and 0 <= v.key < 400:
                self.var_map[key] = 500 + v.key
            elif v.space in ("name", "R", "arg", "local"):
                while self.next_common in self.var_map.values() or \
                        pl.SPILL_POINTER <= self.next_common <= pl.SPILL_END:
                    self.next_common += 1
                self.var_map[key] = self.next_common
                self.next_common += 1
            else:
                raise NotExpressible(f"system variable {v.key}")
            self.lowered(f"variable {v.key} mapped to #{self.var_map[key]}")
        if v.indices and v.space != "num":
            raise NotExpressible(f"array variable {v.key}")
        return self.var_map[key]

    def val(self, e) -> str:
        return self.value(e)

    def addr(self, letter: str, e) -> str:
        if type(e) is n.Num:
            return letter + format_number(e.value, letter in POINT_LETTERS)
        return letter + self.value(e)

    def fresh_label(self) -> str:
        if self.unread_runs:
            # the block numbers of a compact body's runs, read only when a fresh number is needed
            runs, self.unread_runs = self.unread_runs, []
            for run in runs:
                self.used_numbers.update(b.number.lstrip("0") or "0" for b in run_blocks(run) if b.number)
        while str(self.next_label) in self.used_numbers:
            self.next_label += 1
        self.next_label += 1
        return str(self.next_label - 1)

    # -------------------------------------------------------------- program
    def run(self) -> str:
        p = self.program
        self._collect_numbers(p.body)
        for sub in p.subprograms.values():
            self._collect_numbers(sub.body)
        self._plan()
        meta = p.meta or {}
        percent = meta.get("percent", True) if p.dialect == self.dialect else True
        if percent:
            self.out.append("%")
        if meta.get("archive_header"):
            self.out.append(str(meta["archive_header"]))
        head = self._program_word(p.name, meta.get("program_number"))
        library = self._library_entry()
        # a subprogram file (a PROC library, a Sinumerik .SPF) is never lowered to plain motion
        from nctrans.convert import subprogram_file
        self.in_place = library is not None or subprogram_file(p)
        if library is not None:
            # a file that only defines a subprogram (a Sinumerik PROC file) is that subprogram:
            # O<its number>, the body, M99; callers elsewhere call the same number
            self.out.append(f"O{self.sub_numbers[library]} {self._comment(library)}")
            self.lowered(f"subprogram file {library} written as O{self.sub_numbers[library]}")
            names_at = len(self.out)
            self._subprogram(library, p.subprograms[library])
            for key, sub in p.subprograms.items():
                if key != library:
                    self.out.append(f"O{self.sub_numbers.get(key, pl.iso_number(key))}")
                    self._subprogram(key, sub)
            self.out[names_at:names_at] = self._name_table()
            if percent:
                self.out.append("%")
            return spilled.joined(self.out)
        if self.sub_numbers and (head is None or p.dialect != self.dialect):
            # an O block after a headless main program would be read as the main program's number
            head = f"O{pl.stable_number('MAIN ' + (p.name or ''), set(self.sub_numbers.values()))}"
            self.lowered(f"main program numbered {head} (its subprograms follow as O blocks)")
        if head:
            title = meta.get("title")
            self.out.append(head + (f" {self._comment(str(title))}" if title is not None else ""))
        names_at = len(self.out)
        self._power_on()
        self.nodes(p.body)
        for key, sub in p.subprograms.items():
            self.span = sub.span
            if key in self.sub_numbers:
                word = f"O{self.sub_numbers[key]}"
                self.lowered(f"subprogram {key} written as {word}")
            else:
                word = self._program_word(key, None)
            if word is None:
                self.refuse(f"subprogram name {key!r} (ISO programs are O numbers)")
                word = f"({key})"
            self.out.append(word)
            self._subprogram(key, sub)
        self.out[names_at:names_at] = self._name_table()
        if percent:
            self.out.append("%")
        return spilled.joined(self.out)

    def _power_on(self) -> None:
        """The source's power-on feed mode and plane where this control's differ (a lathe's G99
        per revolution and G18, a mill's G94 per minute and G17), written before the body; the
        body starts in the source's plane and programming mode (X as diameter on a lathe)."""
        self.span = n.Span(self.program.file, 1)
        defaults = (self.program.meta or {}).get("defaults") or {}
        self.plane = defaults.get("plane", self.plane)
        self.diameter = defaults.get("diameter") == "diameter"
        try:
            codes = self.power_on_codes(self.power_on_groups)
        except NotExpressible as e:
            self.refuse(f"the power-on {e}")
            return
        if codes:
            self.lowered(f"power-on modes of {self.program.dialect} written out: {' '.join(codes)}")
            self.out.append(" ".join(codes))

    def _power_on_motion(self) -> list:
        """The motion code of a first move that relies on the source control's power-on motion
        mode where this control's differs (a Sinumerik main program starts in G1, seed L24114;
        an ISO one in G0): `X10 F100` there is a feed move, written `G1 X10. F100.`, not left to
        run as a rapid here. A subprogram file's first move runs in its caller's mode: left."""
        if self.motion_mode is not None:
            return []
        from nctrans.convert import subprogram_file
        source = ((self.program.meta or {}).get("defaults") or {}).get("motion")
        if (source is None or self.program.dialect == self.dialect or subprogram_file(self.program)
                or (self.program.meta or {}).get("flattened_from")
                or self.table.defaults().get("motion") == source):
            return []
        self.motion_mode = source
        self.lowered(f"power-on motion mode of {self.program.dialect} written at its first move")
        return [self._g("motion", source)]

    def _name_table(self) -> list[str]:
        """Comment lines naming where each variable of the source lives (ISO has numbers only):
        `(VAR LEN = #100)`, `(VAR ARR[3] = #510..#512)`, `(VAR R1 = #501)`, per unit."""
        lines = []
        for (space, key), number in self.var_map.items():
            if space in ("name", "R", "element"):
                lines.append(f"(VAR {'R' if space == 'R' else ''}{key} = #{number})")
        for unit, plan in self.plans.items():
            where = f" IN {unit}" if unit else ""
            for name, number in plan.locals.items():
                lines.append(f"(VAR {name}{where} = #{number})")
        for name, arr in self.global_arrays.items():
            dims = ",".join(str(d) for d in arr.dims)
            lines.append(f"(VAR {name}[{dims}] = #{arr.base}..#{arr.base + arr.size - 1} ASSUMED)")
        for (unit, name), arr in self.arrays.items():
            where = f" IN {unit}" if unit else ""
            dims = ",".join(str(d) for d in arr.dims)
            lines.append(f"(VAR {name}[{dims}]{where} = #{arr.base}..#{arr.base + arr.size - 1})")
        for number, text in self.strings.items():
            lines.append(self._comment(f'STRING "{text}" = {number}'))
        return lines

    def _library_entry(self) -> Optional[str]:
        """The subprogram a file from another dialect exists to define (its main body does
        nothing), else None."""
        p = self.program
        entry = (p.meta or {}).get("entry")
        if p.dialect == self.dialect or entry not in p.subprograms or entry not in self.sub_numbers:
            return None
        if any(not isinstance(b, n.Block) or b.body for b in p.body):
            return None
        return str(entry)

    def _subprogram(self, key: str, sub: n.Subprogram) -> None:
        """A subprogram's body after its O word: the spill frame pushed, the body, M99."""
        self.unit = key
        self.forget()
        self.rel_tool = None                # the caller's tool
        self.turret_tool = None
        if self.edge_lengths is not None:
            self.edge_lengths.unknown()
        self.span = sub.span
        unit = self.plans[key]
        if unit.refusal:
            self.refuse(unit.refusal)
        elif sub.params:
            self.lowered(f"parameters of {key} passed as G65 arguments: " + ", ".join(
                f"{prm.name}={letter} (#{pl.ARG_LOCALS[letter]})" if letter else
                f"{prm.name}=spill slot {unit.slots[prm.name.upper()][0]}"
                for prm, letter in zip(sub.params, unit.params)))
        if unit.frame:
            self.lowered(f"{unit.frame} parameters and locals of {key} kept on the spill stack "
                         f"#{pl.SPILL_BASE}..#{pl.SPILL_END} (pointer #{pl.SPILL_POINTER})")
            self.out.append(f"#{pl.SPILL_POINTER}=#{pl.SPILL_POINTER}+{unit.frame}")
        if not unit.refusal:
            self._unprogrammed_zero(sub, unit)
        self.nodes(sub.body)
        if (key in self.sub_numbers or unit.frame) and not walk.ends_with_return(sub.body):
            self.out.extend(self._pop_frame())
            self.out.append(self.code_for("call", "m99"))

    def _unprogrammed_zero(self, sub: n.Subprogram, unit: pl.UnitPlan) -> None:
        """A parameter a call leaves out reads 0 in the source (Sinumerik: incomplete parameter
        transfer) but is vacant in a G65 local, and a vacant X#24 drops the word: each letter
        parameter is set to 0 on entry when it came vacant, whoever calls."""
        letters = [letter for prm, letter in zip(sub.params, unit.params) if letter and not prm.by_ref]
        if not letters:
            return
        self.lowered("parameters a call leaves out read 0 as in the source: IF[#nEQ#0]THEN#n=0 on entry")
        for letter in letters:
            k = pl.ARG_LOCALS[letter]
            self.out.append(f"IF[#{k}EQ#0]THEN#{k}=0")

    def _pop_frame(self) -> list[str]:
        """What leaving the current unit must do first: release its spill frame."""
        plan = self.plans.get(self.unit)
        if plan is None or not plan.frame:
            return []
        return [f"#{pl.SPILL_POINTER}=#{pl.SPILL_POINTER}-{plan.frame}"]

    def _plan(self) -> None:
        """Labels, locals and O numbers of every unit, before any jump or call is written."""
        p = self.program
        self.plans[None] = pl.unit_plan(None, p.body, self.fresh_label)
        # a return to a block number (M99 P) lands in the calling unit: the main program
        self.targets[None] = walk.jump_targets(p.body).union(
            *(walk.return_targets(sub.body) for sub in p.subprograms.values()))
        for key, sub in p.subprograms.items():
            self.plans[key] = pl.unit_plan(sub, sub.body, self.fresh_label)
            self.targets[key] = walk.jump_targets(sub.body)
        if p.dialect == self.dialect:
            return
        taken = {pl.iso_number(k) for k in p.subprograms if pl.iso_number(k) is not None}
        for key in p.subprograms:
            if pl.iso_number(key) is None:
                self.sub_numbers[key] = pl.stable_number(key, taken)
                taken.add(self.sub_numbers[key])

    def _callee(self, name: str):
        """(O number, unit plan) of a subprogram of this program called by name, else None."""
        for key in self.program.subprograms:
            if key.upper() == name.upper():
                num = self.sub_numbers.get(key, pl.iso_number(key))
                return (num, self.plans[key]) if num is not None else None
        return None

    @staticmethod
    def _program_word(name, number) -> Optional[str]:
        if name and name[0] in "Oo" and name[1:].replace("_", "").isalnum():
            return "O" + name[1:]
        if name and name.isdigit():
            return "O" + name
        if number is not None:
            return f"O{number}"
        return None

    def _collect_numbers(self, nodes_) -> None:
        self.unread_runs.extend(x for x in nodes_ if type(x) in RUNS)
        for b in walk.blocks(nodes_):
            if b.number:
                self.used_numbers.add(b.number.lstrip("0") or "0")

    # -------------------------------------------------------------- structure
    def nodes(self, nodes_) -> None:
        ahead = iter(nodes_)
        node = next(ahead, None)
        while node is not None:
            after = next(ahead, None)
            if type(node) in RUNS:              # a compact body's run (base.CompactBody)
                self.nodes(run_blocks(node))
            else:
                # what a ,R / ,C leads into (_corner_word): a run's first block
                self.next_node = (after.take(1)[0] or [None])[0] if type(after) in RUNS else after
                self._node(node)
            node = after

    def _node(self, node) -> None:
        self.span = node.span
        structure = type(node) is not n.Block
        if structure:
            self.forget()
        try:
            self.dispatch("s_", node)
        except NotConvertible as err:
            if not self.in_place:
                self.refuse(str(err))
            else:
                self.out.append(self._refused_in_place(err, type(node).__name__))
        except NotExpressible as err:
            self.refuse(str(err))
        if structure:
            self.forget()

    # A comment ends at the first ")" on Fanuc and LinuxCNC, and a "(" inside one is an alarm there
    # ("Nested comment found"): only Siemens ISO mode nests. Parentheses in the text become brackets.
    _FLAT_COMMENT = str.maketrans("()", "[]")

    @classmethod
    def _comment(cls, text: str) -> str:
        return f"({text.translate(cls._FLAT_COMMENT)})"

    def s_Block(self, b: n.Block) -> None:
        prefix = ""
        if b.skip is not None:
            prefix = "/" if b.skip == 0 else f"/{b.skip}"
        targets = self.targets.get(self.unit, ())
        if b.label or (b.number is not None and b.number in targets):
            self.forget()
        if b.label:
            num = self.plans[self.unit].labels[b.label]
            self.lowered(f"label {b.label} written as N{num}")
            if b.number is None:
                prefix += f"N{num} "
            else:
                self.out.append(f"N{num}")
        if b.number is not None:
            prefix += f"N{b.number} "
        lines = self.statements(b.body)
        if self.guards:
            # the checks run before the block, after its number (a jump to it runs them too)
            skip = prefix.split("N")[0]
            if prefix.strip() != skip.strip():
                self.out.append(prefix.strip())
                prefix = skip
            self._flush_guards(skip)
        comment = b.comment
        if b.label:
            comment = f"LABEL {b.label}" + (f" {comment}" if comment else "")
        tail = f" {self._comment(comment)}" if comment is not None else ""
        if not lines:
            if b.body and not (prefix or tail):
                return          # its words were moved or said by others (a held T, a lathe's G43)
            text = (prefix + tail.lstrip()).strip() if (prefix or tail) else ""
            self.out.append(text)
            return
        for i, words in enumerate(lines):
            text = " ".join(words)
            if i == 0:
                text = prefix + text
            elif b.skip is not None:
                text = prefix.split("N")[0] + text
            if i == len(lines) - 1:
                text += tail
            self.out.append(text)
        if self.restore_absolute:
            self.restore_absolute = False
            self.out.append(self.code_for("distance", "absolute"))
        if self.restore_distance is not None:
            self.out.append(self.code_for("distance", self.restore_distance))
            self.restore_distance = None
        if self.restore_arc_incremental:
            self.restore_arc_incremental = False
            self.out.append(self.code_for("arc_distance", "incremental"))

    def s_If(self, node: n.If) -> None:
        then = node.then
        simple = (not node.orelse and len(then) == 1 and type(then[0]) is n.Block
                  and then[0].body and all(type(s) is n.Assign for s in then[0].body[:-1])
                  and type(then[0].body[-1]) in (n.Assign, n.Alarm)
                  and then[0].number is None and then[0].comment is None)
        cond = self.cond(node.cond)
        if simple:
            skip = then[0].skip
            prefix = "" if skip is None else ("/" if skip == 0 else f"/{skip}")
            assigns = "".join(self.assign(s) if type(s) is n.Assign else self.w_Alarm(s)[0][1]
                              for s in then[0].body)
            self._flush_guards(prefix)
            self.out.append(f"{prefix}IF[{cond}]THEN{assigns}")
            return
        self.lowered("IF/ELSE block written with IF..GOTO")
        else_label = self.fresh_label()
        end_label = self.fresh_label()
        self._flush_guards()
        self.out.append(f"IF[[{cond}]EQ0]GOTO{else_label}")
        self.nodes(then)
        self.span = node.span
        self.out.append(f"GOTO{end_label}")
        self.out.append(f"N{else_label}")
        self.nodes(node.orelse)
        self.out.append(f"N{end_label}")

    def _loop_label(self, label) -> str:
        if label is not None and str(label).isdigit():
            return str(label)
        return str(min(self.depth + 1, 3))

    def s_While(self, node: n.While) -> None:
        label = self._loop_label(node.label)
        cond = self.cond(node.cond)
        checks = list(self.guards)          # run again before each new test of the condition
        self._flush_guards()
        self.out.append(f"WHILE[{cond}]DO{label}")
        self.depth += 1
        self.nodes(node.body)
        self.depth -= 1
        self.out.extend(checks)
        self.out.append(f"END{label}")

    def s_Loop(self, node: n.Loop) -> None:
        label = self._loop_label(None)
        self.out.append(f"DO{label}")
        self.depth += 1
        self.nodes(node.body)
        self.depth -= 1
        self.out.append(f"END{label}")

    def s_ForLoop(self, node: n.ForLoop) -> None:
        self.lowered("FOR loop written as WHILE with a # variable")
        var = self.val(node.var)
        step = node.step if node.step is not None else n.Num(1.0)
        down = type(step) is n.Num and step.value < 0
        label = self._loop_label(None)
        start = self.expr(node.start)
        end = self._operand(node.end)
        self._flush_guards()
        self.out.append(f"{var}={start}")
        self.out.append(f"WHILE[{var}{'GE' if down else 'LE'}{end}]DO{label}")
        self.depth += 1
        self.nodes(node.body)
        self.depth -= 1
        self.out.append(f"{var}={var}+{self._operand(step)}")
        self.out.append(f"END{label}")

    def s_RepeatUntil(self, node: n.RepeatUntil) -> None:
        self.lowered("REPEAT..UNTIL written with IF..GOTO")
        top = self.fresh_label()
        self.out.append(f"N{top}")
        self.nodes(node.body)
        self.span = node.span
        cond = self.cond(node.cond)
        self._flush_guards()
        self.out.append(f"IF[[{cond}]EQ0]GOTO{top}")

    def s_Case(self, node: n.Case) -> None:
        self.lowered("CASE written as IF..GOTO")
        subject = self._operand(node.subject)
        self._flush_guards()
        for value, label in node.branches:
            self.out.append(f"IF[{subject}EQ{self._operand(value)}]GOTO{self._goto_target(label)}")
        if node.default is not None:
            self.out.append(f"GOTO{self._goto_target(node.default)}")

    def _operand(self, e) -> str:
        return self.expr(e, self.syntax.unary["-"].prec)

    def _refused_in_place(self, err: NotConvertible, what: str) -> str:
        """NC412 and the alarm line that stands for a construct refused at its place."""
        self.diags.append(at_span(
            "NC412", "warning", f"{what}: {self.target_text} cannot express {err} (source line "
            f"{self.span.line if self.span else 1}), and a subprogram file cannot be lowered to plain "
            f"motion: written as alarm #3000={pl.NOT_CONVERTED_ALARM} at its place, so the control "
            "stops there until it is ported by hand; the rest keeps its structure", self._where()))
        self.guards.clear()
        return f"#3000={pl.NOT_CONVERTED_ALARM} {self._comment('NOT CONVERTED: ' + err.construct)}"

    def cond(self, e) -> str:
        try:
            return self.expr(e)
        except NotConvertible as err:
            if self.in_place:
                raise
            self.refuse(str(err))
            return "0EQ1"
        except NotExpressible as err:
            self.refuse(str(err))
            return "0EQ1"

    def assign(self, s: n.Assign) -> str:
        try:
            if s.target.space == "system":
                number = _external_offset_number(s.target)
                if number is None:
                    raise NotExpressible(f"writing the system variable {s.target.key}")
                self.lowered("Sinumerik external zero offset $P_EXTFRAME[X,TR] written as the "
                             "external work offset #5201..")
                return f"#{number}={self.expr(s.value)}"
            return f"{self.val(s.target)}={self.expr(s.value)}"
        except NotConvertible as err:
            if self.in_place:
                raise
            self.refuse(str(err))
            return ""
        except NotExpressible as err:
            self.refuse(str(err))
            return ""

    def _goto_target(self, target: str) -> str:
        t = str(target)
        if t.isdigit():
            return t
        labels = self.plans[self.unit].labels if self.unit in self.plans else {}
        if t in labels:
            return labels[t]
        self.refuse(f"jump to label {t!r} (no such label in this program unit)")
        return "0"

    # -------------------------------------------------------------- statements
    def _turret_stays(self, body: list) -> list:
        """The block without its T word and turret change where the turret keeps its tool."""
        tools = [i for i, s in enumerate(body) if type(s) is n.ToolSelect]
        turns = [i for i, s in enumerate(body) if type(s) is n.ToolChange]
        if not turns:
            return body
        tool = _const_int(body[tools[-1]].tool) if tools else None
        if not all(body[i].turret for i in turns) or tool is None:
            self.turret_tool = None
            return body
        if tool != self.turret_tool:
            self.turret_tool = tool
            return body
        return [s for i, s in enumerate(body) if i not in turns and i not in tools]

    def statements(self, body) -> list[list[str]]:
        body = self.tool_timing.apply(self, body)
        if self.drops_staying_turret:
            body = self._turret_stays(body)
        lines: list[_Line] = [_Line()]
        names_register = any(type(s) is n.OffsetSelect and s.kind == "length" for s in body)
        for s in body:
            try:
                words = self.dispatch("w_", s)
                if type(s) is n.ModeChange and s.group == "tool_length" and not names_register:
                    words = words + self._length_register(s)
            except NotConvertible as err:
                if not self.in_place:
                    self.refuse(f"{type(s).__name__}: {err}")
                    continue
                words = _Lines([[("#3000", self._refused_in_place(err, type(s).__name__))]])
            except NotExpressible as err:
                self.refuse(f"{type(s).__name__}: {err}")
                continue
            if not words:
                continue
            if type(words) is _Lines:
                for group in words:
                    line = _Line()
                    lines.append(line)
                    line.words.extend(w for _, w in group)
                    line.used.update(k for k, _ in group if k)
                lines.append(_Line())
                continue
            line = lines[-1]
            keys = [k for k, _ in words if k]
            if type(s) is n.ModeChange and s.group == "units":
                keys.append("units")
            # ISO reads F before G20/G21 (in the units before the switch): an F the source reads
            # after its units switch goes on the next line
            if any(k in line.used for k in keys) or (type(s) is n.Feed and "units" in line.used):
                line = _Line()
                lines.append(line)
            line.words.extend(w for _, w in words)
            line.used.update(keys)
        if self.edge_lengths is not None:
            try:
                words = self.edge_lengths.block_words(body)
            except NotConvertible as err:       # raised only in a subprogram file
                lines.append(_Line())
                lines[-1].words.append(self._refused_in_place(err, "OffsetSelect"))
                lines.append(_Line())
                words = []
            keys = [k for k, _ in words if k]
            line = lines[-1]
            if any(k in line.used for k in keys):
                line = _Line()
                lines.append(line)
            line.words.extend(w for _, w in words)
            line.used.update(keys)
        if self.respin and self.spindle_turning is not None and any(
                type(x) is n.ToolChange for x in body) and not any(
                type(x) is n.ModeChange and x.group == "spindle" for x in body):
            # this M6 stops the spindle, the source's change does not: it turns on as it was
            self.lowered("the tool change stops the spindle here (M6 of ISO milling, as Haas and "
                         "LinuxCNC do) and not in the source: its direction written again after it")
            lines.append(_Line())
            lines[-1].words.append(self.code_for("spindle", self.spindle_turning))
        # the chamfer / corner rounding words `,C` `,R` end their block (seed L3962-3967)
        return [sorted(ln.words, key=lambda w: w.startswith(",")) for ln in lines if ln.words]

    def _g(self, group: str, value: str, code: str = "") -> tuple[str, str]:
        written = code
        rule = self.table.lookup(code) if code else None
        if rule is None or (rule.group, rule.value) != (group, value):
            rule = self.table.code_for(group, value)
            code = rule.code if rule is not None else ""
        if rule is None:
            # a mode this control has no code for (a mill's diameter programming): another
            # control's facility
            raise NotConvertible(f"mode {group}={value}", written or f"{group}={value}")
        key = f"{code[0]}:{rule.dialect_group}" if rule.modal and rule.dialect_group is not None else ""
        return key, code

    def w_ModeChange(self, s: n.ModeChange):
        if s.group == "spindle":
            self.spindle_turning = s.value if s.value in ("cw", "ccw") else None
        if s.group == "diameter" and self.table.code_for("diameter", s.value) is None:
            # ISO milling has no diameter mode: the X words are converted to radii instead
            self.diameter = s.value == "diameter"
            self.pos = {}
            return []
        if s.group in ("plane", "cutter_comp", "cycle"):
            self._plane_held(f"mode {s.group}={s.value}")
        if s.group == "distance":
            self.distance = s.value
            self.distance_known = True
        if s.group == "arc_distance":       # under G90.1 ISO writes absolute centres as they are
            self.arc_distance = s.value
        elif s.group == "plane":
            self.plane = s.value
        elif s.group in ("units", "work_offset", "tool_length", "diameter", "cycle"):
            self.pos = {}
        if s.group == "units":
            self.units_mm = s.value == "mm"
        if s.group == "motion":
            self.thread_mode = s.value == "thread"
            self.motion_mode = s.value
            if self.named_cycle is not None:
                return []                   # the G8x mode holds group 1: restored after G80
            self.cip_mode = s.value == "arc_3point"
            if self.cip_mode:
                return []                   # written as G2/G3 by the CIP block itself
        if s.group == "work_offset" and s.value == "G53":
            raise NotConvertible(f"work offset {s.code or 'G53'} (no settable offset): ISO has no modal "
                                 "'no work offset', and G54 is the same only when its offset is zero",
                                 s.code or "G500")
        if s.group == "work_offset" and s.value.startswith("G54.1P"):
            if self.table.code_for("work_offset", "G54.1") is None:
                raise NotExpressible(f"work offset {s.value}")
            return [self.code_word("work_offset", "G54.1"), ("P", "P" + s.value[6:])]
        if s.group == "work_offset" and self.table.code_for("work_offset", s.value) is None:
            raise NotExpressible(f"work offset {s.value}")
        code = s.code.upper() if s.code else ""
        if code and code[0] in "GM" and code[1:].replace(".", "").isdigit():
            from nctrans.rules import normalise_code
            code = normalise_code(code[0], code[1:])
        return [self._g(s.group, s.value, code)]

    def _axes(self, target: dict) -> list:
        words = []
        for k, av in target.items():
            if k not in AXES or len(k) != 1:
                # a machine's own axis name (XV, C1): which ISO letter drives it is the machine's
                raise NotConvertible(f"the axis {k} (ISO axes are the letters {AXES})", f"axis {k}")
            if av.mode not in (None,):
                # ISO's distance mode is one for all axes (G90/G91), and it has no rotary-axis
                # direction of approach (Sinumerik DC/ACP/ACN)
                raise NotConvertible(f"per-word {av.mode} coordinate on {k}",
                                     f"{k}={'IC' if av.mode == 'inc' else 'AC/DC'}(..)")
            value = av.value
            if k == "X" and self.diameter:
                self.lowered("X programmed as a diameter written as a radius", once="diameter")
                value = n.Num(value.value / 2) if type(value) is n.Num else n.Binary("/", value, n.Num(2.0))
            words.append((k, self.addr(k, value)))
        return words

    def _cip(self, s: n.Motion):
        """A three-point arc as G2/G3 with the centre of the circle through start, via and end."""
        a1, a2, a3 = pl.PLANE.get(self.plane, pl.PLANE["XY"])
        if s.center or s.radius is not None or s.turns is not None or s.polar or s.machine_coords:
            raise NotExpressible("a three-point arc (CIP) with centre, radius or turn words")
        if self.diameter and "X" in (a1, a2):
            # the points are diameters in X: the circle through them is not the arc's
            raise NotExpressible("a three-point arc (CIP) with X programmed as a diameter")
        extra = (set(s.target) | set(s.via)) - {a1, a2, a3}
        if extra:
            raise NotExpressible(f"a three-point arc (CIP) moving {', '.join(sorted(extra))}")
        start = dict(self.pos)

        def point(words):
            out = dict(start)
            for k, av in words.items():
                v = constant(av.value)
                inc = av.mode == "inc" or (av.mode is None and self.distance == "incremental")
                if v is None or (inc and k not in start):
                    raise NotExpressible("a three-point arc (CIP) whose points are not constants")
                out[k] = start[k] + v if inc else v
            return out
        mid, end = point(s.via), point(s.target)
        if any(a not in start for a in (a1, a2)):
            raise NotExpressible("a three-point arc (CIP) from a start point that is not a known constant")
        if (a3 in s.via or a3 in s.target) and not (start.get(a3) == mid.get(a3) == end.get(a3)):
            raise NotExpressible("a three-point arc (CIP) outside the working plane")
        c = pl.circle_through((start[a1], start[a2]), (mid[a1], mid[a2]), (end[a1], end[a2]))
        if c is None:
            raise NotExpressible("a three-point arc (CIP) through collinear points")
        c1, c2, cw = c
        words = [self._g("motion", "arc_cw" if cw else "arc_ccw")]
        for a in (a1, a2, a3):
            if a in s.target or a != a3:
                v = end[a] if self.distance != "incremental" else end[a] - start[a]
                words.append((a, a + format_number(v + 0.0, True)))
        for a, c_ in ((a1, c1), (a2, c2)):
            letter = {"X": "I", "Y": "J", "Z": "K"}[a]
            words.append((letter, letter + format_number(c_ - start[a] + 0.0, True)))
        self.lowered(f"three-point arc (CIP) written as {words[0][1]} with its centre computed from "
                     "the constant points")
        self.pos.update({a: end[a] for a in (a1, a2, a3) if a in end})
        return words

    def _aperture_radius(self, s: n.Motion, start: dict) -> str:
        """Opening angle AR= with an end point: the ISO R word of that arc (negative over 180 deg),
        when the start, the end and the angle are constants."""
        a1, a2, _ = pl.PLANE.get(self.plane, pl.PLANE["XY"])
        ang = constant(s.aperture)
        if s.center or s.radius is not None or ang is None or not 0 < ang < 360:
            raise NotExpressible("an arc by opening angle (AR=) with a centre or a computed angle")
        if any(a not in start or a not in self.pos for a in (a1, a2)):
            raise NotExpressible("an arc by opening angle (AR=) from or to a point that is not a constant")
        if self.diameter and "X" in (a1, a2):
            raise NotExpressible("an arc by opening angle (AR=) with X programmed as a diameter")
        chord = math.hypot(self.pos[a1] - start[a1], self.pos[a2] - start[a2])
        r = chord / (2 * math.sin(math.radians(ang) / 2))
        self.lowered("arc by opening angle (AR=) written with the radius R of that arc")
        return format_number(-r if ang > 180 else r, True)

    def w_Motion(self, s: n.Motion):
        if self.named_cycle is not None and s.target:
            return self._named_hole(s)
        if s.via or s.center or s.radius is not None or s.aperture is not None or s.turns is not None:
            self._plane_held("an arc")
        if s.via:
            return self._cip(s)
        if self.cip_mode and s.target:
            raise NotExpressible("a three-point arc (CIP) without an intermediate point")
        if s.thread_start is not None:
            self.start_pending = s.thread_start
            if not (s.target or s.center or s.machine_coords):
                return []                   # SF= alone: written with the next thread block
        start = dict(self.pos)
        self.track(s)
        if s.polar:
            raise NotExpressible("polar motion words")
        if s.indirect:
            raise NotExpressible("axis words with a computed axis (AX[..]=)")
        words = self._power_on_motion()
        if self.thread_mode and s.center:
            return self._thread(s, words) + self._thread_start()
        if self.thread_mode and s.target:
            words += self._thread_start()
        if self.feed_clobbered and self.last_feed is not None and s.target:
            words.append(("F", self.last_feed))
            self.feed_clobbered = False
        if s.machine_coords:
            words.append(self.code_word("nonmodal", "machine_coords"))
        target, switch = per_word.plain_words(self, s)
        words += switch + self._axes(target)
        if s.aperture is not None:
            words.append(("R", "R" + self._aperture_radius(s, start)))
        if s.center and self.arc_distance != "absolute" and all(av.mode == "abs" for av in s.center.values()) \
                and any(constant(av.value) is None or {"I": "X", "J": "Y", "K": "Z"}.get(k, k) not in start
                        for k, av in s.center.items()):
            # absolute centres (Sinumerik I=AC(..)) from a start point known only at run time:
            # this block under G90.1, G91.1 again after it
            self.lowered("absolute arc centre written under G90.1 (G91.1 after the block)")
            words.insert(0, self._g("arc_distance", "absolute"))
            self.restore_arc_incremental = True
            for k, av in s.center.items():
                letter = {"X": "I", "Y": "J", "Z": "K"}.get(k, k)
                words.append((letter, self.addr(letter, av.value)))
        elif s.center:
            for k, av in s.center.items():
                letter = {"X": "I", "Y": "J", "Z": "K"}.get(k, k)
                value = av.value
                if av.mode == "abs" and self.arc_distance != "absolute":
                    # an absolute centre (Sinumerik I=AC(..)) from the known constant start point
                    axis = {"I": "X", "J": "Y", "K": "Z"}.get(k, k)
                    c = constant(value)
                    if c is None or axis not in start:
                        raise NotExpressible(f"an absolute arc centre {k} from an unknown start point")
                    self.lowered(f"absolute arc centre {k} written incremental from the start point")
                    value = n.Num(c - start[axis] + 0.0)
                words.append((letter, self.addr(letter, value)))
        if s.radius is not None:
            words.append(("R", self.addr("R", s.radius)))
        if s.turns is not None:
            t = s.turns
            if type(t) is n.Num:
                words.append(("L", "L" + format_number(t.value + 1)))
            elif type(t) is n.Binary and t.op == "-" and type(t.right) is n.Num and t.right.value == 1:
                words.append(("L", "L" + self.val(t.left)))
            else:
                words.append(("L", "L" + self.val(n.Binary("+", t, n.Num(1.0)))))
        return words

    def _thread(self, s: n.Motion, words: list) -> list:
        """G33 Z.. F<lead> (ISO seed 4.5): the I/J/K lead word of the IR (Sinumerik, flattened
        tapping) is written as F. Flattened plain motion is written for LinuxCNC's rs274 (CONTRACT:
        `--flatten --to iso-m` runs there), whose G33 takes the lead as K and refuses F: there
        the lead is K (nctrans reads G33 K back as the lead too); flatten's NC401 on threads says
        that a Fanuc or Sinumerik ISO-mode control wants F, which the conversion without --flatten
        writes."""
        if len(s.center) != 1:
            raise NotExpressible("a thread with more than one lead word (ISO G33 has one F lead)")
        (av,) = s.center.values()
        words += self._axes(s.target)
        if self.lead_as_k:                  # (flatten's NC401 on the threads says so)
            words.append(("K", self.addr("K", av.value)))
            return words
        words.append(("F", self.addr("F", av.value)))
        self.feed_clobbered = True
        return words

    def _thread_start(self) -> list:
        """The Q word of a thread block (ISO seed 4.1.16: an integer in 0.001 degree): the start
        angle programmed since the last thread block, else a constant one written before (a
        Fanuc's Q holds for its block only, the Sinumerik ISO mode keeps it as setting data:
        written again, both read it the same); a computed angle is written where it was
        programmed only (written again it would be evaluated again). LinuxCNC's G33 has no start
        angle: refused there."""
        e, self.start_pending = self.start_pending, None
        if e is None:
            if not self.start_repeat:
                return []
            e = n.Num(self.start_repeat)
        c = constant(e)
        if c is not None and not math.isfinite(c):
            raise NotExpressible("a thread start angle that is not a finite number")
        if self.lead_as_k and (c is None or c % 360.0):
            raise NotExpressible("a thread start angle (LinuxCNC's G33 has none)")
        if self.lead_as_k:
            return []
        self.start_repeat = c % 360.0 if c is not None else None
        if c is not None:
            return [("Q", "Q" + str(round((c % 360.0) * 1000)))]
        return [("Q", "Q" + self.val(n.Func("round", [n.Binary("*", e, n.Num(1000.0))])))]

    def w_Feed(self, s):
        self.feed_expr = s.value
        self.last_feed = self.addr("F", s.value)
        self.feed_clobbered = False
        return [("F", self.last_feed)]

    def w_SpindleSpeed(self, s):
        if s.spindle != 1:
            raise NotExpressible(f"spindle {s.spindle}")
        return [("S", self.addr("S", s.value))]

    def w_ToolSelect(self, s):
        self.selected_tool = s.tool
        if self.tool_relative:
            self.rel_selected = _const_int(s.tool)
        return [("T", self.addr("T", s.tool))]

    def w_ToolChange(self, s):
        self.pos = {}
        sel = self.selected_tool
        self.spindle_tool = int(sel.value) if type(sel) is n.Num and float(sel.value).is_integer() else None
        if self.tool_relative:
            self.rel_tool = self.rel_selected
        return [self.code_word("tool_change", "change")]

    def _length_register(self, s: n.ModeChange) -> list:
        """The H word of a length switched on by another control's word that names no register
        (Fagor `D1`, M06's implied D1: the active tool's offset). A bare G43 is read differently by
        the ISO controls: LinuxCNC takes the loaded tool's length, a Fanuc the last H programmed
        (none after power-on), so the register is always written: H<tool in the spindle>."""
        if s.value not in ("plus", "minus") or not self.writes_edge_lengths:
            return []
        rule = self.table.lookup(s.code.upper()) if s.code else None
        if rule is not None and rule.group == "tool_length":
            return []                   # this control's own G43/G44: as the source wrote it
        if self.spindle_tool is None:
            raise NotConvertible(f"the tool length {s.code or ''} of the tool in the spindle, which "
                                 "is not known here (ISO needs its H register)", "G43 H..")
        return [("H", f"H{self.spindle_tool}")]

    def w_OffsetSelect(self, s):
        self.pos = {}
        if self.edge_lengths is not None and s.kind == "radius":
            return []       # a cutting edge: its G43 H and, with G41/G42, its D (edge_length)
        if self.tool_relative and s.kind == "radius" and _const_int(s.index) == 1:
            if not self.rel_tool:
                why = ("no tool change before it: the tool the machine holds" if self.rel_tool == 0
                       else "a tool not known here")
                raise NotConvertible(f"the radius of D1, the corrector of the active tool ({why}), which "
                                     "no ISO register names", "D1")
            return [("D", f"D{self.rel_tool}")]
        if self.tool_relative and s.kind == "radius" and self.rel_tool == 0 \
                and (_const_int(s.index) or 0) >= 2 and not flat_radius_number(_const_int(s.index)):
            # no tool change before it: a corrector of the held tool (its analysis: NC123), not
            # register k, which holds another radius
            raise NotConvertible(f"the radius of D{_const_int(s.index)}, a corrector of the active "
                                 "tool with no tool change before it: the tool the machine holds, "
                                 "which no ISO register names", f"D{_const_int(s.index)}")
        letter = "H" if s.kind == "length" else "D"
        return [(letter, self.addr(letter, s.index))]

    def w_Dwell(self, s):
        if s.revolutions is not None:
            raise NotExpressible("a dwell in spindle revolutions")
        sec = s.seconds if s.seconds is not None else n.Num(0.0)
        dwell = self.code_word("nonmodal", "dwell")
        if type(sec) is n.Num:
            ms = _ms_text(sec.value)
            if ms is not None:
                return [dwell, ("P", "P" + ms)]
            return [dwell, ("X", "X" + format_number(sec.value, True))]
        if type(sec) is n.Binary and sec.op == "/" and type(sec.right) is n.Num and sec.right.value == 1000:
            return [dwell, ("P", "P" + self.val(sec.left))]
        return [dwell, ("X", "X" + self.val(sec))]

    def w_SetPosition(self, s):
        self.pos = {}
        return [self.code_word("nonmodal", "set_position")] + self._axes(s.target)

    def w_ResetSetPosition(self, s):
        self.pos = {}
        return [self.code_word("nonmodal", "reset_set_position")]

    def w_HomeReturn(self, s):
        self.pos = {}
        words = [self.code_word("nonmodal", "home" if s.ref == 1 else "home2")]
        modes = {av.mode for av in s.via.values()}
        if modes == {"inc"}:
            # Sinumerik G74 (approach the reference point directly) arrives as a zero
            # incremental via point: ISO writes that as G91 G28 and restores G90 after the block.
            via = {k: n.AxisValue(av.value) for k, av in s.via.items()}
            if self.distance_known is None:
                from nctrans.dialects.base import CannotStream
                raise CannotStream("an incremental reference-point approach before any G90/G91 of a "
                                   "streamed program")
            if not self.distance_known:
                # the G90 written after it would be a guess (per_word: known on every path only)
                raise NotConvertible(
                    "an incremental reference-point approach (written G91 G28, then the G90/G91 in "
                    "force again) where the G90/G91 in force is not known on every path (a jump "
                    "target, a loop or branch, after a call, or a subprogram's start: its caller's)",
                    "G91 G28")
            if self.distance == "absolute":
                self.lowered("incremental reference-point approach written as G91 G28 ... then G90")
                self.restore_absolute = True
            return [self.code_word("distance", "incremental")] + words + self._ref_index(s) + self._axes(via)
        return words + self._ref_index(s) + self._axes(s.via)

    def _ref_index(self, s) -> list:
        words = []
        if s.ref not in (1, 2) and s.ref_index is None:
            words.append(("P", f"P{s.ref}"))
        if s.ref_index is not None:
            words.append(("P", self.addr("P", s.ref_index)))
        return words

    def _additive_trans(self, s: n.FrameOp):
        """ATRANS with no rotation, scale or mirror active: G52 with the accumulated shift."""
        vals = {k: constant(v) for k, v in s.values.items()}
        if self.frame_trans is None or self.frame_other:
            raise NotExpressible("an additive translation (ATRANS) where the frame is not a known plain shift")
        if None in vals.values() or set(vals) - set("XYZ"):
            raise NotExpressible("an additive translation (ATRANS) with computed values or non-XYZ axes")
        total = dict(self.frame_trans)
        for k, v in vals.items():
            total[k] = total.get(k, 0.0) + v
        self.frame_trans = total
        self.pos = {}
        self.lowered("additive translation (ATRANS) written as G52 with the accumulated shift")
        return [self.code_word("nonmodal", "local_offset")] + [(k, k + format_number(v + 0.0, True))
                                                               for k, v in total.items()]

    def w_FrameOp(self, s: n.FrameOp):
        if s.indirect:
            raise NotExpressible("a frame value with a computed axis (AX[..]=)")
        if s.additive:
            if s.op == "trans" and not s.clear:
                return self._additive_trans(s)
            raise NotExpressible(f"an additive frame ({s.op})")
        other = self.frame_other
        trans_before = self.frame_trans
        self.track_frame(s)
        if (s.op in ("trans", "rot", "scale", "mirror") and not s.clear and not s.local and s.center is None
                and (s.op != "rot" or not set(s.values) - set("IJK"))):
            # a frame that replaces the whole programmable frame (Sinumerik TRANS/ROT/SCALE/MIRROR):
            # ISO keeps the components it does not name, so what may be active is cancelled first,
            # each on its own line, rotation and scaling before the mirror (seed L1715-1718)
            cancels = ([[self.code_word("nonmodal", "local_offset")] + [(k, k + "0.") for k in "XYZ"]]
                       if s.op != "trans" and trans_before != {} else [])
            if other:
                cancels += self._cancel_others()
            if cancels or s.op == "rot":
                words = self._replacing(s)
                return _Lines([*cancels, words]) if cancels else words
        if s.op == "all" and s.clear:
            # the whole programmable frame off (Sinumerik TRANS/ROT without values): cancel the
            # local shift, and rotation, scaling and mirroring when they may be active
            words = [self.code_word("nonmodal", "local_offset")] + [(k, k + "0.") for k in "XYZ"]
            if not other:
                return words + self._plane_back()
            # one cancel a line: G69 and G50 are one neutral group, and G52 and G50.1 both take X Y Z
            return _Lines([words, *self._cancel_others(), *([w] for w in self._plane_back())])
        if s.op == "trans":
            shift = self.code_word("nonmodal", "local_offset")
            if s.clear:
                return [shift] + [(k, k + "0.") for k in "XYZ"]
            if not s.local:
                self.lowered("programmable translation written as G52 local offset")
            return [shift] + [(k, self.addr(k, v)) for k, v in s.values.items()]
        if s.op == "rot":
            if s.clear:
                return self._cancel("rot_off") + self._plane_back()
            extra = {k: v for k, v in s.values.items() if k in "IJK"}
            if set(s.values) - set(extra):
                return self._rotation_about(s, other, trans_before)
            words = [self.code_word("frame", "rot")] + (self._axes(s.center) if s.center else [])
            words += [(k, self.addr(k, v)) for k, v in extra.items()]
            if s.angle is not None:
                words.append(("R", self.addr("R", s.angle)))
            return words
        if s.op == "scale":
            if s.clear:
                return self._cancel("scale_off")
            words = [self.code_word("frame", "scale")] + (self._axes(s.center) if s.center else [])
            vals = s.values
            if set(vals) == {"X", "Y", "Z"} and _same(vals.values()):
                words.append(("P", "P" + self._factor(vals["X"])))
            else:
                for axis, letter in (("X", "I"), ("Y", "J"), ("Z", "K")):
                    if axis in vals:
                        words.append((letter, letter + self._factor(vals[axis])))
                if set(vals) - {"X", "Y", "Z"}:
                    raise NotExpressible("scaling of a rotary or extra axis")
            return words
        if s.op == "mirror":
            if s.clear:
                mirror = self._cancel("mirror_off")
                return mirror + [(k, k + "0.") for k in s.values] if mirror else []
            words = [self.code_word("frame", "mirror")]
            center = dict(s.center or {})
            for k in s.values:
                center.setdefault(k, n.AxisValue(n.Num(0.0)))
            return words + self._axes(center)
        raise NotExpressible(f"frame operation {s.op}")

    def _cancel(self, meaning: str) -> list:
        """The code that cancels a frame component (rotation, scaling, mirroring); nothing when the
        dialect has no such component (an ISO lathe: G50/G68 mean other things there), as setting
        one is refused, so none is active."""
        if self.table.code_for("frame", meaning) is None:
            what = {"rot_off": "rotation", "scale_off": "scaling", "mirror_off": "mirroring"}[meaning]
            self.lowered(f"{what} cancel left out: {self.target_text} has no {what}, so none is active")
            return []
        return [self.code_word("frame", meaning)]

    def _rotation_about(self, s: n.FrameOp, other: bool, trans_before) -> list:
        """ROT about one named axis (Sinumerik ROT Y90): G68 in the plane that axis is normal to,
        about the work zero (G68 turns positive from the plane's first axis to its second, as ROT
        turns by the right-hand rule). Another plane than the source's is selected for the
        rotation and the source's selected again at its cancel; in between, what depends on the
        plane (arcs, cycles, compensation) has no ISO spelling."""
        named = [k for k in s.values if k not in "IJK"]
        plane = {"Z": "XY", "Y": "ZX", "X": "YZ"}.get(named[0]) if len(s.values) == 1 else None
        if plane is None or s.center or s.angle is not None:
            raise NotExpressible(f"rotation about {' and '.join(s.values)}")
        # ROT replaces the whole programmable frame: what may be active is cancelled first
        cancel = []
        if trans_before != {}:
            cancel.append([self.code_word("nonmodal", "local_offset")] + [(k, k + "0.") for k in "XYZ"])
        if other:
            cancel += self._cancel_others()
        words = []
        if plane != self.plane:
            words.append(self.code_word("plane", plane))
            self.rotation_plane = plane
        first, second = pl.PLANE[plane][:2]
        self.lowered(f"rotation about {named[0]} written as G68 in the {plane} plane about the work zero"
                     + (f" ({words[0][1]}; the program's plane again at its cancel)" if words else ""))
        words += [self.code_word("frame", "rot"), (first, first + "0."), (second, second + "0."),
                  ("R", self.addr("R", s.values[named[0]]))]
        return _Lines([*cancel, words]) if cancel else words

    def _replacing(self, s: n.FrameOp) -> list:
        """The one component a replacing frame sets, about the work zero (an ISO G68 without X Y
        turns about the current position, so the centre is written)."""
        if s.op == "rot" and s.angle is not None:
            a1, a2, _ = PLANE_AXES[self.plane]
            words = [self.code_word("frame", "rot"), (a1, a1 + "0."), (a2, a2 + "0.")]
            words += [(k, self.addr(k, v)) for k, v in s.values.items()]
            return words + [("R", self.addr("R", s.angle))]
        if s.op == "trans":
            self.lowered("programmable translation written as G52 local offset")
        return self.w_FrameOp(n.FrameOp(s.op, s.values, {} if s.op != "trans" else None, s.angle,
                                        local=s.op == "trans"))

    def _cancel_others(self) -> list:
        """Rotation, scaling and mirroring off, each on a line of its own."""
        mirror = self._cancel("mirror_off")
        lines = [self._cancel("rot_off"), self._cancel("scale_off"),
                 mirror + ([(k, k + "0.") for k in "XYZ"] if mirror else [])]
        return [x for x in lines if x]

    def _plane_back(self) -> list:
        """The source's plane again where a rotation about another axis held another one."""
        if self.rotation_plane is None:
            return []
        self.rotation_plane = None
        return [self.code_word("plane", self.plane)]

    def _plane_held(self, what: str) -> None:
        if self.rotation_plane is not None:
            raise NotExpressible(f"{what} while a rotation holds the ISO plane at {self.rotation_plane} "
                                 f"(the program's is {self.plane})")

    def _factor(self, v) -> str:
        if type(v) is n.Num:
            return format_number(v.value, True)
        return self.val(v)

    def w_CycleParams(self, s: n.CycleParams):
        self.pos = {}
        words = []
        letters = {"r_plane": "R", "peck": "Q", "shift": "Q", "repeat": "K"}
        for key, v in s.values.items():
            if key == "dwell":
                if type(v) is n.Num and _ms_text(v.value) is not None:
                    words.append(("P", "P" + _ms_text(v.value)))
                elif type(v) is n.Binary and v.op == "/" and type(v.right) is n.Num and v.right.value == 1000:
                    words.append(("P", "P" + self.val(v.left)))
                else:
                    words.append(("P", "P" + self.val(n.Binary("*", v, n.Num(1000.0)))))
            elif key in letters:
                words.append((letters[key], self.addr(letters[key], v)))
            else:
                raise NotExpressible(f"cycle parameter {key}")
        return words

    def w_CycleCall(self, s: n.CycleCall):
        self._plane_held(f"the cycle {s.name or s.kind}")
        if s.kind in ("holes_line", "holes_circle"):
            return self._hole_pattern(s)
        if s.kind == "swivel_plane":
            raise NotExpressible(f"the cycle call {s.name or s.kind} (expand cycles first)")
        try:
            cyc = iso_cycle(s, self)
        except CycleRefused as err:
            raise NotExpressible(f"the cycle call {err} (expand cycles first)") from None
        lines = _Lines()
        if s.modal:
            if self.named_cycle is not None:
                lines += self._cycle_off()
            self.named_cycle = cyc
            self.lowered(f"{cyc.name} called modally written as {cyc.retract} {cyc.code} at each "
                         "following position")
            return lines
        # a one-shot call leaves a modal one (MCALL) in force: its G8x mode starts again at the next hole
        if self.named_active:
            lines.append([self.code_word("cycle", "off")])
            self.named_active = False
        self.lowered(f"{cyc.name} written as {cyc.retract} {cyc.code} at the current position, then G80")
        lines.append(self._cycle_words(cyc, []))
        lines += self._restore(cyc) if self.named_cycle is None else [[self.code_word("cycle", "off")]]
        return lines

    def _drill_axis(self) -> str:
        return {"XY": "Z", "ZX": "Y", "YZ": "X"}.get(self.plane, "Z")

    def _cycle_words(self, cyc: IsoCycle, plane_words: list) -> list:
        """The first block of an ISO cycle: G98/G99 G8x, the hole, Z R Q P (F)."""
        ax = self._drill_axis()
        if cyc.rtp is not None and self.pos.get(ax) != cyc.rtp:
            raise NotExpressible(f"{cyc.name} with RTP {format_number(cyc.rtp)} above the approach "
                                 f"level: the ISO cycle returns to where the tool is when it starts "
                                 f"(G98), which is not RTP here")
        words = [self.word_of(cyc.retract), self.word_of(cyc.code), *plane_words, *cyc.words]
        if cyc.feed is not None:
            words.append(("F", self.addr("F", cyc.feed)))
        self.pos = {a: v for a, v in self.pos.items() if a != ax}
        if cyc.rtp is not None:
            self.pos[ax] = cyc.rtp
        return words

    def _restore(self, cyc: IsoCycle) -> list:
        """After G80: the motion mode (ISO G80 leaves none) and the feed the cycle replaced."""
        lines = [[self.code_word("cycle", "off")]]
        if self.motion_mode not in (None, "arc_3point"):
            lines.append([self._g("motion", self.motion_mode)])
        if cyc.feed is not None:
            if self.feed_expr is None:
                raise NotExpressible(f"{cyc.name} with its own feed when the feed before it is unknown")
            lines.append([("F", self.addr("F", self.feed_expr))])
        return lines

    def _cycle_off(self) -> list:
        cyc = self.named_cycle
        self.named_cycle, self.named_active = None, False
        return self._restore(cyc)

    def _named_hole(self, s: n.Motion):
        """A block after MCALL CYCLE8x: it moves to the hole in the plane, then the cycle drills."""
        a1, a2 = {"XY": ("X", "Y"), "ZX": ("Z", "X"), "YZ": ("Y", "Z")}.get(self.plane, ("X", "Y"))
        cyc = self.named_cycle
        if set(s.target) - {a1, a2} or s.center or s.radius is not None or s.via or s.polar \
                or s.machine_coords or s.indirect or s.turns is not None or s.aperture is not None:
            raise NotExpressible(f"a move of {', '.join(sorted(s.target))} while {cyc.name} is called "
                                 "modally (an ISO cycle mode only positions in the plane)")
        if self.motion_mode != "rapid":
            raise NotExpressible(f"a feed move to the hole while {cyc.name} is called modally "
                                 "(an ISO cycle positions at rapid)")
        plane_words = self._axes(s.target)
        ax_pos = self.pos.get(self._drill_axis())
        self.track(s)
        if self.named_active:
            return plane_words
        self.pos[self._drill_axis()] = ax_pos
        if ax_pos is None:
            self.pos.pop(self._drill_axis())
        words = self._cycle_words(cyc, plane_words)
        self.named_active = True
        return words

    def _hole_pattern(self, s: n.CycleCall):
        """HOLES1/HOLES2 as the list of its positions (the modal cycle drills at each)."""
        positions = pattern_positions(s)
        if positions is None:
            raise NotExpressible(f"the hole pattern {s.name or s.kind} with computed arguments")
        a1, a2 = {"XY": ("X", "Y"), "ZX": ("Z", "X"), "YZ": ("Y", "Z")}.get(self.plane, ("X", "Y"))
        lines = _Lines()
        saved = self.motion_mode
        if self.named_cycle is None:
            lines.append([self._g("motion", "rapid")])
            self.motion_mode = "rapid"
        mode = self.motion_mode
        self.motion_mode = "rapid"
        for p1, p2 in positions:
            move = n.Motion({a1: n.AxisValue(n.Num(round(p1, 9) + 0.0)),
                             a2: n.AxisValue(n.Num(round(p2, 9) + 0.0))})
            if self.distance == "incremental":
                raise NotExpressible(f"the hole pattern {s.name} under incremental distances")
            lines.append(self.w_Motion(move) if self.named_cycle is not None else self._axes(move.target))
            if self.named_cycle is None:
                self.track(move)
        self.motion_mode = mode
        if self.named_cycle is None and saved not in (None, "rapid", "arc_3point"):
            lines.append([self._g("motion", saved)])
        self.motion_mode = saved
        self.lowered(f"hole pattern {s.name} written as its {len(positions)} positions")
        return lines

    def w_SubCall(self, s: n.SubCall):
        settings = self.settings_cycle(s)
        if settings is not None:
            return self.w_Passthrough(settings)
        if s.target is not None:
            raise NotExpressible("an indirect call (the called program's name is a string computed as the program runs)")
        self.forget()
        callee = None
        if self.program.dialect != self.dialect and s.name and pl.iso_number(s.name) is None:
            callee = self._callee(s.name)
            if callee is None:
                return self._external_call(s)
        if callee is not None:
            return self._named_call(s, *callee)
        kind = s.kind if s.kind in ("m98", "g65", "g66") else ("g66" if s.modal != "none" else "m98")
        if kind != s.kind:
            self.lowered(f"call of {s.name} written as {self.code_for(*_CALL[kind])}")
        if s.args:
            raise NotExpressible(f"positional arguments of the call to {s.name}")
        words = [self.code_word(*_CALL[kind])]
        prog = self._program_word(s.name, None) if s.name else None
        if s.name and (prog is None or not prog[1:].isdigit()):
            raise NotExpressible(f"a call of {s.name!r} by name (ISO calls O numbers)")
        if prog is not None:
            words.append(("P", "P" + prog[1:]))
        elif "P" in s.named_args:
            words.append(("P", "P" + self.val(s.named_args["P"])))
        if s.repeat is not None:
            words.append(("L", "L" + self.val(s.repeat)))
        if kind == "m98":
            if any(k != "P" for k in s.named_args):
                raise NotExpressible("arguments to an M98 subprogram")
            return words
        sets: dict[int, dict[str, Any]] = {}
        for key, v in s.named_args.items():
            if key == "P":
                continue
            letter = key[0]
            if letter in "IJK" and key[1:].isdigit():
                sets.setdefault(int(key[1:]), {})[letter] = v
            elif len(key) == 1 and key.isalpha():
                words.append(("", self.addr(key, v)))
            else:
                raise NotExpressible(f"macro argument {key!r}")
        for i in sorted(sets):
            for letter in "IJK":
                if letter in sets[i]:
                    words.append(("", self.addr(letter, sets[i][letter])))
        return words

    def _named_call(self, s: n.SubCall, number: int, unit: pl.UnitPlan):
        """A call by name of a subprogram of this program: M98/G65/G66 P<its O number>; positional
        arguments become the G65 letters its parameters were given."""
        if unit.refusal:
            raise NotExpressible(unit.refusal)
        if len(s.args) > len(unit.params):
            raise NotExpressible(f"{len(s.args)} arguments to {s.name}, which takes {len(unit.params)}")
        if s.named_args:
            raise NotExpressible(f"named arguments of the call to {s.name}")
        if s.modal != "none":
            kind = "g66"
        else:
            kind = "g65" if unit.uses_locals else "m98"
        self.lowered(f"call of {s.name} written as {self.code_for(*_CALL[kind])} P{number}")
        return self._call_lines(s, kind, number, unit, self._callee_params(s.name))

    def _external_call(self, s: n.SubCall):
        """A call by name of a subprogram this program does not define: kept as G65 P<the number
        its own file converts to> (pl.stable_number of the name), so the converted caller and the
        converted subprogram file meet; NC404 says the control must provide it. Its parameters
        are laid out as its declaration (Sinumerik EXTERN) says, else as the arguments look:
        array variables by reference in spill slots, other values as G65 letters."""
        if s.named_args or s.kind in ("isocall", "extcall", "pcall"):
            raise NotExpressible(f"a call of {s.name!r} ({s.kind or 'named arguments'}) to a subprogram "
                                 "that is not in this program")
        taken = {num for num in self.sub_numbers.values()}
        taken.update(pl.iso_number(k) for k in self.program.subprograms if pl.iso_number(k) is not None)
        from nctrans.calls import number_of
        number = number_of(s.name)              # L140 is program 140 (nctrans.calls)
        if number is None:
            number = pl.stable_number(s.name, taken)
        params = self._extern_params(s)
        unit = pl.unit_plan(n.Subprogram(s.name, self._where(), [], params), [], self.fresh_label)
        if unit.refusal:
            raise NotExpressible(unit.refusal)
        kind = "g66" if s.modal != "none" else "g65"
        self.diags.append(at_span(
            "NC404", "warning", f"the call of {s.name} is kept as {self.code_for(*_CALL[kind])} P{number}: {s.name} is not in "
            f"this program (a file beside the source is not converted with it), so the target control "
            f"must provide O{number} "
            f"(convert {s.name}'s own file to get it)", self._where()))
        lines = self._call_lines(s, kind, number, unit, params)
        if type(lines) is _Lines and unit.frame and pl.SPILL_BASE + unit.frame <= pl.SPILL_END:
            # the slot past the spilled arguments vacant: where the call's arguments end for a
            # reader of the call (the call event, nctrans.interp.calls._with_spilled)
            at = next(i for i, group in enumerate(lines) if group and group[0][0] != "#")
            lines.insert(at, [("#", f"#[#{pl.SPILL_POINTER}+{pl.SPILL_BASE + unit.frame}]=#0")])
            # and the first slot vacant after it, so a later call passes no stale arguments
            lines.append([("#", f"#[#{pl.SPILL_POINTER}+{pl.SPILL_BASE}]=#0")])
        return lines

    def _extern_params(self, s: n.SubCall) -> list:
        declared = ((self.program.meta or {}).get("extern_params") or {}).get(s.name.upper())
        if declared is not None and len(declared) >= len(s.args):
            return [n.Param(f"P{i}", p.get("type", "REAL"), bool(p.get("by_ref")), list(p.get("dims") or []))
                    for i, p in enumerate(declared)]
        params = []
        for i, arg in enumerate(s.args):
            key = str(arg.key).upper() if type(arg) is n.Var and arg.space == "name" else None
            arr = (self.arrays.get((self.unit, key)) or self.arrays.get((None, key))) if key else None
            if arr is not None and not arg.indices:
                params.append(n.Param(f"P{i}", "REAL", True, list(arr.dims)))
            else:
                params.append(n.Param(f"P{i}"))
        return params

    def _callee_params(self, name: str) -> Optional[list]:
        for key, sub in self.program.subprograms.items():
            if key.upper() == name.upper():
                return sub.params
        return None

    def _call_lines(self, s: n.SubCall, kind: str, number: int, unit: pl.UnitPlan, params):
        """The call and, around it, the spill-stack traffic of its arguments: parameters passed in
        the callee's spill frame are written to #[#149+150+slot] first, by-reference ones read
        back from there after the call."""
        words = [self.code_word(*_CALL[kind]), ("P", f"P{number}")]
        if s.repeat is not None:
            words.append(("L", "L" + self.val(s.repeat)))
        before: list = []
        after: list = []
        for i, (letter, arg) in enumerate(zip(unit.params, s.args)):
            if type(arg) is n.Num and arg.text == "":
                if letter:
                    continue                # an omitted argument stays vacant (the callee reads 0)
                arg = n.Num(0.0)            # a spill slot holds what the last call left there
            if type(arg) is n.Str:
                arg = self._string_argument(s.name, arg)
            if letter:
                words.append(("", self.addr(letter, arg)))
                continue
            prm = params[i]
            offset, size = unit.slots[prm.name.upper()]
            for k, element in enumerate(self._elements(arg, size, s.name)):
                slot = f"#[#{pl.SPILL_POINTER}+{pl.SPILL_BASE + offset + k}]"
                before.append([("#", f"{slot}={self.expr(element)}")])
                if prm.by_ref and type(element) is n.Var:
                    after.append([("#", f"{self.val(element)}={slot}")])
        if not before and not after:
            return words
        return _Lines([*before, words, *after])

    def _string_argument(self, callee: str, arg: n.Str) -> n.Num:
        """A string argument (ISO passes numbers only) as its string number (nctrans.calls), named
        in the table at the top; NC411 says the subprogram must take it so."""
        from nctrans.calls import string_number
        number = string_number(arg.value)
        if self.strings.setdefault(number, arg.value) != arg.value:
            raise NotExpressible(f"the strings {self.strings[number]!r} and {arg.value!r}: both are "
                                 f"string number {number}")
        self.diags.append(at_span(
            "NC411", "warning", f"the string {arg.value!r} passed to {callee} is passed as its string "
            f"number {number} (ISO has no strings): the subprogram the target control provides must "
            "take it so", self._where()))
        return n.Num(float(number))

    def _elements(self, arg, size: int, callee: str) -> list:
        """The argument expressions filling `size` slots: the value itself, or each element of an
        array variable in row-major order."""
        if size == 1:
            return [arg]
        if type(arg) is not n.Var or arg.indices:
            raise NotExpressible(f"an array argument of {callee} that is not an array variable")
        key = str(arg.key).upper()
        arr = self.arrays.get((self.unit, key)) or self.arrays.get((None, key))
        dims = arr.dims if arr is not None else self._slot_dims.get((self.unit, key))
        if dims is None or math.prod(dims) != size:
            raise NotExpressible(f"the argument {arg.key} of {callee}: not an array of {size} elements")
        return [n.Var(arg.space, arg.key, [n.Num(float(i)) for i in idx])
                for idx in itertools.product(*(range(d) for d in dims))]

    def w_ModalCallOff(self, s):
        if self.named_cycle is not None:
            return _Lines(self._cycle_off())
        return [self.code_word("call", "g67")]

    def w_Return(self, s):
        words = [self.code_word("call", "m99")]
        kind = self._source_program_kind() if self.unit is None and s.to_label is None \
            and self.program.dialect != self.dialect else "same"
        if kind == "MPF":
            # another control's return (Sinumerik M17/RET) in a file that is a main program
            # (.MPF, or its %_N_.._MPF header) ends it; an ISO M99 there would restart it endlessly
            self.diags.append(at_span("NC406", "info", "the source returns from its main program "
                                      "here, which ends it: written as M30 (an ISO M99 restarts a "
                                      "main program)", self._where()))
            return [self.code_word("program_end", "end_rewind")]
        if kind is None:
            # a return ending a text that is neither (stdin, no header): run on its own it ends
            # there, but an ISO M99 there restarts it; said, since it may as well be called
            self.diags.append(at_span("NC406", "warning", "the source returns from its main program here, "
                                      "which ends it when run on its own; the M99 written for it "
                                      f"restarts a main program on {self.target_text} (end it with M30 "
                                      "if it is not called as a subprogram)", self._where()))
        if s.to_label is not None:
            words.append(("P", "P" + self._goto_target(s.to_label)))
        pop = self._pop_frame()
        if pop:
            return _Lines([[("#", pop[0])], words])
        return words

    def _source_program_kind(self) -> Optional[str]:
        """"MPF" or "SPF": whether the source file is a main program or a subprogram file, by its
        header (`%_N_.._MPF`) or its name (.MPF/.SPF); None when neither says."""
        meta = self.program.meta if isinstance(self.program.meta, dict) else {}
        kind = str(meta.get("program_type") or "").upper()
        if kind in ("MPF", "SPF"):
            return kind
        suffix = str(self.program.file or "").upper().rpartition(".")[2]
        return suffix if suffix in ("MPF", "SPF") else None

    def w_ProgramEnd(self, s):
        meaning = _PROGRAM_END.get(s.kind, _PROGRAM_END["end_rewind"])
        return [self.code_word(*meaning)]

    def w_Stop(self, s):
        return [self.code_word("stop", "optional" if s.optional else "program")]

    def w_Assign(self, s):
        text = self.assign(s)
        return [("", text)] if text else []

    def w_Goto(self, s: n.Goto):
        target = self.value(s.computed) if s.computed is not None else self._goto_target(s.target)
        if s.cond is not None:
            return [("GOTO", f"IF[{self.cond(s.cond)}]GOTO{target}")]
        return [("GOTO", f"GOTO{target}")]

    def w_SectionRepeat(self, s: n.SectionRepeat):
        raise NotExpressible(f"a program section repetition (REPEAT {s.start}): ISO has no "
                             "repeat of blocks by label")

    def w_Message(self, s):
        self.lowered("message written as an (MSG, ...) comment")
        return [("", self._comment(f"MSG, {self._message_text(s.text)}"))]

    def _message_text(self, e) -> str:
        """A message's text: string parts as they are, values (`"X: " << X`) as the ISO
        expression that holds them in angle brackets, since an ISO comment shows no values."""
        if type(e) is n.Str:
            return e.value
        if type(e) is n.Binary and e.op == "concat":
            return self._message_text(e.left) + self._message_text(e.right)
        self.lowered("a value in a message written as the expression that holds it (the comment "
                     "shows no value)")
        try:
            return f"<{self.expr(e)}>"
        except NotExpressible:
            if type(e) is not n.Var or e.space != "name" or not e.indices:
                raise
            # an element of a global array only shown (a text array, never read as a number):
            # named as the source names it, its indices as ISO expressions
            self.lowered(f"the message value {e.key}[..] (a global array with no ISO place) named "
                         "in the comment", once=("message element", str(e.key).upper()))
            return f"<{e.key}[{','.join(self.expr(i) for i in e.indices)}]>"

    def w_Alarm(self, s):
        """#3000=n with the number moved into the program's own alarms (nctrans.alarm_numbers;
        NC408 where it moves)."""
        self.lowered("alarm written as #3000")
        w = alarm_numbers.written(s, self.table_name, self.program.dialect)
        if w.note:
            self.diags.append(at_span("NC408", "info", w.note, self.span))
        num = self.val(w.number)
        text = ""
        if w.text is not None:
            text = " " + self._comment(w.text.value if type(w.text) is n.Str else self.expr(w.text))
        return [("#3000", f"#3000={num}{text}")]

    def w_VarDecl(self, s: n.VarDecl):
        if s.type in ("STRING", "CHAR", "FRAME", "AXIS"):
            raise NotConvertible(f"a {s.type} variable {s.name} (ISO variables hold numbers only)",
                                 f"DEF {s.type} {s.name}")
        if s.dims:
            return self._array(s)
        var = n.Var("name", s.name)
        plan = self.plans.get(self.unit)
        local = plan.locals.get(s.name.upper()) if plan is not None else None
        if plan is not None and s.name.upper() in plan.slots:
            init = s.init[0] if s.init else n.Num(0.0)
            return [("#", f"{self.var_text(var)}={self.expr(init)}")]
        if local is not None:
            # a G65 local starts vacant; DEF starts at its initial value or 0
            init = s.init[0] if s.init else n.Num(0.0)
            self.lowered(f"local variable {s.name} written as #{local}")
            return [("#", f"#{local}={self.expr(init)}")]
        # DEF without a value starts at 0; a common variable keeps what it held (or is vacant,
        # which a comparison or a G65 argument tells from 0)
        init = s.init[0] if s.init else n.Num(0.0)
        return [("#", f"{self.val(var)}={self.expr(init)}")]

    def _array(self, s: n.VarDecl):
        """A numeric array: a row-major block of common variables, every element set (DEF sets
        them to their initial values or 0; commons keep old values across runs)."""
        dims = list(s.dims)
        if not dims or any(not isinstance(d, int) or d <= 0 for d in dims):
            raise NotConvertible(f"the array {s.name} without constant dimensions (its block of "
                                 "common variables is laid out before the program runs)", f"DEF {s.name}[..]")
        size = 1
        for d in dims:
            size *= d
        base = self.next_array
        if base + size - 1 > pl.COMMON_END:
            raise NotConvertible(f"the array {s.name} ({size} elements): no room left in #500-#999",
                                 f"DEF {s.name}[..]")
        init = list(s.init or [])
        if len(init) > size:
            raise NotExpressible(f"{len(init)} initial values for the array {s.name} of {size}")
        self.next_array += size
        self.arrays[(self.unit, s.name.upper())] = pl.ArrayPlan(base, dims)
        self.lowered(f"array {s.name}[{','.join(map(str, dims))}] stored row-major in "
                     f"#{base}..#{base + size - 1}")
        return _Lines([[("#", f"#{base + i}={self.expr(init[i] if i < len(init) else n.Num(0.0))}")]
                       for i in range(size)])

    def w_ModeSelect(self, s: n.ModeSelect):
        raise NotConvertible(f"a G code of group {s.family} selected by a value computed as the program "
                             "runs (indirect G)", f"G[{s.family}]=..")

    def w_PolarPole(self, s: n.PolarPole):
        raise NotExpressible(f"a polar pole ({s.code or 'G111'}): ISO polar coordinates turn about "
                             "the work zero")

    def w_TravelLimit(self, s: n.TravelLimit):
        self.forget()
        if s.dialect != self.dialect:
            raise NotExpressible(f"travel limits {s.text!r} from {s.dialect or 'the source'} "
                                 f"({s.scope.replace('_', ' ')} limits differ between controls)")
        return [("", s.text)]

    def w_Passthrough(self, s: n.Passthrough):
        self.forget()
        if s.dialect not in ("", self.dialect) and corner_elements.kind_of(s):
            return [("", self._corner_word(s))]
        if s.dialect not in ("", self.dialect):
            from nctrans.interp.unmodelled import no_motion_effect
            from nctrans.interp.spindle_position import is_modelled
            if is_modelled(s):
                return self._spindle_position(s)
            if self._same_in_target(s):
                return [("", s.text)]
            if no_motion_effect(s.reason):
                from nctrans.dialects.base import get
                from nctrans.interp.unmodelled import harmless_elsewhere
                if not harmless_elsewhere(s, get(self.dialect).machine_kind):
                    # an acceleration profile, single-block suppression, a workpiece counter ...:
                    # the path is the same, but what it does on its own control is not done
                    return [("", self._comment(self.foreign_function_comment(s)))]
                # a declaration, preprocessing stop, attribute ...: nothing to do on an ISO control,
                # kept in sight as a comment
                self.lowered(f"{s.dialect} {s.reason} {s.text.strip()!r} kept as a comment (no effect on "
                             "the path)")
                return [("", self._comment(s.text.strip()))]
            raise NotConvertible(f"{s.dialect} text {s.text!r}", s.text.strip())
        return [("", s.text)]

    def _corner_word(self, s: n.Passthrough) -> str:
        """Another dialect's rounding or chamfer as this dialect's `,R` / `,C` where it has the same
        element (rules options.corner_elements); else refused, and lowered to the arc or line."""
        kind = corner_elements.kind_of(s)
        own = {v: k for k, v in corner_elements.settings(self.dialect).get("words", {}).items()}
        word = own.get(kind)
        if word is None:
            raise NotConvertible(f"{s.dialect} {s.reason} {s.text.strip()!r} (no {self.dialect} word for "
                                 "it: the corner is written as the arc or line it inserts)", s.text.strip())
        if not _contour_block(getattr(self, "next_node", None)):
            # the ISO control alarms unless the very next block is a G01/G02/G03 move (seed
            # L4000-4004); the source control may allow blocks between
            raise NotConvertible(f"{s.dialect} {s.reason} {s.text.strip()!r} (the next block is not a "
                                 "contour move, which ISO requires after ,R / ,C: the corner is written "
                                 "as the arc or line it inserts)", s.text.strip())
        if self._corner_unlike_here(s):
            raise NotConvertible(f"{s.dialect} {s.reason} {s.text.strip()!r} (the source control shrinks "
                                 "it to fit or inserts it after blocks that move nothing, where the ISO "
                                 f"control alarms at {own.get(kind, kind)}: the corner is written as the "
                                 "arc or line it inserts)", s.text.strip())
        shrunk = self._corner_shrunk_here(s)
        if shrunk is not None:
            # too large for its blocks: the source control shrinks it (NC229), the ISO control
            # would alarm; the size it shrinks to fits, so the ISO word carries that size
            self.lowered(f"{s.dialect} {s.text.strip()!r} is too large for its blocks: written as "
                         f"{word}{shrunk:g}, the size the source control reduces it to")
            return "," + self.addr(word.lstrip(","), n.Num(shrunk))
        return "," + self.addr(word.lstrip(","), s.value)

    def _corner_shrunk_here(self, s: n.Passthrough):
        """The size the source control shrinks this block's element to, where it shrinks one too
        large for its blocks and this control does not (nctrans.lower.corner_fit); else None."""
        src = corner_elements.settings(s.dialect)
        if src.get("too_large") in (None, corner_elements.settings(self.dialect).get("too_large")):
            return None
        from nctrans.dialects.emit import CONVERSION_MACHINE
        from nctrans.lower.corner_fit import shrunk_corners
        get = CONVERSION_MACHINE.get()
        span = self.span
        if span is None:
            return None
        return shrunk_corners(self.program, get() if get else None).get((span.file, span.line))

    def _corner_unlike_here(self, s: n.Passthrough) -> bool:
        """Whether the source control inserts this block's element in a way the ISO word cannot say
        (nctrans.lower.corner_fit: too large, or across blocks that move nothing)."""
        src = corner_elements.settings(s.dialect)
        mine = corner_elements.settings(self.dialect)
        if all(src.get(k) in (None, mine.get(k)) for k in ("too_large", "zero_length")):
            return False
        from nctrans.dialects.emit import CONVERSION_MACHINE
        from nctrans.lower.corner_fit import unfit_corners
        get = CONVERSION_MACHINE.get()
        span = self.span
        return span is not None and (span.file, span.line) in unfit_corners(self.program, get() if get else None)

    def _spindle_position(self, s: n.Passthrough) -> list:
        """Sinumerik SPOS/SPOSA: M19 positions the spindle at setting data 43240 M19_SPOS (ISO seed
        D.3, 0 degrees by default) and takes no angle, so only an absolute 0 is M19."""
        v = s.value
        if type(v) is n.Func and v.name.upper() in ("AC", "DC", "ACP", "ACN") and len(v.args) == 1:
            v = v.args[0]
        if type(v) is n.Num and v.value % 360.0 == 0.0:
            self.lowered(f"{s.text.strip()!r} written as M19 (which positions the spindle at setting data "
                         "43240 M19_SPOS, 0 degrees by default)")
            return [self.code_word("spindle", "orient")]
        raise NotConvertible(f"spindle positioning {s.text.strip()!r}: ISO M19 positions the spindle at "
                             "one angle only, setting data 43240 M19_SPOS (0 degrees by default), and takes "
                             "no angle word", s.text.strip())

    def _same_in_target(self, s: n.Passthrough) -> bool:
        """Text of another dialect that this dialect's own front end reads as the same construct
        (ISO milling's POPEN/DPRNT in ISO turning: the same macro B words, the same meaning)."""
        from nctrans.dialects.base import get
        own = get(self.dialect)
        if own is None or not s.text.strip() or "\n" in s.text:
            return False
        res = own.parse(s.text, "<passthrough>")
        body = [x for b in res.program.body if isinstance(b, n.Block) for x in b.body]
        return (not res.diagnostics and len(body) == 1 and isinstance(body[0], n.Passthrough)
                and body[0].reason == s.reason)

    def w_DataSetting(self, s: n.DataSetting):
        classes = {("work_offset", False): "2", ("work_offset", True): "20", ("tool_length", False): "10",
                   ("tool_length_wear", False): "11", ("tool_radius", False): "12",
                   ("tool_radius_wear", False): "13"}
        lclass = classes.get((s.kind, s.extended))
        if lclass is None:
            raise NotExpressible(f"data setting {s.kind}")
        words = [self.code_word("nonmodal", "data_setting"), ("L", "L" + lclass), ("P", self.addr("P", s.index))]
        if s.kind == "work_offset":
            words += [(k, self.addr(k, v)) for k, v in s.values.items()]
        elif "value" in s.values:
            words.append(("R", self.addr("R", s.values["value"])))
        return words


def _contour_block(node) -> bool:
    """A block that only moves (a G01/G02/G03 contour move, as far as the block shows): what an ISO
    ,R / ,C must be followed by."""
    if type(node) is not n.Block:
        return False
    moves = False
    for s in node.body:
        t = type(s)
        if t is n.Motion and s.target and not s.machine_coords:
            moves = True
        elif t is n.ModeChange:
            if s.group == "motion" and s.value not in ("linear", "arc_cw", "arc_ccw"):
                return False
        elif t is n.Passthrough and corner_elements.kind_of(s):
            continue
        elif t is not n.Feed:
            return False
    return moves


# SubCall kinds -> the meaning of the code that calls so
_CALL = {"m98": ("call", "m98"), "g65": ("nonmodal", "macro_call"), "g66": ("call", "g66")}
# ProgramEnd kinds -> the meaning of the code that ends a program so (M99: the program restarts)
_PROGRAM_END = {"end": ("program_end", "end"), "end_rewind": ("program_end", "end_rewind"),
                "restart": ("call", "m99")}


def _same(values) -> bool:
    vs = list(values)
    return all(type(v) is n.Num for v in vs) and len({v.value for v in vs}) == 1


def _ms_text(seconds: float) -> Optional[str]:
    """A P text in milliseconds that reads back to exactly `seconds`, or None."""
    ms = seconds * 1000
    for digits in range(0, 10):
        text = format_number(round(ms, digits))
        if float(text) / 1000 == seconds:
            return text
    return None


def emit_program(program: n.Program, emitter: type[IsoEmitter] = IsoEmitter):
    from nctrans.dialects.base import EmitResult
    em = emitter(program)
    text = em.run()
    return EmitResult(text, em.diags)


def _external_offset_number(target: n.Var):
    """ISO's external work offset number (#5201 + axis) of a Sinumerik `$P_EXTFRAME[X,TR]`
    target (nctrans.interp.settable_frames models both as one offset), or None."""
    from nctrans.interp.settable_frames import external_frame_variable
    EXTERNAL = external_frame_variable("sinumerik")
    ix = target.indices or []
    if (str(target.key).upper() != EXTERNAL or len(ix) != 2
            or not all(type(i) is n.Var and i.space == "name" and not i.indices for i in ix)
            or str(ix[1].key).upper() != "TR" or str(ix[0].key).upper() not in ("X", "Y", "Z", "A", "B", "C")):
        return None
    return 5201 + "XYZABC".index(str(ix[0].key).upper())
