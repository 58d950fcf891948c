"""The ISO emitter on a program that arrives in pieces (a streamed parse, or a flattened run).

`IsoEmitter.run()` writes the head (`%`, the O number, ...), then the main body, then the
subprograms and the closing `%`. Here run() is called on a shell of the program whose body is
empty, with the emitter's `nodes` watched so that the place where the body would go is known: the
head and the tail therefore come from run() itself and cannot drift from the whole-program text.
The body is then written chunk by chunk by the same emitter, so its state (modal groups, known
positions) carries over from chunk to chunk exactly as in one pass.

Only a body of plain blocks streams: a jump target, a label or a structure needs the plan run()
makes over the whole body (fresh N numbers must avoid every number in the program), so meeting
one raises CannotStream and the caller converts the whole program instead.
"""
from __future__ import annotations

import copy
from typing import Callable, Iterable, Optional

from nctrans.diagnostics import Diagnostic
from nctrans.dialects.base import CannotStream
from nctrans.ir import nodes as n


def emit_stream(program: n.Program, chunks: Iterable[list], write: Callable[[str], None],
                emitter_class) -> list[Diagnostic]:
    """Write `program` (its body given as `chunks`, lists of nodes) through `emitter_class` to
    `write` as it is produced; the emitter's diagnostics. The text is what emit_program gives."""
    if program.subprograms:
        raise CannotStream("subprograms")
    chunks = iter(chunks)
    first = next(chunks, None)      # a streamed parse fills program.meta as it starts
    shell = copy.copy(program)
    shell.body = []
    e = emitter_class(shell)
    split: Optional[int] = None
    whole_nodes = e.nodes

    def nodes(nodes_) -> None:
        nonlocal split
        if nodes_ is shell.body and split is None:
            split = len(e.out)
            return
        whole_nodes(nodes_)

    e.nodes = nodes
    e.run()
    if split is None:
        raise CannotStream("the emitter did not write a main body")
    head, tail = e.out[:split], e.out[split:]
    e.nodes = whole_nodes

    def no_fresh_label() -> str:
        raise CannotStream("a fresh N number")
    e.fresh_label = no_fresh_label
    e.written = False
    if hasattr(e, "distance_known"):
        e.distance_known = None     # whether the body ends the program (M30) is not seen ahead
    _flush(e, head, write)
    # each chunk is let go before the next is parsed: one chunk of IR is held at a time
    if first is not None:
        _body(e, first, write)
    first = None
    for chunk in chunks:
        _body(e, chunk, write)
        del chunk
    _flush(e, tail, write)
    if not e.written:
        write("\n")                 # as "\n".join([]) + "\n"
    return e.diags


# Statements that jump or call: their targets are planned over the whole program.
_PLANNED = (n.Goto, n.SubCall, n.Return)


def _body(e, chunk: list, write: Callable[[str], None]) -> None:
    for node in chunk:
        if type(node) is not n.Block or node.label or any(type(s) in _PLANNED for s in node.body):
            raise CannotStream(f"{type(node).__name__} at line {node.span.line}")
    e.out = []
    e.nodes(chunk)
    _flush(e, e.out, write)


def _flush(e, lines: list[str], write: Callable[[str], None]) -> None:
    if lines:
        write("\n".join(lines) + "\n")
        e.written = True
