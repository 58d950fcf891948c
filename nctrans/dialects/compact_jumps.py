"""A compact parse of a program that jumps into its main body (GOTO/GOTOB to a label or block
number, CASE, a label loop, M99 restarting an ISO main program, M99 P returning to one of its
block numbers), for convert (base.CompactBody.jumps).

A jump can only land on a block the interpreter and the emitters see: each run of plain blocks
that holds a block a jump names is split there, the block standing alone between the run's
pieces, so no run holds a jump target. The runs are read back once, a chunk at a time, to find
those blocks (only where the run's text holds the number at all).

What reads a stretch of the main body by its labels (REPEAT of a section, a computed GOTO that
may land on any numbered block, a contour given by block numbers or labels) is left to the whole
parse: None."""
from __future__ import annotations

import re
from typing import Optional

from nctrans.interp.compiled import label_key
from nctrans.ir import nodes as n
from nctrans.ir.walk import blocks, walk
from nctrans.plainrun import PlainRun, cut, run_blocks


def jump_targets(program: n.Program) -> Optional[set]:
    """The label keys (compiled.label_key) a jump may land on in the main body, or None when
    something reads a stretch of it by its labels."""
    main = [x for x in program.body if type(x) is not PlainRun]
    subs = [sub.body for sub in program.subprograms.values()]
    targets: set = set()
    for b in blocks(main + [x for body in subs for x in body]):
        for s in b.body:
            t = type(s)
            if t is n.SectionRepeat or (t is n.Goto and s.computed is not None):
                return None
            if t is n.CycleCall and any(k in ("start", "end") or (type(v) is n.Str and ":" in v.value)
                                        for k, v in s.params.items()):
                return None
            if t is n.Goto:
                targets.add(label_key(s.target))
            elif t is n.Return and s.to_label:
                targets.add(label_key(s.to_label))
    for node in walk(main):
        if type(node) is n.Case:
            targets.update(label_key(lab) for _, lab in node.branches)
            if node.default is not None:
                targets.add(label_key(node.default))
    return targets


def split_at_targets(program: n.Program) -> Optional[list]:
    """The main body's items with every run that holds a jump target split around it, or None
    (see jump_targets)."""
    targets = jump_targets(program)
    if targets is None:
        return None
    numbers = sorted(str(t) for t in targets if type(t) is int)
    # a run can only hold a target whose digits its text holds (N0100 is block 100)
    mark = re.compile(r"N0*(?:" + "|".join(numbers) + r")(?!\d)", re.IGNORECASE) if numbers else None
    out: list = []
    for x in program.body:
        if type(x) is not PlainRun or mark is None:
            out.append(x)
            continue
        end = x.extent().pos
        if mark.search(x.text, x.start, end if end is not None else len(x.text)) is None:
            out.append(x)
            continue
        out.extend(_split(x, targets))
    return out


def _split(run: PlainRun, targets: set) -> list:
    """`run` as pieces and the target blocks between them."""
    at = [k for k, b in enumerate(run_blocks(run))
          if b.number is not None and label_key(b.number) in targets]
    out: list = []
    rest: Optional[PlainRun] = run
    done = 0
    for k in at:
        if rest is None:
            break
        if k > done:
            head, rest = cut(rest, k - done)
            out.append(head)
        blocks_, rest = rest.take(1)
        out.extend(blocks_)
        done = k + 1
    if rest is not None:
        out.append(rest)
    return out
