"""Which corner elements of the source its control inserts in a way a target's same word cannot say.

A Sinumerik control shrinks a rounding or chamfer too large for the blocks around it (rules
`too_large = "reduced"` [GK]) and puts an element across blocks that move nothing (`zero_length =
"dummy"`); an ISO control alarms at the same `,R` / `,C`. Whether an element fits is a question of the
geometry at the corner, which only the interpreter knows, so a writer of such a target asks here
before it writes the word: the source runs once (records dropped, memory flat) and the blocks whose
element did not fit or spans such blocks come back as (file, line). The writer then lowers that
construct (the interpreter writes the arc it inserts), or, for an element the control shrinks,
writes the shrunk size (`shrunk_corners`); where not even the smallest element fits, the lowering
refuses it at its line (NC402 after NC219).
"""
from __future__ import annotations

import os
from typing import Any

from nctrans.ir import nodes as n

_LAST: list[Any] = [None, frozenset(), {}]      # (program, its answers): one conversion at a time


def unfit_corners(program: n.Program, machine=None) -> frozenset:
    """(file, line) of every block whose corner element the source control inserts so."""
    _run(program, machine)
    return _LAST[1]


def shrunk_corners(program: n.Program, machine=None) -> dict:
    """(file, line) -> the size (program units) the source control shrinks the block's element to
    where it is too large for its blocks (nctrans.interp.corner_elements._shrunk): a writer whose
    word the target's control alarms on when too large writes that size instead."""
    _run(program, machine)
    return _LAST[2]


def _run(program: n.Program, machine) -> None:
    if _LAST[0] is program:
        return
    from nctrans import pipeline
    from nctrans.interp.interpreter import Interpreter
    source_dir = os.path.dirname(program.file) if program.file and program.file != "<stdin>" else None
    it = Interpreter(program, machine, diagnostics=[],
                     resolver=pipeline.make_resolver(source_dir or None, program.dialect))
    it.corner_unfit = set()
    it.corner_shrunk = {}
    for _ in it.run():
        pass
    _LAST[:] = [program, frozenset(it.corner_unfit), dict(it.corner_shrunk)]
