"""What the ISO emitter decides about a program before writing a line of it.

ISO has no names: labels become N numbers, named subprograms O numbers, PROC parameters G65
argument locals (#1..#33), declared arrays blocks of common variables. These maps must exist
before the first GOTO or call is written (a jump may go forward), so they are computed here in
one pass over the whole program. Also the geometry the emitter needs to turn a three-point arc
(Sinumerik CIP) into a centre-format arc.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Iterator, Optional

from nctrans import calls
from nctrans.ir import nodes as n
from nctrans.ir.walk import blocks, constant, walk

# G65 Type I letters for PROC parameters in order, and the local each one lands in (spec §1.8.1).
# I/J/K are left out (their Type II repetition makes the order ambiguous), G L N O P are not arguments.
ARG_LETTERS = "ABCDEFHMQRSTUVWXYZ"
ARG_LOCALS = {"A": 1, "B": 2, "C": 3, "D": 7, "E": 8, "F": 9, "H": 11, "M": 13, "Q": 17, "R": 18,
              "S": 19, "T": 20, "U": 21, "V": 22, "W": 23, "X": 24, "Y": 25, "Z": 26}
LOCALS = range(1, 34)
COMMON_END = 999                 # last common variable of the #500 block
# The spill stack: what a subprogram cannot keep in its 33 locals (parameters past the 18 G65
# letters, by-reference and array parameters, DEF locals past #33) lives in a frame on a stack of
# common variables, so nested and recursive calls each keep their own (save and restore by moving
# the pointer). #149 holds the stack height (vacant reads as 0); a subprogram with a frame of K
# slots adds K to it on entry and takes K off before each M99, and slot i of its frame is
# #[#149+(150-K+i)]. A caller passes such parameters by writing #[#149+(150+i)] just before the
# call (the callee's frame starts where the caller's ends) and reads by-reference ones back from
# the same variables after it. Named variables of the main program take #100..#148.
SPILL_POINTER = 149
SPILL_BASE = 150
SPILL_END = 199
PLANE = {"XY": ("X", "Y", "Z"), "ZX": ("Z", "X", "Y"), "YZ": ("Y", "Z", "X")}
_ISO_NUMBER = re.compile(r"O?\d+$", re.I)


def iso_number(name: str) -> Optional[int]:
    """The O number a name already is ("O1000", "1000"), or None for a name."""
    return int(name.lstrip("Oo")) if _ISO_NUMBER.match(name or "") else None


def stable_number(name: str, taken: set[int]) -> int:
    """O9000..O9999 from the name alone: the documented mapping of nctrans.calls, so a converted
    caller and the converted subprogram file meet."""
    return calls.stable_number(name, taken)


@dataclass
class ArrayPlan:
    base: int
    dims: list[int]

    @property
    def size(self) -> int:
        return math.prod(self.dims)


@dataclass
class UnitPlan:
    """One program unit (main program or subprogram): its labels and its locals."""
    labels: dict[str, str] = field(default_factory=dict)        # label -> N number
    locals: dict[str, int] = field(default_factory=dict)        # param/DEF name -> #n
    params: list[str] = field(default_factory=list)             # G65 letter per parameter
    uses_locals: bool = False                                   # called with G65 (own local level)
    refusal: Optional[str] = None                               # why its calls cannot be written
    # the spill frame: name -> (slot, size); params[i] is "" for a parameter passed in a slot
    slots: dict[str, tuple[int, int]] = field(default_factory=dict)
    frame: int = 0

    def slot_text(self, offset: int) -> str:
        """The common variable of frame slot `offset` (an expression in the stack pointer)."""
        return f"#[#{SPILL_POINTER}+{SPILL_BASE - self.frame + offset}]"

    def take_slots(self, name: str, size: int) -> None:
        self.slots[name] = (self.frame, size)
        self.frame += size


def circle_through(p1, p2, p3) -> Optional[tuple[float, float, bool]]:
    """Centre (c1, c2) and clockwise flag of the circle through three plane points, or None when
    they are collinear (no arc)."""
    (x1, y1), (x2, y2), (x3, y3) = p1, p2, p3
    den = 2 * (x1 * (y2 - y3) + x2 * (y3 - y1) + x3 * (y1 - y2))
    if abs(den) < 1e-12:
        return None
    s1, s2, s3 = x1 * x1 + y1 * y1, x2 * x2 + y2 * y2, x3 * x3 + y3 * y3
    cx = (s1 * (y2 - y3) + s2 * (y3 - y1) + s3 * (y1 - y2)) / den
    cy = (s1 * (x3 - x2) + s2 * (x1 - x3) + s3 * (x2 - x1)) / den
    cw = ((x2 - x1) * (y3 - y2) - (y2 - y1) * (x3 - x2)) < 0
    return cx, cy, cw


def program_vars(program: n.Program, skip: tuple = ()) -> Iterator[n.Var]:
    """Every variable reference of the program's expressions (index expressions included), in
    the main program and its subprograms; statements of the types in `skip` are not read."""
    stack: list = []

    def expr(e):
        stack.append(e)
        while stack:
            e = stack.pop()
            if e is None or isinstance(e, (n.Num, n.Str, str, int, float, bool)):
                continue
            t = type(e)
            if t is n.Var:
                yield e
                stack.extend(e.indices or ())
            elif t is n.Binary:
                stack.extend((e.left, e.right))
            elif t is n.Unary:
                stack.append(e.operand)
            elif t is n.Func:
                stack.extend(e.args)
            elif t is n.AxisValue:
                stack.append(e.value)
            elif isinstance(e, dict):
                stack.extend(e.values())
            elif isinstance(e, (list, tuple)):
                stack.extend(e)
            elif hasattr(e, "__slots__"):
                stack.extend(getattr(e, f, None) for f in e.__slots__)

    for body in [program.body] + [s.body for s in program.subprograms.values()]:
        for node in walk(body):
            if type(node) is n.Block:
                for s in node.body:
                    if not isinstance(s, skip):
                        yield from expr(s)
            else:
                for attr in ("cond", "subject", "start", "end", "step", "var"):
                    yield from expr(getattr(node, attr, None))


def max_r_used(program: n.Program) -> tuple[int, bool]:
    """Highest constant R number the program uses, and whether any R is indexed by an expression."""
    top, dynamic = -1, False
    for v in program_vars(program):
        if v.space == "R":
            if isinstance(v.key, int):
                top = max(top, v.key)
            else:
                dynamic = True
    return top, dynamic


@dataclass
class GlobalArrayUse:
    """How a program uses an array it does not declare (a GUD of the control's definition files):
    per dimension the largest constant index, and whether any index is computed at run time."""
    highest: list[int]
    computed: bool = False
    elements: set = field(default_factory=set)      # the constant index tuples used


def undeclared_arrays(program: n.Program) -> dict[str, GlobalArrayUse]:
    """Arrays the program indexes but declares nowhere (no DEF, no parameter), by upper-case name.
    Values shown in messages are left out: a message is written as a comment, its values unread."""
    declared = {p.name.upper() for s in program.subprograms.values() for p in s.params}
    for b in blocks(program.body):
        declared.update(s.name.upper() for s in b.body if type(s) is n.VarDecl)
    for sub in program.subprograms.values():
        for b in blocks(sub.body):
            declared.update(s.name.upper() for s in b.body if type(s) is n.VarDecl)
    uses: dict[str, GlobalArrayUse] = {}
    for v in program_vars(program, skip=(n.Message,)):
        if v.space != "name" or not v.indices or str(v.key).upper() in declared:
            continue
        use = uses.setdefault(str(v.key).upper(), GlobalArrayUse([-1] * len(v.indices)))
        if len(use.highest) != len(v.indices):
            use.computed = True           # used with different ranks: laid out never (refused)
            continue
        consts = [constant(e) for e in v.indices]
        for i, c in enumerate(consts):
            if c is None or c != int(c) or c < 0:
                use.computed = True
            else:
                use.highest[i] = max(use.highest[i], int(c))
        if all(c is not None for c in consts):
            use.elements.add(tuple(consts))
    return uses


# Layout of a global array indexed at run time: each dimension after the first spans 1 + its largest
# constant index, at least this; the first takes an equal share of the room left (at most
# GLOBAL_MAX_ROWS rows). Documented in NC410; an index outside raises ARRAY_INDEX_ALARM.
GLOBAL_MIN_EXTENT = 8
GLOBAL_MAX_ROWS = 100
ARRAY_INDEX_ALARM = 101
NOT_CONVERTED_ALARM = 102


def global_layout(uses: dict[str, GlobalArrayUse], first: int, reserved: int) -> dict[str, ArrayPlan]:
    """Row-major blocks from common variable `first` up for the undeclared arrays indexed at run
    time, leaving `reserved` variables free for the rest; {} when they do not fit."""
    computed = {k: u for k, u in sorted(uses.items()) if u.computed}
    if not computed:
        return {}
    tails = {k: [max(h + 1, GLOBAL_MIN_EXTENT) for h in u.highest[1:]] for k, u in computed.items()}
    row = sum(math.prod(t) for t in tails.values())
    room = COMMON_END + 1 - first - reserved
    rows = min(GLOBAL_MAX_ROWS, room // row if row else 0)
    if rows < max(u.highest[0] + 1 for u in computed.values()) or rows < 1:
        return {}
    plans, base = {}, first
    for k, tail in tails.items():
        plans[k] = ArrayPlan(base, [rows, *tail])
        base += plans[k].size
    return plans


def unit_plan(sub: Optional[n.Subprogram], body, fresh_number) -> UnitPlan:
    """Labels -> fresh N numbers; for a subprogram, parameters -> G65 letters/locals and its DEF
    scalars -> the locals left over (a G65 call gives the body its own local level)."""
    plan = UnitPlan()
    for b in blocks(body):
        if b.label and b.label not in plan.labels:
            plan.labels[b.label] = fresh_number()
    if sub is None:
        return plan
    decls = [s for b in blocks(body) for s in b.body if type(s) is n.VarDecl and not s.dims]
    if not sub.params and not decls:
        return plan
    plan.uses_locals = True
    letters = iter(ARG_LETTERS)
    for p in sub.params:
        letter = None if p.by_ref or p.dims else next(letters, None)
        if letter is None:
            # by reference, an array, or past the G65 letters: a slot of the spill frame
            plan.params.append("")
            plan.take_slots(p.name.upper(), math.prod(p.dims) if p.dims else 1)
            if p.dims and not all(isinstance(d, int) and d > 0 for d in p.dims):
                plan.refusal = f"the array parameter {p.name} of {sub.name} without constant dimensions"
            continue
        plan.params.append(letter)
        plan.locals[p.name.upper()] = ARG_LOCALS[letter]
    free = [i for i in LOCALS if i not in plan.locals.values()]
    for d in decls:
        key = d.name.upper()
        if key in plan.locals or key in plan.slots:
            continue
        if free:
            plan.locals[key] = free.pop(0)
        else:
            plan.take_slots(key, 1)
    if plan.frame > SPILL_END - SPILL_BASE + 1:
        plan.refusal = (f"{plan.frame} spilled parameters and locals of {sub.name} (the spill stack "
                        f"#{SPILL_BASE}..#{SPILL_END} holds {SPILL_END - SPILL_BASE + 1})")
    return plan
