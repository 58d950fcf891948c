"""The Fagor emitter on a program that arrives in pieces (a streamed parse, or a flattened run).

`FagorEmitter.run()` writes the local subroutines, then `%NAME`, the power-on modes and the main body.
A program that streams has no subroutines, so the head is `%NAME` and the prologue, written by
the emitter's own methods; the body is then written chunk by chunk by the same emitter, whose
state (motion, distance, plane, tool length) carries over from chunk to chunk as in one pass, so
the text is the one emit_program gives, without holding it whole.

Only plain blocks stream: a jump target must be known before the block it names is written
(`N10:`), so a label, a jump, a call or a structure raises CannotStream and the caller converts
the whole program instead.
"""
from __future__ import annotations

from typing import Callable, Iterable

from nctrans.diagnostics import Diagnostic
from nctrans.dialects.base import CannotStream
from nctrans.ir import nodes as n

from .emitter import FagorEmitter, _program_header

# Statements whose targets are planned over the whole program.
_PLANNED = (n.Goto, n.SubCall, n.Return)


def emit_stream(program: n.Program, chunks: Iterable[list], write: Callable[[str], None]
                ) -> list[Diagnostic]:
    """Write `program` (its body given as `chunks`, lists of nodes) to `write` as it is produced;
    the emitter's diagnostics."""
    if program.subprograms:
        raise CannotStream("subprograms")
    chunks = iter(chunks)
    first = next(chunks, None)      # a streamed parse fills program.meta as it starts
    e = FagorEmitter(program)
    e.in_sub = False
    e._reset()
    e.out.append(f"%{_program_header(program)}")
    e.prologue()
    _flush(e, write)
    # each chunk is let go before the next is parsed: one chunk of IR is held at a time
    if first is not None:
        _body(e, first, write)
    first = None
    for chunk in chunks:
        _body(e, chunk, write)
        del chunk
    return e.diags


def _body(e: FagorEmitter, chunk: list, write: Callable[[str], None]) -> None:
    for node in chunk:
        if type(node) is not n.Block or node.label or any(type(s) in _PLANNED for s in node.body):
            raise CannotStream(f"{type(node).__name__} at line {node.span.line}")
    e.nodes(chunk)
    _flush(e, write)


def _flush(e: FagorEmitter, write: Callable[[str], None]) -> None:
    if e.out:
        write("\n".join(e.out) + "\n")
        e.out = []
