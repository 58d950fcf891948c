"""The interpreter: IR Program -> stream of ToolpathRecord (the canonical motions).

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

Where the code is (split by concern, as rs274ngc splits interp_*.cc). Interpreter is this module's
state (__init__) composed from one mixin per concern; each mixin that handles statements
contributes its table of compilers (statement type -> (handler, data)), merged by
_compiler_table. A handler lives in the module of its concern:
- compiled.py   the instruction form: opcodes, Unit (a compiled body), Frame (a stack entry)
- flow.py       compiling, the run loop, jumps, program end / stop / alarm
- calls.py      subprogram calls, the call stack, parameter scopes, REPEAT sections, SAVE
- statements.py modal groups, F, S, T, dwell, variables, travel limits, unmodelled constructs
- motion.py     G0-G3, G33, CIP/CT arcs, polar words, G53, G28/G30 (the fast path _h_fast)
- records.py    a move -> machine-coordinate records, cutter compensation, the flatten hook
- offsets.py    work offsets, G92, tool length, G10, programmable frames
- cycle_calls.py canned cycles, cycle calls, hole patterns, CYCLE800
- native.py     the native lane: plain runs through the C kernel
- words.py      word values and targets (shared by all of the above)
- lathe.py      lathe semantics; run_checks.py lint checks made while running (NC210-NC214)

Coordinates (all mm): program point -> programmable frame (frames.py) -> work point -> + G92 +
work offset + tool length -> machine point. Records are in machine coordinates.

flatten_hook(record, work_end, work_center): called for every record in stream order, just before
it is yielded; for motion records work_end / work_center are the end point / centre in WORK
coordinates (after the programmable frame, before work offset, G92 and tool length), else None.
"""
from __future__ import annotations

from collections import deque
from typing import Any, Iterator, Optional

from nctrans import plainrun
from nctrans.diagnostics import at_span
from nctrans.interp import comp_radius, contour_tables, edge_data, ggroups, settable_frames, sysvars, tool_change, tool_edges
from nctrans.interp.evaluate import AxisName, EvalError, Evaluator, FrameValue
from nctrans.interp.frames import Offsets, PLANE_AXES, ProgrammableFrame
from nctrans.interp.lathe import LatheMixin
from nctrans.interp.run_checks import RunChecks
from nctrans.interp.state import LINEAR_AXES, ModalState
from nctrans.interp.travel_limits import ProgrammedLimits
from nctrans.ir import nodes as n
from nctrans.toolpath import ToolpathRecord

from nctrans.interp.calls import CallsMixin
from nctrans.interp.cycle_calls import CycleCallsMixin
from nctrans.interp.flow import FlowMixin
from nctrans.interp.motion import MotionMixin
from nctrans.interp.native import NativeLaneMixin
from nctrans.interp.offsets import OffsetsMixin, mirror_before_rotation
from nctrans.interp.records import RecordsMixin
from nctrans.interp.statements import StatementsMixin
from nctrans.interp.words import WordsMixin

# Names importable from here before the split into modules by concern (nctrans.interp.lathe,
# nctrans.lower, tests): kept so those imports go on working.
from nctrans.interp.calls import NOT_SAVED_GROUPS, SAVED_ATTRS, SHARED_SCOPE_CALLS  # noqa: F401
from nctrans.interp.compiled import (BLOCK, CASE, EXEC, JFALSE, JUMP, MAX_CALL_DEPTH, PLAIN,  # noqa: F401
                                     Frame, Unit, _Stop, label_key, program_key)
from nctrans.interp.cycle_calls import CYCLE_LENGTH_KEYS  # noqa: F401
from nctrans.interp.flow import STREAM_BATCH  # noqa: F401
from nctrans.interp.native import KERNEL_BLOCKS, PLAIN_EXPAND  # noqa: F401
from nctrans.interp.offsets import NORMAL, ROT_AXIS, copy_frame  # noqa: F401
from nctrans.interp.words import LENGTH_WORDS  # noqa: F401

MOVE_KINDS = frozenset(("rapid", "linear", "arc"))


def _default_cutting_edge(dialect) -> int:
    """The D number a tool brings when none is programmed (rules/<dialect>.toml
    options.default_cutting_edge; 0: none, G41/G42 without D compensate by zero)."""
    from nctrans.rules import option
    return int(option(dialect, "default_cutting_edge", 0) or 0)


class Interpreter(FlowMixin, CallsMixin, StatementsMixin, MotionMixin, RecordsMixin, OffsetsMixin,
                  CycleCallsMixin, NativeLaneMixin, WordsMixin, LatheMixin, RunChecks):
    """One run of one program: the state every concern module's handlers read and write."""

    def __init__(self, program: n.Program, machine=None, *, diagnostics: list, resolver=None,
                 max_steps: Optional[int] = None, flatten_hook=None, preload=(), fast_sink=None):
        if max_steps is None:
            from nctrans import limits
            max_steps = limits.step_budget()
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
        self.max_unrolled: Optional[int] = None
        if flatten_hook is not None:
            from nctrans import limits
            self.max_unrolled = limits.setting("MAX_UNROLLED", limits.MAX_UNROLLED)
        # "jsonl": the consumer takes JsonChunk items (already written records) among the records;
        # "discard": it drops records unseen (lint). Either lets the native kernel run PlainRuns.
        self.native = plainrun.native       # read per run: tests switch the kernel off
        self.fast_sink = fast_sink if self.native is not None else None
        defaults = program.meta.get("defaults") if isinstance(program.meta, dict) else None
        self.st = ModalState(defaults if isinstance(defaults, dict) else None)
        self.default_edge = _default_cutting_edge(program.dialect)
        self.ev = Evaluator()
        self.frame = ProgrammableFrame(mirror_first=mirror_before_rotation(program.dialect))
        self.off = Offsets()
        self.travel_limits: Optional[ProgrammedLimits] = None     # set by the first TravelLimit
        self.settable = None            # settable_frames.SettableFrames where the dialect has them
        self.edges = None               # tool_edges.ToolEdges where D numbers are cutting edges
        # tools selected by a name the machine file does not number: analysis number -> name (a
        # target that selects tools by number cannot be given one: flatten refuses their change)
        self.unnumbered_tools: dict[int, str] = {}
        if self.st.work_offset:
            self.off.set_work(self._work_offset(self.st.work_offset))
        # machine position (last emitted end) and the same point in program coordinates
        self.mpos: dict[str, float] = ({"X": 0.0, "Z": 0.0} if getattr(machine, "kind", "") == "lathe"
                                       else {"X": 0.0, "Y": 0.0, "Z": 0.0})
        self.pos: dict[str, float] = {}
        # axes the program has positioned with a word so far: the start point is the analysis'
        # assumption, so plain motion writes an axis at its first programmed position even where
        # the analysis has it there already (lower/flatten.py)
        self.positioned: set[str] = set()
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
        self.spindle_stopped_by_tap = False  # the last stop was an ISO tap's own (rules [tapping])
        self.spindle_angle = None         # where SPOS/M19 left the spindle (spindle_position.py)
        self.master_spindle = 1           # SETMS(n) (spindle_position.py); None: not known
        self.thread_start = 0.0           # SD 42000 THREAD_START_ANGLE (thread_starts.py)
        self.comp_d_reported = False      # NC208 once per G41/G42 without a D word
        self.comp_on_span = None          # the G41/G42 block of the episode (comp_radius.py)
        self.comp_checked = True          # its radius's source checked at the first move (NC123)
        self.offsets_of_tool = comp_radius.offsets_of_active_tool(program.dialect)
        self.t_changes_tool = tool_change.changes_on_t_word(machine, program.dialect)
        self.last_from: Optional[dict] = None     # previous move (tangent of Sinumerik CT)
        self.last_arc = None
        self.comp = None
        self.comp_radius = 0.0
        self.comp_exit = False
        self.comp_total = None          # offsets of the cutter compensation episode (records.py)
        self.comp_pos_machine = None    # machine point of the compensated program point (records.py)
        self.modal_call = None          # (SubCall, args snapshot, depth)
        self.cycle_params: dict[str, float] = {}
        self.cycle_initial: Optional[float] = None
        self.modal_cycle = None         # CycleCall with modal=True
        self.pole: Optional[tuple[float, float]] = None   # polar pole in the plane (program coords)
        self.pole_set = False           # a pole was programmed (polar_words.py)
        self.pole_refused: Optional[int] = None            # line of a pole that was refused (NC118)
        self.polar_stored: Optional[tuple[float, float]] = None   # programmed (angle, radius)
        self.unmodelled_motion: Optional[str] = None       # unmodelled motion code in force (G34 ...)
        self.corner = None              # corner_elements.CornerStage while RND/CHF ... is in play
        self.contour_table = None       # contour_tables.Session between CONTPRON/CONTDCON and EXECUTE
        self._diameter_reads: set = set()  # (file, line) of X position reads under DIAMON said (NC138)
        self.contour_procs = contour_tables.kinds(program)
        self.contour_offset = 0.0       # Sinumerik OFFN (contour_offset.py)
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

    def diag(self, rule: str, severity: str, message: str, span=None) -> None:
        """Report once per place: a loop over a faulty block gives one diagnostic, not thousands."""
        sp = span or self.span
        key = (rule, message, sp.file if sp else None, sp.line if sp else 0, sp.col if sp else 0)
        if key in self._reported:
            return
        self._reported.add(key)
        self.diags.append(at_span(rule, severity, message, sp))

    def _compiler_table(self) -> dict:
        """Statement type -> compiler (statement -> (handler, data)): each concern module's table."""
        table: dict = {}
        for part in (self._flow_table, self._calls_table, self._statements_table, self._motion_table,
                     self._offsets_table, self._cycles_table):
            table.update(part())
        return table

    def _work_position_read(self, axis: str) -> float:
        """The current work position of `axis` for a position variable ($AA_IW, $P_EP). Under
        diameter programming (DIAMON) X, the transverse axis, is read as the radius nctrans holds;
        whether the control gives the diameter there is not in the seeds (the system-variable
        table, seed L28087, only says "actual value in the WCS") [GK, not confirmed]. A value that
        may be half or twice the control's changes what it drives, so the read is said at its
        line (NC138), once per line."""
        if axis == "X" and self.st.diameter:
            span = self.span
            where = (span.file, span.line) if span is not None else None
            if where not in self._diameter_reads:
                self._diameter_reads.add(where)
                self.diag("NC138", "warning", "the work position of X is read under diameter "
                          "programming (DIAMON): nctrans gives the radius; whether the control gives "
                          "the diameter here is not documented in the seeds [GK], so what this value "
                          "drives may be half or twice the control's. Read it under DIAMOF (radius) to "
                          "be sure")
        return self.pos.get(axis, 0.0)

    def _register_system(self) -> None:
        """Values of the neutral system variables (vocabulary.SYSTEM_VARIABLES); each dialect's
        rules table maps its spellings onto them."""
        values = self.ev.meanings
        sysv = self.ev.system
        st = self.st
        for a in "XYZABC":
            values[f"axis_position_work.{a}"] = (
                lambda a=a: self._work_position_read(a) / (st.scale if a in LINEAR_AXES else 1))
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
        values["spindle_direction"] = lambda: {"cw": 3.0, "ccw": 4.0}.get(st.spindle_dir, 5.0)
        values["active_tool_radius"] = lambda: (_edge_radius(self) or 0.0) / st.scale
        for flag in ("block_search_active", "simulation_active", "dry_run_active"):
            values[flag] = lambda: 0.0          # a normal run from the start (vocabulary)
        for i in range(3):      # geometry axes of the plane: abscissa, ordinate, applicate
            values[f"plane_axis_{i + 1}"] = (lambda i=i: AxisName(PLANE_AXES[st.plane][i]))
        for name, value in (getattr(self.machine, "variables", None) or {}).items():
            sysv[str(name).upper()] = lambda value=value: float(value)
        sysvars.register(self, self.program.dialect)
        settable_frames.register(self)
        tool_edges.register(self)      # [t, d] edges first: edge_data adds the flat [d] form
        edge_data.register(self)
        # which table coordinate is X held as a diameter (INTERSEC works true to size)
        self.ev.table_diameter_index = lambda: contour_tables.diameter_index(self)
        self.ev.on_unmodelled_read = lambda name: self.diag(
            "NC236", "warning", f"system variable {name} is not modelled: its value is unknown to "
            "the analysis (what it drives is left out)")
        gg = ggroups.index_reader(self.program.dialect, st.groups, self.spelt_codes,
                                  lambda: self.unmodelled_motion)
        if gg is not None:
            variable, reader = gg
            self.ev.indexed_system[variable.upper()] = reader


def _edge_radius(interp) -> Optional[float]:
    """The active tool's radius in mm as the milling cycle models take it (Sinumerik $P_TOOLR)."""
    from nctrans.interp.milling_cycles import _tool_radius
    return _tool_radius(interp)


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
