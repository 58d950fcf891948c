"""Per-construct lowering (nctrans.lower.constructs) of a program parsed compact
(Dialect.parse_compact), with memory flat in the length of its runs of plain blocks.

The segments, their checks and their run are convert's own (constructs.lower_constructs on the
whole parse), indexed as the whole parse's top-level nodes (compact_body.CompactView): a segment
may take runs of plain blocks whole or in part (Sinumerik G70 over a CAM stretch, a modal cycle
over plain positions, a refused plain line), and those runs are cut into pieces at its borders,
never built whole. The run writes each segment's plain motion to a temporary file as it is made
(nctrans.spilled), and the lowered program holds it there as a SpilledRun the emitters read back
a chunk at a time. Since nothing is held, a segment's plain motion is not bounded by
limits.MAX_LOWERED_BLOCKS (as in the streamed lowering, stream_constructs); an endless loop
around a construct still stops at the interpreter's budgets.

A program that jumps into its main body is parsed with no jump target inside a run
(dialects/compact_jumps.py); a jump to a label inside a run (a contour's block numbers, G71 P Q,
in a program parsed compact for its other consumers) still needs the whole parse
(convert.NeedsWholeParse)."""
from __future__ import annotations

import dataclasses
from typing import Callable, Optional

from nctrans.convert import NeedsWholeParse
from nctrans.diagnostics import Diagnostic
from nctrans.ir import nodes as n
from nctrans.ir.walk import blocks
from nctrans.lower import constructs as c
from nctrans.lower.compact_body import CompactView, labelled_blocks
from nctrans.plainrun import PlainRun, run_blocks


def lower_compact(program: n.Program, refusals: list[Diagnostic], target_name: str, *,
                  machine=None, resolver: Optional[Callable] = None
                  ) -> tuple[Optional[n.Program], list[Diagnostic], list[Diagnostic]]:
    """constructs.lower_constructs for a program whose body is a CompactBody: the same segments,
    notes and refusals, and a lowered program whose body is a CompactBody again (its segments'
    plain motion as SpilledRuns)."""
    from nctrans.dialects.base import CompactBody
    if machine is None:
        from nctrans.machine import default_mill
        machine = default_mill()
    view = CompactView(list(program.body.items))
    structure = [(i, x) for i, x in view.pairs() if type(x) is not PlainRun]
    nodes_ = [x for _, x in structure]
    targets = c._jumps(nodes_)
    if targets and (not targets <= c._labels(nodes_)
                    or next(labelled_blocks(view.items, targets, c._label_key), None) is not None):
        raise NeedsWholeParse("a jump to a label that may be in a run of plain blocks")
    segments, remaining = _segments(program, view, refusals)
    segments = c._widen_over_jumps([], segments, structure)
    _static_checks(program, view, structure, segments)
    for seg in segments:
        c._walk_check(seg, [x for i, x in structure if seg.first <= i <= seg.last], machine)
    live = [s for s in segments if s.why_not is None]
    if live:
        _run(program, view, structure, live, machine, resolver)
    new_body, notes = c.close_segments(segments, remaining, target_name, program.file, len(view),
                                       view.slice, view.node, _lines, _spilled)
    if new_body is None:
        return None, notes, remaining
    return dataclasses.replace(program, body=CompactBody(new_body, program.body.jumps)), notes, remaining


def _segments(program: n.Program, view: CompactView, refusals: list[Diagnostic]
              ) -> tuple[list[c.Segment], list[Diagnostic]]:
    """constructs._segments over the view: a refused line inside a run is that block's node."""
    index = view.line_index(program.file, {d.line for d in refusals if d.file == program.file})
    found, outside = c.placed(refusals, program.file, index)
    modal, stretch = _scan(view)
    return c._widened(found, modal, stretch), outside


def _scan(view: CompactView) -> tuple[list[tuple[int, int]], list[tuple[int, int]]]:
    """constructs._modal_runs and _stretch_runs in one pass over the view. A plain block only
    matters to a scan that is open and that a plain block may close (a canned cycle, a corner
    chain or RNDM, a tapping stretch: it holds a motion code and moves); a run is read back only
    while one is, and otherwise stepped over by its count."""
    modal: list[tuple[int, int]] = []
    cycles = c._ModalRuns(lambda a, b: modal.append((a, b)))
    corners = c._CornerRuns(lambda a, b: modal.append((a, b)))
    stretches = c._StretchRuns()

    def open_to_plain() -> bool:
        return ((cycles.start is not None and cycles.kind == "cycle") or corners.start is not None
                or corners.modal or stretches.start["motion"] is not None)

    for k, (i, x) in enumerate(view.pairs()):
        if type(x) is PlainRun:
            if open_to_plain():
                for j, b in view.run_nodes(k):
                    cycles.feed(j, b)
                    corners.feed(j, b)
                    stretches.feed(j, b)
                    if not open_to_plain():
                        break
            continue
        cycles.feed(i, x)
        corners.feed(i, x)
        stretches.feed(i, x)
    last = len(view) - 1
    cycles.end(last)
    corners.end(last)
    return modal, stretches.end(last)


def _labels_in(nodes: list, wanted: set[str]) -> set[str]:
    """The labels of `nodes` (runs read back only for those in `wanted`)."""
    found = c._labels([x for x in nodes if type(x) is not PlainRun])
    missing = wanted - found
    for b in labelled_blocks(nodes, missing, c._label_key):
        found.add(c._label_key(b.number))
    return found


def _static_checks(program: n.Program, view: CompactView, structure: list, segments: list[c.Segment]) -> None:
    """constructs._static_checks over the view: assignments, jumps and G10 are never in a run."""
    subs = [s.body for s in program.subprograms.values()]
    local_names = c._local_names([x for _, x in structure])
    for seg in segments:
        inside_nodes = [x for i, x in structure if seg.first <= i <= seg.last]
        rest = [x for i, x in structure if not seg.first <= i <= seg.last]
        from_elsewhere = c._jumps(rest + [x for s in subs for x in s])
        own = c._jumps(inside_nodes)
        inside = view.slice(seg.first, seg.last) if from_elsewhere or own else inside_nodes
        labels = _labels_in(inside, from_elsewhere | own)
        landing = from_elsewhere & labels
        if landing:
            lab = sorted(landing)[0]
            line = next(b.span.line for b in _blocks(inside)
                        if lab in (c._label_key(b.label), c._label_key(b.number)))
            seg.why_not = (f"a jump or repetition from elsewhere lands on its label {lab} "
                           f"(line {line}), which plain motion does not keep")
        elif not own <= labels:
            seg.why_not = "it jumps out of itself"
        elif any(type(x) is n.DataSetting for b in blocks(inside_nodes) for x in b.body):
            seg.why_not = c.OFFSET_DATA_WHY
        else:
            read: set = set()
            c._vars(rest, read)
            for sb in subs:
                c._vars(sb, read)
            seg.why_not = c._variables_reason(c._written(inside_nodes), read,
                                              lambda sp, k: c._local(sp, k, local_names))


def _blocks(nodes: list):
    """Every Block of `nodes`, runs read back a chunk at a time."""
    for x in nodes:
        if type(x) is PlainRun:
            yield from run_blocks(x)
        else:
            yield from blocks([x])


def _spilled(seg: c.Segment) -> list:
    """A segment's plain motion as the run of its spill (the flattener's last blocks added)."""
    seg.spill.add(seg.flattener.blocks)
    seg.flattener.blocks.clear()
    return [seg.spill.close()]


def _lines(nodes: list) -> tuple[int, int]:
    """(first, last) source line of a segment's blocks (`nodes` in source order)."""
    first = next((b.span.line for b in _blocks(nodes[:1])), None)
    if first is None:
        first = next((b.span.line for b in _blocks(nodes)), nodes[0].span.line)
    last = None
    for x in reversed(nodes):
        for b in _blocks([x]):
            last = b.span.line
        if last is not None:
            break
    return first, last if last is not None else first


def _run(program: n.Program, view: CompactView, structure: list, segments: list[c.Segment],
         machine, resolver) -> None:
    """constructs._run over the view: the marked body a CompactBody (runs cut at the markers),
    each segment's plain motion spilled as it is made."""
    from nctrans.dialects.base import CompactBody
    body: list = []
    done = 0
    for k, seg in enumerate(segments):
        body.extend(view.slice(done, seg.first - 1))
        body.append(c._marker(2 * k))
        body.extend(view.slice(seg.first, seg.last))
        body.append(c._marker(2 * k + 1))
        seg.first_span = n.Span(program.file, _span_line(view.node(seg.first)))
        done = seg.last + 1
    body.extend(view.slice(done, len(view) - 1))
    homing = {(b.span.file, b.span.line) for seg in segments
              for b in blocks([x for i, x in structure if seg.first <= i <= seg.last])
              if any(type(s) is n.HomeReturn for s in b.body)}
    c.run_marked(dataclasses.replace(program, body=CompactBody(body, program.body.jumps)), segments, machine, resolver,
                 homing, None, spill=True)


def _span_line(node) -> int:
    return node.span.line
