"""Which numbered subprograms of a program can become procedures with named parameters.

ISO G65 macros get their arguments as the locals #1-#33 of their own call level; a target with
procedures (Sinumerik PROC) can pass the same values as named parameters instead of global
registers. A subprogram qualifies when every call of it in the program is a plain G65 macro call
(its own level of locals), its body reaches its locals only by number (no `#[expr]` that could land
on one) and calls nothing that shares its locals (M98).

The vacant value decides the rest: an argument left out is vacant in ISO (`#2 EQ 0` is false,
`X#24` drops the word, `#3=#2` copies the vacancy) but a PROC parameter left out is 0, and the
PROC can only ask whether it was programmed ($P_SUBPAR[i]). So an argument the body reads and never
sets (`vacancy_tested`: the emitter writes `#k EQ #0` as NOT $P_SUBPAR[i] and `#k EQ 5` as
$P_SUBPAR[i] AND ARG==5) may be left out by a call only where the body reads it in arithmetic or
in such a comparison; a bare use (`X#24`, `#3=#24`, a comparison with another variable) needs every
call to pass it, else the subprogram stays as it was (global R parameters). The letters come from the source dialect's
table (`options.macro_arguments`, in the program's meta): #1 -> A ... #26 -> Z; a local without a
letter (#10, #27-#33) is a plain local of the procedure. This module decides; the emitter spells.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

from nctrans.ir import nodes as ir
from nctrans.ir import walk

LOCAL_MAX = 33
_NUMBER = re.compile(r"^O?(\d+)$", re.IGNORECASE)


@dataclass
class MacroProc:
    """params: (local number, argument letter) in local order, the procedure's parameters;
    plain_locals: the locals without a letter the body uses."""
    params: list[tuple[int, str]] = field(default_factory=list)
    plain_locals: list[int] = field(default_factory=list)
    vacancy_tested: set[int] = field(default_factory=set)   # read, never set: $P_SUBPAR answers
    # read before it is set, then set, and compared (== / !=): its vacancy is carried by a flag the
    # procedure keeps (GIVEN_<letter>: $P_SUBPAR on entry, updated at each assignment)
    vacancy_flags: set[int] = field(default_factory=set)

    def position(self, local: int) -> int | None:
        """1-based parameter position of a local, as a call passes it."""
        return next((i + 1 for i, (k, _) in enumerate(self.params) if k == local), None)


def key(name: str) -> str:
    """One spelling of a program name: ISO O1000 and 1000 are the same program."""
    m = _NUMBER.match(name or "")
    return str(int(m.group(1))) if m else (name or "").upper()


def plan(program: ir.Program) -> dict[str, MacroProc]:
    """The subprograms (by key()) that become procedures with named parameters."""
    from nctrans.dialects.base import CompactBody
    letters = ((program.meta or {}).get("options") or {}).get("macro_arguments") or {}
    if not letters or not program.subprograms:
        return {}
    by_local = {int(k): str(letter) for letter, k in letters.items()}
    calls: dict[str, list[ir.SubCall]] = {}
    for body in [program.body, *(s.body for s in program.subprograms.values())]:
        if type(body) is CompactBody:
            body = body.items               # its runs of plain lines hold no call
        elif type(body) is not list:
            return {}                       # a streamed body: calls cannot be seen ahead
        for c in _calls(body):
            calls.setdefault(key(c.name), []).append(c)
    out = {}
    for name, sub in program.subprograms.items():
        mine = calls.get(key(name))
        if not mine or any(c.kind != "g65" or c.modal != "none" for c in mine):
            continue
        found = _locals_used(sub.body)
        if found is None or any(c.kind != "g65" for c in _calls(sub.body)):
            continue
        used, written, bare, compares = found
        passed = [{v.key for v in c.bindings.values() if isinstance(v.key, int)} for c in mine]
        arguments = {k for k in used - written if k in by_local}
        overwritten = {k for k in arguments_read_first(sub.body) & written if k in by_local}
        if _unguarded(sub.body, overwritten & bare):
            continue                         # set and used whole: the dropped word depends on it
        if any(_unguarded(sub.body, arguments & bare) - p for p in passed):
            continue                         # a call leaves out an argument the body uses bare
        params = sorted(k for k in arguments.union(*passed) if k in by_local)
        use = local_use(sub.body)
        if use is None or use.left_out(set(params))[1]:
            continue                         # a plain local read while vacant: DEF would read 0
        flags = {k for k in overwritten & compares if k in params}
        out[key(name)] = MacroProc([(k, by_local[k]) for k in params],
                                   sorted(k for k in used if k not in params), arguments, flags)
    return out


@dataclass
class Standalone:
    """A macro file (an O-number program that reads G65 arguments and returns with M99) written
    as a procedure: `proc` has every argument letter as a parameter, in the order a converted
    caller passes them (nctrans.calls.LETTER_LOCALS), so a caller converted on its own agrees
    with it; `bare`: arguments the body uses as a whole value, which a caller must pass (vacant
    drops a word in ISO, an unprogrammed parameter reads 0), checked on entry."""
    proc: MacroProc
    bare: set[int] = field(default_factory=set)


def standalone(program: ir.Program) -> tuple[Standalone | None, str]:
    """The procedure a macro file becomes, or (None, why it cannot)."""
    from nctrans.calls import LETTER_LOCALS
    letters = ((program.meta or {}).get("options") or {}).get("macro_arguments") or {}
    by_local = {int(k): str(letter) for letter, k in letters.items()}
    body = program.body
    if not by_local or type(body) is not list:
        return None, "its arguments have no letters in the source dialect"
    found = _locals_used(body)
    if found is None:
        return None, "it reaches variables by a computed number (#[expr]), which may be its locals"
    if any(c.kind != "g65" for c in _calls(body)):
        return None, "it calls subprograms that share its locals (M98)"
    used, written, bare, compares = found
    order = [k for k in LETTER_LOCALS if k in by_local]
    use = local_use(body)
    if use is None or use.left_out(set(order))[1]:
        return None, "a local without an argument letter is read while vacant (a PROC's DEF reads 0)"
    arguments = {k for k in used - written if k in by_local}
    overwritten = {k for k in arguments_read_first(body) & written if k in by_local}
    risky = _unguarded(body, overwritten & bare)
    if risky:
        k = min(risky)
        return None, (f"it uses the argument #{k} as a whole value where it may be vacant and also "
                      "sets it (whether the word is dropped depends on which value it holds)")
    proc = MacroProc([(k, by_local[k]) for k in order], sorted(k for k in used if k not in by_local),
                     arguments, {k for k in overwritten & compares if k in by_local})
    return Standalone(proc, _unguarded(body, arguments & bare)), ""


def _unguarded(body: list, bare: set[int]) -> set[int]:
    """Of the arguments used bare, those the macro does not test for vacancy itself before every
    such use (nctrans.lower.vacancy_flow): only these must be passed."""
    from nctrans.lower.vacancy_flow import unguarded_bare
    return unguarded_bare(body, bare, lambda x, statement: bare_in(x, statement) & bare)


def _calls(body: list):
    for b in walk.blocks(body):
        for s in b.body:
            if type(s) is ir.SubCall:
                yield s


@dataclass
class LocalUse:
    """How a body uses its locals #1-#33: named anywhere, assigned, used bare (a whole value: a word
    dropped or a vacancy copied when vacant), compared (== / !=, where vacant differs from 0), and
    set first (the first top-level mention assigns it from other values: never read vacant)."""
    used: set[int] = field(default_factory=set)
    written: set[int] = field(default_factory=set)
    bare: set[int] = field(default_factory=set)
    compared: set[int] = field(default_factory=set)
    set_first: set[int] = field(default_factory=set)

    def left_out(self, passed: set[int]) -> tuple[list[int], list[int]]:
        """For a call that passes the locals `passed`: (locals that start vacant and are read
        only as 0 would be: a register for them must be cleared, locals whose vacancy shows)."""
        fresh = sorted(k for k in self.used - passed if k not in self.set_first)
        shows = [k for k in fresh if k in self.bare or k in self.compared]
        return [k for k in fresh if k not in shows], shows


def local_use(body: list) -> LocalUse | None:
    """The LocalUse of a body; None when it reaches variables by a computed number."""
    found = _locals_used(body)
    if found is None:
        return None
    use = LocalUse(*found)
    seen: set[int] = set()

    for node in body:
        if type(node) is not ir.Block:
            seen |= _expr_locals(node)          # a structure: any of its locals may be read first
            continue
        for st in node.body:
            if type(st) is ir.Assign and st.target.space == "num" and isinstance(st.target.key, int):
                seen |= _expr_locals(st.value)
                if st.target.key not in seen:
                    use.set_first.add(st.target.key)
                seen.add(st.target.key)
            else:
                seen |= _expr_locals(st)
    return use


def _expr_locals(e) -> set[int]:
    out: set[int] = set()

    def visit(x) -> None:
        if type(x) is ir.Var:
            if x.space == "num" and isinstance(x.key, int) and 1 <= x.key <= LOCAL_MAX:
                out.add(x.key)
            for i in x.indices or ():
                visit(i)
        elif isinstance(x, (list, tuple)):
            for y in x:
                visit(y)
        elif isinstance(x, dict):
            for y in x.values():
                visit(y)
        elif hasattr(x, "__slots__") and not isinstance(x, (ir.Num, ir.Str, ir.Span)):
            for f in x.__slots__:
                visit(getattr(x, f, None))
    visit(e)
    return out


def _local(e) -> int | None:
    if type(e) is ir.Var and e.space == "num" and isinstance(e.key, int) and 1 <= e.key <= LOCAL_MAX:
        return e.key
    return None


def _compared_bare(e) -> set[int]:
    """The locals a comparison of two variables uses bare (vacant differs from 0 under == / !=,
    and a comparison with #0 is a vacancy test, not a use)."""
    if type(e) is not ir.Binary or e.op not in ("==", "!="):
        return set()
    sides = (e.left, e.right)
    if any(type(x) is ir.Var and x.space == "num" and x.key != 0 for x in sides) and \
            not any(type(x) is ir.Var and x.key == 0 for x in sides) and \
            all(type(x) is ir.Var for x in sides):
        return {k for k in map(_local, sides) if k is not None}
    return set()


def _whole(e) -> set[int]:
    """A value used as it is: vacancy shows (a word dropped, a vacancy copied)."""
    if type(e) is ir.AxisValue:
        e = e.value
    k = _local(e)
    return set() if k is None else {k}


def _expressions(e):
    """Every expression node in e, not into nested bodies."""
    yield e
    if type(e) is ir.Var:
        for i in e.indices or ():
            yield from _expressions(i)
    elif isinstance(e, (list, tuple)):
        for x in e:
            yield from _expressions(x)
    elif isinstance(e, dict):
        for x in e.values():
            yield from _expressions(x)
    elif hasattr(e, "__slots__") and not isinstance(e, (ir.Num, ir.Str, ir.Span)):
        for f in e.__slots__:
            if f not in walk.BODIES:
                yield from _expressions(getattr(e, f, None))


def bare_in(x, statement: bool = True) -> set[int]:
    """The locals a statement (or, statement=False, a structure's condition) uses bare: as a
    whole value (a word's value, an assigned value) or compared with another variable."""
    out: set[int] = set()
    for e in _expressions(x):
        out |= _compared_bare(e)
    if not statement:
        return out
    if type(x) is ir.Assign:
        return out | _whole(x.value)
    for f in x.__slots__:
        v = getattr(x, f, None)
        for y in (v.values() if isinstance(v, dict) else v if isinstance(v, list) else (v,)):
            out |= _whole(y)
    return out


def _locals_used(body: list) -> tuple[set[int], set[int], set[int], set[int]] | None:
    """(the locals #1-#33 a body names, those it assigns, those it uses bare: as a whole value, or
    compared with another variable, those it compares with == / !=); None when it reaches
    variables by a computed number."""
    used: set[int] = set()
    written: set[int] = set()
    bare: set[int] = set()
    compares: set[int] = set()
    indirect = False
    for node in walk.walk(body):
        parts = node.body if type(node) is ir.Block else [node]
        for e in _expressions(parts):
            if type(e) is ir.Var and e.space == "num":
                if e.key is None:
                    indirect = True
                elif _local(e) is not None:
                    used.add(e.key)
            elif type(e) is ir.Binary and e.op in ("==", "!="):
                compares.update(k for k in map(_local, (e.left, e.right)) if k is not None)
        if type(node) is ir.Block:
            written.update(s.target.key for s in node.body if type(s) is ir.Assign
                           and s.target.space == "num" and isinstance(s.target.key, int))
            for s in node.body:
                bare |= bare_in(s)
        else:
            bare |= bare_in(node, statement=False)
    return None if indirect else (used, written, bare, compares)


def ends_with_restart(body: list) -> bool:
    """Whether the last block with statements ends the program with M99 (ISO: return or restart)."""
    last = next((b for b in reversed(body) if isinstance(b, ir.Block) and b.body), None)
    return last is not None and any(isinstance(s, ir.ProgramEnd) and s.kind == "restart" for s in last.body)


def reads_arguments(body: list) -> bool:
    """Whether a program reads ISO locals #1-#33 it never sets: the G65 arguments of a macro."""
    return first_argument_read(body) is not None


def arguments_read_first(body: list) -> set[int]:
    """The locals #1-#33 a body reads (in source order) before it sets them: its G65 arguments."""
    out: set[int] = set()
    first_argument_read(body, out)
    return out


def first_argument_read(body: list, reads: set | None = None) -> tuple[ir.Span | None, int] | None:
    """(the span of the first node, in source order, that reads a G65 argument, its number): the
    first read of a local #1-#33 before (in source order) the program sets it; None when it reads
    none. A macro may overwrite an argument after testing it (Renishaw O9810: IF[#26EQ#0]GOTO..
    then #26=#26+..): that #26 is still an argument."""
    read: set = set()
    written: set = set()
    first: dict[int, ir.Span | None] = {}
    where: list = [None]

    def expr(e) -> None:
        if isinstance(e, ir.Var):
            if e.space == "num" and isinstance(e.key, int) and 1 <= e.key <= LOCAL_MAX \
                    and e.key not in written:
                read.add(e.key)
                first.setdefault(e.key, where[0])
            for i in e.indices or ():
                expr(i)
        elif isinstance(e, (list, tuple)):
            for x in e:
                expr(x)
        elif isinstance(e, dict):
            for x in e.values():
                expr(x)
        elif hasattr(e, "__slots__") and not isinstance(e, (ir.Num, ir.Str, ir.Span)):
            for f in e.__slots__:
                expr(getattr(e, f, None))

    for node in walk.walk(body):
        where[0] = getattr(node, "span", None)
        if isinstance(node, ir.Block):
            for s in node.body:
                if isinstance(s, ir.Assign):
                    if s.target.space == "num" and isinstance(s.target.key, int):
                        written.add(s.target.key)
                    expr(s.value)
                    expr(s.target.indices)
                else:
                    expr(s)
        else:
            for attr in ("cond", "subject", "start", "end", "step"):
                expr(getattr(node, attr, None))
    arguments = read                # each read before the program set it
    if reads is not None:
        reads |= read
    if not arguments:
        return None
    key = min(arguments, key=lambda k: (first[k].line if first[k] is not None else 0, k))
    return first[key], key


def macro_file(program: ir.Program) -> bool:
    """Whether a program is an ISO macro file: its dialect gives G65 arguments letters, and it reads
    locals #1-#33 it never sets and ends with M99. Such a file has no toolpath of its own: what it
    does depends on the arguments a G65 call passes."""
    from nctrans.dialects.base import CompactBody
    from nctrans.plainrun import PlainRun
    letters = ((program.meta or {}).get("options") or {}).get("macro_arguments")
    body = program.body
    if type(body) is CompactBody:           # its runs of plain lines hold no variable and no M99
        last = next((x for x in reversed(body.items) if type(x) is PlainRun
                     or (isinstance(x, ir.Block) and x.body)), None)
        if type(last) is PlainRun:
            return False
        body = [x for x in body.items if type(x) is not PlainRun]
    return bool(letters) and type(body) is list and ends_with_restart(body) and reads_arguments(body)
