"""The Python API: what the command line does, callable from code.

Modelled on sqlglot's `transpile`/`parse_one`: a handful of functions over the same stages the CLI
runs (`nctrans.pipeline`), so a CAM post-processor test, a DNC gateway or a notebook gets exactly the
answers `nctrans convert/lint/toolpath/equiv` print.

Conventions, the same for every function:
- Program text is a `str`; a file is a `pathlib.Path` (or any `os.PathLike`). A `str` is never
  taken for a file name, so a one-line program cannot be mistaken for a path.
- Problems in the user's program are `Diagnostic` records in the result, never exceptions.
  `error_level=ErrorLevel.RAISE` turns error diagnostics into an `NCProgramError` carrying them.
- Misuse of the API (an unknown dialect, an unreadable file, a bad machine file, a wrong argument
  type) raises a subclass of `NCError`.
"""
from __future__ import annotations

import contextlib
import enum
import html
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Iterator, Optional, Sequence, Union, cast

from nctrans import limits
from nctrans import pipeline
from nctrans import linting
from nctrans.diagnostics import once_each
from nctrans import source as _source
from nctrans.diagnostics import Diagnostic
from nctrans.dialects.base import DEFAULT_DIALECT
from nctrans.ir.nodes import Program
from nctrans.machine import Machine, MachineError
from nctrans.toolpath import ToolpathRecord

from nctrans import detection as _detection
from nctrans.detection import Guess

if TYPE_CHECKING:     # equivalence (and the jsonl writer it uses) loads only when equiv() runs
    from nctrans.equivalence import Difference

__all__ = [
    "Conversion", "Equivalence", "ErrorLevel", "NCError", "NCInputError", "NCProgramError",
    "CheckReport", "Toolpath", "UnknownDialectError", "check", "detect", "dialects", "equiv", "lint",
    "parse", "toolpath", "transpile",
]

PathLike = Union[str, "os.PathLike[str]"]
Source = Union[str, "os.PathLike[str]", Program]
MachineLike = Union[Machine, str, "os.PathLike[str]", None]

STRING_LABEL = "<string>"
DEFAULT_TOL = 0.001     # mm, as `nctrans equiv --tol` (nctrans.equivalence.DEFAULT_TOL)


# --------------------------------------------------------------------------- errors

class NCError(Exception):
    """Root of every exception the API raises on misuse (never for problems in a program)."""


class UnknownDialectError(NCError, ValueError):
    """A dialect name that is not registered (see `dialects()`), or text whose dialect cannot be
    told apart (give `read=`/`dialect=`)."""


class NCInputError(NCError):
    """An input that cannot be used at all: an unreadable file, a bad machine file, a bad argument."""


class NCProgramError(NCError):
    """Raised only with `error_level=ErrorLevel.RAISE`: the program has error diagnostics."""

    def __init__(self, diagnostics: Sequence[Diagnostic]):
        self.diagnostics = list(diagnostics)
        errors = [d for d in self.diagnostics if d.severity == "error"]
        first = errors[0].format_text() if errors else "no error"
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        super().__init__(f"{first}{more}")


class ErrorLevel(enum.Enum):
    """What to do with error diagnostics of the user's program (as sqlglot's ErrorLevel)."""
    IGNORE = "ignore"     # return them in the result (the default)
    RAISE = "raise"       # raise NCProgramError carrying all diagnostics


def _raise_on_errors(diags: Sequence[Diagnostic], level: ErrorLevel) -> None:
    if level is ErrorLevel.RAISE and any(d.severity == "error" for d in diags):
        raise NCProgramError(diags)


@contextlib.contextmanager
def _api_errors() -> Iterator[None]:
    """Pipeline failures (unknown dialect, unreadable file, ambiguous detection) as NCError."""
    try:
        yield
    except pipeline.PipelineError as e:
        msg = str(e)
        if "dialect" in msg:
            raise UnknownDialectError(msg) from None
        raise NCInputError(msg) from None


@contextlib.contextmanager
def _search_path(dirs: Iterable[PathLike]) -> Iterator[None]:
    """Directories searched for called subprograms and definition files during one call."""
    extra = [os.fspath(d) for d in dirs]
    for d in extra:
        if not os.path.isdir(d):
            raise NCInputError(f"search path {d}: not a directory")
    saved = list(pipeline.SEARCH_PATHS)
    pipeline.SEARCH_PATHS[:] = [*extra, *saved]     # the CLI's --search-path stays in force
    try:
        yield
    finally:
        pipeline.SEARCH_PATHS[:] = saved


def _check_dialect(name: Optional[str]) -> None:
    if name is not None:
        with _api_errors():
            pipeline.get_dialect(name)


def _machine(machine: MachineLike, dialect: Optional[str]) -> Machine:
    if isinstance(machine, Machine):
        return machine
    if machine is None:
        return pipeline.load_machine(None, dialect)
    if isinstance(machine, (str, os.PathLike)):
        try:
            return Machine.from_toml(os.fspath(machine))
        except MachineError as e:
            raise NCInputError(str(e)) from None
    raise NCInputError(f"machine must be a Machine, a path to MACHINE.toml or None, not {type(machine).__name__}")


def _load(source: Union[str, "os.PathLike[str]", _source.SourceText], dialect: Optional[str], *,
          stream: bool = False, file: str = STRING_LABEL, fallback: Optional[str] = None,
          compact: Union[bool, str] = False) -> pipeline.Loaded:
    """Read and parse text (a str) or a file (a PathLike). The CLI also passes already decoded
    standard input (a SourceText). `compact`: see pipeline.load_source (runs only)."""
    _check_dialect(dialect)
    with _api_errors():
        if isinstance(source, _source.SourceText):
            return pipeline.load_source(source, _source.STDIN, dialect, stream, fallback, compact)
        if isinstance(source, str):
            return pipeline.load_source(_source.from_text(source, file), _source.STDIN, dialect, stream,
                                        fallback, compact)
        if isinstance(source, os.PathLike):
            path = os.fspath(source)
            if os.path.isdir(path):
                raise NCInputError(f"{path}: is a directory (lint takes directories)")
            return pipeline.load(path, dialect, stream, fallback, compact)
    raise NCInputError(f"source must be program text (str) or a path (os.PathLike), not {type(source).__name__}")


# --------------------------------------------------------------------------- discovery

def dialects() -> list[str]:
    """The names of every registered dialect, as the CLI's --from/--to take them."""
    from nctrans.dialects import base
    return list(base.names())


def detect(text: str, filename: Optional[PathLike] = None) -> Guess:
    """Guess the dialect of program text (`filename` adds the evidence of its ending).
    `.dialect` is None when the guess is ambiguous; `.confidence` is 0..1."""
    if not isinstance(text, str):
        raise NCInputError(f"detect takes program text (str), not {type(text).__name__}")
    return _detection.detect(_source.from_text(text).text, None if filename is None else os.fspath(filename))


# --------------------------------------------------------------------------- parse

def parse(text: Union[str, "os.PathLike[str]"], dialect: Optional[str] = None, *,
          file: str = STRING_LABEL, error_level: ErrorLevel = ErrorLevel.IGNORE) -> Program:
    """The IR of a program (`nctrans.ir.schema.dumps(program)` gives its JSON form).

    Parse diagnostics are not raised unless `error_level=ErrorLevel.RAISE`; `lint()` reports them
    together with what running the program finds."""
    ld = _load(text, dialect, file=file)
    _raise_on_errors(ld.diagnostics, error_level)
    if ld.program is None:
        raise NCProgramError(ld.diagnostics)
    return ld.program


# --------------------------------------------------------------------------- transpile

@dataclass
class Conversion:
    """The outcome of `transpile`: the target text (None when refused), every diagnostic, and the
    constructs that were lowered on the way (NC401 diagnostics, each naming one at its line)."""
    text: Optional[str]
    diagnostics: list[Diagnostic] = field(default_factory=list)
    read: str = ""
    write: str = ""

    @property
    def lowered(self) -> list[Diagnostic]:
        return [d for d in self.diagnostics if d.rule == "NC401"]

    @property
    def ok(self) -> bool:
        return self.text is not None

    def __repr__(self) -> str:
        state = f"{len(self.text.splitlines())} lines" if self.text is not None else "refused"
        return (f"<Conversion {self.read} -> {self.write}: {state}, {len(self.diagnostics)} diagnostics, "
                f"{len(self.lowered)} lowered>")


def transpile(text: Union[str, "os.PathLike[str]"], read: Optional[str] = None, write: str = DEFAULT_DIALECT, *,
              flatten: bool = False, strict: bool = False, machine: MachineLike = None,
              search_path: Iterable[PathLike] = (), file: str = STRING_LABEL,
              error_level: ErrorLevel = ErrorLevel.IGNORE, out: Any = None,
              profile: Optional[str] = None) -> Conversion:
    """Convert a program from dialect `read` (detected when None) to dialect `write`.
    `profile`: the control of the source dialect's family (rules `[options.profiles]`, ISO
    milling: "haas"), instead of the one its header comments name.

    Constructs the target cannot express are lowered (NC401 infos, listed in `.lowered`) or the
    conversion is refused (`.text` is None, NC402 errors say why). `flatten` writes plain motion
    only; `strict` refuses every lowering; `machine` (used by flattening) is a Machine or a path to
    MACHINE.toml; `search_path` lists directories for called subprograms.

    `out` (an object with write(str) and reset(), such as nctrans.outfile.OutputFile): the text is
    handed to it as it is produced instead of returned (`.text` is then "" on success), and a
    program that runs straight through is converted as it is parsed, so memory stays flat however
    long it is. On refusal what was written must be discarded (reset() or OutputFile.discard())."""
    _check_dialect(write)
    from nctrans.dialects.emit import conversion_machine, target_profile
    written_for = _target_profile(write, profile)
    with _search_path(search_path), conversion_machine(lambda: _equiv_machine(machine, read, write)), \
            target_profile(write, written_for):
        # written as it goes (`out`): a program that holds structure is parsed compact (its plain
        # stretches held as spans of the text: --flatten runs them, the emitters write them a few
        # blocks at a time), so memory stays flat in program size
        ld = _load(text, read, file=file, stream=out is not None,
                   compact="jumps" if out is not None else False)
        _set_profile(ld, profile, write)
        with _api_errors():
            target = pipeline.get_dialect(write)
        if ld.streamed is not None:
            streamed: Optional[Conversion]
            if flatten:
                streamed = _transpile_flat_stream(ld, target, strict, out,
                                                  _equiv_machine(machine, ld.dialect, write))
            else:
                streamed = _transpile_stream(ld, target, strict, out, machine)
            if streamed is not None:
                _raise_on_errors(streamed.diagnostics, error_level)
                return streamed
            out.reset()                  # convert the whole program: parse it whole
            ld = pipeline.load_source(ld.source, ld.path, ld.dialect)
            _set_profile(ld, profile, write)
        diags = ld.diagnostics
        out_text: Optional[str] = None
        if ld.program is not None and not any(d.severity == "error" for d in diags):
            from nctrans.convert import convert
            program = ld.program
            # a lathe program written for another control runs on the lathe (as equiv runs both)
            flat_machine = _equiv_machine(machine, ld.dialect, write)

            # the plain motion held whole is bounded, except where the caller asked for the
            # whole flattened text (flatten=True and no `out` to stream to)
            held = None if flatten and out is None else limits.setting(
                "MAX_LOWERED_BLOCKS", limits.MAX_LOWERED_BLOCKS)

            def flatten_with(into: list[Diagnostic]) -> Program:
                from nctrans.lower.flatten import flatten as _flatten
                result: Program = _flatten(program, flat_machine, diagnostics=into,
                                           resolver=pipeline.make_resolver(ld.source_dir, ld.dialect),
                                           max_blocks=held, stop_when_incomplete=not flatten)
                return result

            stream_whole = None
            if out is not None:
                def stream_whole(notes: list[Diagnostic]) -> Any:
                    """The last resort, lowering the whole program, written as it runs."""
                    from nctrans.convert import Conversion as Converted
                    done = _transpile_flat_stream(ld, target, strict, out, flat_machine,
                                                  stop_when_incomplete=True)
                    if done is None:
                        return None
                    if done.text is None:
                        out.reset()
                    return Converted(done.text, [*notes, *done.diagnostics], flattened=True)

            result: Any = None
            if flatten and out is not None:         # written as the run goes: flat memory
                result = _transpile_flat_stream(ld, target, strict, out, flat_machine)
            if result is None:
                # written out piece by piece (`out`): the emitters' lines may go to a temporary
                # file (a structure spanning the whole body is held until its end)
                from nctrans import spilled
                with spilled.spooled_output() if out is not None else contextlib.nullcontext():
                    result = convert(program, target, flatten=flatten, strict_mode=strict,
                                     flatten_with=flatten_with, machine=flat_machine,
                                     resolver=pipeline.make_resolver(ld.source_dir, ld.dialect),
                                     stream_whole=stream_whole,
                                     whole=lambda: _parsed_whole(ld, profile, write))
            diags.extend(result.diagnostics)
            out_text = result.text
        elif strict:
            from nctrans.convert import strict as _strict
            diags[:] = _strict(diags)
        if any(d.severity == "error" for d in diags):
            out_text = None
    _raise_on_errors(diags, error_level)
    if out is not None and out_text is not None:
        from nctrans import spilled
        for piece in spilled.pieces(out_text):
            out.write(piece)
        out_text = ""
    return Conversion(out_text, diags, ld.dialect or "", write)


def _parsed_whole(ld: pipeline.Loaded, profile: Optional[str], write: Optional[str] = None) -> Program:
    """The program of `ld` parsed whole (convert's fallback for a compact parse)."""
    whole = pipeline.load_source(ld.source, ld.path, ld.dialect)
    _set_profile(whole, profile, write)
    assert whole.program is not None        # it parsed before, compact
    return whole.program


def _profiles(dialect: Optional[str]) -> list[str]:
    from nctrans.rules import option
    return sorted(option(dialect, "profiles") or {})


def _target_profile(write: str, profile: Optional[str]) -> Optional[str]:
    """The profile the target is written for: `profile` when the target's table names it (a
    source-only profile leaves the target's default)."""
    return profile if profile is not None and profile in _profiles(write) else None


def use_profile(ld: pipeline.Loaded, profile: Optional[str]) -> None:
    """Run or read the loaded program as the source family's control `profile` (None: as detected);
    NCError naming the known ones for a name its rules table does not know."""
    _set_profile(ld, profile)


def _set_profile(ld: pipeline.Loaded, profile: Optional[str], write: Optional[str] = None) -> None:
    """Select the source's control profile by name; a name only the target's table knows is
    the target's (the control the output is written for, `_target_profile`). NCError naming the
    known ones when neither knows it."""
    if profile is None or ld.program is None:
        return
    known = _profiles(ld.dialect)
    if profile in known:
        ld.program.meta["profile"] = profile
        return
    target = _profiles(write) if write else []
    if profile not in target:
        raise NCError(f"profile {profile!r} is not one of {ld.dialect or 'the source'}'s: "
                      f"{', '.join(known) or 'it has none'}"
                      + (f", nor of {write}'s: {', '.join(target) or 'it has none'}" if write else ""))


def _transpile_flat_stream(ld: pipeline.Loaded, target: Any, strict: bool, out: Any,
                           machine: Machine, stop_when_incomplete: bool = False) -> Optional[Conversion]:
    """--flatten with an output sink: the flattened blocks are written as the interpreter makes
    them (convert_flat_stream); None when the target cannot stream (the sink is then reset).
    `stop_when_incomplete`: see flatten_blocks."""
    from nctrans.convert import convert_flat_stream
    from nctrans.lower.flatten import flatten_blocks, flattened_meta
    program = ld.program
    if program is None:
        return None
    resolver = pipeline.make_resolver(ld.source_dir, ld.dialect)

    def blocks(into: list[Diagnostic]) -> Iterator[Any]:
        return flatten_blocks(program, machine, diagnostics=into, resolver=resolver,
                              stop_when_incomplete=stop_when_incomplete)

    result = convert_flat_stream(program, target, blocks, flattened_meta(program), out.write, strict_mode=strict)
    if result is None:
        out.reset()
        return None
    if ld.streamed is None:
        return Conversion(result.text, list(result.diagnostics), ld.dialect or "", target.name)
    pipeline.finish_stream(ld)                  # a streamed parse: its diagnostics come first
    diags = ld.diagnostics
    if any(d.severity == "error" for d in diags):
        return Conversion(None, diags, ld.dialect or "", target.name)   # as the whole parse: not run
    diags.extend(result.diagnostics)
    return Conversion(result.text, diags, ld.dialect or "", target.name)


def _transpile_stream(ld: pipeline.Loaded, target: Any, strict: bool, out: Any,
                      machine: MachineLike = None) -> Optional[Conversion]:
    """A streamed parse converted as it is read (convert_stream), or None when the whole program
    must be converted instead (the target does not stream, or the program holds structure). The
    constructs the target refused are lowered to plain motion streamed too (stream_constructs)."""
    from nctrans.convert import convert_stream
    if ld.program is None:
        return None
    result = convert_stream(ld.program, target, out.write, strict_mode=strict)
    if result is None:
        return None
    pipeline.finish_stream(ld)
    diags = ld.diagnostics
    if result.retry_whole and not any(d.severity == "error" for d in diags):
        result = _lower_constructs_stream(ld, target, result.diagnostics, out, machine)
        if result is None:
            return None
    diags.extend(result.diagnostics)
    text = None if result.text is None or any(d.severity == "error" for d in diags) else ""
    return Conversion(text, diags, ld.dialect or "", target.name)


def _lower_constructs_stream(ld: pipeline.Loaded, target: Any, found: list[Diagnostic], out: Any,
                             machine: MachineLike) -> Any:
    """The constructs of a streamed program the target refused (`found`), lowered to plain motion
    and written as the program is read again (nctrans.lower.stream_constructs); None when the
    whole program must be converted instead."""
    from nctrans.lower.stream_constructs import convert_constructs_stream
    dialect = pipeline.get_dialect(ld.dialect or "")

    def reparse() -> Optional[Program]:
        parsed = dialect.parse_stream(ld.source.text, ld.label)
        return parsed.program if parsed is not None else None

    return convert_constructs_stream(reparse, target, found, out.write, out.reset,
                                     machine=_equiv_machine(machine, ld.dialect, target.name),
                                     resolver=pipeline.make_resolver(ld.source_dir, ld.dialect))


# --------------------------------------------------------------------------- toolpath

class Toolpath(Iterator[ToolpathRecord]):
    """The streamed toolpath of one program: iterate it once for its `ToolpathRecord`s (memory
    stays flat in program length); `.diagnostics` holds what parsing and running reported, complete
    once the iteration has ended."""

    def __init__(self, records: Iterator[ToolpathRecord], diagnostics: list[Diagnostic],
                 label: str, dialect: Optional[str], parsed: bool = True):
        self._records = records
        self.diagnostics = diagnostics
        self.parsed = parsed        # False when the program did not parse (no records follow)
        self.label = label
        self.dialect = dialect
        self.count = 0
        self.done = False

    def __iter__(self) -> "Toolpath":
        return self

    def __next__(self) -> ToolpathRecord:
        try:
            rec = next(self._records)
        except StopIteration:
            self.done = True
            raise
        self.count += 1
        return rec

    def close(self) -> None:
        """Stop the run early (what it holds is released; later iteration ends at once)."""
        close = getattr(self._records, "close", None)
        if close is not None:
            close()

    def summary(self, machine: MachineLike = None) -> str:
        """Run the rest of the toolpath and return what `nctrans toolpath --summary` prints."""
        from nctrans import toolpath_io
        summ = toolpath_io.Summary(_machine(machine, self.dialect))
        for r in self:
            summ.add(r)
        text: str = summ.format(len(self.diagnostics))
        return text

    def plot(self, view: str = "top") -> str:
        """Run the rest of the toolpath and return its backplot as an SVG document (as
        `nctrans backplot -o OUT.svg` draws it: rapids dashed, arcs as arcs, colours per tool)."""
        from nctrans import backplot
        scene = backplot.build_scene(self, self.label, self.diagnostics)
        svg: bytes = backplot.render("svg", scene, view=view)
        return svg.decode("utf-8")

    def _repr_html_(self) -> str:
        """Jupyter shows a toolpath that has not been iterated yet as its plot; one already
        (partly) consumed cannot be replayed, so it shows its summary line."""
        if self.count or self.done:
            return f"<pre>{html.escape(repr(self))}</pre>"
        return self.plot()

    def __repr__(self) -> str:
        state = "complete" if self.done else "running" if self.count else "not started"
        return (f"<Toolpath {self.label} ({self.dialect}): {self.count} records, {state}, "
                f"{len(self.diagnostics)} diagnostics>")


def toolpath(source: Source, dialect: Optional[str] = None, machine: MachineLike = None, *,
             search_path: Iterable[PathLike] = (), file: str = STRING_LABEL,
             profile: Optional[str] = None) -> Toolpath:
    """The canonical motions of a program (text, a path or a parsed `Program`), streamed.

    Records are in machine coordinates, mm and degrees, as `nctrans toolpath --format jsonl`
    writes them. The program runs while the result is iterated. `profile`: the control of the
    source's family that runs it (rules `[options.profiles]`, e.g. iso-m "linuxcnc")."""
    dirs = list(search_path)
    opened = _open_run(source, dialect, dirs, file, profile)
    return _run_opened(opened, _machine(machine, opened[1]), dirs)


def _open_run(source: Source, dialect: Optional[str], dirs: list[PathLike], file: str,
              profile: Optional[str], write: Optional[str] = None) -> tuple[Any, Optional[str]]:
    """(a parsed Program or the loaded source, its dialect): a program ready to run, before the
    machine it runs on is chosen. `write`: the other dialect of an equiv, whose profile the name
    may be instead."""
    if isinstance(source, Program):
        _check_dialect(dialect)
        return source, dialect or source.dialect
    with _search_path(dirs):
        ld = _load(source, dialect, stream=True, file=file, compact=True)
    _set_profile(ld, profile, write)
    return ld, ld.dialect


def _run_opened(opened: tuple[Any, Optional[str]], m: Machine, dirs: list[PathLike]) -> Toolpath:
    def run(records: Iterator[ToolpathRecord]) -> Iterator[ToolpathRecord]:
        with _search_path(dirs):
            yield from records

    what, dialect = opened
    if isinstance(what, Program):
        diags: list[Diagnostic] = []
        with _search_path(dirs):
            records = pipeline.run_toolpath(what, m, diags, dialect=dialect)
        return Toolpath(run(records), diags, what.file, dialect)
    return Toolpath(run(pipeline.toolpath_of(what, m)), what.diagnostics, what.label, dialect,
                    parsed=what.program is not None)


# --------------------------------------------------------------------------- lint

def rule_filter(select: Iterable[str] = (), ignore: Iterable[str] = ()):  # type: ignore[no-untyped-def]
    """A predicate keeping diagnostics whose rule code starts with one of `select` (all when empty)
    and with none of `ignore`; entries may be comma-separated lists of prefixes (`"NC1,NC20"`)."""
    sel = [p.strip().upper() for group in select for p in group.split(",") if p.strip()]
    ign = [p.strip().upper() for group in ignore for p in group.split(",") if p.strip()]

    def keep(d: Diagnostic) -> bool:
        code = d.rule.upper()
        if sel and not any(code.startswith(p) for p in sel):
            return False
        return not any(code.startswith(p) for p in ign)
    return keep


def lint(source: Union[str, "os.PathLike[str]", Iterable["os.PathLike[str]"]], dialect: Optional[str] = None,
         machine: MachineLike = None, *, select: Iterable[str] = (), ignore: Iterable[str] = (),
         search_path: Iterable[PathLike] = (), file: str = STRING_LABEL,
         error_level: ErrorLevel = ErrorLevel.IGNORE, target: Optional[str] = None,
         default_dialect: Optional[str] = None) -> list[Diagnostic]:
    """Diagnostics of program text, a file, a directory (recursed for NC file endings, as
    `nctrans lint DIR`) or several paths, filtered by rule-code prefixes `select`/`ignore`, after
    the programs' own `nctrans: ignore` comments. `target`: also what converting to that dialect
    would lower or refuse (NC4xx; nothing is written). `default_dialect`: the dialect of a file
    when neither `dialect` nor the file's `nctrans: dialect=` pragma names one (before detection;
    the CLI passes the project configuration's)."""
    if isinstance(source, (str, os.PathLike, _source.SourceText)):
        sources: list[Union[str, os.PathLike[str], _source.SourceText]] = [source]
    else:
        sources = list(source)
    keep = rule_filter(list(select), list(ignore))
    out: list[Diagnostic] = []
    with _search_path(search_path):
        for s in sources:
            if isinstance(s, os.PathLike) and os.path.isdir(s):
                files: list[Union[str, os.PathLike[str], _source.SourceText]] = [
                    Path(f) for f in pipeline.iter_inputs([os.fspath(s)])]
            else:
                files = [s]
            if target is not None:
                _check_dialect(target)
            for f in files:
                ld = _load(f, dialect, stream=target is None, file=file, fallback=default_dialect,
                           compact=True)
                m = _machine(machine, ld.dialect)
                if machine is None:
                    diags = linting.lint_loaded(ld, m, target)
                else:                   # a machine given: the machine check's findings too
                    from nctrans.check import check_loaded
                    diags = linting.lint_loaded(ld, m, target, run=lambda l, mm: check_loaded(l, mm)[0])
                out.extend(d for d in diags if keep(d))
    out = list(once_each(out))      # a macro file linted with its caller: once
    _raise_on_errors(out, error_level)
    return out


# --------------------------------------------------------------------------- check

@dataclass
class CheckReport:
    """What `nctrans check` finds for one program on one machine. Truthy when there is no
    finding. `findings`: `nctrans.check.Finding` records (rule, file, line, subject, message,
    the controlled point in machine coordinates and by how much a limit is exceeded);
    `diagnostics`: the program's own diagnostics followed by the findings as diagnostics (what
    `nctrans lint --machine` reports); `cycle_time`: the estimate as `nctrans check --format json`
    gives it ("total_s", "rapid_s", "feed_s", "dwell_s", "tool_change_s", "per_tool")."""
    findings: list[Any]
    diagnostics: list[Diagnostic]
    cycle_time: dict[str, Any]
    moves: int
    machine: str
    label: str
    _report: str = ""

    def __bool__(self) -> bool:
        return not self.findings

    def report(self) -> str:
        """The cycle-time table `nctrans check` prints after the findings."""
        return self._report

    def __repr__(self) -> str:
        return (f"<CheckReport {self.label} on {self.machine!r}: {len(self.findings)} findings, "
                f"{self.moves} moves, cycle {self.cycle_time.get('total_s', 0.0):.1f} s>")


def check(source: Source, dialect: Optional[str] = None, machine: MachineLike = None, *,
          fixtures: Iterable[PathLike] = (), stock: Optional[PathLike] = None,
          search_path: Iterable[PathLike] = (), file: str = STRING_LABEL,
          error_level: ErrorLevel = ErrorLevel.IGNORE) -> CheckReport:
    """Check a program (text, a path or a parsed `Program`) against a machine, as `nctrans check`
    does: travel and programmed limits, feed and spindle limits, collisions with the machine's
    fixtures (and the mesh files in `fixtures`, machine coordinates) and, with stock, rapids into
    uncut material; plus the cycle-time estimate. The toolpath streams through (memory flat in
    program length). Fixtures and stock need the `check` extra; a mesh that cannot be read is an
    NCInputError. `error_level=RAISE`: error diagnostics of the program or the check raise."""
    from nctrans import check as _check
    dirs = list(search_path)
    with _search_path(dirs):
        if isinstance(source, Program):
            _check_dialect(dialect)
            label, dia = source.file, dialect or source.dialect
            m = _machine(machine, dia)
            diags: list[Diagnostic] = []
            records = pipeline.run_toolpath(source, m, diags, dialect=dia)
        else:
            ld = _load(source, dialect, stream=True, file=file)
            label, m = ld.label, _machine(machine, ld.dialect)
            diags = ld.diagnostics
            records = iter(pipeline.toolpath_of(ld, m)) if ld.program is not None else iter(())
        m = _check.with_extra_solids(m, [os.fspath(f) for f in fixtures],
                                     None if stock is None else os.fspath(stock))
        try:
            mc = _check.MachineCheck(m)
            for r in records:
                mc.add(r)
        except MachineError as e:
            raise NCInputError(str(e)) from None
        result = mc.finish()
    out = CheckReport(list(result.findings), list(diags) + [f.to_diagnostic() for f in result.findings],
                       result.cycle.to_dict(), result.moves, m.name, label, result.cycle.report())
    _raise_on_errors(out.diagnostics, error_level)
    return out


# --------------------------------------------------------------------------- equiv

@dataclass
class Equivalence:
    """Whether two programs drive the same toolpath within `tol` mm. Truthy when they do;
    otherwise `difference` says what differs first and where (file:line in each program)."""
    equivalent: bool
    tol: float
    difference: Optional["Difference"] = None
    records: tuple[int, int] = (0, 0)
    diagnostics: list[Diagnostic] = field(default_factory=list)
    endless: bool = False       # both loop for ever: compared as far as the step budget ran

    def __bool__(self) -> bool:
        return self.equivalent

    @property
    def message(self) -> str:
        if self.difference is not None:
            text: str = self.difference.format()
            return text
        if not self.equivalent:
            return "an input did not parse"
        endless = "; both endless, compared as far as the step budget ran" if self.endless else ""
        return (f"equivalent within {self.tol:g} mm ({self.records[0]} and {self.records[1]} toolpath "
                f"records{endless})")

    def __repr__(self) -> str:
        return f"<Equivalence {'yes' if self.equivalent else 'no'}: {self.message}>"


def _equiv_profiles(oa: tuple[Any, Optional[str]], ob: tuple[Any, Optional[str]],
                    profile: Optional[str], profile_b: Optional[str]) -> None:
    """`profile` runs A, and B too where B's table names it (both ISO milling programs as
    LinuxCNC runs them); `profile_b` runs B. NCError when a name is neither's."""
    if profile is not None:
        in_a, in_b = profile in _profiles(oa[1]), profile in _profiles(ob[1])
        if not in_a and not in_b:
            raise NCError(f"profile {profile!r} is not one of {oa[1] or 'A'}'s: "
                          f"{', '.join(_profiles(oa[1])) or 'it has none'}, nor of {ob[1] or 'B'}'s: "
                          f"{', '.join(_profiles(ob[1])) or 'it has none'}")
        if in_a and isinstance(oa[0], pipeline.Loaded):
            _set_profile(oa[0], profile)
        if in_b and profile_b is None and isinstance(ob[0], pipeline.Loaded):
            _set_profile(ob[0], profile)
    if profile_b is not None and isinstance(ob[0], pipeline.Loaded):
        _set_profile(ob[0], profile_b)


def _equiv_machine(machine: MachineLike, da: Optional[str], db: Optional[str]) -> Machine:
    """The one machine both programs of an equiv run on: the given one, else the built-in machine
    of their dialects, the lathe where either is a turning dialect."""
    if machine is not None:
        return _machine(machine, da)
    kinds = {da: pipeline.load_machine(None, da), db: pipeline.load_machine(None, db)}
    return next((m for m in kinds.values() if m.kind == "lathe"), kinds[da])


def _subprogram_file(opened: tuple[Any, Optional[str]]) -> bool:
    """An opened equiv side is a subprogram file by its dialect's file types (convert.subprogram_file)."""
    from nctrans.convert import subprogram_file
    what = opened[0]
    program = what if isinstance(what, Program) else getattr(what, "program", None)
    return program is not None and subprogram_file(program)


# The modes a subprogram file runs in are its caller's: an equiv of it and its conversion starts
# the other side in the same ones (one caller calls either), not in its own control's power-on
# modes (Sinumerik G1 where ISO and Fagor power on in G0: `Z10 F600` is the same move from a
# caller in G1, a feed move against a rapid from power-on)
_CALLERS_MODES = ("motion", "plane", "feed_mode", "distance", "units", "cutter_comp")


def _called_alike(sub: tuple[Any, Optional[str]], other: tuple[Any, Optional[str]]) -> None:
    """Start `other` in the modes `sub` (a subprogram file) starts in."""
    def meta(o: tuple[Any, Optional[str]]) -> Optional[dict[str, Any]]:
        program = o[0] if isinstance(o[0], Program) else getattr(o[0], "program", None)
        return program.meta if program is not None and isinstance(program.meta, dict) else None

    m_sub, m_other = meta(sub), meta(other)
    if m_sub is None or m_other is None:
        return
    mine, theirs = m_sub.get("defaults"), m_other.get("defaults")
    if isinstance(mine, dict) and isinstance(theirs, dict):
        m_other["defaults"] = {**theirs, **{k: mine[k] for k in _CALLERS_MODES if k in mine}}


def _endless_budget(*opened: tuple[Any, Optional[str]]) -> Optional[int]:
    """The smaller step budget of limits.MAX_ENDLESS_STEPS where a side's main program ends by
    starting again (M99): that side never ends, and neither does a side equivalent to it, so
    each would run to MAX_STEPS (minutes) to compare what the first thousand passes show."""
    from nctrans.lower.restart_loop import restart_block
    for o in opened:
        program = o[0] if isinstance(o[0], Program) else getattr(o[0], "program", None)
        if program is not None and restart_block(program.body) is not None:
            return min(limits.setting("MAX_STEPS", limits.MAX_STEPS),
                       limits.setting("MAX_ENDLESS_STEPS", limits.MAX_ENDLESS_STEPS))
    return None


def _budget_spent(diags: list[Diagnostic]) -> bool:
    """The run was cut by the step budget (NC205 as an error: an endless loop)."""
    return any(d.rule == "NC205" and d.severity == "error" and "step budget" in d.message for d in diags)


def equiv(a: Source, b: Source, *, tol: float = DEFAULT_TOL, read_a: Optional[str] = None,
          read_b: Optional[str] = None, machine: MachineLike = None,
          search_path: Iterable[PathLike] = (), profile: Optional[str] = None,
          profile_b: Optional[str] = None) -> Equivalence:
    """Compare the toolpaths of two programs (text, paths or parsed Programs) within `tol` mm,
    as `nctrans equiv` does. Both run on one machine: `machine`, else the built-in one of their
    dialects, and the lathe where one of them is a turning dialect (a lathe program converted to
    a milling dialect's language still runs on the lathe). `profile`: the control that runs A
    (rules `[options.profiles]`), and B where B's table names it too; `profile_b`: B's own."""
    from nctrans import equivalence as _equivalence
    if isinstance(tol, bool) or not isinstance(tol, (int, float)) or not math.isfinite(tol) or tol <= 0:
        raise NCInputError(f"tol must be a positive finite number of mm, not {tol!r}")
    # Both programs run at once, in step (the comparison reads each toolpath as a stream, so
    # memory stays flat); the search path is set once around both runs.
    from nctrans.interp.flow import RESTART_MAIN
    dirs = list(search_path)
    oa = _open_run(a, read_a, dirs, "<a>", None)
    ob = _open_run(b, read_b, dirs, "<b>", None)
    # a subprogram library against a program holding that subprogram: compared as called
    from nctrans import library_equiv
    called_pair = library_equiv.as_called(
        oa, ob, lambda ca, cb, **kw: equiv(ca, cb, tol=tol, machine=machine, profile=profile,
                                           profile_b=profile_b, **kw), dirs)
    if called_pair is not None:
        return cast(Equivalence, called_pair)
    _equiv_profiles(oa, ob, profile, profile_b)
    ma = mb = _equiv_machine(machine, oa[1], ob[1])
    # M99 in a main program loops, as a LOOP does; but where either side is a subprogram file (a
    # Sinumerik .SPF), both are: the other side is its conversion, whose M99 is the return the
    # file's M17/RET was, so each runs once, as its caller would run it
    called = [o for o in (oa, ob) if _subprogram_file(o)]
    if called:
        _called_alike(called[0], ob if called[0] is oa else oa)
    restarts = RESTART_MAIN.set(not called)
    budget = limits.STEP_BUDGET.set(_endless_budget(oa, ob) if not called else None)
    try:
        with _search_path(dirs):
            ta = _run_opened(oa, ma, dirs)
            tb = _run_opened(ob, mb, dirs)
            try:
                diff = _equivalence.compare(ta, tb, tol) if ta.parsed and tb.parsed else None
                for _ in ta:                # the rest of each run: its diagnostics complete
                    pass
                for _ in tb:
                    pass
            finally:
                ta.close()
                tb.close()
    finally:
        RESTART_MAIN.reset(restarts)
        limits.STEP_BUDGET.reset(budget)
    diags = list(once_each(ta.diagnostics + tb.diagnostics))    # a file both sides read: once
    if diff is not None and diff.at_end and _budget_spent(ta.diagnostics) and _budget_spent(tb.diagnostics):
        # both endless (a LOOP, M99 restarting a main program), both cut by the step budget at
        # different points: they agreed on everything both ran
        diff, endless = None, True
    else:
        endless = False
    if not (ta.parsed and tb.parsed):
        return Equivalence(False, tol, None, (ta.count, tb.count), diags)
    return Equivalence(diff is None, tol, diff, (ta.count, tb.count), diags, endless)


