"""The glue every command runs: read a file -> decode -> pick the dialect -> parse -> interpret.

Used by the CLI and by other tools (bench, audit, lsp) so each runs the stages the same way.
User-facing failures that are not diagnostics of the program (a missing file, an unknown dialect,
an ambiguous guess) raise `PipelineError` with the message to print; the CLI maps it to exit 2.
"""
from __future__ import annotations

import gc

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable, Iterator, Optional, Union

from nctrans import detection as _detect
from nctrans import source as _source
from nctrans.diagnostics import Diagnostic, DiagnosticList
from nctrans.dialects import base
from nctrans.ir.nodes import Program
from nctrans.machine import Machine, MachineError, default_lathe, default_mill
from nctrans.machine import load as _load_machine
from nctrans.toolpath import ToolpathRecord

# how sure detection must be that a file is another dialect than --from says before NC005 fires
WRONG_DIALECT_CONFIDENCE = 0.75
WRONG_DIALECT_EVIDENCE = 5.0


class PipelineError(Exception):
    """A failure to report to the user as a message with exit code 2 (not a program diagnostic)."""


@dataclass
class Loaded:
    """Everything known about one input after reading and parsing."""
    path: str
    label: str
    source: _source.SourceText
    dialect: Optional[str]
    program: Optional[Program]
    diagnostics: list[Diagnostic] = field(default_factory=list)
    guess: Optional[_detect.Guess] = None
    # Streamed parse (program.body parses as it is iterated): its diagnostics, moved into
    # `diagnostics` in full-parse order once the toolpath has been run (see _finish_stream).
    streamed: Optional[list[Diagnostic]] = None

    @property
    def source_dir(self) -> Optional[str]:
        return None if self.path == _source.STDIN else str(Path(self.path).resolve().parent)


def get_dialect(name: str) -> base.Dialect:
    """The registered dialect `name`; PipelineError for an unknown or not-yet-available one."""
    d = base.get(name)
    if d is None:
        raise PipelineError(f"unknown dialect {name!r} (known: {', '.join(base.names())})")
    return d


def _family_evidence_only(dialect: str, other: str) -> bool:
    """`other`'s markers are those of a family `dialect` belongs to, for another kind of machine
    (ISO milling's are the ISO family's): a lathe program with no lathe construct in it (G0/G1 on
    X and Z, as a conversion from another control writes it) is still a lathe program, not
    "clearly another dialect"."""
    d, o = base.get(dialect), base.get(other)
    if d is None or o is None:
        return False
    family = type(o).__mro__[1]
    return (isinstance(d, family) and o.markers is getattr(family, "markers", None)
            and d.machine_kind != o.machine_kind)


def _wrong_dialect(src: _source.SourceText, dialect: str, guess: _detect.Guess) -> Optional[Diagnostic]:
    """NC005 when the text (whatever the file is called) is clearly another dialect than the one it
    is parsed as: strong markers of the other dialect and next to none of this one."""
    other, share, evidence = guess.content_leader()
    if other is None or other == dialect or share < WRONG_DIALECT_CONFIDENCE or evidence < WRONG_DIALECT_EVIDENCE:
        return None
    if _family_evidence_only(dialect, other):
        return None
    line, col, text = guess.first_marker.get(other, (1, 1, ""))
    what = f" ({text!r} at line {line})" if text else ""
    return Diagnostic("NC005", "error",
                      f"this looks like {other}, not {dialect}{what}: use --from {other}",
                      src.file, line, col, line, col + max(len(text), 1))


DETECT_HEAD = 64 * 1024
# With --from given, detection only backs the NC005 check (a file that is wholly another
# dialect): its first ~150 lines show that as well, and the marker scan costs ~1.5 ms per KiB
# (16 KiB took 25 ms, a tenth of a streamed toolpath run of a 22k-line CAM file).
_CHECK_HEAD = 4 * 1024


def load_source(src: _source.SourceText, path: str = _source.STDIN, dialect: Optional[str] = None,
                stream: bool = False, fallback: Optional[str] = None, compact: Union[bool, str] = False) -> Loaded:
    """Parse already-read text (`compact`: see Dialect.parse_compact; for runs only): choose the dialect (given, else the file's own `nctrans: dialect=`
    pragma, else `fallback` (the project configuration's), else detected), parse, collect
    diagnostics. With `stream` the parse may be lazy (Dialect.streams): the program must then be
    run exactly once, through toolpath_of or lint, which complete the diagnostics."""
    label = src.file
    diags = DiagnosticList(src.diagnostics)
    if not src.ok:
        return Loaded(path, label, src, dialect, None, diags)
    if dialect is None:
        dialect = _pragma_dialect(src) or fallback
    # The head of a file tells its dialect; scanning a whole 20k-line CAM file would cost more
    # than parsing it.
    head = src.text[:DETECT_HEAD if dialect is None else _CHECK_HEAD]
    guess = _detect.detect(head, None if path == _source.STDIN else path)
    if dialect is None:
        if guess.ambiguous:
            raise PipelineError(f"{label}: cannot tell the dialect ({guess.describe()}): use --from DIALECT")
        dialect = guess.dialect
    d = get_dialect(dialect)
    if stream and d.streams:
        result = d.parse_stream(src.text, label)
        if result is not None:
            return Loaded(path, label, src, dialect, result.program, diags, guess,
                          streamed=result.diagnostics)
    if compact:
        # only run (toolpath, equiv, --flatten): a structured program whose plain stretches are
        # held as spans of the text (Dialect.parse_compact), complete like a whole parse
        # compact="jumps" (convert): a program that jumps into its main body too
        result = d.parse_compact(src.text, label, jumps=compact == "jumps")
        if result is not None:
            _add_parse_diagnostics(diags, result.diagnostics, src, dialect, guess)
            return Loaded(path, label, src, dialect, result.program, diags, guess)
    result = d.parse(src.text, label)
    _freeze_for_process(result.program)
    _add_parse_diagnostics(diags, result.diagnostics, src, dialect, guess)
    return Loaded(path, label, src, dialect, result.program, diags, guess)


# How many more parsed programs may be frozen out of the garbage collector's generations (see
# _freeze_for_process). 0 in a library or a long-lived process (lint over a corpus, the language
# server, the API, tests): a frozen program is never freed. The `nctrans` command, which ends after
# one or two programs, raises it.
FREEZE_BUDGET = 0


def _freeze_for_process(program: Program) -> None:
    """Move a program that lives until the process ends out of the collector's generations, so
    later collections stop re-walking it (measured: up to 1.7x on CAM files). Only within
    FREEZE_BUDGET: everything frozen stays in memory for good, so freezing per file leaked the IR
    of every program a process ever read (~31 MiB per pass over the corpus)."""
    global FREEZE_BUDGET
    if FREEZE_BUDGET > 0:
        FREEZE_BUDGET -= 1
        gc.freeze()


def _add_parse_diagnostics(diags: list, parsed: list, src, dialect: str, guess) -> None:
    diags.extend(parsed)
    if not any(x.rule == "NC005" for x in diags):
        wrong = _wrong_dialect(src, dialect, guess) or _foreign_syntax_error(src, dialect, parsed)
        if wrong is not None:
            diags.append(wrong)


def _foreign_syntax_error(src: _source.SourceText, dialect: str, parsed: list) -> Optional[Diagnostic]:
    """NC005 at the first syntax error (NC002) whose line carries a strong marker of another
    dialect and none of this one's (`X=5` read as ISO): the likely cause is the wrong --from."""
    first = next((d for d in parsed if d.rule == "NC002" and d.severity == "error"), None)
    if first is None or not first.line:
        return None
    start = 0
    for _ in range(first.line - 1):
        start = src.text.find("\n", start) + 1
        if start == 0:
            return None
    end = src.text.find("\n", start)
    found = _detect.foreign_marker(src.text[start:end if end >= 0 else len(src.text)], dialect)
    if found is None:
        return None
    other, col, text = found
    return Diagnostic("NC005", "error",
                      f"this looks like {other}, not {dialect} ({text!r} at line {first.line}): use --from {other}",
                      src.file, first.line, col, first.line, col + max(len(text), 1))


def _finish_stream(ld: Loaded, run_diags: list[Diagnostic]) -> None:
    """After a streamed run: parse the rest of the text (past a program end), then order the
    diagnostics as a full parse would have them (source, parse, NC005, interpreter)."""
    parsed = ld.streamed
    if parsed is None:
        return
    ld.streamed = None
    ld.program.body.drain()
    _add_parse_diagnostics(ld.diagnostics, parsed, ld.source, ld.dialect, ld.guess)
    ld.diagnostics.extend(run_diags)


def finish_stream(ld: Loaded) -> None:
    """After a streamed parse was iterated by something other than the interpreter (a streamed
    conversion): complete and order its diagnostics."""
    _finish_stream(ld, [])


def load(path: str, dialect: Optional[str] = None, stream: bool = False,
         fallback: Optional[str] = None, compact: Union[bool, str] = False) -> Loaded:
    """Read, decode, detect and parse one file ('-' = stdin). PipelineError if it cannot be read.
    `stream`, `fallback`: see load_source."""
    try:
        src = _source.read_source(path)
    except _source.SourceError as e:
        raise PipelineError(str(e)) from None
    return load_source(src, path, dialect, stream, fallback, compact)


def _pragma_dialect(src: _source.SourceText) -> Optional[str]:
    """The dialect a `; nctrans: dialect=NAME` pragma in the first line names (see linting.suppress)."""
    if "nctrans" not in src.text[:400]:
        return None
    from nctrans.linting.suppress import dialect_pragma
    found = dialect_pragma(src.text)
    if found is None:
        return None
    name, line, col = found
    if name not in base.names():
        raise PipelineError(f"{src.file}:{line}:{col}: the dialect pragma names {name!r}, "
                            f"which is not a dialect (known: {', '.join(base.names())})")
    return name


def load_program(path_or_dash: str, dialect: Optional[str] = None
                 ) -> tuple[Optional[Program], list[Diagnostic], Optional[str]]:
    """(Program or None, diagnostics, dialect name) for one file; see `load` for the full record."""
    ld = load(path_or_dash, dialect)
    return ld.program, ld.diagnostics, ld.dialect


def load_machine(path: Optional[str], dialect: Optional[str] = None) -> Machine:
    """The machine from MACHINE.toml, or the built-in default (a lathe for turning dialects)."""
    if path is None:
        d = base.get(dialect) if dialect else None
        return default_lathe() if d is not None and d.machine_kind == "lathe" else default_mill()
    try:
        return _load_machine(path)
    except MachineError as e:
        raise PipelineError(str(e)) from None


def _display_path(path: Path) -> str:
    """A path as diagnostics show it: relative to the working directory when inside it."""
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)


def make_resolver(source_dir: Optional[str], dialect: Optional[str] = None) -> Optional[Callable]:
    """The interpreter's subprogram resolver, searching the source's directory (the working
    directory for stdin). Called files are parsed in the caller's dialect; their own diagnostics
    are reported when they are linted themselves, not again through every caller; only that a
    called file has syntax errors is said at the call (NC129), as the path leaves them out."""
    from nctrans.interp.resolver import Resolver

    def parse_file(path: Path) -> Optional[Program]:
        try:
            src = _source.decode(_source.read_bytes(path), _display_path(Path(path)))
        except _source.SourceError:
            return None
        if not src.ok:
            return None
        name = dialect or _detect.detect(src.text, str(path)).dialect
        if name is None:
            return None
        try:
            res = get_dialect(name).parse(src.text, src.file)
        except PipelineError:
            return None
        errors = [d for d in res.diagnostics if d.severity == "error"]
        if errors:             # said once at the call (NC129): what did not parse never runs
            res.program.meta["parse_errors"] = (len(errors), errors[0].format_text())
        return res.program

    d = base.get(dialect) if dialect else None
    candidates = d.subprogram_files if d is not None else _any_dialect_files
    return Resolver([source_dir or os.getcwd(), *search_paths()], parse_file, candidates)


def _any_dialect_files(name: str) -> list[str]:
    """Subprogram file names of every registered dialect (the caller's dialect is unknown)."""
    return list(dict.fromkeys(f for d in base.dialects() for f in d.subprogram_files(name)))


# Directories searched for called subprograms and definition files after the source's own directory
# (CLI --search-path, then the NCTRANS_PATH environment variable). Lookups stay inside them.
SEARCH_PATHS: list[str] = []


def search_paths() -> list[str]:
    env = [d for d in os.environ.get("NCTRANS_PATH", "").split(os.pathsep) if d]
    return [*SEARCH_PATHS, *env]


# (path, mtime_ns, dialect) -> parsed definition file; a directory lint parses each once
_DEFINITION_CACHE: dict[tuple, Optional[Program]] = {}


def definition_programs(source_dir: Optional[str], dialect: Optional[str],
                        search_paths: Iterable[str] = ()) -> list[Program]:
    """The parsed definition files (Dialect.definition_files) of the source directory and the search
    paths, in file-name order, for the interpreter to preload their declarations. Unreadable or
    unparsable files are skipped: they are reported when they are linted themselves."""
    d = base.get(dialect) if dialect else None
    endings = d.definition_files if d is not None else ()
    if not endings:
        return []
    dirs: list[Path] = []
    for d in [source_dir or os.getcwd(), *search_paths]:
        p = Path(d).resolve()
        if p.is_dir() and p not in dirs:
            dirs.append(p)
    out = []
    for d in dirs:
        for f in sorted(d.iterdir()):
            if f.suffix.lower() not in endings or f.name.startswith(".") or not f.is_file():
                continue
            try:
                key = (str(f), f.stat().st_mtime_ns, dialect)
            except OSError:
                continue
            if key not in _DEFINITION_CACHE:
                _DEFINITION_CACHE[key] = _parse_definition(f, dialect)
            prog = _DEFINITION_CACHE[key]
            if prog is not None:
                out.append(prog)
    return out


def _parse_definition(path: Path, dialect: str) -> Optional[Program]:
    try:
        src = _source.decode(_source.read_bytes(path), _display_path(path))
    except _source.SourceError:
        return None
    if not src.ok:
        return None
    try:
        d = get_dialect(dialect)
    except PipelineError:
        return None
    # parsed once per content and code version across processes (nctrans.parse_cache)
    from nctrans import parse_cache
    return parse_cache.definition(src.text, src.file, dialect, lambda: d.parse(src.text, src.file).program)


def run_toolpath(program: Program, machine: Optional[Machine], diagnostics: list[Diagnostic], *,
                 source_dir: Optional[str] = None, dialect: Optional[str] = None,
                 max_steps: Optional[int] = None, fast_sink: Optional[str] = None
                 ) -> Iterator[ToolpathRecord]:
    """Stream the program's toolpath; interpreter diagnostics are appended to `diagnostics`.
    fast_sink: see interp.interpret (the jsonl writer and lint pass it; other consumers get
    ToolpathRecords only)."""
    from nctrans.interp import interpret     # deferred: `detect` and `rules` need no interpreter
    kwargs = {"diagnostics": diagnostics, "resolver": make_resolver(source_dir, dialect),
              "fast_sink": fast_sink}
    preload = definition_programs(source_dir, dialect, search_paths())
    if preload:
        kwargs["preload"] = preload
    if max_steps is not None:
        kwargs["max_steps"] = max_steps
    return interpret(program, machine, **kwargs)


def toolpath_of(ld: Loaded, machine: Optional[Machine] = None,
                fast_sink: Optional[str] = None) -> Iterator[ToolpathRecord]:
    """Toolpath of a loaded file (nothing when it did not parse); diagnostics go to ld.diagnostics.
    fast_sink="jsonl": the items may include plainrun.JsonChunk (toolpath_io.write_jsonl takes them)."""
    if ld.program is None:
        return iter(())
    if ld.streamed is not None:
        return _streamed_toolpath(ld, machine, fast_sink)
    return run_toolpath(ld.program, machine, ld.diagnostics, source_dir=ld.source_dir,
                        dialect=ld.dialect, fast_sink=fast_sink)


# Allocations between young-generation collections while a streamed program runs. Parse and run
# allocate ~20 objects per block and almost all die by reference count; collecting every 700
# allocations (the default) cost ~15% of the run. Cyclic garbage stays bounded by this count.
STREAM_GC_THRESHOLD = 100_000


def _streamed_toolpath(ld: Loaded, machine: Optional[Machine],
                       fast_sink: Optional[str]) -> Iterator[ToolpathRecord]:
    run_diags: list[Diagnostic] = DiagnosticList()
    thresholds = gc.get_threshold()
    gc.set_threshold(max(thresholds[0], STREAM_GC_THRESHOLD), *thresholds[1:])
    try:
        yield from run_toolpath(ld.program, machine, run_diags, source_dir=ld.source_dir,
                                dialect=ld.dialect, fast_sink=fast_sink)
        _finish_stream(ld, run_diags)
    finally:
        gc.set_threshold(*thresholds)


def lint(ld: Loaded, machine: Optional[Machine] = None) -> list[Diagnostic]:
    """Parse diagnostics plus the interpreter's (records are drained and dropped)."""
    if ld.program is not None:
        for _ in toolpath_of(ld, machine, fast_sink="discard"):
            pass
    _finish_stream(ld, [])
    return ld.diagnostics


# --------------------------------------------------------------------------- paths

def all_extensions() -> set[str]:
    """File endings (lower case) of every registered dialect: what a directory walk picks up."""
    exts: set[str] = set()
    for name in base.names():
        exts.update(_detect.extensions(name))
    return exts


def iter_inputs(paths: Iterable[str]) -> Iterator[str]:
    """Files to process: files as given, directories recursed (NC file endings only, hidden entries
    skipped, sorted for stable output), '-' for stdin. Missing paths are yielded too, so the caller
    reports them through the normal read error."""
    exts = all_extensions()
    for p in paths:
        if p != _source.STDIN and os.path.isdir(p):
            for root, dirs, files in os.walk(p):
                dirs[:] = sorted(d for d in dirs if not d.startswith("."))
                for f in sorted(files):
                    if not f.startswith(".") and Path(f).suffix.lower() in exts:
                        full = os.path.join(root, f)
                        if _source.is_regular_file(full):   # never a FIFO or device in a walk
                            yield full
        else:
            yield p
