"""The interpreter loop: IR Program -> stream of ToolpathRecord (the canonical motions).

How it runs
- Each program or subprogram body is compiled once (cached per Subprogram) into a flat list of
  instructions with jumps, so GOTO to any block number or label works whatever the structure:
  BLOCK (the block's statements, each pre-compiled into a handler + data pair), JUMP, JFALSE
  (conditional jump on a compiled expression), EXEC (a side effect such as a FOR step), CASE.
- Calls keep an explicit stack of frames (no Python recursion), so the loop is one generator:
  records are built into a small buffer per instruction and yielded at once; nothing accumulates.
- Every repeated instruction (a block run again by a loop, jump or call; every control
  instruction) costs one step; straight-line blocks are free, so programs of any length run to
  their end. When `max_steps` is spent, NC205 (an error) names the line and the stream ends.
  ISO M99 in a main program (ProgramEnd "restart") would loop for ever: the interpreter analyses
  the one pass and stops with NC205 (a warning: everything in the program was analysed).
- Block-skip blocks (`/`) run, as with LinuxCNC's rs274 (block delete switch off).

Coordinates (all mm): program point -> programmable frame (frames.py) -> work point -> + G92 +
work offset + tool length -> machine point. Records are in machine coordinates. The start of a
record is the end dict of the previous motion record (shared, never mutated).

Arcs: `turns` is the number of EXTRA full turns (LinuxCNC ARC_FEED |rotation| - 1); an arc whose
start equals its end in the plane is a full circle. `center` holds the plane's two axes plus the
normal axis at the arc's end height (as tests/rs274.py reads LinuxCNC).

flatten_hook(record, work_end, work_center): called for every record in stream order, just before
it is yielded; for motion records work_end / work_center are the end point / centre in WORK
coordinates (after the programmable frame, before work offset, G92 and tool length), else None.
"""
from __future__ import annotations

import math
import re
from collections import deque
from itertools import islice
from typing import Any, Callable, Iterator, Optional

from nctrans.diagnostics import at_span
from nctrans.interp import arcs
from nctrans.interp.evaluate import (UNKNOWN, AxisName, EvalError, Evaluator, FrameValue, Scope,
                                     constant)
from nctrans.interp.frames import PLANE_AXES, Offsets, ProgrammableFrame
from nctrans.interp.lathe import TURNING_KINDS, LatheMixin
from nctrans.interp.run_checks import RunChecks
from nctrans.interp.state import LINEAR_AXES, ModalState
from nctrans.interp.travel_limits import ProgrammedLimits
from nctrans.interp import ggroups, indirect_g, rigid_tap, sections, sysvars, unmodelled
from nctrans.ir import nodes as n
from nctrans.ir.vocabulary import UNMODELLED_LIMITS, UNMODELLED_MODES
from nctrans import plainrun
from nctrans.plainrun import JsonChunk, PlainRun
from nctrans.toolpath import ToolpathRecord
from nctrans.toolpath_io import _spell, _str as _json_str    # the kernel writes as the writer does

from nctrans.interp.cutter_comp import CutterCompensator, PlannedMove
from nctrans.interp.milling_cycles import run_milling_cycle
from nctrans.interp.cycles import (coarse_pitch, cycle_table, deep_hole_steps, expand_cycle, hole_pattern,
                                   plane_cycle_levels, swivel_plan, tap_steps, unmodelled_cycle)

BLOCK, JUMP, JFALSE, EXEC, CASE, PLAIN = range(6)
SHARED_SCOPE_CALLS = frozenset(("m98", "shared"))
MAX_CALL_DEPTH = 16
STREAM_BATCH = 256          # blocks of a streamed main body compiled at a time
PLAIN_EXPAND = 64           # blocks of a PlainRun expanded at a time when the kernel cannot run it
KERNEL_BLOCKS = 4096        # blocks per kernel call: its JSON text (~1 MB) is all it holds
MOVE_KINDS = frozenset(("rapid", "linear", "arc"))
NORMAL = {"XY": "Z", "ZX": "Y", "YZ": "X"}
ROT_AXIS = NORMAL
_LABEL_NUM = re.compile(r"^N?0*(\d+)$")
_PROG_NUM = re.compile(r"^[OoPp]?0*(\d+)$")
LENGTH_WORDS = LINEAR_AXES | frozenset("IJK")     # words converted by inch mode
CYCLE_LENGTH_KEYS = frozenset(("bottom", "r_plane", "retract_plane", "safety", "peck", "shift",
                               "depth_rel", "first_peck", "decrement", "min_peck", "relief"))


def label_key(text: Any) -> Any:
    """Block numbers compare numerically ("0100" == "N100" == 100); labels by upper-case name."""
    s = str(text).strip()
    if s.isdigit():
        return int(s)
    m = _LABEL_NUM.match(s.upper())
    if m:
        return int(m.group(1))
    return s.upper()


def program_key(name: str) -> str:
    """Subprogram names compare without the O and leading zeros when numeric ("O0100" == "100")."""
    s = str(name).strip()
    m = _PROG_NUM.match(s)
    if m:
        return "#" + str(int(m.group(1)))
    return s.upper()


class Unit:
    """A compiled program body: instructions, label positions, parameters.
    save: the subprogram has the SAVE attribute (modal G codes and frames restored on return)."""
    __slots__ = ("name", "code", "labels", "params", "file", "seen", "save")

    def __init__(self, name: str, file: str, params: list):
        self.name = name
        self.file = file
        self.code: list[tuple] = []
        self.labels: dict[Any, list[int]] = {}
        self.params = params
        self.seen = bytearray()
        self.save = False


class Frame:
    """A call-stack entry: where to resume in the caller, and how to repeat the callee.
    saved: the caller's modal state and frames, restored on return from a SAVE subprogram."""
    __slots__ = ("unit", "pc", "sidx", "scope", "callee", "repeats", "args", "make_scope", "modal",
                 "saved", "section")

    def __init__(self, unit, pc, sidx, scope, callee, repeats, make_scope, modal=False, saved=None,
                 section=False):
        self.unit, self.pc, self.sidx, self.scope = unit, pc, sidx, scope
        self.callee, self.repeats, self.make_scope, self.modal = callee, repeats, make_scope, modal
        self.saved = saved
        self.section = section      # a repeated program section (REPEAT), not a call level


# Modal groups a SAVE subprogram does not restore: not G codes (spindle, coolant, tool length),
# or state whose restoring mid-path would need its own approach (cutter compensation, cycles).
NOT_SAVED_GROUPS = frozenset(("spindle", "coolant", "tool_length", "cutter_comp", "cycle"))
SAVED_ATTRS = ("motion", "plane", "incremental", "arc_absolute", "scale", "feed_scale", "feed_mode",
               "work_offset", "cycle_retract")


def copy_frame(src: ProgrammableFrame, dst: Optional[ProgrammableFrame] = None) -> ProgrammableFrame:
    """A copy of a programmable frame (dicts copied, tuples shared), or `src` copied into `dst`."""
    if dst is None:
        dst = ProgrammableFrame.__new__(ProgrammableFrame)
    for slot in ProgrammableFrame.__slots__:
        v = getattr(src, slot)
        setattr(dst, slot, dict(v) if type(v) is dict else v)
    return dst


class _Stop(Exception):
    """Internal: end the whole run (program end, alarm)."""


def _default_cutting_edge(dialect) -> int:
    """The D number a tool brings when none is programmed (rules/<dialect>.toml
    options.default_cutting_edge; 0: none, G41/G42 without D compensate by zero)."""
    from nctrans.rules import load_table
    try:
        return int(load_table(dialect).options.get("default_cutting_edge", 0) or 0)
    except Exception:       # no table of that name (a test dialect): no default edge
        return 0


class Interpreter(LatheMixin, RunChecks):
    def __init__(self, program: n.Program, machine=None, *, diagnostics: list, resolver=None,
                 max_steps: Optional[int] = None, flatten_hook=None, preload=(), fast_sink=None):
        if max_steps is None:
            from nctrans import limits
            max_steps = limits.setting("MAX_STEPS", limits.MAX_STEPS)
        if machine is None:
            from nctrans.machine import default_mill
            machine = default_mill()
        self.program = program
        self.machine = machine
        self.diags = diagnostics
        self._reported: set = set()
        self.resolver = resolver
        self.max_steps = max_steps
        self.hook = flatten_hook
        # "jsonl": the consumer takes JsonChunk items (already written records) among the records;
        # "discard": it drops records unseen (lint). Either lets the native kernel run PlainRuns.
        self.native = plainrun.native       # read per run: tests switch the kernel off
        self.fast_sink = fast_sink if self.native is not None else None
        defaults = program.meta.get("defaults") if isinstance(program.meta, dict) else None
        self.st = ModalState(defaults if isinstance(defaults, dict) else None)
        self.default_edge = _default_cutting_edge(program.dialect)
        self.ev = Evaluator()
        self.frame = ProgrammableFrame()
        self.off = Offsets()
        self.travel_limits: Optional[ProgrammedLimits] = None     # set by the first TravelLimit
        if self.st.work_offset:
            self.off.set_work(self._work_offset(self.st.work_offset))
        # machine position (last emitted end) and the same point in program coordinates
        self.mpos: dict[str, float] = ({"X": 0.0, "Z": 0.0} if getattr(machine, "kind", "") == "lathe"
                                       else {"X": 0.0, "Y": 0.0, "Z": 0.0})
        self.pos: dict[str, float] = {}
        self._resync()
        self.out: list = []
        self._hookq: deque = deque()
        self.units: dict[int, Unit] = {}
        self.sub_index: dict[str, tuple[n.Subprogram, str]] = {}
        self._index_subprograms(program)
        self._resolved: dict[str, Any] = {}
        self.compilers = self._compiler_table()
        # runtime flags
        self.moved = False
        self.feed_reported = False
        # NC209: the program itself stopped the spindle (M5), not the power-on state: programs
        # that never mention the spindle (fragments, subprograms, machines without one) are not
        # flagged. Moves then take the Python path, which reports the first feed move once.
        self.spindle_stopped = False
        self.spindle_reported = False
        self.comp_d_reported = False      # NC208 once per G41/G42 without a D word
        self.last_from: Optional[dict] = None     # previous move (tangent of Sinumerik CT)
        self.last_arc = None
        self.comp = None
        self.comp_radius = 0.0
        self.comp_exit = False
        self.modal_call = None          # (SubCall, args snapshot, depth)
        self.cycle_params: dict[str, float] = {}
        self.cycle_initial: Optional[float] = None
        self.modal_cycle = None         # CycleCall with modal=True
        self.pole: Optional[tuple[float, float]] = None   # polar pole in the plane (program coords)
        self.unmodelled_motion: Optional[str] = None       # unmodelled motion code in force (G34 ...)
        self._unmodelled_at = None                          # the span of the block that set it
        self.spelt_codes: dict[str, str] = {}   # neutral group -> the code spelt last ($P_GG)
        self.stack: list[Frame] = []
        self.sections = 0               # REPEAT section frames on the stack (not call levels)
        self.in_modal = 0               # frames of the modal subprogram (MCALL/G66) on the stack
        self.span: Optional[n.Span] = None
        self._rc_init()                 # run_checks: NC210-NC214
        self._register_system()
        for prog in preload or ():
            self._preload(prog)

    def _preload(self, prog: n.Program) -> None:
        """Run the declarations of a definition file (Sinumerik GUD *.DEF) as global variables
        before the program starts. Their own errors belong to that file's lint, not this run."""
        ev = self.ev
        stack = list(prog.body)
        for sub in (prog.subprograms or {}).values():
            stack.extend(sub.body)
        for node in stack:
            if type(node) is not n.Block:
                continue
            for st in node.body:
                if type(st) is n.VarDecl:
                    try:
                        ev.declare(st, scope="global")
                    except EvalError:
                        pass

    # ================================================================ diagnostics
    def diag(self, rule: str, severity: str, message: str, span=None) -> None:
        """Report once per place: a loop over a faulty block gives one diagnostic, not thousands."""
        sp = span or self.span
        key = (rule, message, sp.file if sp else None, sp.line if sp else 0, sp.col if sp else 0)
        if key in self._reported:
            return
        self._reported.add(key)
        self.diags.append(at_span(rule, severity, message, sp))

    # ================================================================ compile
    def _index_subprograms(self, program: n.Program) -> None:
        for name, sub in (program.subprograms or {}).items():
            self.sub_index.setdefault(program_key(name), (sub, program.file))
            self.sub_index.setdefault(program_key(sub.name), (sub, program.file))

    def unit_for(self, key: int, name: str, body: list, file: str, params: list) -> Unit:
        unit = self.units.get(key)
        if unit is None:
            unit = Unit(name, file, params)
            self._emit_nodes(body, unit)
            unit.seen = bytearray(len(unit.code))
            self.units[key] = unit
        return unit

    def _emit_nodes(self, nodes_: list, unit: Unit) -> None:
        code = unit.code
        for node in nodes_:
            t = type(node)
            if t is n.Block:
                # statements compile on first execution (see run): the first record of a huge
                # program comes after one cheap flattening pass, not a full compile
                pc = len(code)
                code.append((BLOCK, None, node, node.span))
                if node.number is not None and node.number != "":
                    unit.labels.setdefault(label_key(node.number), []).append(pc)
                if node.label:
                    unit.labels.setdefault(label_key(node.label), []).append(pc)
            elif t is PlainRun:
                code.append(_plain_entry(node))
            elif t is n.If:
                j = len(code)
                code.append(None)
                self._emit_nodes(node.then, unit)
                if node.orelse:
                    k = len(code)
                    code.append(None)
                    code[j] = (JFALSE, self._cond(node.cond), len(code), node.span)
                    self._emit_nodes(node.orelse, unit)
                    code[k] = (JUMP, len(code), None, node.span)
                else:
                    code[j] = (JFALSE, self._cond(node.cond), len(code), node.span)
            elif t is n.While:
                top = len(code)
                code.append(None)
                self._emit_nodes(node.body, unit)
                code.append((JUMP, top, None, node.span))
                code[top] = (JFALSE, self._cond(node.cond), len(code), node.span)
                if node.label:
                    unit.labels.setdefault(label_key(node.label), []).append(top)
            elif t is n.Loop:
                top = len(code)
                self._emit_nodes(node.body, unit)
                code.append((JUMP, top, None, node.span))
            elif t is n.RepeatUntil:
                top = len(code)
                self._emit_nodes(node.body, unit)
                code.append((JFALSE, self._cond(node.cond), top, node.span))
            elif t is n.ForLoop:
                init, test, incr = self._for_parts(node)
                code.append((EXEC, init, None, node.span))
                top = len(code)
                code.append(None)
                self._emit_nodes(node.body, unit)
                code.append((EXEC, incr, None, node.span))
                code.append((JUMP, top, None, node.span))
                code[top] = (JFALSE, test, len(code), node.span)
            elif t is n.Case:
                subj = self.ev.compile(node.subject)
                branches = [(self.ev.compile(v), lab) for v, lab in node.branches]
                code.append((CASE, (subj, branches, node.default), None, node.span))

    def _compile_block(self, block: n.Block) -> list:
        out = []
        comp = self.compilers
        trigger = False
        for s in block.body:
            c = comp.get(type(s))
            if c is not None:
                if type(s) is n.Passthrough and unmodelled.takes_motion(s):
                    out.insert(0, c(s))      # it owns the block's axis words: before the motion
                    continue
                out.append(c(s))
            t = type(s)
            if (t is n.ModeChange and s.group == "motion" and s.value in ("rapid", "linear")) or \
                    t is n.Feed or t is n.SpindleSpeed:
                trigger = True
        if trigger:
            out.append((self._h_mcall_trigger, None))
        return out

    def _h_mcall_trigger(self, _):
        """Sinumerik MCALL also calls after a block without path motion that programs G0/G1, or S
        or F while G0/G1 is active (seed L5076-5080); ISO G66 calls after moves only."""
        mc = self.modal_call
        if mc is not None and mc[0].kind == "mcall" and self.st.motion in ("rapid", "linear"):
            self.moved = True

    def _cond(self, expr) -> Callable[[], Any]:
        f = self.ev.compile(expr)

        def cond():
            v = f()
            if v is UNKNOWN:
                self.diag("NC107", "info", "condition depends on a value unknown at analysis "
                          "time; taken as false")
                return False
            return bool(v) if v is not None else False
        return cond

    def _for_parts(self, node: n.ForLoop):
        ev = self.ev
        get = ev.compile(node.var)
        put = ev.compile_store(node.var)
        start, end = ev.compile(node.start), ev.compile(node.end)
        step = ev.compile(node.step) if node.step is not None else (lambda: 1.0)

        def init():
            put(start())

        def test():
            s, v, e = step(), get(), end()
            if UNKNOWN in (s, v, e):
                return False
            return (v or 0) <= (e or 0) if (s or 0) >= 0 else (v or 0) >= (e or 0)

        def incr():
            put((get() or 0) + (step() or 0))
        return init, test, incr

    def _compiler_table(self) -> dict:
        return {
            n.ModeChange: self._c_mode, n.Motion: self._c_motion, n.Feed: self._c_feed,
            n.SpindleSpeed: self._c_speed, n.ToolSelect: self._c_tool,
            n.ToolChange: lambda s: (self._h_toolchange, s), n.OffsetSelect: self._c_offset,
            n.Dwell: self._c_dwell, n.SetPosition: lambda s: (self._h_setpos, s),
            n.ResetSetPosition: lambda s: (self._h_resetpos, s),
            n.FrameOp: lambda s: (self._h_frame, s), n.HomeReturn: lambda s: (self._h_home, s),
            n.CycleParams: lambda s: (self._h_cycle_params, s),
            n.CycleCall: lambda s: (self._h_cycle_call, s), n.SubCall: lambda s: (self._h_call, s),
            n.ModalCallOff: lambda s: (self._h_modal_off, s), n.Return: lambda s: (self._h_return, s),
            n.ProgramEnd: lambda s: (self._h_end, s), n.Stop: lambda s: (self._h_stop, s),
            n.Assign: self._c_assign, n.VarDecl: lambda s: (self._h_decl, s),
            n.Goto: self._c_goto, n.Alarm: lambda s: (self._h_alarm, s),
            n.DataSetting: lambda s: (self._h_data, s),
            n.PolarPole: lambda s: (self._h_pole, s),
            n.ModeSelect: lambda s: (lambda d: indirect_g.select_mode(self, d), (s, self.ev.compile(s.index))),
            n.SectionRepeat: lambda s: (self._h_section, (s, None if s.count is None
                                                           else self.ev.compile(s.count))),
            n.Passthrough: self._c_passthrough,
            n.SpindleLimit: lambda s: (self._h_spindle_limit, s),
            n.TravelLimit: lambda s: (self._h_travel_limit, (s, self._words(s.values), self._words(s.corner))),
        }

    # ================================================================ helpers
    def _value(self, f, what: str) -> Optional[float]:
        """Evaluate a compiled expression that must be a number; None if vacant/unknown."""
        v = f()
        if v is None:
            return None
        if v is UNKNOWN:
            self.diag("NC107", "info", f"{what} depends on a value unknown at analysis time; "
                      "the word is ignored")
            return None
        if isinstance(v, str):
            raise EvalError("NC104", f"string used as {what}")
        v = float(v)
        if v - v != 0.0:                 # infinity or NaN: never let it reach a record
            raise EvalError("NC108", f"{what} is {v} (out of range)")
        return v

    def _words(self, d: Optional[dict]) -> tuple:
        """Pre-compile axis words: (axis, constant|None, closure, mode)."""
        if not d:
            return ()
        out = []
        AV, Num = n.AxisValue, n.Num
        for axis, av in d.items():
            if type(av) is AV:
                expr, mode = av.value, av.mode
            else:
                expr, mode = av, None
            c = float(expr.value) if type(expr) is Num else constant(expr)
            if c is not None and c - c != 0.0:      # infinite/NaN constant: an error when it runs
                out.append((axis.upper(), None, _non_finite(axis, c), mode))
                continue
            if type(expr) is Num:
                out.append((axis.upper(), c, None, mode))
                continue
            out.append((axis.upper(), c, None if c is not None else self.ev.compile(expr), mode))
        return tuple(out)

    def _eval_words(self, words: tuple) -> list:
        """[(axis, value in mm/deg, mode)] with vacant words dropped."""
        scale = self.st.scale
        diameter = self.st.diameter
        out = []
        for axis, c, f, mode in words:
            if type(axis) is not str:
                axis = self._indirect_axis(axis())
            v = c if c is not None else self._value(f, f"{axis} word")
            if v is None:
                continue
            if axis in LENGTH_WORDS:
                v *= scale
            if diameter and axis == "X":        # the toolpath holds the radius (lathe.py)
                v *= 0.5
            out.append((axis, v, mode))
        return out

    @staticmethod
    def _indirect_axis(value: Any) -> str:
        """The axis of AX[expr]: an axis name (a DEF AXIS variable, $P_AXN3, X)."""
        if isinstance(value, str) and value.strip():
            return value.strip().upper()
        raise EvalError("NC104", f"AX[..] needs an axis name, not {value!r}")

    def _target(self, vals: list) -> dict[str, float]:
        """Program-coordinate target of evaluated words from the current point."""
        tgt = dict(self.pos)
        inc_default = self.st.incremental
        for axis, v, mode in vals:
            cur = tgt.get(axis)
            if cur is None:
                cur = self._new_axis(axis)
                tgt[axis] = cur
            inc = inc_default if mode is None else mode == "inc"
            tgt[axis] = cur + v if inc else v
        return tgt

    def _new_axis(self, axis: str) -> float:
        """First use of an axis: it was at machine 0; add it to the machine and program points."""
        self.mpos = dict(self.mpos)
        self.mpos[axis] = 0.0
        self._resync()
        return self.pos[axis]

    def _resync(self) -> None:
        """Program point from the machine point (after an offset or frame change)."""
        tot = self.off.total
        work = {a: v - tot.get(a, 0.0) for a, v in self.mpos.items()}
        self.pos = self.frame.to_program(work)

    def _to_machine(self, p: dict[str, float]) -> dict[str, float]:
        w = p if self.frame.identity else self.frame.to_work(p)
        tot = self.off.total
        if not tot:
            return dict(w)
        return {a: v + tot.get(a, 0.0) for a, v in w.items()}

    def _work_offset(self, name: str) -> dict[str, float]:
        if name.upper() == "G53":
            return {}
        return self.machine.work_offset(name)

    # ================================================================ records
    def _record(self, kind: str, **kw) -> None:
        rec = ToolpathRecord(0, self.span.file if self.span else self.program.file,
                             self.span.line if self.span else 1, kind, **kw)
        if self.comp is not None:
            self._comp_out(self.comp.push(rec))
        else:
            self.out.append(rec)
            if self.hook is not None:
                self._hookq.append(None)

    def _move(self, kind: str, end: dict[str, float], center=None, cw=None, turns=None) -> None:
        """Emit a move from the current program point to `end` (program coords); update position."""
        if self.watch and self.capture is None:
            self._rc_move(kind, end)
        start = self.pos
        self.pos = end
        if self.capture is not None:            # reading a turning contour: no motion
            self.capture.append((kind, start, end, center, cw, self.span))
            return
        if self.css_surface is not None:
            self._css_move(end)
        self.last_from = start
        self.last_arc = (center, cw) if kind == "arc" else None
        if self.comp_exit or self.comp is not None or (
                self.st.comp_side != "off" and self.comp_radius):
            if self._comp_move(kind, start, end, center, cw, turns):
                return
        elif self.st.comp_side != "off" and not self.st.radius_index:
            self._comp_without_offset(kind, start, end, center, cw, turns)
            return
        self._finish_move(kind, start, end, center, cw, turns, self._payload())

    def _comp_without_offset(self, kind, start, end, center, cw, turns) -> None:
        """G41/G42 on with no D word. Where the dialect's table names the cutting edge a tool
        brings by default (options.default_cutting_edge, Sinumerik D1), compensate with it as if
        written; else the controller compensates by zero: NC208, and the move runs as programmed."""
        edge = self.default_edge
        if edge:
            self.st.radius_index = edge
            self.comp_radius = self.machine.radius_offset(edge)
            if self.comp_radius and self._comp_move(
                    kind, start, end, center, cw, turns):
                return
        elif not self.comp_d_reported:
            self.comp_d_reported = True
            self.diag("NC208", "error", f"cutter compensation ({self.st.comp_side}) is on but no D word "
                      "selects a radius offset: the tool runs on the programmed contour uncompensated")
        self._finish_move(kind, start, end, center, cw, turns, self._payload())

    def _payload(self) -> tuple:
        sp = self.span
        st = self.st
        return (sp.file if sp else self.program.file, sp.line if sp else 1, st.feed, st.feed_mode,
                st.spindle_speed, st.tool, st.plane)

    def _finish_move(self, kind, start, end, center, cw, turns, payload, start_given=False) -> None:
        file, line, feed, feed_mode, speed, tool, plane = payload
        mend = self._to_machine(end)
        mstart = self._to_machine(start) if start_given else self.mpos
        if len(mstart) != len(mend):
            mstart = {**{a: mend[a] for a in mend if a not in mstart}, **mstart}
        if kind == "rapid":
            rec = ToolpathRecord(0, file, line, "rapid", mstart, mend, spindle=speed, tool=tool)
        else:
            rec = ToolpathRecord(0, file, line, "linear" if kind == "linear" else "arc", mstart,
                                 mend, feed=feed, feed_mode=feed_mode, spindle=speed, tool=tool)
        if self.css_surface is not None:    # constant surface speed, for `check` to judge
            rec.css, rec.spindle_limit = self.css_surface, self.css_limit
            rec.css_axis = mend.get("X", 0.0) - end.get("X", 0.0)
        mc = None
        if kind == "arc":
            a1, a2, an = PLANE_AXES[plane]
            cprog = {a1: center[0], a2: center[1], an: end.get(an, 0.0)}
            full = dict(end)
            full.update(cprog)
            mfull = self._to_machine(full)
            mc = {a1: mfull[a1], a2: mfull[a2], an: mfull[an]}
            rec.center = mc
            rec.plane = plane
            rec.direction = ("cw" if cw else "ccw") if not self.frame.mirror_swap else (
                "ccw" if cw else "cw")
            rec.turns = turns
        self.mpos = mend
        self.out.append(rec)
        if self.hook is not None:
            tot = self.off.total
            work = {a: v - tot.get(a, 0.0) for a, v in mend.items()}
            wc = None if mc is None else {a: v - tot.get(a, 0.0) for a, v in mc.items()}
            self._hookq.append((work, wc))

    # ---------------------------------------------------------------- cutter compensation
    def _comp_move(self, kind, start, end, center, cw, turns) -> bool:
        pm = PlannedMove(kind=kind, start=start, end=end,
                         center=None if center is None else self._center_dict(center, end),
                         direction=None if cw is None else ("cw" if cw else "ccw"),
                         turns=turns, payload=self._payload())
        if self.comp_exit:
            comp, self.comp, self.comp_exit = self.comp, None, False
            if comp is not None:
                self._comp_out(comp.finish(pm), comp)
                return True
            return False
        if self.comp is None:
            side = self.st.comp_side
            r = self.comp_radius
            if r < 0:           # a negative stored radius swaps the side
                side, r = ("right" if side == "left" else "left"), -r
            self.comp = self._compensator(side, r)     # lathe.py: the tool-nose tip
        self._comp_out(self.comp.push(pm))
        return True

    def _center_dict(self, center, end) -> dict[str, float]:
        a1, a2, an = PLANE_AXES[self.st.plane]
        return {a1: center[0], a2: center[1], an: end.get(an, 0.0)}

    def _comp_out(self, items, comp=None) -> None:
        comp = comp or self.comp
        probs = getattr(comp, "problems", None)
        if probs:
            from nctrans.diagnostics import Diagnostic
            for payload, msg in probs:
                file, line = (payload[0], payload[1]) if isinstance(payload, tuple) else (
                    self.program.file, 1)
                self.diags.append(Diagnostic("NC204", "error", msg, file, line))
            probs.clear()
        for it in items:
            if isinstance(it, PlannedMove):
                c = it.center
                plane = it.payload[6]
                a1, a2, _ = PLANE_AXES[plane]
                cc = None if c is None else (c[a1], c[a2])
                cw = None if it.direction is None else it.direction == "cw"
                self._finish_move(it.kind, it.start, it.end, cc, cw, it.turns, it.payload,
                                  start_given=True)
            else:
                self.out.append(it)
                if self.hook is not None:
                    self._hookq.append(None)

    def _comp_flush(self) -> None:
        if self.comp is not None:
            comp, self.comp = self.comp, None
            self._comp_out(comp.finish(None), comp)

    # ================================================================ statement compilers/handlers
    def _c_mode(self, s: n.ModeChange):
        return (self._h_mode, s)

    def _h_mode(self, s: n.ModeChange):
        st = self.st
        g, v = s.group, s.value
        self._rc_mode(g, v)
        if s.code:
            self.spelt_codes[g] = s.code
        if g == "motion":
            if st.cycle != "off":
                self._cycle_off()
            st.set(g, v)
            self.unmodelled_motion = None
        elif g == "cycle":
            self.unmodelled_motion = None
            if v == "off":
                self._cycle_off()
            else:
                if st.cycle == "off" or self.cycle_initial is None:
                    self.cycle_initial = self.pos.get(NORMAL[st.plane], 0.0)
                st.set(g, v)
        elif g == "work_offset":
            st.set(g, v)
            self.off.set_work(self._work_offset(v))
            self._resync()
        elif g == "tool_length":
            st.set(g, v)
            self._apply_length()
        elif g == "cutter_comp":
            prev = st.comp_side
            st.set(g, v)
            if v != prev:
                self.comp_d_reported = False
            if v == "off" and prev != "off" and self.comp is not None:
                self.comp_exit = True
            elif v != "off" and self.comp is not None and prev != v:
                # side switch while active: finish with the next move, restart after
                self.comp_exit = True
        elif g == "spindle":
            st.set(g, v)
            self.spindle_stopped = v == "off"
            self.spindle_reported = False
            self._record("spindle", spindle_dir=v, spindle=st.spindle_speed)
        elif g == "coolant":
            st.set(g, v)
            self._record("coolant", coolant=v)
        elif g == "units":
            st.set(g, v)
        elif g == "plane":
            st.set(g, v)
        elif g == "spindle_mode":
            st.set(g, v)
            self._css_mode(v)
        else:
            st.set(g, v)
        left_out = UNMODELLED_MODES.get((g, v))
        if left_out is not None:
            self.diag("NC220", "warning", f"{s.code or g + '=' + v} is not modelled ({left_out})")

    def _cycle_off(self) -> None:
        self.st.set("cycle", "off")
        self.cycle_params = {}
        self.cycle_initial = None

    def _apply_length(self) -> None:
        st = self.st
        if st.length_mode == "off":
            z = 0.0
        else:
            idx = st.length_index if st.length_index is not None else st.tool
            z = self.machine.length_offset(int(idx)) if idx else 0.0
            if st.length_mode == "minus":
                z = -z
        self.off.set_tool(z)
        self._resync()
        if self.travel_limits is not None:      # limits on the tool tip follow its length
            self._send_limits()

    def _c_feed(self, s: n.Feed):
        c = constant(s.value)
        f = None if c is not None else self.ev.compile(s.value)
        return (self._h_feed, (c, f))

    def _h_feed(self, d):
        c, f = d
        v = c if c is not None else self._value(f, "feed")
        if v is None:
            return
        if v < 0:
            self.diag("NC105", "error", f"negative feed {v:g}")
            return
        st = self.st
        st.feed = v if st.feed_mode == "inverse_time" else v * st.feed_scale
        self.feed_reported = False
        self._rc_feed_set()

    def _c_speed(self, s: n.SpindleSpeed):
        return (self._h_speed, self.ev.compile(s.value))

    def _h_speed(self, f):
        v = self._value(f, "spindle speed")
        if v is None:
            return
        if v < 0:
            self.diag("NC105", "error", f"negative spindle speed {v:g}")
            return
        st = self.st
        if st.groups.get("spindle_mode") == "css" and self._css_applies():
            v = self._css_speed_word(v)
        changed = v != st.spindle_speed
        st.spindle_speed = v
        if changed and st.spindle_dir in ("cw", "ccw"):
            self._record("spindle", spindle_dir=st.spindle_dir, spindle=v)

    def _c_tool(self, s: n.ToolSelect):
        return (self._h_tool, self.ev.compile(s.tool))

    def _h_tool(self, f):
        raw = f()
        if isinstance(raw, str):          # Sinumerik tool management: T="DRILL"
            self.st.tool_selected = self._named_tool(raw)
            return
        v = self._value(lambda: raw, "tool number")
        if v is not None:
            self.st.tool_selected = int(round(v))

    def _named_tool(self, name: str) -> int:
        """The number of a tool selected by name: the machine's tool with that `name`, else a
        stable number of its own above the machine's tools (reported once as NC107)."""
        key = name.strip().upper()
        numbers = self.__dict__.setdefault("_tool_names", {})
        if key not in numbers:
            tools = getattr(self.machine, "tools", None) or []
            match = next((t.number for t in tools if str(getattr(t, "name", "")).upper() == key), None)
            if match is None:
                match = max([t.number for t in tools] + [0] + list(numbers.values())) + 1
                self.diag("NC107", "info", f"tool {name!r} is not named in the machine's tool table; "
                          f"analysed as tool {match} with no geometry")
            numbers[key] = match
        return numbers[key]

    def _h_toolchange(self, s):
        st = self.st
        self._rc_tool_change()
        if st.tool_selected is None:
            self.diag("NC105", "warning", "tool change without a selected tool")
        st.tool = st.tool_selected
        self._record("tool_change", tool=st.tool)

    def _c_offset(self, s: n.OffsetSelect):
        return (self._h_offset, (s.kind, self.ev.compile(s.index)))

    def _h_offset(self, d):
        kind, f = d
        v = self._value(f, "offset number")
        if v is None:
            return
        i = int(round(v))
        if kind == "length":
            self.st.length_index = i
            if self.st.length_mode != "off":
                self._apply_length()
        else:
            self.st.radius_index = i
            self.comp_radius = self.machine.radius_offset(i) if i else 0.0

    def _c_dwell(self, s: n.Dwell):
        sec = None if s.seconds is None else self.ev.compile(s.seconds)
        rev = None if s.revolutions is None else self.ev.compile(s.revolutions)
        return (self._h_dwell, (sec, rev))

    def _h_dwell(self, d):
        sec, rev = d
        t = 0.0
        if sec is not None:
            t = self._value(sec, "dwell") or 0.0
        elif rev is not None:
            r = self._value(rev, "dwell") or 0.0
            s = self.st.spindle_speed
            if not s:
                self.diag("NC105", "warning", "dwell in revolutions with no spindle speed")
                t = 0.0
            else:
                t = r * 60.0 / s
        if t < 0:
            self.diag("NC105", "error", f"negative dwell {t:g}")
            return
        self._record("dwell", dwell_s=t)

    def _c_assign(self, s: n.Assign):
        v = s.value
        if type(v) is n.Func and v.name.upper() in ("SET", "REP") and s.target.indices:
            return (self._h_exec, self.ev.compile_assign(s.target, v))
        return (self._h_assign, (self.ev.compile_store(s.target), self.ev.compile(s.value)))

    @staticmethod
    def _h_exec(f):
        f()

    def _h_assign(self, d):
        put, f = d
        put(f())

    def _h_decl(self, s: n.VarDecl):
        self.ev.declare(s)

    def _c_goto(self, s: n.Goto):
        cond = None if s.cond is None else self._cond(s.cond)
        return (self._h_goto, (label_key(s.target), s.direction, cond))

    def _h_goto(self, d):
        target, direction, cond = d
        if cond is not None and not cond():
            return None
        return ("goto", target, direction)

    def _h_return(self, s: n.Return):
        return ("return", s.to_label)

    def _h_end(self, s: n.ProgramEnd):
        if s.kind == "restart" and self.stack:
            # M99 at the end of a file's main body that was called as a subprogram: a return
            return ("return", None)
        self._comp_flush()
        self._record("stop", stop_kind="end")
        if s.kind == "restart" and not self.stack:
            self.diag("NC205", "warning", f"analysis truncated at line {self.span.line}: the "
                      "program restarts (return in a main program); one pass analysed")
        raise _Stop

    def _h_stop(self, s: n.Stop):
        self._record("stop", stop_kind="optional" if s.optional else "stop")

    def _h_alarm(self, s: n.Alarm):
        """Sinumerik SETAL(n), Fanuc #3000=n (message): the control stops with alarm n (NC221)."""
        try:
            num = self.ev.compile(s.number)()
            text = None if s.text is None else self.ev.compile(s.text)()
        except EvalError:
            num, text = "?", None
        if isinstance(num, float) and num == int(num):
            num = int(num)
        if num is UNKNOWN:
            num = "(unknown number)"
        what = f": {text}" if isinstance(text, str) and text else ""
        self.alarm = (n.Num(float(num)) if isinstance(num, (int, float)) else s.number,
                      n.Str(text) if isinstance(text, str) and text else None, self.span)
        self.diag("NC221", "error", f"the program raises alarm {num}{what}; the control stops "
                  "here, so the analysis ends at this line")
        raise _Stop

    def _h_data(self, s):
        """G10 data setting: write work offsets or tool-offset registers into the machine copy."""
        vals = {}
        for k, e in s.values.items():
            v = self._value(self.ev.compile(e), f"{k} value")
            if v is not None:
                vals[k.upper()] = v
        idx = self._value(self.ev.compile(s.index), "offset number")
        if idx is None:
            return
        idx = int(round(idx))
        inc = self.st.incremental
        if self.machine is not None and not getattr(self, "_machine_copied", False):
            self.machine = self.machine.copy()
            self._machine_copied = True
        m = self.machine
        if s.kind == "work_offset":
            if s.extended:
                name = f"G54.1P{idx}"
            elif idx == 0:
                name = "EXT"
            elif 1 <= idx <= 6:
                name = f"G{53 + idx}"
            else:
                self.diag("NC105", "error", f"work offset number {idx} out of range")
                return
            cur = dict(m.offsets.get(name, {}))
            for a, v in vals.items():
                v *= self.st.scale if a in LINEAR_AXES else 1.0
                cur[a] = cur.get(a, 0.0) + v if inc else v
            m.offsets[name] = cur
            if self.st.work_offset and self.st.work_offset.upper() == name:
                self.off.set_work(self._work_offset(name))
                self._resync()
        elif s.kind.startswith("tool_"):
            v = vals.get("VALUE", 0.0) * self.st.scale
            store = m.length_offsets if "length" in s.kind else m.radius_offsets
            old = store.get(idx, m.length_offset(idx) if "length" in s.kind else m.radius_offset(idx))
            store[idx] = old + v if inc else v

    # ---------------------------------------------------------------- motion
    def _c_motion(self, s: n.Motion):
        if (s.center is None and s.radius is None and s.turns is None and not s.polar
                and not s.machine_coords and s.via is None and s.aperture is None
                and not s.indirect):
            fast = []
            AV, Num = n.AxisValue, n.Num
            for axis, av in s.target.items():
                if type(av) is AV and type(av.value) is Num and av.mode in (None, "abs", "inc") \
                        and float(av.value.value) - float(av.value.value) == 0.0:
                    a = axis.upper()
                    fast.append((a, float(av.value.value), av.mode, a in LINEAR_AXES))
                else:
                    break
            else:
                return (self._h_fast, [tuple(fast), s, None])
        return (self._h_motion, self._c_motion_full(s))

    def _c_motion_full(self, s: n.Motion) -> tuple:
        words = self._words(s.target)
        if s.indirect:
            words += tuple((self.ev.compile(axis), None, self.ev.compile(av.value), av.mode)
                           for axis, av in s.indirect)
        center = self._words(s.center)
        radius = None if s.radius is None else self.ev.compile(s.radius)
        turns = None if s.turns is None else self.ev.compile(s.turns)
        polar = None
        if s.polar:
            polar = {k: self.ev.compile(v) for k, v in s.polar.items()}
        via = self._words(s.via)
        ap = getattr(s, "aperture", None)
        aperture = None if ap is None else self.ev.compile(ap)
        return (words, center, radius, turns, s.machine_coords, polar, via, aperture)

    def _slow(self, d):
        full = d[2]
        if full is None:
            full = d[2] = self._c_motion_full(d[1])
        return self._h_motion(full)

    def _h_fast(self, d):
        """The hot path: a rapid/linear move with literal words and no frame, comp or cycle."""
        words = d[0]
        st = self.st
        if (st.cycle != "off" or self.modal_cycle is not None or self.comp is not None
                or self.comp_exit or st.comp_side != "off" or not self.frame.identity
                or self.unmodelled_motion is not None or st.diameter
                or self.css_surface is not None or self.spindle_stopped or self.watch):
            return self._slow(d)
        motion = st.motion
        if motion == "rapid":
            feed = None
        elif motion == "linear":
            feed = st.feed
            if not feed:
                self._need_feed()
        else:
            return self._slow(d)
        self.moved = True
        if not words:
            return None
        tgt = self.pos.copy()
        scale = st.scale
        inc = st.incremental
        for axis, v, mode, lin in words:
            if lin and scale != 1.0:
                v = v * scale
            cur = tgt.get(axis)
            if cur is None:                  # first use of an axis: the general path adds it
                return self._slow(d)
            if (inc if mode is None else mode == "inc"):
                v += cur
            tgt[axis] = v
        self.last_from = self.pos
        self.last_arc = None
        self.pos = tgt
        tot = self.off.total
        mend = {a: v + tot.get(a, 0.0) for a, v in tgt.items()} if tot else tgt.copy()
        mstart = self.mpos
        self.mpos = mend
        sp = self.span
        if feed is None:
            rec = ToolpathRecord(0, sp.file, sp.line, "rapid", mstart, mend, None, None, None,
                                 None, None, None, st.spindle_speed, st.tool)
        else:
            rec = ToolpathRecord(0, sp.file, sp.line, "linear", mstart, mend, None, None, None,
                                 None, feed, st.feed_mode, st.spindle_speed, st.tool)
        self.out.append(rec)
        if self.hook is not None:
            self._hookq.append(({a: v - tot.get(a, 0.0) for a, v in mend.items()}, None))
        return None

    def _h_motion(self, d):
        words, center, radius, turns, machine, polar, via, aperture = d
        st = self.st
        if self.unmodelled_motion is not None:
            if self._unmodelled_at is self.span:
                return                  # the code's own block: reported with the code
            self.diag("NC220", "warning", f"motion under {self.unmodelled_motion} is not modelled: "
                      "this block's axis words move nothing in the analysed toolpath")
            return
        self.moved = True
        vals = self._eval_words(words)
        if polar:
            vals = self._polar(vals, polar)
        if self.modal_cycle is not None and st.cycle == "off" and not machine:
            self._motion_plain(vals, d)
            if any(a in PLANE_AXES[st.plane][:2] for a, _, _ in vals):
                self._run_cycle_call(self.modal_cycle)
            return
        if st.cycle != "off" and not machine:
            self._cycle_hole(vals)
            return
        if machine:
            self._machine_move(vals)
            return
        self._motion_plain(vals, d)

    def _motion_plain(self, vals, d):
        _, center, radius, turns, _, _, via, aperture = d
        st = self.st
        motion = st.motion
        if motion == "rapid":
            if vals:
                self._move("rapid", self._target(vals))
            return
        if motion == "linear":
            if vals:
                self._need_feed()
                self._move("linear", self._target(vals))
            return
        if motion == "thread":
            if vals:
                self._g33_move(vals, center)
            return
        if motion in rigid_tap.MODES:
            if vals:
                rigid_tap.rigid_tap_move(self, vals, center, motion)
            return
        if motion in ("arc_cw", "arc_ccw"):
            self._arc(vals, center, radius, turns, motion == "arc_cw", aperture)
            return
        if motion == "arc_3point":
            self._arc_3point(vals, via)
            return
        if motion == "arc_tangent":
            self._arc_tangent(vals)
            return
        if vals:
            self.diag("NC207", "error", "axis words while no motion mode is active")

    def _need_feed(self) -> None:
        st = self.st
        if not st.feed and not self.feed_reported:
            self.feed_reported = True
            self.diag("NC202", "error", "feed move with no feed rate programmed")
        if self.spindle_stopped and not self.spindle_reported:
            self.spindle_reported = True
            self.diag("NC209", "warning", "feed move while the spindle is stopped (M5, or a tool change that stops it): the tool "
                      "would rub or break; start the spindle (M3/M4) before cutting")

    def _g33_move(self, vals, center) -> None:
        """G33: a feed synchronised with the spindle, `lead` mm per revolution: the feed is
        lead x S and the record carries the lead (pitch). The lead is the I/J/K word of the
        block (Sinumerik, LinuxCNC, Fagor: the one of the axis that travels furthest when
        several are given), else the F word in a dialect whose table says F is the lead
        (`[options] thread_lead = "feed"`: ISO seed 4.5 `G33 Z.. F<lead>`)."""
        st = self.st
        target = self._target(vals)
        leads = {a: abs(v) for a, v, _ in self._eval_words(center)} if center else {}
        lead = None
        if leads:
            travel = {w: abs(target.get(a, 0.0) - self.pos.get(a, 0.0))
                      for w, a in (("I", "X"), ("J", "Y"), ("K", "Z"))}
            lead = leads[max(leads, key=lambda w: travel.get(w, 0.0))]
        elif self._thread_lead_is_feed():
            lead = st.feed if st.feed and st.feed_mode != "inverse_time" else None   # mm
        if not lead:
            self.diag("NC206", "error", "thread move (G33) without a lead: the move is not made")
            return
        if not st.spindle_speed:
            self.diag("NC209", "warning", "thread move (G33) with no spindle speed: the feed "
                      "(lead x S) is unknown")
        saved, saved_mode = st.feed, st.feed_mode
        st.feed = lead * st.spindle_speed if st.spindle_speed else None
        st.feed_mode = "per_min"
        mark = len(self.out)
        try:
            self._move("linear", target)
        finally:
            st.feed, st.feed_mode = saved, saved_mode
        for rec in self.out[mark:]:
            rec.pitch = lead

    def _thread_lead_is_feed(self) -> bool:
        v = getattr(self, "_lead_is_feed", None)
        if v is None:
            try:
                from nctrans.rules import load_table
                v = load_table(self.program.dialect).options.get("thread_lead") == "feed"
            except Exception:          # no table for this dialect
                v = False
            self._lead_is_feed = v
        return v

    def _polar(self, vals, polar):
        """Polar words (radius, angle in the active plane about the pole: program zero until
        G110/G111/G112 sets one). A word left out keeps its value from the current point."""
        a1, a2, _ = PLANE_AXES[self.st.plane]
        r = self._value(polar["radius"], "polar radius") if "radius" in polar else None
        ang = self._value(polar["angle"], "polar angle") if "angle" in polar else None
        if r is None and ang is None:
            return vals
        c1, c2 = self.pole or (0.0, 0.0)
        p1, p2 = self.pos.get(a1, 0.0) - c1, self.pos.get(a2, 0.0) - c2
        if r is None:
            r = math.hypot(p1, p2)
        else:
            r *= self.st.scale
        if ang is None:
            ang = math.degrees(math.atan2(p2, p1))
        rest = [w for w in vals if w[0] not in (a1, a2)]
        return rest + [(a1, c1 + r * math.cos(math.radians(ang)), "abs"),
                       (a2, c2 + r * math.sin(math.radians(ang)), "abs")]

    def _c_passthrough(self, s: n.Passthrough):
        if unmodelled.no_motion_effect(s.reason, getattr(self.machine, "kind", "mill")) or \
                s.reason in unmodelled.REPORTED_AS_ERROR:
            return (self._h_known, None)
        return (self._h_unmodelled, (s, unmodelled.takes_motion(s)))

    @staticmethod
    def _h_known(_):
        """A construct known to have no effect on the programmed path."""

    def _h_unmodelled(self, d):
        s, code = d
        what = f"{s.text!r}" + (f" ({s.reason})" if s.reason else "")
        if code is not None:
            self.unmodelled_motion = code
            self._unmodelled_at = self.span
            self.diag("NC220", "warning", f"{what} is not modelled: its axis words, and those of "
                      "the blocks after it until the next motion code, move nothing in the analysed "
                      "toolpath")
        else:
            self.diag("NC220", "warning", f"{what} is not modelled: the analysed toolpath leaves "
                      "it out")
        if s.reason in UNMODELLED_LIMITS:       # tell the machine check it cannot judge these
            self._record("limits", zone="unmodelled")

    def _h_travel_limit(self, d) -> None:
        """Programmed travel limits (travel_limits.py): nothing moves; `limits` records tell the
        machine check. Values are lengths in program units, X as a radius."""
        s, words, corner = d
        if self.travel_limits is None:
            self.travel_limits = ProgrammedLimits(getattr(self.machine, "axes", None))
        scale = self.st.scale

        def values(ws):
            out = {}
            for axis, c, f, _mode in ws:
                v = c if c is not None else self._value(f, f"{axis} limit")
                if v is not None:
                    out[axis] = v * scale if axis in LENGTH_WORDS else v
            return out
        self.travel_limits.apply(s.kind, s.scope, values(words), values(corner), s.incremental)
        self._send_limits()

    def _send_limits(self) -> None:
        for kw in self.travel_limits.pending(self.off.tool_z):
            self._record("limits", **kw)

    def _h_pole(self, s: n.PolarPole) -> None:
        """G110/G111/G112: the pole relative to the last programmed point, the workpiece zero or
        the last pole, whatever G90/G91 (spec 9.2); given by plane axis words or by polar words
        about that point. Nothing moves."""
        a1, a2, _ = PLANE_AXES[self.st.plane]
        if s.relative_to == "last_point":
            ref = (self.pos.get(a1, 0.0), self.pos.get(a2, 0.0))
        elif s.relative_to == "pole":
            ref = self.pole or (0.0, 0.0)
        else:
            ref = (0.0, 0.0)
        if s.polar:
            polar = {k: self.ev.compile(v) for k, v in s.polar.items()}
            r = self._value(polar["radius"], "pole radius") if "radius" in polar else None
            ang = self._value(polar["angle"], "pole angle") if "angle" in polar else None
            r = (r or 0.0) * self.st.scale
            ang = math.radians(ang or 0.0)
            self.pole = (ref[0] + r * math.cos(ang), ref[1] + r * math.sin(ang))
            return
        d = {a1: 0.0, a2: 0.0}
        for axis, v, _ in self._eval_words(self._words(s.target)):
            if axis in d:
                d[axis] = v
        self.pole = (ref[0] + d[a1], ref[1] + d[a2])

    def _machine_move(self, vals) -> None:
        """G53: the words are machine coordinates of the controlled point, this block only."""
        mend = dict(self.mpos)
        for a, v, _ in vals:
            mend[a] = v
        kind = "linear" if self.st.motion == "linear" else "rapid"
        if kind == "linear":
            self._need_feed()
        tot = self.off.total
        end = self.frame.to_program({a: v - tot.get(a, 0.0) for a, v in mend.items()})
        self._move(kind, end)

    def _arc_3point(self, vals, via) -> None:
        """Sinumerik CIP: the circle through start, intermediate point and end."""
        a1, a2, _ = PLANE_AXES[self.st.plane]
        start = self.pos
        end = self._target(vals)
        mid = self._target(self._eval_words(via)) if via else None
        self._need_feed()
        if mid is None:
            self.diag("NC203", "error", "3-point arc without an intermediate point")
            return
        p = [(q.get(a1, 0.0), q.get(a2, 0.0)) for q in (start, mid, end)]
        (x1, y1), (x2, y2), (x3, y3) = p
        den = 2 * (x1 * (y2 - y3) + x2 * (y3 - y1) + x3 * (y1 - y2))
        if abs(den) < 1e-12:
            self.diag("NC203", "error", "3-point arc through collinear points")
            return
        s1, s2, s3 = x1 * x1 + y1 * y1, x2 * x2 + y2 * y2, x3 * x3 + y3 * y3
        cx = (s1 * (y2 - y3) + s2 * (y3 - y1) + s3 * (y1 - y2)) / den
        cy = (s1 * (x3 - x2) + s2 * (x1 - x3) + s3 * (x2 - x1)) / den
        cw = ((x2 - x1) * (y3 - y2) - (y2 - y1) * (x3 - x2)) < 0
        self._move("arc", end, (cx, cy), cw, 0)

    def _tangent(self) -> Optional[tuple[float, float]]:
        a1, a2, _ = PLANE_AXES[self.st.plane]
        e1, e2 = self.pos.get(a1, 0.0), self.pos.get(a2, 0.0)
        if self.last_arc is not None:
            (c1, c2), cw = self.last_arc
            r1, r2 = e1 - c1, e2 - c2
            t = (r2, -r1) if cw else (-r2, r1)
        elif self.last_from is not None:
            t = (e1 - self.last_from.get(a1, 0.0), e2 - self.last_from.get(a2, 0.0))
        else:
            return None
        ln = math.hypot(*t)
        return None if ln < 1e-12 else (t[0] / ln, t[1] / ln)

    def _arc_tangent(self, vals) -> None:
        """Sinumerik CT: an arc leaving tangentially from the previous path."""
        a1, a2, _ = PLANE_AXES[self.st.plane]
        t = self._tangent()
        end = self._target(vals)
        self._need_feed()
        s1, s2 = self.pos.get(a1, 0.0), self.pos.get(a2, 0.0)
        d1, d2 = end.get(a1, 0.0) - s1, end.get(a2, 0.0) - s2
        if t is None:
            self.diag("NC203", "error", "tangential arc without a previous direction")
            return
        nl = (-t[1], t[0])                       # left normal
        dn = d1 * nl[0] + d2 * nl[1]
        if abs(dn) < 1e-12:                      # end straight ahead: a line
            self._move("linear", end)
            return
        k = (d1 * d1 + d2 * d2) / (2 * dn)
        self._move("arc", end, (s1 + k * nl[0], s2 + k * nl[1]), k < 0, 0)

    def _arc(self, vals, center, radius, turns, cw, aperture=None) -> None:
        st = self.st
        plane = st.plane
        a1, a2, an = PLANE_AXES[plane]
        start = self.pos
        end = self._target(vals)
        s1, s2 = start.get(a1, 0.0), start.get(a2, 0.0)
        e1, e2 = end.get(a1, 0.0), end.get(a2, 0.0)
        inch = st.scale != 1.0
        if center:
            self._rc_arc(center)
        nturns = 0
        if turns is not None:
            t = self._value(turns, "turns")
            if t is not None:
                nturns = max(int(round(t)), 0)
        self._need_feed()
        try:
            if aperture is not None:
                ang = self._value(aperture, "opening angle")
                if ang is None or not 0 < ang < 360:
                    raise arcs.ArcError(f"arc opening angle {ang} outside 0..360")
                cvals = self._eval_words(center)
                if cvals and not any(a in (a1, a2) for a, _, _ in vals):
                    # centre + angle: the end is the start turned about the centre
                    cd = {a: v for a, v, _ in cvals}
                    ci = {"I": "X", "J": "Y", "K": "Z"}
                    c1, c2 = s1, s2
                    for a, v in cd.items():
                        ax = ci.get(a, a)
                        absolute = dict((w, m == "abs") for w, _, m in cvals)[a] or st.arc_absolute
                        if ax == a1:
                            c1 = v if absolute else s1 + v
                        elif ax == a2:
                            c2 = v if absolute else s2 + v
                    phi = math.radians(-ang if cw else ang)
                    r1, r2 = s1 - c1, s2 - c2
                    end = dict(end)
                    end[a1] = c1 + r1 * math.cos(phi) - r2 * math.sin(phi)
                    end[a2] = c2 + r1 * math.sin(phi) + r2 * math.cos(phi)
                    self._move("arc", end, (c1, c2), cw, nturns)
                    return
                half = math.hypot(e1 - s1, e2 - s2) / 2
                r = half / math.sin(math.radians(ang) / 2)
                c1, c2 = arcs.center_from_radius(s1, s2, e1, e2, r if ang <= 180 else -r, cw, inch)
            elif radius is not None:
                r = self._value(radius, "arc radius")
                if r is None:
                    raise arcs.ArcError("arc radius is vacant")
                c1, c2 = arcs.center_from_radius(s1, s2, e1, e2, r * st.scale, cw, inch)
            else:
                cvals = self._eval_words(center)
                if not cvals:
                    raise arcs.ArcError("arc without centre or radius")
                c1, c2 = s1, s2
                cd = {a: v for a, v, _ in cvals}
                absolute = {a: (m == "abs") if m else st.arc_absolute for a, _, m in cvals}
                ci = {"X": "X", "Y": "Y", "Z": "Z", "I": "X", "J": "Y", "K": "Z"}
                for a, v in cd.items():
                    ax = ci.get(a, a)
                    if ax == a1:
                        c1 = v if absolute[a] else s1 + v
                    elif ax == a2:
                        c2 = v if absolute[a] else s2 + v
                err = arcs.check_center(s1, s2, e1, e2, c1, c2, inch)
                if err:
                    raise arcs.ArcError(err)
        except arcs.ArcError as ex:
            self.diag("NC203", "error", str(ex))    # the controller alarms: no motion
            if st.diameter:
                self._radius_x_check(vals, center, radius, cw)
            return
        self._move("arc", end, (c1, c2), cw, nturns)

    # ---------------------------------------------------------------- cycles
    def _h_cycle_params(self, s: n.CycleParams):
        scale = self.st.scale
        for k, e in s.values.items():
            v = self._value(self.ev.compile(e), f"cycle {k}")
            if v is None:
                continue
            self.cycle_params[k] = v * scale if k in CYCLE_LENGTH_KEYS else v

    def _cycle_hole(self, vals) -> None:
        st = self.st
        plane = st.plane
        a1, a2, ax = PLANE_AXES[plane]
        p = self.cycle_params
        repeat = p.pop("repeat", 1)
        for a, v, mode in vals:
            if a == ax:
                p["bottom"] = v
        if not vals and "bottom" not in p:
            return
        missing = [k for k in ("bottom", "r_plane") if k not in p]
        if missing:
            self.diag("NC206", "error", f"canned cycle without {' and '.join(missing)}")
            return
        self._rc_cycle()
        initial = self.cycle_initial if self.cycle_initial is not None else self.pos.get(ax, 0.0)
        if st.incremental:
            zr = initial + p["r_plane"]
            zb = zr + p["bottom"]
        else:
            zr, zb = p["r_plane"], p["bottom"]
        retract = initial if st.cycle_retract == "initial" else zr
        plane_vals = [(a, v, m) for a, v, m in vals if a != ax]
        hole = self._target(plane_vals)
        hole[ax] = self.pos.get(ax, 0.0)
        step = None
        if st.incremental:
            step = {a: v for a, v, m in plane_vals if m != "abs"}
        self._expand(st.cycle, hole, zr, zb, retract, p, int(round(repeat)), step)

    def _position_at(self) -> str:
        mode = self.__dict__.get("_cycle_positioning")
        if mode is None:
            mode = self._cycle_positioning = cycle_table().position_at(self.program.dialect)
        return mode

    def _expand(self, kind, hole, approach, bottom, retract, p, repeat=1, step=None,
                steps=None) -> None:
        st = self.st
        feed = p.get("feed")
        feed = feed * st.feed_scale if feed is not None else (st.feed or 0.0)
        if not feed:
            self._need_feed()
        if repeat < 1:
            return
        if steps is None:
            steps = expand_cycle(kind, plane=st.plane, position=dict(self.pos), hole=hole,
                                 approach=approach, bottom=bottom, retract=retract,
                                 peck=p.get("peck"), dwell_s=p.get("dwell"), shift=p.get("shift"),
                                 feed=feed, spindle_dir=st.spindle_dir, units_mm=st.scale == 1.0,
                                 repeat=repeat, step=step, position_at=self._position_at())
        elif callable(steps):
            steps = steps(feed)
        pitch = None
        if kind in ("tap", "tap_left"):
            pitch = p.get("pitch")
            if pitch is None:
                pitch = feed if st.feed_mode == "per_rev" else (
                    feed / st.spindle_speed if st.spindle_speed else None)
        saved = st.feed
        st.feed = feed
        try:
            for s in steps:
                k = s[0]
                if k in ("rapid", "linear"):
                    pt = dict(self.pos)
                    pt.update(s[1])
                    mark = len(self.out)
                    self._move(k, pt)
                    if pitch is not None and k == "linear":
                        for rec in self.out[mark:]:
                            rec.pitch = pitch     # tapping: the feed is the spindle's times the lead
                elif k == "feed":
                    st.feed = s[1]
                elif k == "dwell":
                    self._record("dwell", dwell_s=float(s[1] or 0.0))
                elif k == "spindle":         # the cycle turns it (tapping reversal, CYCLE84 SDAC)
                    st.set("spindle", s[1])
                    self.spindle_stopped = s[1] in ("off", "orient")
                    self._record("spindle", spindle_dir=s[1], spindle=st.spindle_speed)
                elif k == "stop":
                    self._record("stop", stop_kind="stop")
        finally:
            st.feed = saved
        if kind == "bore_manual":        # the operator retracted by hand (see cycles.py)
            ax = PLANE_AXES[st.plane][2]
            pos = dict(self.pos)
            pos[ax] = max(retract, approach) if approach >= bottom else min(retract, approach)
            self.pos = pos
            self.mpos = self._to_machine(pos)

    def _h_cycle_call(self, s: n.CycleCall):
        if s.kind in TURNING_KINDS:
            return self._turning_cycle(s)
        if s.name and s.kind != "swivel_plane" and self._find_unit(s.name) is not None:
            return self._cycle_code(s)
        if s.kind in ("holes_line", "holes_circle", "holes_grid"):
            return self._hole_pattern(s)
        if s.kind == "swivel_plane":
            self._swivel_plane(s)
            return
        if s.kind == "milling":
            return run_milling_cycle(self, s)
        if s.modal:
            self.modal_cycle = s
            return
        self._run_cycle_call(s)

    def _cycle_code(self, s: n.CycleCall):
        """A cycle whose own code is in the program or beside it (CYCLE81.SPF on the search
        path): the control runs that code, so the interpreter calls it with the call's
        arguments in their places (omitted ones as the control passes them) instead of the
        built-in model. MCALL makes it a modal call like any subprogram's."""
        table = cycle_table()
        spec = ({c.name: c for c in table.cycle} | {p.name: p for p in table.pattern}
                | {m.name: m for m in table.milling}).get(s.name.upper())
        params = list(spec.params) if spec is not None else []
        args = [s.params.get(table.neutral(p), n.Num(0.0, "")) for p in params]
        unit = self._find_unit(s.name)          # a PROC declaring fewer parameters than the table
        given = [i for i, p in enumerate(params) if table.neutral(p) in s.params]
        keep = max(len(unit.params) if unit is not None and unit.params else len(args),
                   given[-1] + 1 if given else 0)
        args = args[:keep]
        if s.modal:
            call = n.SubCall(s.name, args, modal="after_move", kind="mcall")
            self.modal_cycle = None
            self.modal_call = (call, self._call_args(call), self._depth())
            return None
        return ("call", n.SubCall(s.name, args, kind="proc"))

    def _hole_pattern(self, s: n.CycleCall):
        """Sinumerik HOLES1/HOLES2/CYCLE801: the modally called cycle at each position of the
        pattern (only positioning when no cycle is modal). Under a modal subprogram call (MCALL
        of a PROC, such as a CYCLE81.SPF beside the program) the positions run as blocks of
        their own, so the call follows each of them as it follows any block that moves."""
        pat = {p.name: p for p in cycle_table().pattern}.get((s.name or "").upper())
        if pat is None:
            self.diag("NC103", "warning", f"hole pattern {s.name or s.kind} is not known")
            return
        args = []
        for p in pat.params:
            e = s.params.get(p.lower())
            args.append(None if e is None else self._value(self.ev.compile(e), p))
        a1, a2, _ = PLANE_AXES[self.st.plane]
        sc = self.st.scale
        holes = hole_pattern(pat.name, args)
        if self.modal_call is not None and self.modal_cycle is None and holes:
            positions = Unit(pat.name, self.span.file if self.span else "", [])
            positions.code = [(BLOCK, [(self._h_pattern_position, (a1, a2, p1 * sc, p2 * sc))],
                               None, self.span) for p1, p2 in holes]
            positions.seen = bytearray(b"\x01" * len(holes))
            return ("pattern", positions)
        for p1, p2 in holes:
            hole = dict(self.pos)
            hole[a1], hole[a2] = p1 * sc, p2 * sc
            self._move("rapid", hole)        # the pattern's positioning block, even when there
            if self.modal_cycle is not None:
                self._run_cycle_call(self.modal_cycle)

    def _h_pattern_position(self, d) -> None:
        """One position of a hole pattern under a modal subprogram call: a rapid in the plane."""
        a1, a2, p1, p2 = d
        hole = dict(self.pos)
        hole[a1], hole[a2] = p1, p2
        self.moved = True
        self._move("rapid", hole)            # a positioning block, even when already there

    def _run_cycle_call(self, s: n.CycleCall, hole: Optional[dict] = None) -> None:
        st = self.st
        ax = PLANE_AXES[st.plane][2]
        params = {}
        for k, e in s.params.items():
            v = self._value(self.ev.compile(e), f"cycle {k}")
            if v is not None:
                params[k] = v * st.scale if k in CYCLE_LENGTH_KEYS else v
        if "bottom" not in params and "depth_rel" not in params:
            self.diag("NC206", "error", f"cycle {s.name or s.kind} without a depth")
            return
        approach, bottom, retract = plane_cycle_levels(params, current=self.pos.get(ax, 0.0))
        self._rc_cycle()
        steps = None
        if hole is not None and any(abs(hole.get(a, 0.0) - self.pos.get(a, 0.0)) > 0
                                    for a in PLANE_AXES[st.plane][:2]):
            self._move("rapid", {**self.pos, **{a: hole[a] for a in PLANE_AXES[st.plane][:2]}})
        hole = dict(self.pos)
        kind = s.kind
        if kind in ("peck", "chip_break") and "peck" not in params:
            steps = self._deep_hole(params, approach, bottom, retract)
        elif kind in ("tap", "tap_left"):
            kind, steps = self._tap(s, params, approach, bottom, retract)
            if steps is None:
                return
        self._expand(kind, hole, approach, bottom, retract, params, steps=steps)

    def _tap(self, s: n.CycleCall, p: dict, approach: float, bottom: float, retract: float):
        """CYCLE84/CYCLE840: lead from PIT, else from the M size MPIT; its sign gives the hand;
        feed = lead * S (spindle-synchronised)."""
        st = self.st
        lead = p.get("pit") or None
        if lead is None and p.get("mpit"):
            lead = coarse_pitch(p["mpit"])
            if lead is not None and p["mpit"] < 0:
                lead = -lead
        if lead is None:
            self.diag("NC206", "error", f"{s.name or 'tapping cycle'} without a thread pitch "
                      "(PIT) or a known thread size (MPIT)")
            return s.kind, None
        kind = "tap_left" if lead < 0 else "tap"
        lead = abs(lead) * (st.scale if "pit" in p and p.get("pit") else 1.0)
        if not st.spindle_speed:
            self.diag("NC206", "error", f"{s.name or 'tapping cycle'} with no spindle speed")
            return kind, None
        p["pitch"] = lead
        p["feed"] = lead * st.spindle_speed / st.scale
        after = {3: "cw", 4: "ccw", 5: "off"}.get(int(p.get("sdac", 0) or 0))
        steps = tap_steps(plane=st.plane, approach=approach, bottom=bottom, retract=retract,
                          dwell_s=p.get("dwell"), forward="ccw" if kind == "tap_left" else "cw",
                          after=after)
        return kind, steps

    def _deep_hole(self, p: dict, approach: float, bottom: float, retract: float):
        """CYCLE83 infeeds from FDEP/FDPR and DAM (cycles.deep_hole_steps)."""
        rfp = p.get("r_plane", 0.0)
        up = 1.0 if approach >= bottom else -1.0
        first = p.get("first_peck")
        if "fdpr" in p:
            first = rfp - up * abs(p["fdpr"] * self.st.scale)
        vari = int(p.get("vari", 0) or 0)
        vari = 1 if vari % 10 == 1 else 0
        anticipation = p.get("_dis1")     # _DIS1: re-approach distance (VARI=1), a length
        if anticipation is not None:
            anticipation *= self.st.scale

        def make(feed: float):
            return deep_hole_steps(plane=self.st.plane, vari=vari, approach=approach, rfp=rfp,
                                   bottom=bottom, retract=retract, first=first,
                                   decrement=p.get("decrement", 0.0), dwell_bottom=p.get("dwell"),
                                   dwell_top=p.get("dts"), relief=p.get("relief"), feed=feed,
                                   first_factor=p.get("frf"), anticipation=anticipation)
        return make

    def _swivel_plane(self, s: n.CycleCall) -> None:
        """Sinumerik CYCLE800 [GK]: retract in machine coordinates (_FR), then the programmable
        frame becomes TRANS(_X0..) : AROT(axis by axis) : ATRANS(_X1..) (_ST 1: composed on the
        current frame). Rotary axes are not positioned: that needs the machine's swivel data
        record (kinematics), which the machine model does not hold (NC107 info)."""
        params: dict[str, Any] = {}
        for k, e in s.params.items():
            if k == "swivel_record":
                v = self.ev.compile(e)()
                params[k] = None if v is None or v is UNKNOWN else v
            else:
                v = self._value(self.ev.compile(e), f"CYCLE800 {k}")
                if v is not None:
                    params[k] = v
        plan = swivel_plan(params)
        self._swivel_retract(plan)
        if plan.mode != "axis":
            self.diag("NC107", "info", f"CYCLE800 swivel mode {plan.mode!r} (_MODE "
                      f"{int(params.get('swivel_mode', 0))}) needs the machine's swivel data record "
                      "and is not interpreted; the programmable frame is kept")
            return
        if plan.rotations:
            rec = params.get("swivel_record")
            self.diag("NC107", "info", f"rotary axis positioning needs the swivel data record "
                      f"{str(rec or '')!r} (machine kinematics, not in the machine model); the rotary "
                      "axes are not moved, only the programmable frame is swivelled")

        def op(kind: str, vals: dict[str, float], additive: bool) -> None:
            self._h_frame(n.FrameOp(kind, {a: n.Num(v) for a, v in vals.items()}, additive=additive))

        op("trans", plan.ref, plan.additive)
        for axis, angle in plan.rotations:
            op("rot", {axis: angle}, True)
        op("trans", plan.shift, True)

    def _swivel_retract(self, plan) -> None:
        """CYCLE800 _FR: rapid moves in machine Z (then X and Y) to the machine model's max travel."""
        if plan.retract == "none":
            return
        if plan.retract == "unknown":
            self.diag("NC105", "error", "CYCLE800 retract mode _FR must be 0, 1, 2, 4 or 5; no retract")
            return
        steps: list[dict[str, float]] = []
        z = self.mpos.get("Z", 0.0)
        if plan.retract == "tool_inc":
            steps.append({"Z": z + plan.retract_inc * self.st.scale})
        else:
            axes = [("Z",)] + ([("X", "Y")] if plan.retract == "z_xy" else [])
            for group in axes:
                target = {}
                for a in group:
                    ax = self.machine.axes.get(a)
                    if ax is None or ax.max is None:
                        self.diag("NC107", "info", f"the machine model has no max travel for {a}; "
                                  "CYCLE800 does not retract that axis")
                        continue
                    target[a] = float(ax.max)
                if target:
                    steps.append(target)
        tot = self.off.total
        for target in steps:
            mend = dict(self.mpos)
            mend.update(target)
            if all(abs(mend[a] - self.mpos.get(a, 0.0)) < 1e-12 for a in target):
                continue
            self._move("rapid", self.frame.to_program({a: v - tot.get(a, 0.0) for a, v in mend.items()}))

    # ---------------------------------------------------------------- offsets and frames
    def _h_setpos(self, s: n.SetPosition):
        vals = self._eval_words(self._words(s.target))
        if not vals:
            return
        target = self._target(vals)
        work = self.frame.to_work(target)
        g92 = dict(self.off.g92)
        wo = self.off.work
        for a, _, _ in vals:
            tl = self.off.tool_z if a == "Z" else 0.0
            g92[a] = self.mpos.get(a, 0.0) - wo.get(a, 0.0) - tl - work[a]
        self.off.set_g92(g92)
        self.pos = target

    def _h_resetpos(self, s):
        self.off.set_g92({})
        self._resync()

    def _h_frame(self, s: n.FrameOp):
        st = self.st
        scale = st.scale
        fr = self.frame
        op = s.op

        def num(e, what, lin=True):
            v = self._value(self.ev.compile(e), what)
            return None if v is None else v * (scale if lin else 1.0)

        def center():
            out = {}
            for a, av in (s.center or {}).items():
                e = av.value if isinstance(av, n.AxisValue) else av
                v = num(e, f"{a} centre", a.upper() in LINEAR_AXES)
                if v is not None:
                    out[a.upper()] = v
            return out

        # A programmable op that is neither additive, local (ISO G52) nor pivoted (ISO G68/G51/
        # G51.1 give a centre) replaces the whole programmable frame (Sinumerik TRANS/ROT/SCALE/
        # MIRROR); the others replace only their own component.
        replace_all = (not s.additive and not s.local and s.center is None and not s.clear
                       and op in ("trans", "rot", "scale", "mirror"))
        if replace_all:
            fr.clear()
        if op == "all":
            if s.clear:
                fr.clear()
        elif op == "trans":
            if s.clear:
                fr.set_local({})
            else:
                vals = {}
                for a, e in s.values.items():
                    v = num(e, f"{a} shift", a.upper() in LINEAR_AXES)
                    if v is not None:
                        vals[a.upper()] = v
                fr.set_local(vals, additive=s.additive)
        elif op == "rot":
            if s.clear:
                fr.set_rotation(None, 0.0, {})
            else:
                plane = st.plane
                if s.angle is not None:
                    ang = num(s.angle, "rotation angle", False) or 0.0
                    axis = ROT_AXIS[plane]
                    piv = center()
                    a1, a2, _ = PLANE_AXES[plane]
                    if s.center is not None and not s.additive:
                        # ISO G68: a missing centre coordinate is the current point
                        for a in (a1, a2):
                            piv.setdefault(a, self.pos.get(a, 0.0))
                    fr.set_rotation(axis, ang, piv, additive=s.additive)
                else:
                    first = True
                    for a, e in s.values.items():
                        ang = num(e, f"{a} rotation", False)
                        if ang is not None:
                            fr.set_rotation(a.upper(), ang, center(),
                                            additive=s.additive or not first)
                            first = False
        elif op == "scale":
            if s.clear:
                fr.set_scale({}, {})
            else:
                f = {a.upper(): num(e, f"{a} scale", False) for a, e in s.values.items()}
                fr.set_scale({a: v for a, v in f.items() if v is not None}, center())
        elif op == "mirror":
            if s.clear:
                keep = {a: v for a, v in fr.mirror_axes.items()
                        if s.values and a not in {k.upper() for k in s.values}}
                fr.set_mirror(keep)
            else:
                piv = center()
                axes = {a.upper(): piv.get(a.upper(), 0.0) for a in s.values}
                for a, v in piv.items():
                    axes.setdefault(a, v)
                fr.set_mirror(axes)
        self._resync()

    def _h_home(self, s: n.HomeReturn):
        """G28/G30: rapid to the intermediate point, then to the reference point (machine 0 for
        every reference point, as LinuxCNC's default #5161.. / #5181..) on the named axes;
        with no axis words every axis goes home directly."""
        vals = self._eval_words(self._words(s.via))
        if vals:
            self._move("rapid", self._target(vals))
            axes = [a for a, _, _ in vals]
        else:
            axes = list(self.mpos)
        tot = self.off.total
        mend = dict(self.mpos)
        for a in axes:
            mend[a] = 0.0
        self._move("rapid", self.frame.to_program({a: v - tot.get(a, 0.0) for a, v in mend.items()}))

    def _set_pframe(self, value: Any) -> None:
        """$P_PFRAME = frame: the programmable frame becomes `value`, each step acting as the
        frame instruction it stands for: the first replaces (TRANS/ROT/SCALE/MIRROR), the
        following ones add in the system it produced (ATRANS/AROT/ASCALE/AMIRROR)."""
        if value is UNKNOWN:
            self.diag("NC107", "info", "the programmable frame variable is assigned a value unknown at "
                      "analysis time; the programmable frame is kept")
            return
        if not isinstance(value, FrameValue):
            raise EvalError("NC104", "the programmable frame needs a frame value (a frame expression or "
                            "variable)")
        self.frame.clear()
        first = True
        for step in value.steps:
            op, vals = step
            if op == "state":
                copy_frame(vals, self.frame)
            else:
                self._h_frame(n.FrameOp(op, {a: n.Num(v) for a, v in vals}, additive=not first))
            first = False
        self._resync()

    # ---------------------------------------------------------------- calls
    def _h_call(self, s: n.SubCall):
        if s.modal == "after_move":
            self.modal_call = (s, self._call_args(s), self._depth())
            return None
        return ("call", s)

    def _depth(self) -> int:
        """The call level (a repeated section is not one: MCALL still calls in it)."""
        return len(self.stack) - self.sections

    def _h_section(self, d):
        s, count = d
        rep = 1
        if count is not None:
            r = self._value(count, "repeat count P")
            rep = 1 if r is None else int(round(r))
        return ("section", s, rep) if rep >= 1 else None

    def _section(self, s: n.SectionRepeat, rep: int, unit: Unit, pc: int, sidx: int):
        """Run a program section again `rep` times (nctrans.interp.sections), then resume after
        the REPEAT statement at (pc, sidx)."""
        first, last, problem = sections.section_bounds(s, unit.labels, label_key, pc)
        key = ("section", id(unit), first, last)
        callee = self.units.get(key)
        if callee is None and not problem:
            code, labels, problem = sections.section_code(unit.code, unit.labels, first, last,
                                                          (JUMP, JFALSE))
            if not problem:
                callee = Unit(unit.name, unit.file, unit.params)
                callee.code, callee.labels = code, labels
                callee.seen = bytearray(len(code))
                self.units[key] = callee
        if problem:
            self.diag("NC222", "error", f"{'REPEATB' if s.line_only else 'REPEAT'}: {problem}; "
                      "the repetition is skipped")
            return unit, unit.code, pc, sidx
        if len(self.stack) >= MAX_CALL_DEPTH:
            self.diag("NC105", "error", f"calls and repeated sections nested deeper than "
                      f"{MAX_CALL_DEPTH}; REPEAT {s.start} skipped")
            return unit, unit.code, pc, sidx
        scope = self.ev.scope
        self.stack.append(Frame(unit, pc, sidx, scope, callee, rep - 1, lambda: scope,
                                section=True))
        self.sections += 1
        return callee, callee.code, 0, 0

    def _h_modal_off(self, s):
        self.modal_call = None
        self.modal_cycle = None

    def _call_args(self, s: n.SubCall, params: Optional[list] = None) -> tuple[list, dict]:
        """Argument values; a VAR (by_ref) parameter of the callee gets a reference instead."""
        byref = [bool(getattr(p, "by_ref", False)) for p in params or ()]
        ev = self.ev
        pos = [ev.make_ref(e) if i < len(byref) and byref[i] else ev.compile(e)()
               for i, e in enumerate(s.args)]
        named = {k.upper(): self.ev.compile(e)() for k, e in s.named_args.items()}
        # ISO-style call arguments are in program units; they are passed as written
        return pos, named

    def _find_unit(self, name: str) -> Optional[Unit]:
        key = program_key(name)
        hit = self.sub_index.get(key)
        if hit is None and self.resolver is not None:
            if key not in self._resolved:
                from_file = self.span.file if self.span else self.program.file
                try:
                    prog = self.resolver(name, from_file)
                except Exception as ex:   # a resolver bug must not end the analysis
                    self.diag("NC103", "warning", f"cannot load subprogram {name}: {ex}")
                    prog = None
                self._resolved[key] = prog
                if prog is not None:
                    self._index_subprograms(prog)
                    if key not in self.sub_index:
                        sub = n.Subprogram(name, n.Span(prog.file, 1), prog.body)
                        self.sub_index[key] = (sub, prog.file)
            hit = self.sub_index.get(key)
        if hit is None:
            return None
        sub, file = hit
        unit = self.unit_for(id(sub), sub.name, sub.body, file, sub.params)
        unit.save = any(str(a).upper() == "SAVE" for a in (sub.attrs or ()))
        return unit

    def _make_scope(self, s: n.SubCall, unit: Unit, args: tuple) -> Callable[[], Scope]:
        pos, named = args
        # calls that open no parameter level of their own: ISO M98, and "shared" (Fagor LL, L,
        # #CALL), which shares the caller's named locals too
        share = s.kind in SHARED_SCOPE_CALLS and not pos and not named
        caller = self.ev.scope

        def make():
            sc = Scope(num=caller.num if share else None, args=dict(named))
            if share and s.kind == "shared":
                sc.names, sc.args = caller.names, caller.args
            for p, v in zip(unit.params, pos):
                sc.names[p.name.upper()] = v
            for p in unit.params[len(pos):]:       # not programmed in the call: preset to zero (seed
                if not p.by_ref and not p.dims:    # "Incomplete parameter transfer")
                    sc.names.setdefault(p.name.upper(), "" if p.type.upper().startswith("STRING") else 0)
            for k, v in named.items():
                var = s.bindings.get(k)
                if var is None:
                    continue
                if var.space == "num" and isinstance(var.key, int):
                    sc.num[var.key] = v
                elif var.space in ("name", "arg", "local"):
                    (sc.names if var.space == "name" else sc.args)[str(var.key).upper()] = v
                elif var.space == "R" and isinstance(var.key, int):
                    self.ev.R[var.key] = v
            return sc
        return make

    # ================================================================ system variables
    def _register_system(self) -> None:
        """Values of the neutral system variables (vocabulary.SYSTEM_VARIABLES); each dialect's
        rules table maps its spellings onto them."""
        values = self.ev.meanings
        sysv = self.ev.system
        st = self.st
        for a in "XYZABC":
            values[f"axis_position_work.{a}"] = (
                lambda a=a: self.pos.get(a, 0.0) / (st.scale if a in LINEAR_AXES else 1))
            values[f"axis_position_machine.{a}"] = (
                lambda a=a: self.mpos.get(a, 0.0) / (st.scale if a in LINEAR_AXES else 1))
        values["programmable_frame"] = lambda: FrameValue((("state", copy_frame(self.frame)),))
        self.ev.meaning_setters["programmable_frame"] = self._set_pframe
        values["active_tool"] = lambda: float(st.tool or 0)
        values["programmed_tool"] = lambda: float(st.tool_selected or 0)
        values["active_tool_edge"] = lambda: float(st.radius_index or 0)
        # F as programmed, in the feed unit in force (G700 inch/min; G70 keeps mm/min)
        values["feed"] = lambda: (st.feed or 0.0) / (st.feed_scale if st.feed_mode != "inverse_time" else 1.0)
        values["spindle_speed"] = lambda: st.spindle_speed or 0.0
        for i in range(3):      # geometry axes of the plane: abscissa, ordinate, applicate
            values[f"plane_axis_{i + 1}"] = (lambda i=i: AxisName(PLANE_AXES[st.plane][i]))
        for name, value in (getattr(self.machine, "variables", None) or {}).items():
            sysv[str(name).upper()] = lambda value=value: float(value)
        sysvars.register(self, self.program.dialect)
        gg = ggroups.index_reader(self.program.dialect, st.groups, self.spelt_codes,
                                  lambda: self.unmodelled_motion)
        if gg is not None:
            variable, reader = gg
            self.ev.indexed_system[variable.upper()] = reader

    # ================================================================ the loop
    def run(self) -> Iterator[ToolpathRecord]:
        prog = self.program
        body = prog.body
        # A main body that is not a list is streamed (iso-m parse_stream: no jumps, no calls):
        # it is compiled a batch of blocks at a time, run, and the batch dropped, so memory does
        # not grow with the program. Labels are per batch (nothing jumps to them).
        stream = None
        if type(body) is not list:
            stream = iter(body)
            body = []
        main = self.unit_for(id(prog), prog.name or "main", body, prog.file, [])
        unit, code = main, main.code
        pc = sidx = 0
        steps = 0
        max_steps = self.max_steps
        out = self.out
        self._seq = 0
        diag = self.diag
        try:
            while True:
                if pc >= len(code):
                    if stream is not None and unit is main and not self.stack:
                        batch = list(islice(stream, STREAM_BATCH))
                        if batch:
                            code.clear()
                            main.labels.clear()
                            if all(type(x) is n.Block for x in batch):
                                # straight blocks: no labels to index (nothing jumps)
                                code.extend([(BLOCK, None, x, x.span) for x in batch])
                            else:
                                self._emit_nodes(batch, main)
                            main.seen = bytearray(len(code))
                            pc = sidx = 0
                            continue
                        stream = None
                    # falling off the end of a body: implicit return / end of program
                    if not self.stack:
                        break
                    unit, code, pc, sidx = self._return(None)
                    continue
                ins = code[pc]
                op = ins[0]
                # The budget counts repeated execution (a block run again by a loop, a jump back
                # or a call, and every control instruction), never a straight-line block (or a
                # PlainRun of them, which only a streamed main body holds) running the first
                # time: a 30 M-block CAM program runs to its end, an endless loop stops.
                # Running out is an error: the analysis is incomplete.
                if (op != BLOCK and op != PLAIN
                        or op == BLOCK and (ins[1] is not None or unit.seen[pc])):
                    steps += 1
                    if steps > max_steps:
                        sp = ins[3]
                        diag("NC205", "error", f"analysis truncated at line {sp.line if sp else 0}: "
                             f"step budget of {max_steps} repeated steps (loop iterations, jumps "
                             "back, calls) exhausted", sp)
                        break
                if op == BLOCK:
                    self.span = ins[3]
                    stmts = ins[1]
                    if stmts is None:
                        # a block runs compiled; the compiled form is kept only once it runs a
                        # second time (loops, calls), so straight-line code adds no memory
                        stmts = self._compile_block(ins[2])
                        seen = unit.seen
                        if seen[pc]:
                            code[pc] = (BLOCK, stmts, ins[2], ins[3])
                        else:
                            seen[pc] = 1
                    ctl = None
                    if sidx == 0:
                        self.moved = False
                    nst = len(stmts)
                    while sidx < nst:
                        h, data = stmts[sidx]
                        sidx += 1
                        try:
                            ctl = h(data)
                        except EvalError as ex:
                            diag(ex.rule, ex.severity, ex.message)
                            ctl = None
                        if ctl is not None:
                            break
                    if ctl is None:
                        sidx = 0
                        pc += 1
                        if self.moved and self.modal_call is not None and not self.in_modal:
                            ctl = ("modal_call",)
                    if ctl is not None:
                        unit, code, pc, sidx = self._control(ctl, unit, pc, sidx)
                elif op == PLAIN:
                    self.span = ins[3]
                    done, rest = self._plain(ins[1], KERNEL_BLOCKS + 1)   # straight blocks: free
                    pc += 1
                    if rest:
                        # What the kernel left (Blocks, and the rest of the run) replaces what has
                        # run: runs only come in streamed main bodies, where nothing jumps back,
                        # so the batch stays short however long the run is.
                        code[:pc] = rest
                        pc = 0
                        unit.seen = bytearray(len(code))
                elif op == JUMP:
                    pc = ins[1]
                elif op == JFALSE:
                    self.span = ins[3]
                    try:
                        ok = ins[1]()
                    except EvalError as ex:
                        diag(ex.rule, ex.severity, ex.message)
                        ok = False
                    pc = pc + 1 if ok else ins[2]
                elif op == EXEC:
                    self.span = ins[3]
                    try:
                        ins[1]()
                    except EvalError as ex:
                        diag(ex.rule, ex.severity, ex.message)
                    pc += 1
                elif op == CASE:
                    self.span = ins[3]
                    subj, branches, default = ins[1]
                    target = default
                    try:
                        v = subj()
                        for f, lab in branches:
                            if f() == v:
                                target = lab
                                break
                    except EvalError as ex:
                        diag(ex.rule, ex.severity, ex.message)
                    pc += 1
                    if target is not None:
                        unit, code, pc, sidx = self._control(("goto", target, "forward"),
                                                             unit, pc - 1, 0)
                if out:
                    yield from self._release(out)
        except _Stop:
            pass
        try:
            self._comp_flush()
            yield from self._release(out)
        except _Stop:
            pass

    # ---------------------------------------------------------------- plain runs
    def _plain(self, run: PlainRun, budget: int) -> tuple[int, list]:
        """Run a PlainRun: through the native kernel as far as it goes identically, then the
        blocks it hands back through the Python path. Returns (blocks run here, code entries
        still to run: the next Blocks and the rest of the run)."""
        done = 0
        tried = self._kernel_ready()
        if tried:
            limit = min(budget, KERNEL_BLOCKS)
            done, run = self._plain_kernel(run, limit)
            if run is None:
                return done, []
            if done == limit < budget:          # only the call's size stopped it: go on
                return done, [_plain_entry(run)]
        blocks, rest = run.take(1 if tried else PLAIN_EXPAND)
        entries = [(BLOCK, None, b, b.span) for b in blocks]
        if rest is not None:
            entries.append(_plain_entry(rest))
        return done, entries

    def _kernel_ready(self) -> bool:
        """The state the kernel handles: _h_fast's (no cycle, comp, frame), no modal call or
        flatten hook, feed per minute or per revolution, one axis order for both positions."""
        st = self.st
        if (self.fast_sink is None or st.cycle != "off" or self.modal_cycle is not None
                or self.comp is not None or self.comp_exit or st.comp_side != "off"
                or not self.frame.identity or self.modal_call is not None or self.hook is not None
                or st.feed_mode not in ("per_min", "per_rev") or self.out
                or self.unmodelled_motion is not None or self.spindle_stopped or self.watch
                or st.feed_scale != st.scale):     # the kernel scales F as it scales lengths
            return False
        axes = "".join(self.pos)
        return len(axes) == len(self.pos) and axes == "".join(self.mpos) and _KERNEL_AXES.issuperset(axes)

    def _plain_kernel(self, run: PlainRun, budget: int) -> tuple[int, Optional[PlainRun]]:
        st = self.st
        pos, mpos = self.pos, self.mpos
        axes = "".join(pos)
        tot = self.off.total
        motion = plainrun.motion_code(st.motion)
        tail = ""
        if st.spindle_speed is not None:
            tail += ',"spindle":' + _spell(st.spindle_speed)
        if st.tool is not None:
            tail += f',"tool":{int(st.tool)}'
        write = self.fast_sink == "jsonl"
        (stop, line, blocks, chunk, records, prog, mach, new_motion, feed, feed_seen,
         last_from, last_arc, last_g) = self.native.run(
            run.text, run.start, run.end, run.sep, run.line, axes, list(pos.values()),
            [tot.get(a, 0.0) for a in axes] if tot else None, list(mpos.values()), st.scale,
            st.incremental, motion, st.feed, f',"feed_mode":"{st.feed_mode}"', tail, self._seq,
            _json_str(run.file), budget, write, st.plane, st.arc_absolute,
            arcs.CENTER_TOL_INCH if st.scale != 1.0 else arcs.CENTER_TOL_MM)
        if blocks:
            self.pos = dict(zip(axes, prog))
            self.mpos = dict(zip(axes, mach))
            if last_from is not None:
                self.last_from = dict(zip(axes, last_from))
                self.last_arc = None if last_arc is None else ((last_arc[0], last_arc[1]), last_arc[2])
                self.moved = True
            if new_motion != motion:
                st.set("motion", plainrun.MOTIONS[new_motion])
            if feed_seen:
                st.feed = feed
                self.feed_reported = False
                self._rc_feed_scale = st.feed_scale
            if records:
                if write:
                    self.out.append(JsonChunk(chunk, records))
                else:
                    self._seq += records
        rest = None
        if blocks < run.blocks:
            # the front end's static mode where the rest starts: the last G word the kernel ran
            motion_at, cycle_at = ((plainrun.MOTIONS[last_g], None) if last_g >= 0
                                   else (run.motion, run.cycle))
            rest = PlainRun(run.file, run.text, stop, run.end, line, run.sep, run.blocks - blocks,
                            run.lower, motion_at, cycle_at, run.arc_abs)
        return blocks, rest

    def _release(self, out: list) -> Iterator[ToolpathRecord]:
        """Number the records a block produced, show them to the flatten hook, and hand them on."""
        hook, hookq = self.hook, self._hookq
        for rec in out:
            if rec.__class__ is JsonChunk:
                self._seq += rec.count
                yield rec
                continue
            end = rec.end
            if end is not None and not _finite_point(end, rec.center):
                out.clear()
                self.diag("NC108", "error", f"a coordinate of this {rec.kind} move is out of range "
                          f"(infinite or not a number): {end}; the analysis stops here",
                          n.Span(rec.file, rec.line, 1))
                raise _Stop()
            self._seq += 1
            rec.seq = self._seq
            if hook is not None:
                w = hookq.popleft() if hookq else None
                hook(rec, *(w or (None, None)))
            yield rec
        out.clear()

    def _control(self, ctl, unit, pc, sidx):
        """Apply a control result from a statement: goto, call, return."""
        kind = ctl[0]
        if kind == "turning":
            return self._turning_control(ctl[1], unit, pc, sidx)
        if kind == "goto":
            target = self._find_label(unit, ctl[1], ctl[2], pc)
            if target is None and self.stack and self.stack[-1].section:
                self.diag("NC222", "error", f"jump to {ctl[1]} out of a repeated program section "
                          "is not modelled; the repetition ends here")
                self.stack[-1].repeats = 0
                return self._return(None)
            if target is None:
                self.diag("NC102", "error", f"jump target {ctl[1]} not found")
                if self.stack:
                    return self._return(None)
                raise _Stop
            return unit, unit.code, target, 0
        if kind == "return":
            if not self.stack:
                raise _Stop
            while self.stack[-1].section:          # RET inside a repeated section ends the call
                self.stack[-1].repeats = 0
                self._return(None)
                if not self.stack:
                    raise _Stop
            return self._return(ctl[1])
        if kind == "section":
            return self._section(ctl[1], ctl[2], unit, pc, sidx)
        if kind in ("call", "modal_call"):
            if kind == "call":
                s = ctl[1]
                args = None
            else:
                s, args, _ = self.modal_call
            callee = self._find_unit(s.name)
            if callee is None:
                what = unmodelled_cycle(s.name)
                if what is not None and not what.moves:
                    return unit, unit.code, pc, sidx      # settings only (CYCLE832): no path effect
                if what is not None:
                    self.diag("NC103", "warning", f"{s.name} ({what.meaning}) is a standard "
                              f"cycle nctrans does not model, and no {s.name} PROC was found "
                              "beside the program or on the search path: the call is skipped and "
                              "moves nothing in the analysed toolpath")
                    return unit, unit.code, pc, sidx
                self.diag("NC103", "warning", f"subprogram {s.name} not found; the call is skipped")
                self._opaque_call(s)
                return unit, unit.code, pc, sidx
            if len(self.stack) >= MAX_CALL_DEPTH:
                self.diag("NC105", "error", f"subprogram calls nested deeper than "
                          f"{MAX_CALL_DEPTH}; call of {s.name} skipped")
                return unit, unit.code, pc, sidx
            try:
                if args is None:
                    args = self._call_args(s, callee.params)
                rep = 1
                if s.repeat is not None:
                    r = self._value(self.ev.compile(s.repeat), "repeat count")
                    rep = 1 if r is None else int(round(r))
            except EvalError as ex:
                self.diag(ex.rule, ex.severity, ex.message)
                return unit, unit.code, pc, sidx
            if rep < 1:
                return unit, unit.code, pc, sidx
            make = self._make_scope(s, callee, args)
            saved = self._save_state() if callee.save else None
            modal = kind == "modal_call"
            self.stack.append(Frame(unit, pc, sidx, self.ev.scope, callee, rep - 1, make,
                                    modal=modal, saved=saved))
            self.in_modal += modal
            self.ev.scope = make()
            return callee, callee.code, 0, 0
        if kind == "pattern":
            scope = self.ev.scope
            self.stack.append(Frame(unit, pc, sidx, scope, ctl[1], 0, lambda: scope, section=True))
            self.sections += 1
            return ctl[1], ctl[1].code, 0, 0
        return unit, unit.code, pc, sidx

    def _opaque_call(self, s: n.SubCall) -> None:
        """A call nothing here defines: a "call" record (name, evaluated arguments in binding
        order: positional ones, then named ones by the local they bind), so a conversion that keeps
        the call can be compared with its source."""
        exprs = list(s.args)
        named = sorted(s.named_args.items(), key=lambda kv: (
            s.bindings[kv[0]].key if kv[0] in s.bindings and isinstance(s.bindings[kv[0]].key, int)
            else 1000, kv[0]))
        exprs += [e for _, e in named]
        values = []
        for e in exprs:
            if type(e) is n.Num and e.text == "":
                values.append(None)             # an omitted argument
                continue
            try:
                values.append(self._value(self.ev.compile(e), "call argument"))
            except EvalError:
                values.append(None)
        self._record("call", call=s.name, args=values)

    def _return(self, to_label):
        fr = self.stack[-1]
        if fr.repeats > 0 and to_label is None:
            fr.repeats -= 1
            self.ev.scope = fr.make_scope()
            return fr.callee, fr.callee.code, 0, 0
        self.stack.pop()
        self.moved = False       # the caller's block resumes after the call: no motion of its own
        if fr.section:
            self.sections -= 1
        if fr.modal:
            self.in_modal -= 1
        self.ev.scope = fr.scope
        if fr.saved is not None:
            self._restore_state(fr.saved)
        unit, pc, sidx = fr.unit, fr.pc, fr.sidx
        if to_label is not None:
            target = self._find_label(unit, to_label, "any", pc)
            if target is None:
                self.diag("NC102", "error", f"return target {to_label} not found in the caller")
            else:
                return unit, unit.code, target, 0
        return unit, unit.code, pc, sidx

    def _save_state(self) -> tuple:
        st = self.st
        return (dict(st.groups), {a: getattr(st, a) for a in SAVED_ATTRS}, st.feed,
                copy_frame(self.frame))

    def _restore_state(self, saved: tuple) -> None:
        """Return from a SAVE subprogram (spec 1.6): the modal G codes, the settable and the
        programmable frame as at the call; F too when the feed type (G group 15) changed."""
        groups, attrs, feed, frame = saved
        st = self.st
        feed_mode = st.feed_mode
        work = st.work_offset
        for g, v in groups.items():
            if g not in NOT_SAVED_GROUPS:
                st.groups[g] = v
        for a, v in attrs.items():
            setattr(st, a, v)
        if st.feed_mode != feed_mode:
            st.feed = feed
        if st.work_offset != work:
            self.off.set_work(self._work_offset(st.work_offset) if st.work_offset else {})
        copy_frame(frame, self.frame)
        self._resync()

    @staticmethod
    def _find_label(unit: Unit, target, direction: str, pc: int) -> Optional[int]:
        pcs = unit.labels.get(target if type(target) is int else label_key(target))
        if not pcs:
            return None
        if direction in ("forward", "any"):
            for p in pcs:
                if p > pc:
                    return p
            if direction == "forward":
                return None
        best = None
        for p in pcs:
            if p <= pc:
                best = p
        if best is None and direction == "any":
            return pcs[0]
        return best


def interpret(program: n.Program, machine=None, *, diagnostics: list, resolver=None,
              max_steps: Optional[int] = None, flatten_hook=None, preload=(),
              fast_sink: Optional[str] = None) -> Iterator[ToolpathRecord]:
    """Run `program` and yield its canonical motions one by one (see the module docstring).
    preload: programs whose declarations (VarDecl) run first as global variables, such as the
    definition files (Sinumerik GUD *.DEF) beside the program. fast_sink: "jsonl" when the
    consumer also takes JsonChunk items (records the native kernel already wrote as JSON lines),
    "discard" when it drops records unseen; either lets plain runs take the kernel."""
    return Interpreter(program, machine, diagnostics=diagnostics, resolver=resolver,
                       max_steps=max_steps, flatten_hook=flatten_hook, preload=preload,
                       fast_sink=fast_sink).run()


_KERNEL_AXES = frozenset("XYZABCUVW")


def _finite_point(end: dict, center: Optional[dict]) -> bool:
    """No infinity or NaN in a record's end point or centre (a sum overflows only if a term is
    ~1e308, which is out of any range anyway)."""
    t = sum(end.values())
    if center is not None:
        t += sum(center.values())
    return t - t == 0.0


def _non_finite(axis: str, value: float) -> Callable[[], Any]:
    def fail():
        raise EvalError("NC108", f"{axis.upper()} word is {value} (out of range)")
    return fail


def _plain_entry(run: PlainRun) -> tuple:
    """The code entry of a PlainRun; its span (first line) places an NC205 step-budget warning."""
    return (PLAIN, run, None, n.Span(run.file, run.line, 1, run.line, 1))

