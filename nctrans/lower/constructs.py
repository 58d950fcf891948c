"""Per-construct lowering: a construct the target cannot express becomes plain motion on its own,
and the rest of the program keeps its structure.

The target's emitter names each construct it cannot write (NC402 at its line). Each one is widened
to a *segment* of the main program's top-level nodes that can be replaced on its own:
- the top-level node holding the line (a block, or a whole loop / branch: "its loop");
- a modal canned cycle or modal call together with every block it runs at, from the block that
  selects it to the block that cancels it ("its cycle call").
The program then runs once through the interpreter with a zero dwell as marker before and after
each segment; the records between a segment's markers are written back as plain-motion blocks
(`flatten._Flattener`), framed by the modes they need (mm, absolute, incremental arc centres) and
followed by the source's modes as they stand at the segment's end marker (units, distance, plane,
motion, feed, feed mode, work offset, tool length), so what follows runs as in the source.

A segment is left as a refusal (NC402, saying why) when replacing it alone would be wrong: it is not
in the main program (a subprogram's body runs once per call), jumps cross its border, it sets
variables read elsewhere, it runs more or less than once, cutter compensation, a programmable frame,
G92 or a local offset is active at its border, or it holds what plain motion cannot carry (an
unresolved call, an unmodelled construct). A segment's plain motion is held in memory until the
program is emitted again, so it is bounded (limits.MAX_LOWERED_BLOCKS): an endless loop around a
construct is refused at that bound, not after the step budget (gigabytes later), and the run stops
as soon as every segment is refused.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Callable, Optional

from nctrans import limits
from nctrans.diagnostics import Diagnostic
from nctrans.interp import corner_elements
from nctrans.interp.interpreter import Interpreter
from nctrans.lower.flatten import (ISO_OFFSETS, UNMODELLED_RULES, _Flattener, _Walker, length_in_effect,
                                  takes_unknown_path)
from nctrans.ir import nodes as n
from nctrans.ir.walk import blocks, walk

from nctrans.convert import CONSTRUCT_NOTE as NOTE, HELD_LIMIT_NOTE, NeedsWholeParse

# run diagnostics inside a segment after which its plain motion would lack what the source does:
# the --flatten ones plus NC220 (a construct the interpreter does not model: its plain motion would
# silently leave it out, G16 polar mode written as Cartesian moves)
SEGMENT_UNMODELLED = UNMODELLED_RULES + ("NC220",)

# why a segment holding a G10 (DataSetting) is not lowered alone (also the streamed lowering's)
OFFSET_DATA_WHY = "it writes offset data (G10) that the rest of the program runs with"


def _blocks_lowering(d: Diagnostic) -> bool:
    """A run diagnostic inside a segment after which its plain motion would not be the source's:
    something left out (SEGMENT_UNMODELLED), the step budget, or a path taken for a value only the
    machine knows (flatten.takes_unknown_path: `IF[#1005EQ1]GOTO10` run as if false)."""
    return (d.rule in SEGMENT_UNMODELLED or (d.rule == "NC205" and d.severity == "error")
            or takes_unknown_path(d))


class _AllRefused(Exception):
    """Raised from the run's hook once every segment is refused: the rest of the run is moot."""

MARKER_FILE = "<nctrans:segment>"


@dataclass
class Segment:
    first: int                          # top-level node indices, inclusive
    last: int
    refusals: list[Diagnostic] = field(default_factory=list)
    why_not: Optional[str] = None       # set when it cannot be lowered on its own
    # filled by the run
    starts: int = 0
    ends: int = 0
    flattener: object = None
    end_state: Optional[dict] = None
    start_state: Optional[dict] = None  # the source's modes where it starts (the target's too)
    notes: list[Diagnostic] = field(default_factory=list)    # what plain motion leaves out (NC401/NC403)
    diag_mark: int = 0                  # interpreter diagnostics before it started
    first_span: Optional[n.Span] = None  # the span its plain motion's first block takes
    spill: object = None                # a compact program's: its plain motion as it is made (nctrans.spilled)


def _line_index(body: list, file: str) -> dict[int, int]:
    """Source line -> index of the top-level node that holds it."""
    index: dict[int, int] = {}
    for i, node in enumerate(body):
        for inner in walk([node]):
            sp = getattr(inner, "span", None)
            if sp is not None and sp.file == file:
                index.setdefault(sp.line, i)
    return index


class _ModalRuns:
    """(first, last) top-level indices of each modal cycle or modal call run: from the block that
    selects it to the block that cancels it (the end of the body when nothing does). An ISO canned
    cycle ends at G80 or a motion code of group 01; a modal call (G66, MCALL) at its cancel only; a
    programmable frame or G92 shift at a frame cancel (the run's end checks the frame is gone).
    Fed one node at a time, so a streamed body is scanned as it is parsed; `closed(first, last)`
    is called for each run as it ends."""

    def __init__(self, closed: Callable[[int, int], None]):
        self.closed = closed
        self.start: Optional[int] = None
        self.kind = ""

    def feed(self, i: int, node) -> None:
        if type(node) is not n.Block:
            return
        for s in node.body:
            t = type(s)
            if t is n.ModeChange and s.group == "cycle" and s.value != "off":
                if self.start is None:
                    self.start, self.kind = i, "cycle"
            elif (t is n.CycleCall and s.modal) or (t is n.SubCall and s.modal != "none"):
                if self.start is None:
                    self.start, self.kind = i, "call"
            elif (t is n.FrameOp and not s.clear) or t is n.SetPosition:
                if self.start is None:
                    self.start, self.kind = i, "frame"
            elif self.start is not None and self.kind == "frame" and (
                    (t is n.FrameOp and s.clear) or t is n.ResetSetPosition):
                self.closed(self.start, i)
                self.start = None
            elif self.start is not None and (
                    (self.kind == "cycle" and t is n.ModeChange and (s.group == "motion" or s.group == "cycle"))
                    or (self.kind == "call" and t is n.ModalCallOff)):
                self.closed(self.start, i)
                self.start = None

    def end(self, last: int) -> None:
        """The body ended at index `last`."""
        if self.start is not None:
            self.closed(self.start, last)
            self.start = None


class _CornerRuns:
    """(first, last) top-level indices of each chain of corner elements (Sinumerik RND, CHF, RNDM,
    ISO ,R ,C): from a node whose block leads to a rounding or chamfer to the next node that moves
    without leading to one. The element joins two blocks (interp/corner_elements.py), so lowered
    apart one of them would lose it. Fed one node at a time (see _ModalRuns)."""

    def __init__(self, closed: Callable[[int, int], None]):
        self.closed = closed
        self.start: Optional[int] = None
        self.modal = False                  # RNDM in force (a computed value counts as on)

    def feed(self, i: int, node) -> None:
        moves = leads = False
        for x in walk([node]):
            if type(x) is not n.Block:
                continue
            for s in x.body:
                t = type(s)
                if t is n.Motion and (s.target or s.indirect or s.polar):
                    moves = True
                elif t is n.Passthrough and (kind := corner_elements.kind_of(s)):
                    if kind == "round_modal":
                        self.modal = not (type(s.value) is n.Num and s.value.value == 0)
                    elif kind in ("round", "chamfer_leg", "chamfer_length"):
                        leads = True
        leads = leads or (self.modal and moves)
        if self.start is not None and moves and not leads:
            self.closed(self.start, i)
            self.start = None
        elif self.start is None and leads:
            self.start = i

    def end(self, last: int) -> None:
        if self.start is not None:
            self.closed(self.start, last)
            self.start = None


def _modal_runs(body: list) -> list[tuple[int, int]]:
    runs: list[tuple[int, int]] = []
    scan = _ModalRuns(lambda a, b: runs.append((a, b)))
    corner_scan = _CornerRuns(lambda a, b: runs.append((a, b)))
    for i, node in enumerate(body):
        scan.feed(i, node)
        corner_scan.feed(i, node)
    scan.end(len(body) - 1)
    corner_scan.end(len(body) - 1)
    return runs


# Modes some targets lack whose stretch must be lowered whole: what follows the mode's block reads
# it (the next axis words tap, the next F is mm/min), so lowering the block alone would leave the
# rest of the stretch in the wrong mode. group -> values of that kind.
STRETCH_MODES = {
    # Sinumerik G70: lengths in inch, feeds in the basic system (ISO and Fagor inch reads F in inch)
    "units": frozenset(("inch_geometry",)),
    # Sinumerik G331/G332, Fagor G63: every later block with axis words taps or retracts
    "motion": frozenset(("tap_rigid", "tap_rigid_retract", "tap_interp")),
    # Sinumerik G500 (no settable offset): every later position is in the basic frame, not the
    # G54 an ISO control keeps, until another offset is selected
    "work_offset": frozenset(("G53",)),
    # ISO G16: every later block's plane words are radius and angle (interp/polar_input.py)
    "polar": frozenset(("on",)),
}


def _sets(node, group: str, values=None) -> bool:
    """A block that selects a mode of `group` itself (one of `values` when given)."""
    return type(node) is n.Block and any(
        type(s) is n.ModeChange and s.group == group and (values is None or s.value in values)
        for s in node.body)


class _StretchRuns:
    """(first, last) top-level indices from a node that selects a STRETCH_MODES value to the node
    before the block that selects another value of the same group (the end of the body when
    nothing does). A segment holding the first node takes the whole run: the target refused the
    mode, so none of the stretch may keep its structure. Fed one node at a time (see _ModalRuns);
    `end` lists them group by group, in STRETCH_MODES order; only those whose first index
    `keep` accepts are kept."""

    def __init__(self, keep: Callable[[int], bool] = lambda first: True):
        self.keep = keep
        self.start: dict[str, Optional[int]] = {group: None for group in STRETCH_MODES}
        self.found: dict[str, list[tuple[int, int]]] = {group: [] for group in STRETCH_MODES}

    def feed(self, i: int, node) -> None:
        for group, values in STRETCH_MODES.items():
            start = self.start[group]
            if start is None:
                if any(type(s) is n.ModeChange and s.group == group and s.value in values
                       for x in walk([node]) if type(x) is n.Block for s in x.body):
                    self.start[group] = i
            elif _sets(node, group) and not _sets(node, group, values):
                if self.keep(start):
                    self.found[group].append((start, i - 1))
                self.start[group] = None

    def end(self, last: int) -> list[tuple[int, int]]:
        """The runs, the body having ended at index `last`."""
        for group, start in self.start.items():
            if start is not None and self.keep(start):
                self.found[group].append((start, last))
            self.start[group] = None
        return [run for group in STRETCH_MODES for run in self.found[group]]


def _stretch_runs(body: list) -> list[tuple[int, int]]:
    scan = _StretchRuns()
    for i, node in enumerate(body):
        scan.feed(i, node)
    return scan.end(len(body) - 1)


def _vars(obj, out: set) -> None:
    """Every variable (space, key) an IR object mentions."""
    if obj is None or isinstance(obj, (str, int, float, bool, n.Num, n.Str, n.Span)):
        return
    if type(obj) is n.Var:
        out.add((obj.space, str(obj.key).upper() if obj.space == "name" else obj.key))
        for e in obj.indices or ():
            _vars(e, out)
        return
    if isinstance(obj, dict):
        for v in obj.values():
            _vars(v, out)
        return
    if isinstance(obj, (list, tuple)):
        for v in obj:
            _vars(v, out)
        return
    for name in getattr(obj, "__slots__", ()):
        _vars(getattr(obj, name, None), out)


def _written(nodes: list) -> set:
    out: set = set()
    for node in walk(nodes):
        if type(node) is n.Block:
            for s in node.body:
                if type(s) is n.Assign:
                    _vars(s.target, out)
                elif type(s) is n.VarDecl:
                    out.add(("name", s.name.upper()))
        elif type(node) is n.ForLoop:
            _vars(node.var, out)
    return {(sp, k) for sp, k in out if sp != "system"}


def _local_names(nodes: list) -> set[str]:
    """The names the nodes declare local (DEF in a main body), upper case."""
    return {s.name.upper() for b in blocks(nodes) for s in b.body
            if type(s) is n.VarDecl and s.scope in ("local", "", None)}


def _local(space: str, key, local_names: set[str]) -> bool:
    """A variable that ends with the program: a DEF local of its main body (`local_names`) or an
    ISO local #1-#33 of the main program. Anything else (R parameters, GUD names, common variables)
    is seen by the next program, so a lowering that drops its assignment would change what
    happens there."""
    if space == "num":
        return isinstance(key, int) and 1 <= key <= 33
    if space == "name":
        return key in local_names
    if space == "local":            # a call-frame parameter or local user variable (not a V.S. global)
        from nctrans.lower.frame_locals import lasting
        return not lasting(key)
    return False


def _label_key(x) -> str:
    """A label as a jump finds it: upper case (Sinumerik "Mark1:" .. GOTOB MARK1), a block number
    without leading zeros (ISO N0010 .. GOTO 10)."""
    t = str(x).upper()
    return str(int(t)) if t.isdigit() else t


def _labels(nodes: list) -> set[str]:
    return {_label_key(x) for b in blocks(nodes) for x in (b.label, b.number) if x is not None}


def _jumps(nodes: list) -> set[str]:
    """Every label a jump, return, repetition or contour reference of `nodes` names (upper case)."""
    return {_label_key(t) for t in _jump_targets(nodes)}


def _jump_targets(nodes: list) -> set[str]:
    out: set[str] = set()
    for node in walk(nodes):
        if type(node) is n.Block:
            out.update(str(s.target) for s in node.body if type(s) is n.Goto)
            if any(type(s) is n.Goto and s.computed is not None for s in node.body):
                # ISO GOTO #2 can land on any numbered block
                out.update(str(b.number) for b in walk(nodes) if type(b) is n.Block and b.number)
            out.update(str(s.to_label) for s in node.body if type(s) is n.Return and s.to_label)
            # a section repetition (REPEAT start end, REPEATB) runs its labels' blocks again: a
            # label it names inside a lowered stretch would be gone from the output
            for s in node.body:
                if type(s) is n.SectionRepeat:
                    out.update(str(x) for x in (s.start, s.end) if x)
            # a turning cycle's contour (G71 P.. Q..): the blocks it reads and runs past
            out.update(str(int(v.value)) for s in node.body if type(s) is n.CycleCall
                       for k, v in s.params.items() if k in ("start", "end") and type(v) is n.Num)
        elif type(node) is n.Case:
            out.update(str(t) for _, t in node.branches)
            if node.default:
                out.add(str(node.default))
    return out


def _segments(program: n.Program, refusals: list[Diagnostic]) -> tuple[list[Segment], list[Diagnostic]]:
    """Group the refusals into segments of the main body; refusals outside it stay as they are."""
    body = program.body
    found, outside = placed(refusals, program.file, _line_index(body, program.file))
    return _widened(found, _modal_runs(body), _stretch_runs(body)), outside


def placed(refusals: list[Diagnostic], file: str, index: dict[int, int]
           ) -> tuple[list[Segment], list[Diagnostic]]:
    """A one-node segment for each refusal at a line of the main body (`index`: line -> node),
    and the refusals elsewhere (a subprogram's, another file's)."""
    found: list[Segment] = []
    outside: list[Diagnostic] = []
    for d in refusals:
        i = index.get(d.line) if d.file == file else None
        if i is None:
            outside.append(d)
        else:
            found.append(Segment(i, i, [d]))
    return found, outside


def _widened(found: list[Segment], modal_runs, stretch_runs) -> list[Segment]:
    """Each refused node's segment grown over the modal runs and stretches it touches, then
    segments that meet merged."""
    for a, b in modal_runs:
        for seg in found:
            if seg.first <= b and seg.last >= a:
                seg.first, seg.last = min(seg.first, a), max(seg.last, b)
    for a, b in stretch_runs:
        for seg in found:
            if seg.first <= a <= seg.last:     # the target refused the mode itself
                seg.last = max(seg.last, b)
    found.sort(key=lambda s: s.first)
    merged: list[Segment] = []
    for seg in found:
        if merged and seg.first <= merged[-1].last + 1:
            merged[-1].last = max(merged[-1].last, seg.last)
            merged[-1].refusals.extend(seg.refusals)
        else:
            merged.append(seg)
    return merged


def _widen_over_jumps(body: list, segments: list[Segment], pairs: Optional[list] = None) -> list[Segment]:
    """Each segment grown until no jump of the main body crosses its border: a jump into it, out
    of it, back over it or forward past it takes the jump's whole span with it, so a label loop
    (LBL: ... GOTOB LBL) around a construct is lowered whole, as its loop. `pairs`: (index,
    node) of the nodes to look at instead of the body's (a compact body's other than its runs)."""
    if pairs is None:
        pairs = list(enumerate(body))
    where: dict[str, int] = {}
    for i, node in pairs:
        for lab in _labels([node]):
            where.setdefault(lab, i)
    spans = [(min(i, where[t]), max(i, where[t])) for i, node in pairs
             for t in _jumps([node]) if t in where]
    for seg in segments:
        changed = True
        while changed:
            changed = False
            for lo, hi in spans:
                overlaps = lo <= seg.last and hi >= seg.first
                if overlaps and (lo < seg.first or hi > seg.last):
                    seg.first, seg.last = min(seg.first, lo), max(seg.last, hi)
                    changed = True
    segments.sort(key=lambda s: s.first)
    merged: list[Segment] = []
    for seg in segments:
        if merged and seg.first <= merged[-1].last + 1:
            merged[-1].last = max(merged[-1].last, seg.last)
            merged[-1].refusals.extend(seg.refusals)
        else:
            merged.append(seg)
    return merged


def _static_checks(program: n.Program, segments: list[Segment]) -> None:
    body = program.body
    subs = [s.body for s in program.subprograms.values()]
    local_names = _local_names(body)
    for seg in segments:
        inside = body[seg.first:seg.last + 1]
        rest = body[:seg.first] + body[seg.last + 1:]
        landing = _jumps(rest + [x for s in subs for x in s]) & _labels(inside)
        if landing:
            # its plain motion has no labels: the jump would find none
            lab = sorted(landing)[0]
            line = next(b.span.line for b in blocks(inside)
                        if lab in (_label_key(b.label), _label_key(b.number)))
            seg.why_not = (f"a jump or repetition from elsewhere lands on its label {lab} "
                           f"(line {line}), which plain motion does not keep")
        elif not _jumps(inside) <= _labels(inside):
            seg.why_not = "it jumps out of itself"
        elif any(type(x) is n.DataSetting for b in blocks(inside) for x in b.body):
            # G10 writes offsets the later blocks run with: its plain motion is nothing, and the
            # rest would run with the target's old offsets (was silently wrong)
            seg.why_not = OFFSET_DATA_WHY
        else:
            read: set = set()
            _vars(rest, read)
            for sb in subs:
                _vars(sb, read)
            seg.why_not = _variables_reason(_written(inside), read,
                                            lambda sp, k: _local(sp, k, local_names))


# How a variable of a numbered space is named in a note (a bare number said nothing: "it sets 1").
_SPACE_SPELLING = {"R": "R{}", "num": "#{}", "arg": "argument {}"}


def _var_name(space: str, key) -> str:
    return _SPACE_SPELLING.get(space, "{}").format(key)


def _variables_reason(written: set, read_elsewhere: set, local: Callable[[str, object], bool]
                      ) -> Optional[str]:
    """Why a segment that writes `written` cannot be lowered on its own (its assignments vanish
    into plain motion), or None: the rest of the program reads one, or one outlives the program
    (`local(space, key)` is False)."""
    shared = sorted(_var_name(sp, k) for sp, k in written & read_elsewhere)
    lasting = sorted(_var_name(sp, k) for sp, k in written if not local(sp, k))
    if shared:
        return f"it sets {', '.join(shared[:3])}, which the rest of the program reads"
    if lasting:
        return (f"it sets {', '.join(lasting[:3])}, which outlives the program "
                "(a global, common or R variable)")
    return None


def _mode_state(interp: Interpreter) -> dict:
    st = interp.st
    length_mode, length_index = length_in_effect(interp, st)
    return {"units": st.groups.get("units"), "distance": st.groups.get("distance"),
            "plane": st.plane, "motion": st.motion, "feed_mode": st.feed_mode, "feed": st.feed,
            "scale": st.scale, "feed_scale": st.feed_scale, "work_offset": st.work_offset, "length_mode": length_mode,
            "length_index": length_index, "arc_absolute": st.arc_absolute, "tool_selected": st.tool_selected,
            "comp": st.comp_side != "off" or interp.comp is not None,
            "frame": not interp.frame.identity or any(v for v in interp.off.g92.values())}


def _selection_to_restore(seg: Segment) -> Optional[int]:
    """The tool a segment leaves selected (T without a change: a preselection) where the target
    has another one selected after its plain motion, which writes T only with a change: the
    selection would be lost, and the next change take the wrong tool. None: nothing to write."""
    st = seg.end_state
    if st is None or seg.flattener is None:
        return None
    written = seg.flattener.tool_written
    target = written if written is not None else (seg.start_state or st).get("tool_selected")
    sel = st.get("tool_selected")
    return sel if sel is not None and sel != target else None


def _restore(seg: Segment, span: n.Span, units_follow: bool) -> n.Block:
    """The source's modes at the segment's end, where the target after the plain motion is in
    others (`units_follow`: nothing of the main body follows, or the next block selects its own
    units). The target is in what the plain motion last wrote, and where it wrote nothing of a
    group, in the source's mode at the segment's start (the structural part before it kept the
    source's modes): a mode the segment changed without a move (G49, G18, G55, G95 alone in a
    lowered block) is set here, or the later structural blocks would run without it."""
    st, fl = seg.end_state, seg.flattener
    start = seg.start_state or st
    plane = fl.plane if fl.plane is not None else start["plane"]
    sel = fl.sel if fl.sel is not None else start["work_offset"]
    written_length = fl.length if fl.length[0] != "unknown" else (start["length_mode"],
                                                                   start["length_index"])
    feed_mode = fl.feed_mode if fl.feed_mode is not None else start["feed_mode"]
    motion = fl.motion if fl.motion is not None else start["motion"]
    body: list = []
    if st["units"] == "inch" or (st["units"] == "inch_geometry" and not units_follow):
        body.append(n.ModeChange("units", st["units"]))
    if st["distance"] == "incremental":
        body.append(n.ModeChange("distance", "incremental"))
    if st["arc_absolute"]:
        body.append(n.ModeChange("arc_distance", "absolute"))
    if plane != st["plane"]:
        body.append(n.ModeChange("plane", st["plane"]))
    settable = st["work_offset"] in ISO_OFFSETS or str(st["work_offset"]).startswith("G54.1P")
    # no settable offset in the source (Sinumerik G500): the plain motion ran under G54, the
    # target's power-on offset, as the structural part around it does
    if sel is not None and settable and st["work_offset"] != sel:
        body.append(n.ModeChange("work_offset", st["work_offset"]))
    length = (st["length_mode"], st["length_index"])
    if length[0] != written_length[0] or (length[0] != "off" and length[1] != written_length[1]):
        body.append(n.ModeChange("tool_length", length[0]))
        if length[0] != "off" and length[1] is not None:
            body.append(n.OffsetSelect("length", n.Num(float(length[1]))))
    if feed_mode is not None and st["feed_mode"] != feed_mode:
        body.append(n.ModeChange("feed_mode", st["feed_mode"]))
    if motion is not None and st["motion"] != motion and \
            st["motion"] in ("rapid", "linear", "arc_cw", "arc_ccw"):
        body.append(n.ModeChange("motion", st["motion"]))
    feed_differs = (st["feed"] != fl.feed or st["feed_scale"] != 1.0) if fl.feed is not None \
        else st["feed"] != start["feed"]
    if st["feed"] is not None and feed_differs:
        scale = st["feed_scale"] if st["feed_mode"] != "inverse_time" else 1.0
        body.append(n.Feed(n.Num(round(st["feed"] / scale, 9))))
    selected = _selection_to_restore(seg)
    if selected is not None:
        body.append(n.ToolSelect(n.Num(float(selected))))
    return n.Block(span, body, comment="nctrans: modes of the source restored" if body else None)


def lower_constructs(program: n.Program, refusals: list[Diagnostic], target_name: str, *,
                     machine=None, resolver: Optional[Callable] = None
                     ) -> tuple[Optional[n.Program], list[Diagnostic], list[Diagnostic]]:
    """(program with each lowerable segment replaced by plain motion or None when none is, NC401/
    NC403 notes, refusals that remain)."""
    from nctrans.dialects.base import CompactBody
    if type(program.body) is CompactBody:       # its runs of plain blocks never built whole
        from nctrans.lower.compact_constructs import lower_compact
        return lower_compact(program, refusals, target_name, machine=machine, resolver=resolver)
    if type(program.body) is not list:
        return None, [], refusals
    if machine is None:
        from nctrans.machine import default_mill
        machine = default_mill()
    segments, remaining = _segments(program, refusals)
    segments = _widen_over_jumps(program.body, segments)
    _static_checks(program, segments)
    for seg in segments:
        _walk_check(seg, program.body[seg.first:seg.last + 1], machine)
    live = [s for s in segments if s.why_not is None]
    if live:
        _run(program, live, machine, resolver)
    new_body, notes = close_segments(
        segments, remaining, target_name, program.file, len(program.body),
        lambda lo, hi: program.body[lo:hi + 1], program.body.__getitem__, _lines,
        lambda seg: seg.flattener.blocks)
    if new_body is None:
        return None, notes, remaining
    return dataclasses.replace(program, body=new_body), notes, remaining


def close_segments(segments: list[Segment], remaining: list[Diagnostic], target_name: str, file: str,
                   size: int, slice_: Callable, node_at: Callable, lines_of: Callable,
                   plain_of: Callable) -> tuple[Optional[list], list[Diagnostic]]:
    """After the run, each segment in turn: a refused one adds its refusals to `remaining`; a
    lowered one gives its NC401 notes and is replaced by its plain motion (`plain_of(seg)`: the
    flattener's blocks, or the run they were spilled to) and the block that restores the modes
    its end leaves. (the new body, None when nothing was lowered; the notes.) The body is seen
    through its `size` nodes, `slice_(lo, hi)` (nodes lo..hi as items), `node_at(i)` and
    `lines_of(items)` ((first, last) source line): a list or a compact view."""
    new_body: list = []
    notes: list[Diagnostic] = []
    done = 0
    lowered_any = False
    for seg in segments:
        ended = _settle(seg)
        if seg.why_not is not None:
            remaining.extend(refused(seg))
            continue
        first_line, last_line = lines_of(slice_(seg.first, seg.last))
        notes.extend(lowered_notes(seg, target_name, first_line, last_line))
        new_body.extend(slice_(done, seg.first - 1))
        new_body.extend(plain_of(seg))
        units_follow = seg.last == size - 1 or _sets(node_at(seg.last + 1), "units")
        restore = _restore(seg, n.Span(file, last_line), units_follow) if not ended else None
        if restore is not None and restore.body:
            new_body.append(restore)
        done = seg.last + 1
        lowered_any = True
    if not lowered_any:
        return None, notes
    new_body.extend(slice_(done, size - 1))
    return new_body, notes


def _lines(nodes: list) -> tuple[int, int]:
    """(first, last) source line of a segment's nodes: the lowest and highest of its blocks."""
    lines = [b.span.line for b in blocks(nodes)] or [nodes[0].span.line]
    return min(lines), max(lines)


def _walk_check(seg: Segment, nodes: list, machine) -> None:
    """What plain motion cannot carry among a segment's nodes (flatten._Walker): why it is not
    lowered, or the notes of what its plain motion leaves out."""
    if seg.why_not is not None:
        return
    found: list[Diagnostic] = []
    _Walker(found, getattr(machine, "kind", "mill")).nodes(nodes)
    blocked = [d for d in found if d.severity == "error"]
    if blocked:
        seg.why_not = reason_at(blocked[0])
    else:
        seg.notes = [dataclasses.replace(d, message=d.message.replace("--flatten", "plain motion"))
                     for d in found]


def _settle(seg: Segment) -> bool:
    """After the run: why a segment is not lowered when it did not run once or ends under cutter
    compensation; whether it ended the program."""
    ended = seg.flattener is not None and seg.flattener.ended
    if seg.why_not is None and (seg.starts != 1 or seg.ends != (0 if ended else 1)):
        seg.why_not = ("it does not run exactly once" if seg.starts else "it never runs")
    if seg.why_not is None and seg.end_state is not None and seg.end_state["comp"]:
        seg.why_not = "cutter radius compensation is on at its end"
    return ended


def reason_at(d: Diagnostic) -> str:
    """A diagnostic as the reason a segment is not lowered, with its line: a segment of several
    lines refuses each, and a reason with no line read as each refused line's own (line 3's call
    refused as "SUBX.NC not found", line 2's, looked like line 2's NC103 printed twice)."""
    return f"at line {d.line}, " + d.message.replace("--flatten", "plain motion")


def refused(seg: Segment) -> list[Diagnostic]:
    """The refusals of a segment that cannot be lowered on its own, saying why."""
    return [dataclasses.replace(d, message=f"{d.message}; it cannot be lowered to plain motion on "
                                f"its own: {seg.why_not}") for d in seg.refusals]


def lowered_notes(seg: Segment, target_name: str, first_line: int, last_line: int) -> list[Diagnostic]:
    """One NC401 for a segment lowered to plain motion (lines first-last), at its first refusal,
    counting the others (one note per refused line repeated the same span), then what its plain
    motion leaves out."""
    if not seg.refusals:
        return list(seg.notes)
    what = "line " + str(first_line) if first_line == last_line else f"lines {first_line}-{last_line}"
    first = seg.refusals[0]
    others = sorted({d.line for d in seg.refusals[1:]} - {first.line})
    also = ""
    if others:
        shown = ", ".join(map(str, others[:MORE_LINES_SHOWN])) + (", ..." if len(others) > MORE_LINES_SHOWN else "")
        also = f" (nor what line{'s' if len(others) > 1 else ''} {shown} hold{'' if len(others) > 1 else 's'})"
    note = Diagnostic("NC401", "info", f"{first.message} — {target_name} cannot express it{also}, so "
                      f"{what} {'was' if first_line == last_line else 'were'} {NOTE} "
                      "(the rest keeps its structure)", first.file, first.line, first.column,
                      first.end_line, first.end_column)
    return [note] + seg.notes


# Lines named in a segment's one lowering note besides its first refusal (the count is in the span).
MORE_LINES_SHOWN = 5


def _marker(k: int) -> n.Block:
    return n.Block(n.Span(MARKER_FILE, k), [n.Dwell(seconds=n.Num(0.0))])


def _run(program: n.Program, segments: list[Segment], machine, resolver) -> None:
    """One run of the program with markers around the segments, each segment's records written
    as plain motion by its own flattener."""
    body: list = []
    done = 0
    for k, seg in enumerate(segments):
        body.extend(program.body[done:seg.first])
        body.append(_marker(2 * k))
        body.extend(program.body[seg.first:seg.last + 1])
        body.append(_marker(2 * k + 1))
        seg.first_span = _first_span(program, seg)
        done = seg.last + 1
    body.extend(program.body[done:])
    homing = {(b.span.file, b.span.line) for seg in segments
              for b in blocks(program.body[seg.first:seg.last + 1])
              if any(type(x) is n.HomeReturn for x in b.body)}
    run_marked(dataclasses.replace(program, body=body), segments, machine, resolver, homing,
               limits.setting("MAX_LOWERED_BLOCKS", limits.MAX_LOWERED_BLOCKS))


def run_marked(marked: n.Program, segments: list[Segment], machine, resolver, homing: set,
               most: Optional[int], spill: bool = False) -> None:
    """Run `marked` (the program with the segments' markers) through a SegmentHook."""
    hook = SegmentHook(marked, segments, machine, homing, most, spill)
    it = Interpreter(marked, machine, diagnostics=hook.diags, resolver=resolver, flatten_hook=hook)
    hook.interp = it
    try:
        for _ in it.run():
            pass
    except _AllRefused:
        return
    hook.finish()


class SegmentHook:
    """The flatten hook of the one run that lowers the segments: at a segment's start marker it
    checks the state the segment starts in and gives it a flattener, then hands that flattener
    the records up to the end marker, where it takes the source's modes. `most`: the plain-motion
    blocks a segment may hold (None when they are written as they come, not held). Raises
    _AllRefused once every segment is refused: the rest of the run is moot."""

    def __init__(self, program: n.Program, segments: list[Segment], machine, homing: set,
                 most: Optional[int], spill: bool = False):
        self.program = program
        self.spill = spill              # plain motion goes to a temporary file as it is made (Segment.spill)
        self.segments = segments
        self.machine = machine
        self.homing = homing            # (file, line) of the G28/G30 blocks inside segments
        self.most = most
        self.diags: list[Diagnostic] = []       # the interpreter's
        self.interp: Optional[Interpreter] = None
        self.current: Optional[Segment] = None

    def refuse(self, seg: Segment, why: str) -> None:
        """`seg` cannot be lowered: drop what it holds, and end the run once nothing is left to
        lower."""
        seg.why_not = seg.why_not or why
        seg.flattener = None
        seg.spill = None
        if all(s.why_not is not None for s in self.segments):
            raise _AllRefused()

    def __call__(self, rec, work_end, work_center) -> None:
        if rec.file == MARKER_FILE:
            self.marker(self.segments[rec.line // 2], rec.line % 2 == 0)
            return
        seg = self.current
        if seg is None or seg.flattener is None:
            return
        if (rec.file, rec.line) in self.homing and rec.kind == "rapid" and rec.start is not None and \
                rec.end is not None and all(abs(rec.end[a] - rec.start.get(a, rec.end[a])) < 1e-9 for a in rec.end):
            return      # G28's intermediate point where the tool already is: LinuxCNC does not move
        seg.flattener.hook(rec, work_end, work_center)
        if self.spill and len(seg.flattener.blocks) >= 1024:
            seg.spill.add(seg.flattener.blocks)
            seg.flattener.blocks.clear()
        if self.most is not None and len(seg.flattener.blocks) > self.most:
            self.current = None
            self.refuse(seg, f"its plain motion runs past {self.most:,} blocks, {HELD_LIMIT_NOTE} "
                             "(NCTRANS_MAX_LOWERED_BLOCKS; an endless loop?); convert --flatten streams "
                             "the whole program instead")

    def marker(self, seg: Segment, start: bool) -> None:
        it = self.interp
        state = _mode_state(it)
        if not start:
            seg.ends += 1
            seg.end_state = state
            if state["frame"] and seg.why_not is None:
                seg.why_not = "a programmable frame, G92 or local offset is active where it ends"
            for d in self.diags[seg.diag_mark:]:
                if _blocks_lowering(d):
                    seg.why_not = seg.why_not or reason_at(d)
            selected = _selection_to_restore(seg)
            name = it.unnumbered_tools.get(selected) if selected is not None else None
            if name is not None and seg.why_not is None:
                seg.why_not = (f"it selects tool {name!r}, which the target selects by number, and "
                               "the machine file names no tool so")
            self.current = None
            return
        seg.starts += 1
        seg.diag_mark = len(self.diags)
        seg.start_state = state
        if seg.starts > 1:
            self.current = None
            self.refuse(seg, "it does not run exactly once")
            return
        if state["comp"]:
            seg.why_not = "cutter radius compensation is on where it starts"
        elif it.st.diameter or getattr(it, "css_surface", None) is not None:
            seg.why_not = "diameter programming or constant surface speed is on where it starts"
        elif state["frame"]:
            seg.why_not = "a programmable frame, G92 or local offset is active where it starts"
        fl = _Flattener(self.program, self.machine, seg.notes)
        fl.interp = it
        fl.sel, fl.length, fl.motion, fl.plane = None, ("unknown", None), None, None
        fl.feed, fl.feed_mode, fl.speed, fl.spindle_dir = None, None, it.st.spindle_speed, it.st.spindle_dir
        fl.mpos = dict(it.mpos)
        fl.written_axes = set(it.positioned)    # the structural text before wrote those
        begin = [n.ModeChange("units", "mm"), n.ModeChange("distance", "absolute")]
        if state["arc_absolute"]:
            begin.append(n.ModeChange("arc_distance", "incremental"))
        fl.blocks.append(n.Block(seg.first_span, begin,
                                 comment="nctrans: plain motion of a construct the target lacks"))
        seg.flattener = fl
        if self.spill:
            from nctrans.spilled import Spill
            seg.spill = Spill()
        self.current = seg

    def finish(self) -> None:
        """After the run: a segment that ended the program (M30 inside it) never reached its end
        marker, so what the run left out inside it is checked here."""
        for seg in self.segments:
            if seg.flattener is not None and seg.flattener.ended and seg.ends == 0:
                for d in self.diags[seg.diag_mark:]:
                    if _blocks_lowering(d):
                        seg.why_not = seg.why_not or reason_at(d)


def _first_span(program: n.Program, seg: Segment) -> n.Span:
    node = program.body[seg.first]
    return n.Span(program.file, node.span.line)
