"""Loop lowerings: IR -> IR passes for targets that have WHILE but not every kind of loop.

A pass takes a Program and returns a new Program (the input is left as it was: a conversion may
fall back to flattening the original) and its diagnostics: one NC401 info, at the first construct
it rewrote. A target dialect lists the passes it needs in `Dialect.lowering_passes`; the emitter then
never sees the construct, so each lowering is written once for every target instead of once per
emitter.
"""
from __future__ import annotations

import dataclasses
from typing import Callable, Optional

from nctrans.diagnostics import Diagnostic, at_span
from nctrans.ir import nodes as n
from nctrans.dialects.base import CompactBody
from nctrans.ir.walk import BODIES


def for_to_while(program: n.Program) -> tuple[n.Program, list[Diagnostic]]:
    """FOR var = start TO end [STEP s] ... ENDFOR  ->  var = start; WHILE var <= end (>= for a
    negative constant step) ... var = var + step; END. The loop variable ends one step past `end`,
    as on a control that runs FOR itself."""
    return _rewrite(program, n.ForLoop, _for_as_while, "FOR loops written as WHILE loops")


def _for_as_while(loop: n.ForLoop) -> list:
    step = loop.step if loop.step is not None else n.Num(1.0)
    down = type(step) is n.Num and step.value < 0
    cond = n.Binary(">=" if down else "<=", loop.var, loop.end)
    increment = n.Block(loop.span, [n.Assign(loop.var, n.Binary("+", loop.var, step))])
    return [n.Block(loop.span, [n.Assign(loop.var, loop.start)]),
            n.While(loop.span, cond, [*loop.body, increment])]


def _rewrite(program: n.Program, kind: type, rewrite: Callable[[object], list],
             message: str) -> tuple[n.Program, list[Diagnostic]]:
    """`program` with every node of type `kind` replaced by rewrite(node) (after its own bodies
    are rewritten); NC401 `message` at the first one."""
    first: list[Optional[n.Span]] = []

    def nodes(ns: list) -> list:
        out = []
        changed = False
        for node in ns:
            if type(node) is kind and not first:      # source order: before its nested ones
                first.append(node.span)
            new = node
            if type(node) is not n.Block:
                subs = {attr: nodes(getattr(node, attr)) for attr in BODIES
                        if isinstance(getattr(node, attr, None), list)}
                if any(subs[a] is not getattr(node, a) for a in subs):
                    new = dataclasses.replace(node, **subs)
            if type(new) is kind:
                out.extend(rewrite(new))
                changed = True
            else:
                out.append(new)
                changed = changed or new is not node
        return out if changed else ns

    body = program.body
    if type(body) is list:          # a streamed body runs straight through: no loops in it
        body = nodes(body)
    elif type(body) is CompactBody:     # its runs are plain blocks: the structures between them
        items = nodes(body.items)
        if items is not body.items:
            body = CompactBody(items, body.jumps)
    subs = {}
    for name, sub in (program.subprograms or {}).items():
        new = nodes(sub.body)
        subs[name] = sub if new is sub.body else dataclasses.replace(sub, body=new)
    if not first:
        return program, []
    result = dataclasses.replace(program, body=body, subprograms=subs)
    return result, [at_span("NC401", "info", message, first[0])]


# A pass that rewrites structures only (loops, branches) leaves a body of plain blocks as it is: a
# streamed conversion (whose body is plain blocks by construction) may skip it.
for_to_while.structural_only = True  # type: ignore[attr-defined]
