"""`convert --flatten`: an IR Program of plain motion only, for controllers and tools without macros.

The interpreter already knows what a program does, so flattening is running it and writing its
toolpath records back as IR blocks (the interpreter's `flatten_hook` sees every record just before
it is yielded). Loops are unrolled, calls and cycles expanded, expressions evaluated, programmable
frames and local offsets folded into coordinates, because the records hold their results.

What the output keeps, so the target machine's own data still applies:
- the work offset selection (G54..G59, G54.1Pn) as a modal code. Coordinates are written as
  `machine point - (offset of that selection in the given machine model) - (tool length)`; so the
  flattened program reproduces the source's machine positions exactly on the same machine model,
  and on the real target its own offset registers apply as they would to the source.
  The hook's work points are not used for this because they exclude G92/G52 and reflect G10 writes
  the target's registers do not have; taking the difference from the machine point folds G92, G52,
  G10 and G53/G28 moves into coordinates with one rule. A source with no work offset active
  (Sinumerik G500/G53) is written under G54 relative to the model's G54 values (NC401 says so).
- tool length compensation (G43 H.. as ModeChange tool_length + OffsetSelect length) when the source
  had it active, so the target's tool-length registers apply. Negative compensation (G44, which
  LinuxCNC lacks) is folded into coordinates instead (NC401).
- tool changes, spindle speed and direction, coolant, dwells, stops, feeds and feed mode.
Cutter radius compensation is folded: the tool-centre path is written with compensation off.

Arcs are written with incremental centre words I/J/K computed from the point the target actually
starts from (the previous written, rounded end), so the arc the target computes has the source's
centre within the rounding of DECIMALS. Every block's span is the source line that caused the
motion, so diagnostics and `equiv` point back to the source.

Reporting: each kind of lowering present in the program (static walk of the program, its
subprograms and every file the resolver loads) is one NC401 info at its first source line.
Constructs the interpreter does not model (IR Passthrough) cannot be placed in the flattened
stream: M functions are dropped with NC403 (warning), constructs known to have no effect on motion
with NC401, anything else with NC402 (error), each at its line. An unresolved call (NC103) or a
truncated run (step budget) makes the flattened program incomplete: NC402.
"""
from __future__ import annotations

import math

import dataclasses
import re
import types
from typing import Any, Callable, Iterator, Optional

from nctrans.convert import HELD_LIMIT_NOTE as HELD_LIMIT
from nctrans.diagnostics import Diagnostic, at_span
from nctrans.dialects.emit import flat_forms
from nctrans.interp import corner_elements, spindle_position
from nctrans.interp.interpreter import Interpreter
from nctrans.interp.frames import PLANE_AXES
from nctrans.interp.rigid_tap import COMPENSATING_CHUCK
from nctrans.interp.unmodelled import modelled, no_motion_effect
from nctrans.ir import nodes as n
from nctrans.ir.vocabulary import NO_EFFECT_PREFIX
from nctrans.ir.walk import walk
from nctrans.ir.vocabulary import UNMODELLED_MODES
from nctrans.lower.flat_tapping import TEMPLATES, TapWriter
from nctrans.toolpath import ToolpathRecord

DECIMALS = 6                        # mm / degrees written: 1 nm, far under any controller's resolution
_EPS = 0.5 * 10 ** -DECIMALS
ISO_OFFSETS = ("G54", "G55", "G56", "G57", "G58", "G59")
CENTRE_WORD = {"X": "I", "Y": "J", "Z": "K"}
STRUCTURE = (n.If, n.While, n.ForLoop, n.Loop, n.RepeatUntil, n.Case)
# Diagnostics saying a construct was skipped and moved nothing (NC103 not modelled; NC224/NC225 a
# milling cycle that cannot run here; NC219 a corner element the control inserts in a way not
# modelled): output lowered from that run would lack its motion.
UNMODELLED_RULES = ("NC103", "NC224", "NC225", "NC219", "NC117", "NC118", "NC119", "NC216")

_M_FUNCTION = re.compile(r"^\s*(?:M\d+(?:\.\d+)?(?:\s*=\s*\d+)?\s*)+$", re.IGNORECASE)

# kinds of lowering: key -> message (one NC401 each, at the first source line where it applies)
LOWERINGS = {
    "loop": "loops unrolled",
    "branch": "conditions and jumps resolved",
    "call": "subprogram calls expanded",
    "cycle": "canned cycles expanded into motion",
    "frame": "programmable frames and local offsets folded into coordinates",
    "expr": "expressions and variables evaluated",
    "arcform": "radius, 3-point, tangential, polar and opening-angle arcs written as centre arcs",
    "units": "inch input written in mm",
    "comp": "cutter radius compensation folded: the tool-centre path is written with "
            "compensation off",
    "message": "messages left out",
}


def _r(v: float) -> float:
    v = round(v, DECIMALS)
    return 0.0 if v == 0 else v


def _num(v: float) -> n.Num:
    return n.Num(_r(v))


def _is_expr(e: Any) -> bool:
    """True for any expression that is not a literal number (so evaluating it is a lowering)."""
    return isinstance(e, (n.Var, n.Unary, n.Binary, n.Func, n.Str))


def _has_expr(obj: Any) -> bool:
    if _is_expr(obj):
        return True
    if isinstance(obj, n.AxisValue):
        return _is_expr(obj.value)
    if isinstance(obj, dict):
        return any(_has_expr(v) for v in obj.values())
    if isinstance(obj, (list, tuple)):
        return any(_has_expr(v) for v in obj)
    return False


class _Walker:
    """Static scan of the source for the lowerings flattening applies and for dropped constructs."""

    def __init__(self, diags: list[Diagnostic], machine_kind: str = "mill"):
        self.diags = diags
        self.machine_kind = machine_kind
        self.first: dict[str, n.Span] = {}
        self.dropped: set = set()
        self.seen_programs: set[int] = set()

    def note(self, kind: str, span: Optional[n.Span]) -> None:
        if kind not in self.first and span is not None:
            self.first[kind] = span

    def program(self, p: n.Program) -> None:
        if id(p) in self.seen_programs:
            return
        self.seen_programs.add(id(p))
        if type(p.body) is list:
            self.nodes(p.body)
        else:                       # a compact body (base.CompactBody): its runs taken apart
            from nctrans.convert import stream_chunks
            for chunk in stream_chunks(p.body, 256):
                self.nodes(chunk)
        for sub in (p.subprograms or {}).values():
            self.nodes(sub.body)

    def nodes(self, nodes_: list) -> None:
        for node in walk(nodes_):
            t = type(node)
            if t is n.Block:
                for s in node.body:
                    self.statement(s, node.span)
            elif t in (n.While, n.ForLoop, n.Loop, n.RepeatUntil):
                self.note("loop", node.span)
                if t is not n.Loop:
                    self.note("expr", node.span)
            else:
                self.note("branch", node.span)
                self.note("expr", node.span)

    def statement(self, s, span: n.Span) -> None:
        t = type(s)
        if t is n.Goto:
            self.note("loop" if s.direction == "backward" else "branch", span)
        elif t is n.SectionRepeat:
            self.note("loop", span)
        elif t is n.SubCall:
            self.note("call", span)
        elif t is n.CycleCall or t is n.CycleParams or (t is n.ModeChange and s.group == "cycle"
                                                         and s.value != "off"):
            self.note("cycle", span)
        elif t in (n.FrameOp, n.SetPosition, n.ResetSetPosition, n.DataSetting, n.HomeReturn,
                   n.PolarPole):
            self.note("frame", span)
        elif t is n.Assign or t is n.VarDecl:
            self.note("expr", span)
        elif t is n.Message:
            self.note("message", span)
        elif t is n.Motion:
            if s.machine_coords:
                self.note("frame", span)
            if s.radius is not None or s.via or s.polar or s.aperture is not None:
                self.note("arcform", span)
            if s.indirect:
                self.note("expr", span)
        elif t is n.ModeChange:
            if s.group == "units" and s.value in ("inch", "inch_geometry"):
                self.note("units", span)
            elif s.group == "cutter_comp" and s.value != "off":
                self.note("comp", span)
            elif s.group == "motion" and s.value in ("arc_3point", "arc_tangent"):
                self.note("arcform", span)
        elif t is n.Passthrough:
            self.passthrough(s, span)
            return
        elif t is n.TravelLimit:        # no motion; the limits stay in the check's toolpath
            self.passthrough(n.Passthrough(s.text, NO_EFFECT_PREFIX + " (travel limits)", s.dialect), span)
            return
        if "expr" not in self.first and t is not n.Passthrough and dataclasses.is_dataclass(s):
            if any(_has_expr(getattr(s, f.name)) for f in dataclasses.fields(s)):
                self.note("expr", span)

    def passthrough(self, s: n.Passthrough, span: n.Span) -> None:
        key = (span.file, span.line, s.text)
        if key in self.dropped:
            return
        self.dropped.add(key)
        what = f"{s.text!r}" + (f" ({s.reason})" if s.reason else "")
        if spindle_position.is_positioning(s):
            return                     # run: its spindle record is written, or NC220 says it addressed
            #                            a spindle that is not the master (interp/spindle_position.py)
        if s.reason == COMPENSATING_CHUCK:                       # nctrans.interp.rigid_tap
            self.diags.append(at_span("NC401", "info", f"--flatten writes {s.text} (tapping with a "
                                      "compensating chuck) as the block's G1 feed move it is; the "
                                      "feed override hold at 100 % is not written", span))
        elif corner_elements.kind_of(s):
            self.diags.append(at_span("NC401", "info", f"--flatten writes {what} as the arc or line "
                                      "it inserts at the corner (interp/corner_elements)", span))
        elif modelled(s):
            self.diags.append(at_span("NC401", "info", f"--flatten folds {what} into the compensated "
                                      "coordinates", span))
        elif no_motion_effect(s.reason, self.machine_kind):
            self.diags.append(at_span("NC401", "info", f"--flatten leaves out {what}: no effect on "
                                      "the motion", span))
        elif _M_FUNCTION.match(s.text):
            self.diags.append(at_span("NC403", "warning", f"--flatten drops the machine function "
                                      f"{what}: nctrans does not model it, so it has no place in the "
                                      "flattened motion; add it by hand if the target needs it", span))
        else:
            self.diags.append(at_span("NC402", "error", f"--flatten cannot expand {what}: nctrans "
                                      "does not model what it does, so the flattened motion would "
                                      "silently lose it", span))

    def report(self) -> None:
        for kind, msg in LOWERINGS.items():
            sp = self.first.get(kind)
            if sp is not None:
                self.diags.append(at_span("NC401", "info", f"--flatten: {msg} (first at line "
                                          f"{sp.line})", sp))


def _register_text(v) -> str:
    if isinstance(v, dict):
        return " ".join(f"{a}{float(x):g}" for a, x in sorted(v.items())) or "0"
    return f"{float(v):g}"


def _target_kind() -> Optional[str]:
    """The machine kind of the dialect a conversion writes (None outside one)."""
    from nctrans.dialects.emit import TARGET_PROFILE
    current = TARGET_PROFILE.get()
    if current is None:
        return None
    from nctrans.dialects.base import get
    return get(current[0]).machine_kind


def length_in_effect(interp, st) -> tuple[str, Optional[int]]:
    """The tool length the source has on, as the target writes it: ("plus", register) or ("off",
    None). ISO-style sources switch it with G43/G44/G49 (`length_mode`); where a D selects a
    cutting edge (tool_edges: no G43 in the source) the edge brings its length, and the target
    needs the length on as well, or a program that ran with it would run on the gauge line
    (on a real machine the tool tip then lies its length lower). Edge D1 is the tool's own
    register, D<d> the register d, D0 none: the reading of the ISO writer's edge_length. A lathe
    (the machine analysed, or the target's: its T word names the offset) applies no edge length
    (tool_edges: not modelled), so none is written there either. G44
    comes back as ("minus", register): the flattener folds it, a segment's end restores it."""
    edges = getattr(interp, "edges", None) if interp is not None else None
    if edges is not None and getattr(interp.machine, "kind", "mill") != "lathe" \
            and _target_kind() != "lathe":
        d = int(getattr(st, "radius_index", 0) or 0)
        if not d:
            return ("off", None)
        return ("plus", int(st.tool or 1) if d == 1 else d)
    if st.length_mode in ("plus", "minus"):
        idx = st.length_index if st.length_index is not None else st.tool
        if idx:
            return (st.length_mode, int(idx))
    return ("off", None)


class _Flattener:
    """Turns the interpreter's records into blocks, tracking what the target's modal state is."""

    def __init__(self, program: n.Program, machine, diags: list[Diagnostic]):
        self.source_dialect = program.dialect
        self.program = program
        self.machine = machine
        self.diags = diags
        self.interp: Optional[Interpreter] = None
        self.blocks: list[n.Block] = []
        self.ended = False
        # the target's modal state as written so far
        self.sel: Optional[str] = None
        self.length: tuple[str, Optional[int]] = ("off", None)
        self.motion: Optional[str] = None
        self.plane = "XY"
        self.feed: Optional[float] = None
        self.feed_mode = "per_min"
        self.speed: Optional[float] = None
        self.spindle_dir: Optional[str] = None
        self.mpos: dict[str, float] = {"X": 0.0, "Y": 0.0, "Z": 0.0}   # target's machine point
        # axes the target text has positioned; one the source positioned is written at its first
        # move even where the analysis' start point has it already: on the machine the tool starts
        # anywhere (`G0 X0 Y0 Z10` then `G1 Z-1` must not become `G0 Z10`, `G1 Z-1`)
        self.written_axes: set[str] = set()
        self.off: dict[str, float] = {}            # target's offsets (work + tool length), mm
        self.noted: set[str] = set()
        self.tool_written: Optional[int] = None    # the tool of the last change written
        self._raw: Optional[tuple] = None          # interpreter state the offsets were synced for
        # taps written in the target control's tapping form (flat_tapping.py); records held for
        # a tap are written later with the offsets state they came with (st_override)
        self.st_override = None
        forms = flat_forms()
        self.taps = TapWriter(self, forms, self._replay, self._offsets_state) \
            if forms.get("tapping") in TEMPLATES else None

    def info_once(self, key: str, message: str, span: n.Span) -> None:
        if key not in self.noted:
            self.noted.add(key)
            self.diags.append(at_span("NC401", "info", message, span))

    def header(self) -> None:
        span = n.Span(self.program.file, 1)
        self.blocks.append(n.Block(span, [
            n.ModeChange("units", "mm"), n.ModeChange("distance", "absolute"),
            n.ModeChange("plane", "XY"), n.ModeChange("cutter_comp", "off"),
            n.ModeChange("feed_mode", "per_min"),
        ], comment="flattened by nctrans: plain motion, mm, absolute"))

    # ------------------------------------------------------------------ offsets
    def _wanted_offsets(self, span: n.Span) -> tuple[str, tuple[str, Optional[int]]]:
        st = self.st_override or self.interp.st
        sel = (st.work_offset or "").upper()
        if sel not in ISO_OFFSETS and not sel.startswith("G54.1P"):
            self.info_once("no_offset", f"--flatten: no settable work offset active (here "
                           f"{st.work_offset or 'none'}): coordinates written under G54, relative "
                           "to the machine model's G54 values", span)
            sel = "G54"
        length = length_in_effect(self.interp, st)
        if length[0] == "minus":
            length = ("off", None)
            self.info_once("g44", "--flatten: negative tool length compensation folded into "
                           "coordinates (written with length compensation off)", span)
        return sel, length

    def _sync_offsets(self, body: list, span: n.Span) -> None:
        st = self.st_override or self.interp.st
        raw = (st.work_offset, st.length_mode, st.length_index, st.tool, getattr(st, "radius_index", None))
        if raw == self._raw:
            return
        self._raw = raw
        sel, length = self._wanted_offsets(span)
        if sel != self.sel:
            body.append(n.ModeChange("work_offset", sel))
            self.sel = sel
        if length != self.length:
            if length[0] == "off":
                body.append(n.ModeChange("tool_length", "off"))
            else:
                body.append(n.ModeChange("tool_length", "plus"))
                body.append(n.OffsetSelect("length", n.Num(float(length[1]))))
            self.length = length
        off = {a.upper(): float(v) for a, v in self.machine.work_offset(sel).items()}
        if length[0] == "plus":
            off["Z"] = off.get("Z", 0.0) + self.machine.length_offset(length[1])
        self.off = off
        self._written_register(sel, length, span)

    def _written_register(self, sel: str, length, span: n.Span) -> None:
        """NC417 where plain motion runs under a register the program itself writes (G10, #5221=,
        $P_UIFR): the output keeps the selection (G55, H1) but not the write, and its coordinates
        are relative to the machine model's value, so on the target the register's own content
        applies instead of what the source put there."""
        ran = getattr(self.interp, "machine", None) if self.interp is not None else None
        if ran is None or ran is self.machine:
            return
        checks = [(sel, ran.work_offset(sel), self.machine.work_offset(sel))]
        if length[0] == "plus":
            h = length[1]
            checks.append((f"H{h}", ran.length_offset(h), self.machine.length_offset(h)))
        for name, now, model in checks:
            if now != model and name not in self.noted:
                self.noted.add(name)
                self.diags.append(at_span(
                    "NC417", "warning", f"plain motion runs under {name}, which the program writes "
                    f"(here {_register_text(now)}; the machine model: {_register_text(model)}): the "
                    "output selects it but does not carry the write, and its coordinates are "
                    "relative to the model's value, so on the target the register's own content "
                    "applies", span))

    # ------------------------------------------------------------------ records
    def _offsets_state(self):
        st = self.interp.st
        return types.SimpleNamespace(work_offset=st.work_offset, length_mode=st.length_mode,
                                     length_index=st.length_index, tool=st.tool,
                                     radius_index=st.radius_index)

    def _replay(self, rec: ToolpathRecord, work_end, work_center, state) -> None:
        self.st_override = state
        try:
            self.record(rec, work_end, work_center)
        finally:
            self.st_override = None

    def hook(self, rec: ToolpathRecord, work_end, work_center) -> None:
        if self.ended:
            return
        if self.taps is not None and self.taps.offer(rec, work_end, work_center):
            return
        self.record(rec, work_end, work_center)

    def record(self, rec: ToolpathRecord, work_end, work_center) -> None:
        if self.ended:
            return
        span = n.Span(rec.file, rec.line)
        kind = rec.kind
        if kind in ("rapid", "linear", "arc"):
            self.move(rec, span)
        elif kind == "tool_change":
            name = self.interp.unnumbered_tools.get(rec.tool) if self.interp is not None else None
            if name is not None:
                # the analysis' own number for a named tool is no pocket or tool number of any
                # machine: writing it would load another tool
                self.diags.append(at_span("NC402", "error", f"plain motion cannot write the change to "
                                          f"tool {name!r}: the target selects tools by number, and "
                                          "the machine file names no tool so (give it a [[tools]] "
                                          f"entry with name = {name!r} and its number, --machine)",
                                          span))
            # no tool known (the source's T word failed): the change alone, as the source did
            body = [] if rec.tool is None else [n.ToolSelect(n.Num(float(rec.tool)))]
            self.tool_written = rec.tool
            self.blocks.append(n.Block(span, body + [n.ToolChange()]))
            # the target's M6 may stop the spindle (LinuxCNC's does: a G33 after it then stops
            # with "spindle not turning"): the direction the source programs next is written again
            self.spindle_dir = None
        elif kind == "spindle":
            body = []
            if rec.spindle is not None and rec.spindle != self.speed:
                body.append(n.SpindleSpeed(_num(rec.spindle)))
                self.speed = rec.spindle
            if rec.spindle_dir == "orient" and rec.spindle_angle is not None and math.isnan(rec.spindle_angle):
                self.diags.append(at_span("NC402", "error", "--flatten cannot write the spindle "
                                          "position here: the angle it turns to is not known (IC from "
                                          "a turning spindle)", span))
                self.spindle_dir = None
            elif rec.spindle_dir == "orient" and rec.spindle_angle:
                # positioned to an angle: no M code says it; the source's own word (only its
                # dialect has one), which other targets refuse at this line (interp/spindle_position.py)
                body.append(n.Passthrough(f"SPOS={rec.spindle_angle:.6g}", spindle_position.REASON,
                                          self.source_dialect, "SPOS", _num(rec.spindle_angle)))
                self.spindle_dir = "orient at an angle"
            elif rec.spindle_dir and rec.spindle_dir != self.spindle_dir:
                body.append(n.ModeChange("spindle", rec.spindle_dir))
                self.spindle_dir = rec.spindle_dir
            if body:
                self.blocks.append(n.Block(span, body))
        elif kind == "coolant":
            self.blocks.append(n.Block(span, [n.ModeChange("coolant", rec.coolant or "off")]))
        elif kind == "dwell":
            self.blocks.append(n.Block(span, [n.Dwell(seconds=_num(rec.dwell_s or 0.0))]))
        elif kind == "stop":
            if rec.stop_kind == "end":
                self.blocks.append(n.Block(span, [n.ProgramEnd("end_rewind")]))
                self.ended = True
            else:
                self.blocks.append(n.Block(span, [n.Stop(optional=rec.stop_kind == "optional")]))

    def move(self, rec: ToolpathRecord, span: n.Span) -> None:
        if rec.kind == "arc" and rec.turns:
            # Extra full turns are spelled differently by every controller (ISO L, LinuxCNC P,
            # Sinumerik TURN=); plain motion writes them as one full circle per turn instead.
            for piece in _split_turns(rec):
                self.move(piece, span)
            return
        body: list = []
        self._sync_offsets(body, span)
        off = self.off
        end = rec.end or {}
        prog_now = {a: v - off.get(a, 0.0) for a, v in self.mpos.items()}
        target_vals = {a: _r(v - off.get(a, 0.0)) for a, v in end.items()}
        if rec.kind == "arc":
            plane = rec.plane or "XY"
            a1, a2, _ = PLANE_AXES[plane]
            if plane != self.plane:
                body.append(n.ModeChange("plane", plane))
                self.plane = plane
            motion = "arc_cw" if rec.direction == "cw" else "arc_ccw"
        else:
            a1 = a2 = None
            motion = rec.kind
        thread = rec.kind == "linear" and bool(rec.pitch)
        if thread:
            # tapping / G33: spindle-synchronised, never a plain feed (its feed is lead x S)
            motion = "thread"
            self.info_once("thread", "--flatten: tapping and threads written as spindle-synchronised "
                           "G33 moves with their lead, the spindle reversed between them as the "
                           "source's cycle does (first at this line); ISO milling writes the lead as "
                           "F (ISO seed 4.5), as K for LinuxCNC (--profile linuxcnc)", span)
        if motion != self.motion:
            body.append(n.ModeChange("motion", motion))
            self.motion = motion
        if thread:
            self.feed = None                 # ISO writes the lead as F: the feed is written again
        elif rec.kind != "rapid":
            fm = rec.feed_mode or "per_min"
            if fm != self.feed_mode:
                body.append(n.ModeChange("feed_mode", fm))
                self.feed_mode = fm
                self.feed = None
            if rec.feed is not None and (rec.feed != self.feed or fm == "inverse_time"):
                body.append(n.Feed(_num(rec.feed)))
                self.feed = rec.feed
        first = self.interp.positioned - self.written_axes if self.interp is not None else ()
        axes = [a for a, v in target_vals.items()
                if a in (a1, a2) or a not in prog_now or abs(v - prog_now[a]) > _EPS or a in first]
        if not axes:
            axes = list(target_vals)
        motion_stmt = n.Motion({a: n.AxisValue(n.Num(target_vals[a])) for a in axes})
        if thread:
            along = max(("X", "Y", "Z"), key=lambda a: abs(target_vals.get(a, prog_now.get(a, 0.0))
                                                           - prog_now.get(a, 0.0)))
            motion_stmt.center = {CENTRE_WORD[along]: n.AxisValue(_num(rec.pitch))}
            start = rec.thread_start or 0.0          # a setting: written where it changes
            if start != getattr(self, "thread_start", 0.0):
                motion_stmt.thread_start = _num(start)
                self.thread_start = start
        if rec.kind == "arc":
            c = rec.center or {}
            motion_stmt.center = {CENTRE_WORD[a]: n.AxisValue(_num(c.get(a, 0.0) - self.mpos.get(a, 0.0)))
                                  for a in (a1, a2)}
            if rec.turns:
                motion_stmt.turns = n.Num(float(rec.turns))
        body.append(motion_stmt)
        self.blocks.append(n.Block(span, body))
        # where the target now is: the written (rounded) program point plus its offsets
        mpos = dict(self.mpos)
        for a, v in target_vals.items():
            mpos[a] = v + off.get(a, 0.0)
        self.mpos = mpos
        self.written_axes.update(axes)


def _centre_at(centre: dict, point: dict, a1: str, a2: str) -> dict:
    """The arc centre as records carry it: plane coordinates, other axes at the end point."""
    return {a: (centre.get(a, 0.0) if a in (a1, a2) else point[a]) for a in centre}


def _split_turns(rec: ToolpathRecord) -> list[ToolpathRecord]:
    """An arc (or helix) with extra full turns as `turns` full circles plus the final part,
    the axes outside the plane advancing in proportion to the angle swept."""
    a1, a2, _ = PLANE_AXES[rec.plane or "XY"]
    start, end, c = rec.start or {}, rec.end or {}, rec.center or {}

    def angle(p):
        return math.atan2(p.get(a2, 0.0) - c.get(a2, 0.0), p.get(a1, 0.0) - c.get(a1, 0.0))

    sweep = angle(end) - angle(start)
    if rec.direction == "cw":
        sweep = -sweep
    sweep %= 2 * math.pi
    if sweep < 1e-9:
        sweep = 2 * math.pi
    total = sweep + 2 * math.pi * rec.turns
    pieces, prev = [], dict(start)
    for k in range(1, rec.turns + 1):
        f = 2 * math.pi * k / total
        point = {a: start.get(a, 0.0) + (v - start.get(a, 0.0)) * f for a, v in end.items()}
        point[a1], point[a2] = start.get(a1, 0.0), start.get(a2, 0.0)
        pieces.append(dataclasses.replace(rec, start=prev, end=point, turns=0,
                                          center=_centre_at(c, point, a1, a2)))
        prev = point
    pieces.append(dataclasses.replace(rec, start=prev, end=dict(end), turns=0))
    return pieces


def _walked(body, walker: "_Walker") -> Iterator:
    """The blocks of a streamed body (runs of plain blocks taken apart), each walked by `walker`
    as it is handed on."""
    from nctrans.convert import stream_chunks
    for chunk in stream_chunks(body, 256):
        walker.nodes(chunk)
        yield from chunk


def flatten(program: n.Program, machine=None, *, diagnostics: list,
            resolver: Optional[Callable] = None, max_steps: Optional[int] = None,
            max_blocks: Optional[int] = None, stop_when_incomplete: bool = False) -> n.Program:
    """Plain-motion Program equivalent to `program` on `machine` (default mill); NC4xx diagnostics
    (and the interpreter's own) are appended to `diagnostics`. With `max_blocks` the program held
    in memory stops there: the run ends and an NC402 error at the last block says so (the
    flattened program is incomplete; flatten_blocks streams it instead). `stop_when_incomplete`:
    see flatten_blocks."""
    stream = flatten_blocks(program, machine, diagnostics=diagnostics, resolver=resolver,
                            max_steps=max_steps, stop_when_incomplete=stop_when_incomplete)
    blocks: list = []
    for block in stream:
        blocks.append(block)
        if max_blocks is not None and len(blocks) > max_blocks:
            stream.close()
            diagnostics.append(Diagnostic(
                "NC402", "error", f"the program lowered to plain motion runs past {max_blocks:,} "
                f"blocks, {HELD_LIMIT} (NCTRANS_MAX_LOWERED_BLOCKS; an endless loop?): convert "
                "--flatten streams it instead", block.span.file, block.span.line))
            break
    return n.Program(program.file, program.dialect, blocks, {}, flattened_meta(program), None)


def flattened_meta(program: n.Program) -> dict:
    """The meta of the flattened program (what its emitter reads before the first block)."""
    meta: dict[str, object] = {"flattened_from": program.dialect, "percent": True}
    defaults = program.meta.get("defaults") if isinstance(program.meta, dict) else None
    if isinstance(defaults, dict):
        # the records hold the radius: the flattened program is in radius whatever the source was
        meta["defaults"] = {g: v for g, v in defaults.items() if g != "diameter"}
    return meta


def flatten_blocks(program: n.Program, machine=None, *, diagnostics: list,
                   resolver: Optional[Callable] = None, max_steps: Optional[int] = None,
                   stop_when_incomplete: bool = False) -> Iterator[n.Block]:
    """The blocks of flatten()'s program, one at a time as the run produces them, so a program
    whose loops unroll into millions of moves is never held whole. `diagnostics` is complete
    once the iteration has ended. `stop_when_incomplete`: the run ends at the first thing that
    makes the flattened program incomplete (an unresolved call, the step budget) when the caller
    only needs to know the lowering is refused (convert's last resort): a real program of 100k
    moves would otherwise run to its end first."""
    if machine is None:
        from nctrans.machine import default_mill
        machine = default_mill()
    from nctrans.dialects.base import CompactBody
    streamed = type(program.body) is not list and type(program.body) is not CompactBody
    first_diag = len(diagnostics)
    # A streamed body (a straight program parsed as it runs) is walked block by block as the
    # interpreter takes it; its notes go where the whole walk would have put them, first.
    walker = _Walker([] if streamed else diagnostics, getattr(machine, "kind", "mill"))
    if streamed:
        program = dataclasses.replace(program, body=_walked(program.body, walker))
    else:
        walker.program(program)

    wrapped = None
    if resolver is not None:
        def wrapped(name, from_file):
            prog = resolver(name, from_file)
            if prog is not None:
                walker.program(prog)
            return prog

    interp_diags: list[Diagnostic] = []
    fl = _Flattener(program, machine, diagnostics)
    fl.header()
    kwargs = {"diagnostics": interp_diags, "resolver": wrapped, "flatten_hook": fl.hook}
    if max_steps is not None:
        kwargs["max_steps"] = max_steps
    interp = Interpreter(program, machine, **kwargs)
    fl.interp = interp
    last: Optional[n.Block] = None
    seen = 0
    for _ in interp.run():
        if fl.blocks:
            last = fl.blocks[-1]
            yield from fl.blocks
            fl.blocks.clear()
        if stop_when_incomplete and len(interp_diags) > seen:
            if any(_incomplete(d) or takes_unknown_path(d) for d in interp_diags[seen:]):
                break
            seen = len(interp_diags)
    if fl.taps is not None:
        fl.taps.flush()
    if fl.blocks:
        last = fl.blocks[-1]
    raised = getattr(interp, "alarm", None)
    if raised is not None:
        # the source stops with an alarm here: the flattened program raises the same alarm, so
        # the run's NC221 becomes a lowering note (the conversion keeps the behaviour)
        number, text, span, own_base = raised
        fl.blocks.append(n.Block(span, [n.Alarm(number, text, own_base)]))
        last = fl.blocks[-1]
        for i, d in enumerate(interp_diags):
            if d.rule == "NC221":
                interp_diags[i] = Diagnostic("NC401", "info", f"--flatten: the program raises an alarm "
                                             f"here ({d.message.split(';')[0][len('the program raises '):]}"
                                             "); the flattened program raises it too", d.file, d.line,
                                             d.column, d.end_line, d.end_column)
    if not fl.ended:
        span = last.span if last is not None else n.Span(program.file, 1)
        fl.blocks.append(n.Block(span, [n.ProgramEnd("end_rewind")]))
    yield from fl.blocks
    fl.blocks.clear()
    if streamed:
        for _ in program.body:      # what follows the program end is walked as a whole walk would
            pass
        diagnostics[first_diag:first_diag] = walker.diags
        walker.diags = diagnostics
    diagnostics.extend(interp_diags)
    for d in interp_diags:
        if _incomplete(d):
            diagnostics.append(Diagnostic("NC402", "error", f"--flatten output would be incomplete: "
                                          f"{d.message}", d.file, d.line, d.column, d.end_line,
                                          d.end_column))
        elif stop_when_incomplete and takes_unknown_path(d):
            diagnostics.append(Diagnostic("NC402", "error", f"{UNKNOWN_VALUE_NOTE}: {d.message}", d.file,
                                          d.line, d.column, d.end_line, d.end_column))
    walker.report()


UNKNOWN_VALUE_NOTE = "plain motion would take one path for a value only the machine knows"


def takes_unknown_path(d: Diagnostic) -> bool:
    """A run diagnostic saying the path taken depends on a value unknown to the analysis (NC107 as
    a warning: a condition taken as false, a word ignored; a probe result, a PLC input): plain
    motion written from that run would fix one path the machine may not take. `--flatten` asks for
    it and says so (the warning stays); a lowering nctrans chooses on its own refuses it. NC123
    likewise: a cutter compensation radius of a tool the program never chose, and NC125: of an
    ISO register the machine file does not give (interp/comp_radius)."""
    return d.rule in ("NC107", "NC123", "NC125") and d.severity == "warning"


def _incomplete(d: Diagnostic) -> bool:
    """A run diagnostic after which the flattened program lacks motion the source has, or has
    other motion: a mode the interpreter records but does not model (ISO G16 polar input: its
    words were read as Cartesian coordinates; ir.vocabulary.UNMODELLED_MODES)."""
    return d.rule in UNMODELLED_RULES or (d.rule == "NC205" and "budget" in d.message) or (
        d.rule == "NC220" and any(left_out in d.message for left_out in UNMODELLED_MODES.values()))
