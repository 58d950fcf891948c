"""Per-construct lowering of a program that streams, written as it goes: memory stays flat in
program size.

convert's per-construct lowering (`nctrans.lower.constructs`) holds the whole program parsed: it
finds the segments over the top-level nodes, runs the program once with markers around them and
emits the lowered program again. A program that streams runs straight through: the streaming
emitter took it whole (it refuses labels, jumps, calls and structures) and only refused single
constructs, so no jump or loop crosses a segment, and the same lowering is done in three passes
over the text, none of which holds it parsed:

1. survey (`_survey`): the node each refusal is at, and the modal runs and stretches that widen it
   (only those that can touch a refused node are kept). The segments are then widened and merged
   as convert widens them;
2. a run of the interpreter over a second parse with markers around the segments, each segment's
   records going to its own flattener (`constructs.SegmentHook`). Each segment's nodes are
   scanned (variables, what plain motion cannot carry) as they go to the interpreter, standing in
   for convert's checks before its run (a segment that sets variables takes one more parse, to
   count who else reads them);
3. the target's streaming emitter over a third parse: nodes outside the segments go to it as they
   are; at a segment the run is driven to the segment's end marker, its plain motion handed on as
   it comes, then the source's modes; the segment's own nodes are skipped. Between segments the run
   lags behind the emitter, and it stops after the last segment.

What a segment cannot be lowered for, the notes and the refusals are convert's, and so is the last
resort: when a refusal remains, the whole program is lowered to plain motion, streamed too.
"""
from __future__ import annotations

import bisect
from collections import Counter
from dataclasses import dataclass, field
from typing import Callable, Iterable, Iterator, Optional

from nctrans.convert import Conversion, _is_refusal, _whole_note, _with_header, stream_chunks, subprogram_file
from nctrans.diagnostics import Diagnostic
from nctrans.dialects.base import CannotStream
from nctrans.interp.interpreter import Interpreter
from nctrans.ir import nodes as n
from nctrans.ir.walk import blocks
from nctrans.lower.constructs import (
    OFFSET_DATA_WHY, STRETCH_MODES, Segment, SegmentHook, _AllRefused, _local, _local_names, _marker, _ModalRuns,
    _restore, _sets, _StretchRuns, _CornerRuns, _variables_reason, _vars, _written, lowered_notes, reason_at, refused)
from nctrans.lower.flatten import _Walker


def _nodes(body: Iterable) -> Iterator:
    """The nodes of a streamed body one by one (runs of plain blocks taken apart a few at a
    time: the passes that only look at nodes hold no more)."""
    for chunk in stream_chunks(body, 256):
        yield from chunk


class _NotStraight(Exception):
    """The program holds a node only the whole-program lowering handles (a label, a structure)."""


class _AllSegmentsRefused(Exception):
    """Pass 3 stops: no segment can be lowered on its own."""


@dataclass
class _Scan:
    """What pass 2 learns about one segment's nodes as they go to the interpreter."""
    walker: _Walker
    found: list[Diagnostic] = field(default_factory=list)     # the walker's
    written: set = field(default_factory=set)
    mentions: Counter = field(default_factory=Counter)        # variable -> nodes inside naming it
    first_line: Optional[int] = None
    last_line: Optional[int] = None
    static_why: Optional[str] = None        # why not, found before the run in convert
    offset_data: bool = False               # holds a G10: never lowered alone (constructs.py)
    walk_notes: list[Diagnostic] = field(default_factory=list)


@dataclass
class _Survey:
    segments: list[Segment]
    outside: list[Diagnostic]               # refusals at no node of the main body


# Statements that name other blocks (jumps, calls, section repetitions): the streaming emitters
# refuse them, so a program holding one was never surveyed; checked all the same.
_NAMING = (n.Goto, n.SubCall, n.Return, n.SectionRepeat)


def _straight(node) -> n.Block:
    if type(node) is not n.Block or node.label or any(type(s) in _NAMING for s in node.body):
        raise _NotStraight(f"{type(node).__name__} at line {node.span.line}")
    return node


def _survey(nodes: Iterable, file: str, refusals: list[Diagnostic]) -> _Survey:
    """Pass 1: the segments of `refusals` over a streamed body (see the module docstring)."""
    wanted = {d.line for d in refusals if d.file == file}
    index: dict[int, int] = {}
    refused_at: list[int] = []              # indices of refused nodes, ascending
    modal: list[tuple[int, int]] = []
    stretch: list[tuple[int, int]] = []

    def modal_closed(a: int, b: int) -> None:
        k = bisect.bisect_left(refused_at, a)
        if k < len(refused_at) and refused_at[k] <= b:
            modal.append((a, b))

    # a stretch matters only when it starts inside a segment: at a refused node, inside a modal
    # run, or inside a stretch of another group (the widening's own order)
    relevant: set[int] = set()
    modal_scan = _ModalRuns(modal_closed)
    corner_scan = _CornerRuns(modal_closed)
    stretch_scan = _StretchRuns(keep=relevant.__contains__)
    last = -1
    for i, node in enumerate(nodes):
        node = _straight(node)
        last = i
        line = node.span.line
        if line in wanted and line not in index and node.span.file == file:
            index[line] = i
            refused_at.append(i)
        open_before = modal_scan.start is not None or any(
            s is not None for s in stretch_scan.start.values())
        modal_scan.feed(i, node)
        corner_scan.feed(i, node)
        stretch_scan.feed(i, node)
        if i in stretch_scan.start.values() and (
                open_before or modal_scan.start is not None or (refused_at and refused_at[-1] == i)):
            relevant.add(i)
    modal_scan.end(last)
    corner_scan.end(last)
    stretch = stretch_scan.end(last)
    found: list[Segment] = []
    outside: list[Diagnostic] = []
    for d in refusals:
        i = index.get(d.line) if d.file == file else None
        if i is None:
            outside.append(d)
        else:
            found.append(Segment(i, i, [d]))
    from nctrans.lower.constructs import _widened
    return _Survey(_widened(found, modal, stretch), outside)


class _StreamedLowering:
    """Passes 2 and 3 over two parses of the same text."""

    def __init__(self, survey: _Survey, run_program: n.Program, machine, resolver,
                 reparse: Callable[[], Optional[n.Program]]):
        self.survey = survey
        self.reparse = reparse
        self.segments = survey.segments
        self.scans = []
        for _ in self.segments:
            found: list[Diagnostic] = []
            self.scans.append(_Scan(_Walker(found, getattr(machine, "kind", "mill")), found))
        marked = n.Program(run_program.file, run_program.dialect,
                           self._marked(_nodes(run_program.body), run_program.file),
                           {}, run_program.meta, None)
        # the interpreter reads the program's meta (defaults) as it starts: the streamed parse
        # filled it by then, as the interpreter pulls the first blocks
        self.hook = SegmentHook(run_program, self.segments, machine, set(), None)
        self.interp = Interpreter(marked, machine, diagnostics=self.hook.diags, resolver=resolver,
                                  flatten_hook=self.hook)
        self.hook.interp = self.interp
        self.records = self.interp.run()
        self.run_over = False

    # pass 2: what the interpreter runs
    def _marked(self, nodes: Iterable, file: str) -> Iterator[n.Block]:
        segs = self.segments
        k = 0
        for i, node in enumerate(nodes):
            seg = segs[k] if k < len(segs) else None
            if seg is None or i < seg.first:
                yield node
                continue
            if i == seg.first:
                seg.first_span = n.Span(file, node.span.line)
                yield _marker(2 * k)
            self._scan(self.scans[k], node)
            yield node
            if i == seg.last:
                self._checked(seg, self.scans[k])
                yield _marker(2 * k + 1)
                k += 1

    def _mentions(self, wanted: set) -> tuple[Counter, set[str]]:
        """(how many nodes of the whole body name each variable of `wanted`, the names the body
        declares local): one more streamed parse, made only for a segment that sets variables."""
        program = self.reparse()
        total: Counter = Counter()
        names: set[str] = set()
        for node in _nodes(program.body if program is not None else ()):
            seen: set = set()
            _vars(node, seen)
            total.update(seen & wanted)
            names |= _local_names([node])
        return total, names

    def _scan(self, scan: _Scan, node) -> None:
        scan.walker.nodes([node])
        scan.written |= _written([node])
        seen: set = set()
        _vars(node, seen)
        scan.mentions.update(seen)
        for b in blocks([node]):
            line = b.span.line
            scan.first_line = line if scan.first_line is None else min(scan.first_line, line)
            scan.last_line = line if scan.last_line is None else max(scan.last_line, line)
            if any(type(x) is n.DataSetting for x in b.body):
                scan.offset_data = True
            if any(type(x) is n.HomeReturn for x in b.body):
                self.hook.homing.add((b.span.file, line))

    def _checked(self, seg: Segment, scan: _Scan) -> None:
        """convert's checks before its run, on the segment's nodes now all seen: the variables it
        sets, then what plain motion cannot carry."""
        if scan.offset_data:
            scan.static_why = OFFSET_DATA_WHY
        elif scan.written:
            total, names = self._mentions(scan.written)
            elsewhere = {v for v, count in total.items() if count > scan.mentions.get(v, 0)}
            scan.static_why = _variables_reason(scan.written, elsewhere,
                                                lambda sp, k: _local(sp, k, names))
        if scan.static_why is None:
            blocked = [d for d in scan.found if d.severity == "error"]
            if blocked:
                scan.static_why = reason_at(blocked[0])
            else:
                scan.walk_notes = [_replace_flatten(d) for d in scan.found]

    # pass 3: what the emitter writes
    def emitted(self, body: Iterable) -> Iterator[n.Block]:
        segs = self.segments
        k = 0
        nodes = enumerate(_nodes(body))
        nxt = next(nodes, None)
        while nxt is not None:
            i, node = nxt
            if k < len(segs) and i == segs[k].first:
                seg = segs[k]
                yield from self._drive(seg)
                while nxt is not None and nxt[0] <= seg.last:
                    nxt = next(nodes, None)
                units_follow = nxt is None or _sets(nxt[1], "units")
                if self._verdict(seg, self.scans[k]) is None and seg.end_state is not None:
                    restore = _restore(seg, n.Span(node.span.file, self.scans[k].last_line or node.span.line),
                                       units_follow)
                    if restore.body:
                        yield restore
                k += 1
                continue
            yield node
            nxt = next(nodes, None)

    def _drive(self, seg: Segment) -> Iterator[n.Block]:
        """Run until `seg` has ended (or the run has), handing on its plain motion as it comes."""
        while seg.ends == 0 and not self.run_over:
            try:
                next(self.records)
            except StopIteration:
                self.run_over = True
            except _AllRefused:
                raise _AllSegmentsRefused() from None
            fl = seg.flattener
            if fl is not None and fl.blocks:
                yield from fl.blocks
                fl.blocks.clear()

    def _verdict(self, seg: Segment, scan: _Scan) -> Optional[str]:
        """Why `seg` cannot be lowered on its own (convert's reasons in convert's order), or None;
        set as seg.why_not."""
        seg.why_not = scan.static_why or seg.why_not
        ended = seg.flattener is not None and seg.flattener.ended
        if seg.why_not is None and (seg.starts != 1 or seg.ends != (0 if ended else 1)):
            seg.why_not = "it does not run exactly once" if seg.starts else "it never runs"
        if seg.why_not is None and seg.end_state is not None and seg.end_state["comp"]:
            seg.why_not = "cutter radius compensation is on at its end"
        return seg.why_not

    def outcome(self, target_name: str) -> tuple[list[Diagnostic], list[Diagnostic]]:
        """(notes of the segments lowered, refusals that remain), once pass 3 has ended."""
        self.hook.finish()
        notes: list[Diagnostic] = []
        remaining = list(self.survey.outside)
        for seg, scan in zip(self.segments, self.scans):
            if self._verdict(seg, scan) is not None:
                remaining.extend(refused(seg))
                continue
            seg.notes[:0] = scan.walk_notes
            first = scan.first_line if scan.first_line is not None else seg.first_span.line
            last = scan.last_line if scan.last_line is not None else first
            notes.extend(lowered_notes(seg, target_name, first, last))
        return notes, remaining

    def refused_lines(self) -> list[tuple[int, int]]:
        """(first, last) source lines of each segment that cannot be lowered on its own."""
        return [(scan.first_line, scan.last_line) for seg, scan in zip(self.segments, self.scans)
                if seg.why_not is not None and scan.first_line is not None]

    def close(self) -> None:
        self.records.close()


def _replace_flatten(d: Diagnostic) -> Diagnostic:
    import dataclasses
    return dataclasses.replace(d, message=d.message.replace("--flatten", "plain motion"))


def convert_constructs_stream(reparse: Callable[[], Optional[n.Program]], target, found: list[Diagnostic],
                              write: Callable[[str], None], reset: Callable[[], None], *, machine,
                              resolver=None) -> Optional[Conversion]:
    """convert()'s per-construct lowering for a program that streams, written to `write` as it
    goes. `reparse()` parses the program again, streamed; `found` is what the streaming emitter
    reported on the program as it stands (its NC402 refusals are the constructs to lower).
    `reset()` discards what was written. A Conversion as convert() gives it (text "" when written,
    None when refused), or None when the program needs the whole-program path after all."""
    refusals = [d for d in found if _is_refusal(d)]
    if not refusals:
        return None
    others = [d for d in found if not _is_refusal(d)]
    first = reparse()
    if first is None or subprogram_file(first):
        return None             # convert() says why a subprogram file's constructs are not lowered
    try:
        survey = _survey(_nodes(first.body), first.file, refusals)
    except _NotStraight:
        return None
    run_program, emit_program = reparse(), reparse()
    if run_program is None or emit_program is None:
        return None
    lowering = _StreamedLowering(survey, run_program, machine, resolver, reparse)
    reset()
    again: Optional[list[Diagnostic]] = None
    try:
        again = target.emit_stream(emit_program, stream_chunks(lowering.emitted(emit_program.body)),
                                   _with_header(target, emit_program, write))
    except CannotStream:
        reset()
        return None
    except _AllSegmentsRefused:
        pass
    finally:
        lowering.close()
    if again is None and not all(s.why_not is not None for s in survey.segments):
        reset()
        return None
    notes, remaining = lowering.outcome(target.name)
    if again is not None:
        # a refused segment was written as plain motion all the same (its verdict came at its
        # end): what the target refuses in that motion is moot, convert emits the segment as it was
        moot = lowering.refused_lines()
        kept = {(d.file, d.line) for d in remaining}
        remaining += [d for d in again if _is_refusal(d) and (d.file, d.line) not in kept
                      and not any(a <= d.line <= b for a, b in moot)]
    if not remaining:
        return Conversion("", others + notes)
    reset()
    return _whole_stream(reparse, target, write, reset, machine, resolver,
                         [_whole_note(d, target) for d in remaining], others + notes, remaining)


def _whole_stream(reparse, target, write, reset, machine, resolver, whole_notes: list[Diagnostic],
                  before: list[Diagnostic], remaining: list[Diagnostic]) -> Optional[Conversion]:
    """convert()'s last resort, streamed: the whole program lowered to plain motion, written as it
    runs (stopping at the first thing that makes it incomplete); when that fails too, refused with
    `before` and the `remaining` refusals."""
    from nctrans.convert import convert_flat_stream, whole_failure
    from nctrans.lower.flatten import flatten_blocks, flattened_meta
    program = reparse()
    if program is None:
        return None

    def flat(into: list[Diagnostic]):
        return flatten_blocks(program, machine, diagnostics=into, resolver=resolver,
                              stop_when_incomplete=True)

    done = convert_flat_stream(program, target, flat, flattened_meta(program), write)
    if done is None:
        reset()
        return None
    if done.text is None:
        reset()
        if getattr(target, "refuses_in_place", False):
            return None     # convert() writes what is left as alarms in place (NC412), parsed whole
        return Conversion(None, before + whole_failure(remaining, done.diagnostics))
    return Conversion(done.text, [*whole_notes, *done.diagnostics], flattened=True)
