"""Analyses over the IR that the interpreter's run does not make: they look at the whole program
text, including what never runs.

- NC104 at the assignment: a value whose type the dialect cannot convert to the variable's
  declared type (a STRING assigned to a REAL, where the dialect's table says so). The table is
  `options.type_conversions` in rules/<dialect>.toml; a dialect without one is not checked.
- NC110: a string literal longer than its variable's declared STRING[n].
- NC111: a read of a variable that nothing in the file sets (a DEF without a value that is never
  assigned; an ISO local #1-#33 in the main program or common #100-#199 never assigned).
- NC112: blocks after the main program's end that no jump reaches.
- NC240: a construct nctrans does not model in a block the run never reached (a PROC file's or a
  macro file's body linted on its own, a subprogram nothing calls, a branch not taken): at run
  time it would be NC220, so it is said here instead of passing silently (issue 8).
- --target DIALECT: the NC4xx the conversion to DIALECT would report, from its emitter (nothing
  is written).
Modal and motion logic (NC202-NC209) is checked by the interpreter as it runs.
"""
from __future__ import annotations

from typing import Iterator, Optional

from nctrans import pipeline
from nctrans.diagnostics import Diagnostic, at_span
from nctrans.ir import nodes as n
from nctrans.ir.walk import blocks, program_jump_targets, units, walk
from nctrans.plainrun import PlainRun

# ISO macro variables a program itself must set before reading them (spec: locals are vacant at
# program start, commons at power-on); #500+ persist across programs and are not flagged.
_ISO_LOCALS = range(1, 34)
_ISO_COMMONS = range(100, 200)


def run(ld: pipeline.Loaded, machine, target: Optional[str] = None, runner=None) -> list[Diagnostic]:
    """Parse, interpreter and IR diagnostics of one loaded file. The toolpath is run once by
    `runner(ld, machine)` (default pipeline.lint, which drops the records)."""
    tail = _watch_tail(ld)
    diags = list((runner or pipeline.lint)(ld, machine))
    program = ld.program
    if program is None:
        return diags
    if tail is not None:
        diags.extend(tail.report(ld.label))
        return diags if target is not None else _said_once(diags)
    typed = type_checks(program, ld.dialect)
    # a literal too long for its STRING[n] is NC110 at its line, reached by the run or not; the
    # run's own NC109 for the same assignment ("cut to n characters") said it twice
    too_long = {(d.file, d.line) for d in typed if d.rule == "NC110"}
    if too_long:
        diags = [d for d in diags if not (d.rule == "NC109" and (d.file, d.line) in too_long
                                          and d.message.startswith("string of"))]
    diags.extend(typed)
    diags.extend(unset_reads(program))
    diags.extend(unreachable(program))
    diags.extend(unmodelled_not_run(program, getattr(machine, "kind", "mill"), diags))
    if target is not None:
        diags.extend(portability(ld, machine, target))
    else:
        diags = _said_once(diags)
    return diags


_KEPT_VERBATIM = " has no meaning in the IR; kept verbatim"


def _said_once(diags: list[Diagnostic]) -> list[Diagnostic]:
    """Without a conversion target, a construct the front end keeps verbatim (NC403, written for
    a conversion: `M93 has no meaning in the IR`) and the run's word that it is not modelled
    (NC220, or NC240 where the run does not reach it: `'M93' ... is not modelled`) are one thing
    said twice at one line: the run's word is kept."""
    said = {(d.file, d.line, d.message.split("'")[1]) for d in diags
            if d.rule in ("NC220", "NC240") and d.message.count("'") >= 2}
    return [d for d in diags if not (d.rule == "NC403" and d.message.endswith(_KEPT_VERBATIM)
                                     and (d.file, d.line, d.message[:-len(_KEPT_VERBATIM)]) in said)]


# --------------------------------------------------------------------------- walking the IR
# (nctrans.ir.walk knows how structures nest; expressions are walked here)

def _exprs(obj) -> Iterator:
    """Every expression-tree object under a statement (values of its fields, recursively)."""
    if isinstance(obj, (list, tuple)):
        for x in obj:
            yield from _exprs(x)
    elif isinstance(obj, dict):
        for x in obj.values():
            yield from _exprs(x)
    elif isinstance(obj, (n.Num, n.Str)) or obj is None or isinstance(obj, (str, int, float, bool)):
        return
    elif isinstance(obj, n.Var):
        yield obj
        if obj.indices:
            yield from _exprs(obj.indices)
    elif hasattr(obj, "__slots__") and not isinstance(obj, n.Span):
        for k in obj.__slots__:
            yield from _exprs(getattr(obj, k))


def _reads(stmt) -> Iterator[n.Var]:
    """Variables a statement reads (an assignment's target is written, its indices read)."""
    if isinstance(stmt, n.Assign):
        if stmt.target.indices:
            yield from _exprs(stmt.target.indices)
        yield from _exprs(stmt.value)
    elif isinstance(stmt, n.VarDecl):
        yield from _exprs(stmt.init)
    elif isinstance(stmt, n.SubCall):        # bindings are where the callee receives, not reads
        yield from _exprs([stmt.args, stmt.named_args, stmt.repeat, stmt.target])
    else:
        yield from _exprs(stmt)


def _structure_reads(node) -> Iterator[n.Var]:
    for name in ("cond", "subject", "start", "end", "step"):
        yield from _exprs(getattr(node, name, None))


# --------------------------------------------------------------------------- types (NC104, NC110)

def _declarations(program: n.Program) -> dict[str, n.VarDecl]:
    out: dict[str, n.VarDecl] = {}
    for _, body in units(program):
        for b in blocks(body):
            for s in b.body:
                if isinstance(s, n.VarDecl):
                    out.setdefault(s.name.upper(), s)
    return out


# neutral IR function names (nctrans.ir.nodes.Func) whose result is a number
_NUMERIC_FUNCS = frozenset(("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sqrt", "abs", "round",
                            "fix", "fup", "trunc", "ln", "exp", "pow", "log", "minval", "maxval"))
_COMPARISONS = {"==", "!=", "<", "<=", ">", ">="}


def _type_of(e, decls: dict[str, n.VarDecl]) -> Optional[str]:
    """The static type of an expression where the text alone tells it; None when unknown."""
    if isinstance(e, n.Str):
        return "STRING"
    if isinstance(e, n.Num):
        return "REAL"
    if isinstance(e, n.Var):
        if e.space == "R":
            return "REAL"
        if e.space == "name" and isinstance(e.key, str):
            d = decls.get(e.key.upper())
            return d.type.upper() if d is not None else None
        return None
    if isinstance(e, n.Binary):
        if e.op == "concat":
            return "STRING"
        if e.op in _COMPARISONS or e.op in ("and", "or", "xor"):
            return "BOOL"
        return "REAL" if {_type_of(e.left, decls), _type_of(e.right, decls)} <= {"REAL", "INT"} else None
    if isinstance(e, n.Func):
        return "REAL" if e.name.lower() in _NUMERIC_FUNCS else None
    return None


def _conversions(dialect: Optional[str]) -> Optional[dict[str, list[str]]]:
    """from-type -> the types it may be assigned to (rules/<dialect>.toml options.type_conversions)."""
    from nctrans.rules import load_table
    try:
        d = pipeline.get_dialect(dialect)
        table = load_table(getattr(d, "table", None) or dialect)
    except Exception:       # a dialect without a table of its own: nothing to check against
        return None
    conv = table.options.get("type_conversions")
    return {k.upper(): [t.upper() for t in v] for k, v in conv.items()} if isinstance(conv, dict) else None


def type_checks(program: n.Program, dialect: Optional[str]) -> list[Diagnostic]:
    decls = _declarations(program)
    if not decls:
        return []
    conv = _conversions(dialect)
    out: list[Diagnostic] = []
    for _, body in units(program):
        for b in blocks(body):
            for s in b.body:
                if isinstance(s, n.Assign):
                    target, values = s.target, [s.value]
                    if target.space != "name" or not isinstance(target.key, str):
                        continue
                    decl = decls.get(target.key.upper())
                elif isinstance(s, n.VarDecl) and s.init:
                    decl, values = s, s.init
                else:
                    continue
                if decl is None:
                    continue
                to = decl.type.upper()
                for v in values:
                    frm = _type_of(v, decls)
                    if conv is not None and frm in conv and to in conv and to not in conv[frm]:
                        out.append(at_span("NC104", "error",
                                           f"{frm} value assigned to {decl.name}, declared {to}: "
                                           f"{program.dialect} converts no {frm} to {to}", b.span))
                    if (to == "STRING" and decl.length is not None and isinstance(v, n.Str)
                            and len(v.value) > decl.length):
                        out.append(at_span("NC110", "error",
                                           f"string of {len(v.value)} characters assigned to "
                                           f"{decl.name}, declared STRING[{decl.length}] (the analysis "
                                           f"reads it cut to {decl.length} characters)", b.span))
    return out


# --------------------------------------------------------------------------- never-set reads (NC111)

def unset_reads(program: n.Program) -> list[Diagnostic]:
    decls = _declarations(program)
    set_names: set[str] = set()
    set_nums: set[int] = set()
    passed: set[str] = set()
    reads: list[tuple[n.Var, n.Span, bool]] = []     # (var, where, in the main program)

    def note_write(v: n.Var) -> None:
        if v.space == "name" and isinstance(v.key, str):
            set_names.add(v.key.upper())
        elif v.space == "num":
            if isinstance(v.key, int):
                set_nums.add(v.key)
            elif v.key is None:           # #[expr]: could be any number
                set_nums.update(_ISO_COMMONS)
                set_nums.update(_ISO_LOCALS)

    for sub, body in units(program):
        main = sub is None
        for node in walk(body):
            if not isinstance(node, n.Block):
                if isinstance(node, n.ForLoop):
                    note_write(node.var)
                reads.extend((v, node.span, main) for v in _structure_reads(node))
                continue
            for s in node.body:
                if isinstance(s, n.Assign):
                    note_write(s.target)
                elif isinstance(s, n.VarDecl) and s.init:
                    set_names.add(s.name.upper())
                elif isinstance(s, n.SubCall):
                    for v in _exprs(s):
                        if isinstance(v, n.Var) and isinstance(v.key, str):
                            passed.add(v.key.upper())   # may be a VAR (by reference) argument
                reads.extend((v, node.span, main) for v in _reads(s))
    # A file that does not end its main program (M30/M2) is itself a macro or subprogram (G65 P..,
    # ending M99): its locals are the caller's arguments and its commons the caller's values.
    complete = any(
        isinstance(b, n.Block) and _ends(b) for b in program.body)
    out: list[Diagnostic] = []
    seen: set = set()
    for v, span, main in reads:
        if v.space == "name" and isinstance(v.key, str):
            key = v.key.upper()
            d = decls.get(key)
            if d is None or d.scope != "local" or key in set_names or key in passed or d.dims:
                continue
            what = f"{d.name} is read but nothing sets it (declared without a value: it reads as the type's default)"
        elif v.space == "num" and isinstance(v.key, int):
            key = v.key
            if key in set_nums or not complete or not ((main and key in _ISO_LOCALS) or key in _ISO_COMMONS):
                continue
            what = f"#{key} is read but nothing in this file sets it (vacant unless another program did)"
        else:
            continue
        if key in seen:
            continue
        seen.add(key)
        out.append(at_span("NC111", "warning", what, v.span or span))
    return out


# --------------------------------------------------------------------------- unreachable (NC112)

def _jump_targets(program: n.Program) -> set[str]:
    """Every label and block number a jump can reach, spelt as _is_target compares them."""
    return {t.upper().lstrip("N") for t in program_jump_targets(program)}


def _is_target(b: n.Block, targets: set[str]) -> bool:
    names = {str(x).upper().lstrip("N") for x in (b.number, b.label) if x is not None}
    if b.number is not None:
        try:
            names.add(str(int(float(b.number))))
        except ValueError:
            pass
    return bool(names & targets)


def _ends(b: n.Block) -> bool:
    return any(isinstance(s, n.ProgramEnd) and s.kind in ("end", "end_rewind") for s in b.body)


def _does_something(b: n.Block) -> bool:
    """A block with an effect: a second end (M30 then M2) or a stop after the end changes nothing."""
    return any(not isinstance(s, (n.ProgramEnd, n.Stop)) for s in b.body)


def unreachable(program: n.Program) -> list[Diagnostic]:
    body = program.body
    if type(body) is not list:      # a compact body (base.CompactBody): its items, runs as they are
        body = list(body)
    end = next((i for i, node in enumerate(body) if isinstance(node, n.Block) and _ends(node)), None)
    if end is None:
        return []
    targets = _jump_targets(program)
    rest = _expanded(body[end + 1:])
    for i, node in enumerate(rest):
        if isinstance(node, n.Block) and _is_target(node, targets):
            return []
        if not isinstance(node, n.Block) or _does_something(node):
            count = sum(1 for x in rest[i:] if not isinstance(x, n.Block) or _does_something(x))
            return [at_span("NC112", "warning",
                            f"never runs: {count} block(s) after the program end at line "
                            f"{body[end].span.line}, and no jump reaches them", node.span)]
    return []


# --------------------------------------------------------------------------- not run (NC240)

def unmodelled_not_run(program: n.Program, kind: str, run: list[Diagnostic]) -> list[Diagnostic]:
    """NC240 at each block holding a construct the interpreter would report as not modelled
    (NC220) but which the run never reached: nothing else would say it is not modelled."""
    from nctrans.interp.statements import reported_unmodelled
    said = {(d.file, d.line) for d in run if d.rule == "NC220"}
    out = []
    for name, body in units(program):
        why = (f"subprogram {name} is not called by this file's own run" if name is not None else
               "the analysis does not reach this block (a macro or PROC file runs only when called, "
               "a branch not taken, after the end)")
        for b in blocks(body):
            if b.span is None or (b.span.file, b.span.line) in said:
                continue
            found = [s for s in b.body if type(s) is n.Passthrough and reported_unmodelled(s, kind)]
            if found:
                s = found[0]
                more = f" (+{len(found) - 1} more in this block)" if len(found) > 1 else ""
                reason = f" ({s.reason})" if s.reason else ""
                out.append(at_span("NC240", "warning", f"{s.text.strip()!r}{reason} is not modelled, "
                                   f"and {why}: what it does is in no analysed toolpath{more}", b.span))
    return out


def _expanded(nodes: list) -> list:
    """Nodes with their runs of plain blocks (a compact body's PlainRuns) taken apart."""
    out: list = []
    for node in nodes:
        if type(node) is PlainRun:
            out.extend(node.expand())
        else:
            out.append(node)
    return out


class _Tail:
    """For a streamed parse (the body is parsed as it runs, and the interpreter pulls it in
    batches, past a program end): watch the blocks go by; those after the first block that ends
    the program are NC112 (a streamed program has no jumps, so nothing reaches them)."""

    def __init__(self, body):
        self.first = None
        self.count = 0
        self.end_line = 0
        self._gen = self._watch(iter(body))

    def _watch(self, items):
        end_type, block_type = n.ProgramEnd, n.Block
        for b in items:
            if b.__class__ is block_type:
                for st in b.body:
                    if st.__class__ is end_type and st.kind in ("end", "end_rewind"):
                        self.end_line = b.span.line
                        yield b
                        break
                else:
                    yield b
                    continue
                break
            yield b
        for b in items:
            if b.__class__ is not block_type:          # a run of plain blocks (nctrans.plainrun)
                if self.first is None:
                    self.first = n.Span(b.file, b.line)
                self.count += getattr(b, "blocks", 1)
            elif _does_something(b):
                if self.first is None:
                    self.first = b.span
                self.count += 1
            yield b

    def __iter__(self):
        return self._gen

    def drain(self) -> None:
        for _ in self._gen:
            pass

    def report(self, label: str) -> list[Diagnostic]:
        if self.first is None:
            return []
        # the full parse's wording (unreachable): a streamed program has no jumps
        return [at_span("NC112", "warning", f"never runs: {self.count} block(s) after the program end "
                        f"at line {self.end_line}, and no jump reaches them", self.first)]


def _watch_tail(ld: pipeline.Loaded) -> Optional[_Tail]:
    if ld.streamed is None or ld.program is None or not hasattr(ld.program.body, "drain"):
        return None
    tail = _Tail(ld.program.body)
    ld.program.body = tail
    return tail


# --------------------------------------------------------------------------- portability (--target)

def portability(ld: pipeline.Loaded, machine, target: str) -> list[Diagnostic]:
    """What `nctrans convert --to TARGET` would report (lowerings NC401, refusals NC402)."""
    from nctrans.convert import convert
    from nctrans.lower.flatten import flatten
    dialect = pipeline.get_dialect(target)
    if target == ld.dialect:
        return []

    def flatten_with(into, p=ld.program):
        return flatten(p, machine, diagnostics=into,
                       resolver=pipeline.make_resolver(ld.source_dir, ld.dialect))
    try:
        result = convert(ld.program, dialect, flatten_with=flatten_with, machine=machine,
                         resolver=pipeline.make_resolver(ld.source_dir, ld.dialect))
    except Exception as e:          # the emitter's bug must not hide the lint report
        return [Diagnostic("NC402", "error", f"--target {target}: the conversion failed: "
                           f"{type(e).__name__}: {e}", ld.label)]
    out = []
    for d in result.diagnostics:
        if d.rule.startswith("NC4"):
            if d.file in ("<stdin>", "") and ld.label != d.file:
                d.file = ld.label        # program-level notes carry no span of their own
            out.append(d)
    return out
