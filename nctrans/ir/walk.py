"""Walking the IR: the one place that knows how structures nest, where jumps land, and which
expressions are constants. Front ends, emitters and lowering passes use these instead of writing
their own recursion over `then` / `orelse` / `body`.
"""
from __future__ import annotations

from typing import Iterable, Iterator, Optional

from nctrans.ir import nodes as n
from nctrans.spilled import SpilledRun

# The node lists a structure holds, in source order (If: then, orelse; loops: body).
BODIES = ("then", "orelse", "body")


def children(node) -> Iterator[Iterable]:
    """The node lists nested in a structure (nothing for a Block). The plain motion of a construct
    lowered in a compact program (nctrans.spilled.SpilledRun) holds the Blocks the whole parse
    holds in its place, modes and all: they are read back a chunk at a time, so an analysis sees
    them as it sees the whole parse's (a run of plain source lines holds only motion and feeds)."""
    if type(node) is n.Block:
        return
    if type(node) is SpilledRun:
        yield _spilled_blocks(node)
        return
    for attr in BODIES:
        sub = getattr(node, attr, None)
        if sub:
            yield sub


def _spilled_blocks(run: SpilledRun) -> Iterator[n.Block]:
    part: Optional[SpilledRun] = run
    while part is not None:
        got, part = part.take(0)
        yield from got


def walk(nodes: Iterable) -> Iterator:
    """Every node of a node list, structures before what they hold, in source order."""
    for node in nodes:
        yield node
        for sub in children(node):
            yield from walk(sub)


def blocks(nodes: Iterable) -> Iterator[n.Block]:
    """Every Block of a node list, in source order, inside structures too."""
    for node in walk(nodes):
        if type(node) is n.Block:
            yield node


def units(program: n.Program) -> Iterator[tuple[Optional[str], list]]:
    """(None, main body) then (name, body) of each subprogram the program defines."""
    yield None, program.body
    for name, sub in (program.subprograms or {}).items():
        yield name, sub.body


def return_targets(nodes: Iterable) -> set[str]:
    """Block numbers a return jumps back to (ISO M99 P<n>): they are in the calling unit."""
    return {str(s.to_label) for b in blocks(nodes) for s in b.body
            if type(s) is n.Return and s.to_label}


def jump_targets(nodes: Iterable) -> set[str]:
    """Labels and block numbers a jump in these nodes can reach (GOTO, CASE branches, a return to a
    block number): where a position known from the blocks before stops being known."""
    out: set[str] = set()
    for node in walk(nodes):
        t = type(node)
        if t is n.Block:
            for s in node.body:
                if type(s) is n.Goto and s.computed is not None:
                    # a computed block number can land on any numbered block of these nodes
                    out.update(str(b.number) for b in blocks(nodes) if b.number is not None)
                elif type(s) is n.Goto:
                    out.add(str(s.target))
                elif type(s) is n.Return and s.to_label:
                    out.add(str(s.to_label))
                elif type(s) is n.SectionRepeat:      # the section runs again from its label
                    out.add(str(s.start))
                elif type(s) is n.CycleCall:          # CYCLE95/CYCLE72 contour "START:END"
                    out.update(v.value.partition(":")[0].strip() for v in s.params.values()
                               if type(v) is n.Str and ":" in v.value)
        elif t is n.Case:
            out.update(str(label) for _, label in node.branches)
            if node.default is not None:
                out.add(str(node.default))
    return out


def program_jump_targets(program: n.Program) -> set[str]:
    """jump_targets of every unit of the program."""
    out: set[str] = set()
    for _, body in units(program):
        out |= jump_targets(body)
    return out


def literal(e) -> Optional[float]:
    """The value of a number as written, signed or not (-5), else None: cheap enough for hot paths."""
    t = type(e)
    if t is n.Num:
        return float(e.value)
    if t is n.Unary and type(e.operand) is n.Num:
        if e.op == "-":
            return -float(e.operand.value)
        if e.op == "+":
            return float(e.operand.value)
    return None


_FOLD = {"+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
         "/": lambda a, b: a / b}


def constant(e) -> Optional[float]:
    """The value of a constant expression (numbers, unary sign and + - * /), else None; a division
    by zero is not a constant."""
    t = type(e)
    if t is n.Num:
        return e.value
    if t is n.Unary and e.op in ("-", "+"):
        v = constant(e.operand)
        return None if v is None else (-v if e.op == "-" else v)
    if t is n.Binary and e.op in _FOLD:
        a, b = constant(e.left), constant(e.right)
        if a is None or b is None or (e.op == "/" and b == 0):
            return None
        return _FOLD[e.op](a, b)
    return None


def ends_with_return(body: list) -> bool:
    """True when the last block with statements in `body` returns or ends the program (a
    subroutine that needs no return appended)."""
    for node in reversed(body):
        if not isinstance(node, n.Block):
            return False
        if any(isinstance(s, (n.Return, n.ProgramEnd)) for s in node.body):
            return True
        if node.body:
            return False
    return False
