"""Conversion between dialects: front end of A -> IR -> (lowering B needs) -> emitter of B.

The policy, in one place (sqlglot's "unsupported level"):
- the target emitter first writes the program structurally (loops, variables, calls and cycles kept
  where the target has them), recording NC401 for each construct it lowered on the way, and NC404
  for each call it keeps of a subprogram that is not there (the target control must provide it);
- when the emitter cannot express a construct (NC402), that construct alone (its block, its loop or
  branch, its modal cycle with the blocks it runs at) is lowered to plain motion
  (`nctrans.lower.constructs`), the rest keeps its structure, and the program is emitted again; each
  refusal becomes an NC401 info naming the construct, its line and the lines lowered;
- what cannot be lowered on its own (inside a subprogram, jumped into, setting variables the rest
  reads, or holding what plain motion cannot carry) stays an NC402 error saying why, and the
  conversion is refused; `--flatten` lowers the whole program instead;
- `strict` turns every lowering into an error.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Callable, Iterable, Optional

from nctrans import spilled
from nctrans.diagnostics import Diagnostic
from nctrans.dialects.base import Dialect
from nctrans.ir.nodes import Block, Program


# Words of the NC401 messages that tell the two kinds of lowering to plain motion apart (the
# structural-share benchmark counts them).
WHOLE_PROGRAM_NOTE = "the program was lowered to plain motion"
CONSTRUCT_NOTE = "lowered to plain motion here"
# Words of the NC402 reason of a construct whose plain motion is over limits.MAX_LOWERED_BLOCKS: the
# whole program lowered would be larger still, so it is not tried without --flatten (which streams).
HELD_LIMIT_NOTE = "the most a conversion holds in memory"
# ... and of a refusal whose whole-program lowering a budget stopped (whole_failure)
BUDGET_NOTE = "lowering the whole program instead stops at line"


class NeedsWholeParse(Exception):
    """Lowering a construct of a compact program (Dialect.parse_compact) would need a jump target
    inside one of its runs of plain blocks (nctrans.lower.compact_constructs): convert() converts
    it parsed whole."""


@dataclass
class Conversion:
    text: Optional[str]                 # None when the conversion was refused
    diagnostics: list[Diagnostic] = field(default_factory=list)
    flattened: bool = False
    # convert_stream: refused for a construct that lowering the whole program may still carry
    retry_whole: bool = False


def _is_refusal(d: Diagnostic) -> bool:
    return d.rule == "NC402" and d.severity == "error"


def _library_entry(program: Program) -> Optional[str]:
    """The subprogram a file exists to define (a Sinumerik PROC file), when its main body does
    nothing of its own: such a file has no toolpath until something calls it, so lowering it to
    plain motion would silently produce an empty program."""
    entry = program.meta.get("entry") if program.meta else None
    if not entry or entry not in program.subprograms:
        return None
    for node in program.body:
        if not isinstance(node, Block) or node.body:
            return None
    return str(entry)


def _library_refusal(program: Program, entry: str, target: str) -> Diagnostic:
    sub = program.subprograms[entry]
    return Diagnostic("NC402", "error",
                      f"{entry} is a subprogram library with no main program: it cannot be lowered to "
                      f"plain motion for {target} on its own; convert the programs that call it "
                      f"(with --flatten) instead", sub.span.file, sub.span.line, sub.span.col)


def _macro_file_note(program: Program) -> Optional[str]:
    """Why an ISO macro file is not lowered to plain motion, whole or a construct of it (None for
    any other program): with no G65 call passing its arguments, plain motion would run it with
    every argument vacant (typically straight into its own argument alarm) from no known position,
    which is not the macro (a subprogram's constructs are not lowered alone either)."""
    from nctrans.lower.macro_procs import macro_file
    if not macro_file(program):
        return None
    return ("it is a macro file (it reads G65 arguments #1-#33 it never sets and returns with M99): "
            "it has no toolpath until a G65 call passes its arguments, so neither the file nor a part "
            "of it is lowered to plain motion (that would run it with every argument vacant, from no "
            "known position)")


def subprogram_file(program: Program) -> bool:
    """Whether a program is a subprogram file by its dialect's file types (Dialect.subprogram_file,
    a Sinumerik .SPF): it runs from its caller's position and modes (G90/G91, units, plane,
    offsets), not from the power-on state a run of it alone starts in."""
    from nctrans.dialects.base import get
    dialect = get(program.dialect)
    return dialect is not None and dialect.subprogram_file(program)


def _subprogram_file_note(program: Program) -> Optional[str]:
    """Why a construct of a subprogram file is not lowered to plain motion, alone or with the whole
    file (None for any other program): plain motion is computed from a run that starts at the
    power-on state (G90, the origin), where the file runs from its caller's."""
    if not subprogram_file(program):
        return None
    return ("it is in a subprogram file, which runs from its caller's position and G90/G91: plain "
            "motion computed from the power-on state (G90, the origin) would not follow them, so "
            "no part of the file is lowered; port that construct by hand, or convert the programs "
            "that call it with --flatten")


def _macro_refusal(program: Program, why: str) -> Diagnostic:
    """NC402 at the first construct that reads a G65 argument (what plain motion would run
    vacant), not at the file's first block."""
    from nctrans.dialects.base import CompactBody
    from nctrans.lower.macro_procs import first_argument_read
    from nctrans.plainrun import PlainRun
    body = program.body
    if type(body) is CompactBody:       # its runs of plain lines read no variable
        body = [x for x in body.items if type(x) is not PlainRun]
    found = first_argument_read(body) if type(body) is list else None
    span = found[0] if found is not None else None
    here = f" (it reads the argument #{found[1]} first here)" if found is not None else ""
    return Diagnostic("NC402", "error", f"{program.name or program.file} is not flattened{here}: {why}; "
                      "convert the programs that call it with --flatten instead", program.file,
                      span.line if span is not None else 1, span.col if span is not None else 1)


# Why a macro file's construct is refused in place rather than lowered (NC412 wording).
MACRO_IN_PLACE_NOTE = ("in a macro file (it has no toolpath until a G65 call passes its arguments, so "
                       "no part of it is lowered to plain motion)")


def _refused_in_place(program: Program, target: Dialect, refusals: list[Diagnostic],
                      where: str):
    """The target's emission of `program` with each refused construct (NC402, `refusals`) written
    as an alarm at its place (NC412) and the rest structural, for a target that refuses in place
    (Dialect.refuses_in_place): the last resort after lowering the construct, and the whole
    program, to plain motion failed. The control stops at the alarm, so nothing after it runs on
    that path and nothing is guessed. None when the target does not, when a refusal is over the
    held limit or a budget stopped the lowering (a limit, not a missing mapping: said as it is),
    or when the emission still refuses something (a syntax error is never refused in place) or
    does not read back in the target."""
    if not getattr(target, "refuses_in_place", False) or not refusals:
        return None
    if any(HELD_LIMIT_NOTE in d.message or BUDGET_NOTE in d.message for d in refusals):
        return None         # a limit stopped the lowering, not a missing mapping: said as it is
    at: dict = {}
    for d in refusals:          # what the construct is, without why it was not lowered
        why = d.message.split("; it cannot be lowered", 1)[0].split("; it is a macro file", 1)[0]
        at.setdefault((d.file, d.line), f"{why} {where}".rstrip())
    meta = {**(program.meta or {}), "refuse_in_place": at}
    again = target.emit(dataclasses.replace(program, meta=meta))
    if any(_is_refusal(d) for d in again.diagnostics):
        return None
    # what the refusals kept from being written before (another control's words the emitter
    # passes through) must read back in the target, or the conversion stays refused
    back = target.parse(spilled.as_str(again.text), program.file)
    if any(d.severity == "error" for d in back.diagnostics):
        return None
    return again


def _lower_whole(program: Program, target: Dialect, flatten_with, refusals: list[Diagnostic]):
    """(emission, diagnostics) of the whole program lowered to plain motion, the last resort when
    a construct cannot be lowered on its own; (None, [the held-limit or step-budget error]) when
    that is refused too (its other reasons are the refusals themselves; a limit is news to the
    user, so the caller adds it to them)."""
    from nctrans.lower.flatten import UNKNOWN_VALUE_NOTE
    flat_diags: list[Diagnostic] = []
    flat = lower_for(flatten_with(flat_diags), target, flat_diags)
    again = target.emit(flat)
    found = [*(_whole_note(d, target) for d in refusals), *flat_diags, *again.diagnostics]
    if any(d.severity == "error" for d in found):
        return None, [d for d in found if d.severity == "error" and (
            HELD_LIMIT_NOTE in d.message or d.rule == "NC205" or UNKNOWN_VALUE_NOTE in d.message)]
    return again, found


def whole_failure(refusals: list[Diagnostic], whole: list[Diagnostic]) -> list[Diagnostic]:
    """The refusals, saying why lowering the whole program failed too when a budget stopped it
    or it would fix a value only the machine knows (`whole`: that lowering's diagnostics): an
    endless loop is named at its line."""
    from nctrans.lower.flatten import UNKNOWN_VALUE_NOTE
    stop = next((d for d in whole if d.rule == "NC205" and d.severity == "error"), None)
    unknown = next((d for d in whole if d.rule == "NC402" and UNKNOWN_VALUE_NOTE in d.message), None)
    if stop is not None:
        why = f"{BUDGET_NOTE} {stop.line}: {stop.message}"
    elif unknown is not None:       # (a compensation radius of a tool the program never chose)
        why = f"lowering the whole program instead fails at line {unknown.line}: {unknown.message}"
    else:
        return refusals
    return [dataclasses.replace(d, message=f"{d.message}; {why}") for d in refusals]


def _whole_note(refusal: Diagnostic, target: Dialect) -> Diagnostic:
    """The NC401 that says a refusal made the whole program plain motion."""
    d = refusal
    return Diagnostic("NC401", "info", f"{d.message} — {target.name} cannot express it, so "
                      f"{WHOLE_PROGRAM_NOTE} (as with --flatten)", d.file, d.line, d.column,
                      d.end_line, d.end_column)


def header(program: Program, target: str) -> str:
    """The header comment of a converted program: what it was converted from, to which dialect
    (detection reads that back: nctrans.detection.written_by_nctrans), and by what."""
    from nctrans import __version__
    file = program.file.replace("(", "[").replace(")", "]")
    return f"converted by nctrans {__version__} from {program.dialect} to {target}: {file}"


def lower_for(program: Program, target: Dialect, diags: list[Diagnostic]) -> Program:
    """Run the IR -> IR passes the target lists (Dialect.lowering_passes), in order; each returns
    the new program and its NC401 diagnostics."""
    for lowering in target.lowering_passes:
        program, found = lowering(program)
        diags.extend(found)
    return program


def strict(diags: list[Diagnostic]) -> list[Diagnostic]:
    """--strict: every lowering (NC401) and every construct refused in place (NC412) becomes an
    error."""
    out = []
    for d in diags:
        if d.rule in ("NC401", "NC412") and d.severity != "error":
            d = Diagnostic(d.rule, "error", f"{d.message} (refused by --strict)", d.file, d.line,
                           d.column, d.end_line, d.end_column, d.fix)
        out.append(d)
    return out


def convert(program: Program, target: Dialect, *, flatten_with: Optional[Callable[[list], Program]],
            flatten: bool = False, strict_mode: bool = False, machine=None,
            resolver: Optional[Callable] = None,
            stream_whole: Optional[Callable[[list], Optional[Conversion]]] = None,
            whole: Optional[Callable[[], Program]] = None) -> Conversion:
    """Emit `program` in `target`. `flatten_with(diagnostics) -> Program` lowers it to plain motion
    (it closes over the machine and the subprogram resolver); None when lowering is unavailable
    (single constructs are then not lowered either). `machine` and `resolver` serve the run that
    lowers single constructs. `stream_whole(notes)`, when given, lowers the whole program (the last
    resort) written as it runs, not held: a Conversion with `notes` first (its text "" when
    written, None when refused and the output discarded), or None when the target cannot stream.

    `program` may be parsed compact (Dialect.parse_compact: its main body's runs of plain blocks
    held as spans of the text, written a few blocks at a time, so memory stays flat); when a
    construct's lowering would need a jump target inside a run, it is converted again parsed
    whole: `whole()` (by default its runs expanded in place)."""
    args = dict(flatten_with=flatten_with, flatten=flatten, strict_mode=strict_mode, machine=machine,
                resolver=resolver, stream_whole=stream_whole)
    try:
        return _convert(program, target, **args)
    except NeedsWholeParse:
        return _convert(whole() if whole is not None else expanded(program), target, **args)


def expanded(program: Program) -> Program:
    """A compact program (Dialect.parse_compact) with its runs of plain blocks expanded in place:
    the program a whole parse gives; any other program as it is."""
    from nctrans.dialects.base import CompactBody
    from nctrans.plainrun import PlainRun
    if type(program.body) is not CompactBody:
        return program
    body: list = []
    for item in program.body.items:
        if type(item) is PlainRun:
            body.extend(item.expand())
        else:
            body.append(item)
    return dataclasses.replace(program, body=body)


def _convert(program: Program, target: Dialect, *, flatten_with: Optional[Callable[[list], Program]],
             flatten: bool, strict_mode: bool, machine, resolver: Optional[Callable],
             stream_whole: Optional[Callable[[list], Optional[Conversion]]]) -> Conversion:
    diags: list[Diagnostic] = []
    flattened = False
    library = _library_entry(program)
    if flatten and library is not None:
        return Conversion(None, [_library_refusal(program, library, target.name)])
    macro = _macro_file_note(program) if library is None else None
    if flatten and macro is not None:
        return Conversion(None, [_macro_refusal(program, macro)])
    if flatten and flatten_with is not None:
        program = flatten_with(diags)
        flattened = True
    program = lower_for(program, target, diags)
    result = target.emit(program)
    refusals = [d for d in result.diagnostics if _is_refusal(d)]
    if refusals and library is not None:
        diags.extend(result.diagnostics)
        diags.append(_library_refusal(program, library, target.name))
    elif refusals and macro is not None and not flattened and not strict_mode and (
            in_place := _refused_in_place(program, target, refusals, MACRO_IN_PLACE_NOTE)) is not None:
        # a macro file is a subprogram: no construct of it is lowered alone, nor the whole file;
        # where the target refuses in place, each construct it cannot express is an alarm there
        diags.extend(in_place.diagnostics)
        result = in_place
    elif refusals and macro is not None and not flattened:
        # a macro file is a subprogram: no construct of it is lowered alone, nor the whole file
        diags.extend(dataclasses.replace(d, message=f"{d.message}; {macro}; port that construct by hand, "
                                         "or convert the programs that call it with --flatten")
                     if _is_refusal(d) else d for d in result.diagnostics)
    elif refusals and not flattened and (called := _subprogram_file_note(program)) is not None:
        diags.extend(dataclasses.replace(d, message=f"{d.message}; {called}") if _is_refusal(d) else d
                     for d in result.diagnostics)
    elif refusals and not flattened and flatten_with is not None and not strict_mode:
        from nctrans.lower.constructs import lower_constructs
        lowered, notes, remaining = lower_constructs(program, refusals, target.name, machine=machine,
                                                     resolver=resolver)
        others = [d for d in result.diagnostics if not _is_refusal(d)]
        again = target.emit(lowered) if lowered is not None else None
        if again is not None:
            kept = {(d.file, d.line) for d in remaining}
            remaining = remaining + [d for d in again.diagnostics
                                     if _is_refusal(d) and (d.file, d.line) not in kept]
        too_large = any(HELD_LIMIT_NOTE in d.message for d in remaining)
        streamed = stream_whole([_whole_note(d, target) for d in remaining]) \
            if remaining and not too_large and stream_whole is not None else None
        if streamed is not None and streamed.text is not None:
            # the lowering passes' notes (FOR as WHILE) first, as the held whole lowering keeps them
            return dataclasses.replace(streamed, diagnostics=[*diags, *streamed.diagnostics])
        if streamed is not None:
            remaining = whole_failure(remaining, streamed.diagnostics)
        whole = _lower_whole(program, target, flatten_with, remaining) \
            if remaining and not too_large and streamed is None else None
        if whole is not None and whole[0] is None and whole[1]:
            held = [d for d in whole[1] if HELD_LIMIT_NOTE in d.message]
            if held:
                remaining = [dataclasses.replace(d, message=f"{d.message}; {held[0].message}")
                             for d in remaining]
            else:
                remaining = whole_failure(remaining, whole[1])
        in_place = None
        if remaining and not too_large and not (whole is not None and whole[0] is not None):
            in_place = _refused_in_place(lowered if lowered is not None else program, target,
                                         remaining, "")
        if whole is not None and whole[0] is not None:
            # some construct could not be lowered on its own: the whole program as plain motion
            diags.extend(whole[1])
            result, flattened = whole[0], True
        elif in_place is not None:
            # nor the whole program: each construct left is an alarm at its place (NC412)
            diags.extend(notes)
            diags.extend(in_place.diagnostics)
            result = in_place
        else:
            diags.extend(others)
            diags.extend(notes)
            diags.extend(remaining)
            if again is not None:
                result = again
    else:
        diags.extend(result.diagnostics)
    if strict_mode:
        diags = strict(diags)
    refused = any(d.severity == "error" for d in diags)
    text = None if refused else target.with_header(result.text, header(program, target.name))
    return Conversion(text, diags, flattened)


# Blocks handed to a streaming emitter at a time: large enough that per-chunk costs vanish,
# small enough that memory stays flat (~2 KiB of IR per block).
STREAM_CHUNK = 4096


def stream_chunks(body, size: int = STREAM_CHUNK):
    """Lists of at most `size` Blocks from a streamed body; a PlainRun (a lazy run of plain
    blocks) is taken apart `size` blocks at a time, never expanded whole."""
    from nctrans.plainrun import PlainRun
    batch: list = []
    for node in body:
        if type(node) is PlainRun:
            run = node
            while run is not None:
                blocks, run = run.take(size - len(batch))
                batch.extend(blocks)
                del blocks          # not held while the next batch is taken
                if len(batch) >= size:
                    yield batch
                    batch = []
            continue
        batch.append(node)
        if len(batch) >= size:
            yield batch
            batch = []
    if batch:
        yield batch


def convert_stream(program: Program, target: Dialect, write: Callable[[str], None], *,
                   strict_mode: bool = False) -> Optional[Conversion]:
    """convert() for a program whose body is a streamed parse (it runs straight through): the
    target's text goes to `write` as it is produced, so memory stays flat however long the
    program. None when the target cannot stream (or must lower the program first): convert the
    whole program instead. A Conversion whose text is None was refused (discard what was written);
    `retry_whole` then says a refusal (NC402) might still be lowered to plain motion by converting
    the whole program. Text, when not refused, is "" (everything was written)."""
    if not all(getattr(p, "structural_only", False) for p in target.lowering_passes):
        return None             # a pass that may rewrite plain blocks needs the whole program
    from nctrans.dialects.base import CannotStream
    try:
        found = target.emit_stream(program, stream_chunks(program.body),
                                   _with_header(target, program, write))
    except CannotStream:
        return Conversion(None, [], retry_whole=True)
    if found is None:
        return None
    refusals = [d for d in found if _is_refusal(d)]
    diags = strict(found) if strict_mode else list(found)
    if refusals and not strict_mode:
        return Conversion(None, diags, retry_whole=True)
    refused = any(d.severity == "error" for d in diags)
    return Conversion(None if refused else "", diags)


def _with_header(target: Dialect, program: Program,
                 write: Callable[[str], None]) -> Callable[[str], None]:
    """`write` that puts the conversion's header comment into the first chunk a stream writes."""
    first = [True]

    def write_with_header(text: str) -> None:
        if first[0]:
            first[0] = False
            text = target.with_header(text, header(program, target.name))
        write(text)
    return write_with_header


def convert_flat_stream(program: Program, target: Dialect, blocks: Callable[[list], Iterable],
                        meta: dict, write: Callable[[str], None], *,
                        strict_mode: bool = False) -> Optional[Conversion]:
    """convert(flatten=True) written as the run goes: `blocks(diagnostics)` yields the flattened
    program's blocks as the interpreter produces them (nctrans.lower.flatten.flatten_blocks) and
    the target writes them chunk by chunk, so a program whose loops unroll into millions of moves
    is never held whole. None when the target cannot stream (convert the whole program instead);
    a Conversion whose text is None was refused (discard what was written)."""
    library = _library_entry(program)
    if library is not None:
        return Conversion(None, [_library_refusal(program, library, target.name)])
    macro = _macro_file_note(program)
    if macro is not None:
        return Conversion(None, [_macro_refusal(program, macro)])
    if not all(getattr(p, "structural_only", False) for p in target.lowering_passes):
        return None
    from nctrans.dialects.base import CannotStream
    flat_diags: list[Diagnostic] = []
    shell = Program(program.file, program.dialect, [], {}, meta, None)
    try:
        found = target.emit_stream(shell, stream_chunks(blocks(flat_diags)),
                                   _with_header(target, program, write))
    except CannotStream:
        return None
    if found is None:
        return None
    diags = flat_diags + list(found)
    if strict_mode:
        diags = strict(diags)
    refused = any(d.severity == "error" for d in diags)
    return Conversion(None if refused else "", diags, flattened=True)
