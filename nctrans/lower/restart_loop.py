"""M99 at the end of an ISO main program: the control starts the program again, for ever.

A target with an endless loop (Sinumerik LOOP, Fagor $WHILE 1) writes the body inside one; a
target without one must never write the restart as one pass and a program end (issue #9)."""
from __future__ import annotations

from typing import Optional

from nctrans.ir import nodes as n


def restart_block(body: list) -> Optional[int]:
    """The index of the main body's last block when it ends the program with a restart (M99)."""
    if type(body) is not list:
        return None
    last = next((i for i in range(len(body) - 1, -1, -1)
                 if isinstance(body[i], n.Block) and body[i].body), None)
    if last is None or not any(isinstance(s, n.ProgramEnd) and s.kind == "restart"
                               for s in body[last].body):
        return None
    return last


def as_loop(body: list, last: int) -> list:
    """The body with the restart of block `last` taken out and everything up to it in a Loop."""
    b = body[last]
    rest = [s for s in b.body if not (isinstance(s, n.ProgramEnd) and s.kind == "restart")]
    inner = body[:last] + ([n.Block(b.span, rest, b.number, b.label, b.skip, b.comment)]
                           if rest or b.number or b.comment else [])
    return [n.Loop(body[0].span if body else b.span, inner)] + body[last + 1:]
