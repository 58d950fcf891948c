"""The command line (CONTRACT.md "Commands"): argument parsing and wiring only.

Every stage lives elsewhere (pipeline, output, equiv, toolpath_io, catalogue, detect); this module
reads arguments, calls them, prints, and maps outcomes to the contract's exit codes:
0 success, 1 diagnostics at or above --fail-on (or equiv found a difference), 2 usage error,
unreadable file, unknown dialect or internal failure - always with a message, never a traceback
(set NCTRANS_DEBUG=1 to get the traceback of an internal failure).
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Iterable, Optional

from nctrans import __version__, api
from nctrans import output as _output
from nctrans import pipeline
from nctrans import source as _source
from nctrans.diagnostics import SEVERITY_RANK, Diagnostic, once_each

# catalogue, detect, equiv, toolpath_io, inspect and tempfile are imported by the commands that
# use them: start-up time is a large share of a `toolpath` or `lint` run on one file.

EXIT_OK, EXIT_DIAGNOSTICS, EXIT_USAGE = 0, 1, 2
NOT_IMPLEMENTED = ("audit", "fuzz", "lsp")


class UsageError(Exception):
    """A problem with how nctrans was called (exit 2)."""


# --------------------------------------------------------------------------- printing helpers

def _err(msg: str) -> None:
    print(f"nctrans: {msg}", file=sys.stderr)


def _fancy(stream) -> bool:
    return hasattr(stream, "isatty") and stream.isatty() and not os.environ.get("NO_COLOR")


def _print_text_diags(diags: list[Diagnostic], stream) -> None:
    """gcc-style lines; coloured with rich when the stream is a terminal."""
    diags = sorted(diags, key=_output.sort_key)
    if not diags:
        return
    if _fancy(stream):
        from rich.console import Console
        from rich.markup import escape
        con = Console(file=stream, highlight=False, soft_wrap=True)
        colour = {"error": "bold red", "warning": "yellow", "info": "cyan"}
        for d in diags:
            con.print(f"[bold]{escape(d.file)}:{d.line}:{d.column}:[/bold] "
                      f"[{colour.get(d.severity, 'white')}]{d.severity}[/][dim]\\[{d.rule}][/dim] {escape(d.message)}")
    else:
        stream.write(_output.format_text(diags))
        stream.flush()


def _progress(total: int, description: str):
    """A rich progress bar on stderr for long runs on a terminal; None in CI or when piped."""
    if total < 2 or os.environ.get("CI") or not sys.stderr.isatty():
        return None
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
    prog = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                    console=Console(stderr=True), transient=True)
    prog.start()
    prog.add_task(description, total=total)
    return prog


def _at_or_above(diags: Iterable[Diagnostic], severity: str) -> bool:
    rank = SEVERITY_RANK[severity]
    return any(SEVERITY_RANK.get(d.severity, 2) >= rank for d in diags)


def _debug() -> bool:
    return os.environ.get("NCTRANS_DEBUG", "") not in ("", "0")


def _internal(where: str, exc: BaseException) -> None:
    if _debug():
        raise exc
    _err(f"internal error{where}: {type(exc).__name__}: {exc} (NCTRANS_DEBUG=1 shows the traceback)")


def _check_dialect(name: Optional[str]) -> None:
    if name is not None:
        pipeline.get_dialect(name)


# --------------------------------------------------------------------------- convert

def _target_extension(dialect: str) -> str:
    """The file ending `convert` writes for `dialect`: the first of its endings."""
    exts = pipeline.get_dialect(dialect).extensions
    return exts[0] if exts else ".nc"


def _file_keys(path: Path) -> list:
    """What identifies a file: its resolved path and, when it exists, (device, inode) (any
    spelling, through links). A few lookups per path, so checking N outputs is linear in N (pairwise
    Path.resolve() made 1,000 sources take 49 s)."""
    keys: list = [("path", str(path.resolve()))]
    try:
        st = os.stat(path)
        keys.append(("inode", st.st_dev, st.st_ino))
    except OSError:
        pass
    return keys


def write_atomic(path: Path, text: str | bytes) -> None:
    """Write `text` (or bytes) to `path` through a temporary file in the same directory and
    os.replace, so a reader never sees a half-written file and a failure leaves any old file intact."""
    import tempfile
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        binary = isinstance(text, bytes)
        with (os.fdopen(fd, "wb") if binary else os.fdopen(fd, "w", encoding="utf-8", newline="")) as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _cli_source(path: str):
    """What the API reads for a command-line input: a Path, or standard input already decoded."""
    if path != _source.STDIN:
        return Path(path)
    try:
        return _source.read_source(path)
    except _source.SourceError as e:
        raise pipeline.PipelineError(str(e)) from None


def cmd_convert(args) -> int:
    _check_dialect(args.from_)
    target = pipeline.get_dialect(args.to)
    if args.output and args.out_dir:
        raise UsageError("give either -o or --out-dir, not both")
    if args.src.count(_source.STDIN) > 1:
        raise UsageError("'-' (stdin) can be given once")
    # (source, path relative to the output directory) - directories are recursed, keeping structure
    jobs: list[tuple[str, Path]] = []
    ext = _target_extension(target.name)
    for s in args.src:
        if s != _source.STDIN and os.path.isdir(s):
            if not args.out_dir:
                raise UsageError(f"{s} is a directory: converting a directory needs --out-dir")
            for f in pipeline.iter_inputs([s]):
                jobs.append((f, Path(os.path.relpath(f, s)).with_suffix(ext)))
        else:
            jobs.append((s, Path("stdin" if s == _source.STDIN else Path(s).stem + ext)))
    sources = [j[0] for j in jobs]
    if args.output and len(sources) > 1:
        raise UsageError("-o takes one source; use --out-dir for several")
    if len(sources) > 1 and not args.out_dir:
        raise UsageError("several sources need --out-dir")
    # decide every output path first, and refuse before doing any work
    from nctrans.outfile import kind_of
    outputs: dict[str, Optional[Path]] = {}
    inputs = {k: s for s in sources if s != _source.STDIN for k in _file_keys(Path(s))}
    written: dict = {}
    for s, rel in jobs:
        if args.output:
            out = None if args.output == "-" else Path(args.output)
        elif args.out_dir:
            out = Path(args.out_dir) / rel
        else:
            out = None
        if out is not None:
            kind = kind_of(out)
            if kind == "dir":
                raise UsageError(f"{out}: is a directory (use --out-dir)")
            keys = _file_keys(out)
            for key in keys:
                if key in inputs:
                    raise UsageError(f"refusing to overwrite the input {inputs[key]} with the output {out}")
                if key in written:
                    raise UsageError(f"{s} and {written[key]} would both be written to {out}")
            if args.out_dir and kind != "new" and not args.overwrite:
                raise UsageError(f"{out} exists and is not an output of this run: refusing to "
                                 "overwrite it (--overwrite replaces existing files)")
            written.update((key, s) for key in keys)
        outputs[s] = out
    machine = pipeline.load_machine(args.machine, args.from_) if args.flatten or args.machine else None
    status = EXIT_OK
    bar = _progress(len(sources), "convert")
    for s in sources:
        if bar is not None:
            bar.advance(bar.task_ids[0])
        from nctrans.outfile import OutputFile
        with OutputFile(outputs[s]) as sink:
            try:
                conv = api.transpile(_cli_source(s), read=args.from_, write=target.name,
                                     flatten=args.flatten, strict=args.strict, machine=machine,
                                     out=sink, profile=args.profile)
            except (api.NCError, pipeline.PipelineError) as e:
                _err(str(e))
                status = EXIT_USAGE
                continue
            _print_text_diags(conv.diagnostics, sys.stderr)
            if conv.text is None:
                _err(f"{_source.label_for(s)}: not converted (errors above)")
                status = max(status, EXIT_DIAGNOSTICS)
                continue
            try:
                sink.commit()
            except OSError as e:
                _err(f"{sink.path or 'standard output'}: cannot write: {e.strerror or e}")
                status = EXIT_USAGE
    if bar is not None:
        bar.stop()
    return status


# --------------------------------------------------------------------------- lint

def cmd_lint(args) -> int:
    from nctrans import linting as _lint
    from nctrans.linting import config as _config
    _check_dialect(args.from_)
    if args.target:
        _check_dialect(args.target)
    try:
        cfg = _config.discover(args.config)
    except _config.ConfigError as e:
        raise UsageError(str(e)) from None
    machine_path = args.machine or (cfg.machine_path() if cfg else None)
    machine = pipeline.load_machine(machine_path, args.from_) if machine_path else None
    selection = _lint.Selection(
        _lint.Selection.parse(args.select) or _lint.Selection.parse(cfg.select if cfg else ()),
        _lint.Selection.parse(cfg.ignore if cfg else ()) + _lint.Selection.parse(args.ignore))
    fail_on = args.fail_on or (cfg.fail_on if cfg else None) or "error"
    files = list(pipeline.iter_inputs(args.paths))
    if not files:
        _err("no NC files found in " + " ".join(args.paths))
        sys.stdout.write(_output.render(args.format, [], 0) if args.format != "text" else "")
        return EXIT_OK
    if _source.STDIN in files and files.count(_source.STDIN) > 1:
        raise UsageError("'-' (stdin) can be given once")
    all_diags: list[Diagnostic] = []
    status = EXIT_OK
    bar = _progress(len(files), "lint")
    done = 0
    try:
        for f in files:
            try:
                diags = api.lint(_cli_source(f), args.from_, machine, target=args.target,
                                 default_dialect=cfg.dialect_for(f) if cfg else None)
                done += 1
            except (api.NCError, pipeline.PipelineError) as e:
                _err(str(e))
                status = EXIT_USAGE
                continue
            except Exception as e:  # a bug on one file must not lose the report for the others
                _internal(f" on {f}", e)
                status = EXIT_USAGE
                continue
            finally:
                if bar is not None:
                    bar.advance(bar.task_ids[0])
            extra = cfg.ignored_for(f) if cfg else []
            all_diags.extend(d for d in diags if selection.keeps(d.rule, extra))
    finally:
        if bar is not None:
            bar.stop()
    all_diags = list(once_each(all_diags))     # a macro file linted with its caller: once
    if args.format == "text":
        _print_text_diags(all_diags, sys.stdout)
    else:
        sys.stdout.write(_output.render(args.format, all_diags, done))
        sys.stdout.flush()
    if status == EXIT_OK and _at_or_above(all_diags, fail_on):
        status = EXIT_DIAGNOSTICS
    return status


# --------------------------------------------------------------------------- toolpath

def cmd_toolpath(args) -> int:
    _check_dialect(args.from_)
    # a structured program is only run here: compact (its plain stretches as spans of the text)
    ld = pipeline.load(args.src, args.from_, stream=True, compact=True)
    machine = pipeline.load_machine(args.machine, ld.dialect)
    if ld.program is None:
        _print_text_diags(ld.diagnostics, sys.stderr)
        return EXIT_DIAGNOSTICS
    api.use_profile(ld, args.profile)
    jsonl = not args.summary and args.format != "csv"
    records = pipeline.toolpath_of(ld, machine, fast_sink="jsonl" if jsonl else None)
    from nctrans import toolpath_io
    out = sys.stdout
    if args.summary:
        summ = toolpath_io.Summary(machine)
        for r in records:
            summ.add(r)
        _print_text_diags(ld.diagnostics, sys.stderr)
        out.write(summ.format(len(ld.diagnostics)))
    else:
        writer = toolpath_io.write_csv if args.format == "csv" else toolpath_io.write_jsonl
        writer(records, out)
        out.flush()
        _print_text_diags(ld.diagnostics, sys.stderr)
    return EXIT_DIAGNOSTICS if _at_or_above(ld.diagnostics, args.fail_on) else EXIT_OK


# --------------------------------------------------------------------------- check

def cmd_check(args) -> int:
    """Findings (and the program's own errors) as diagnostics, then the cycle time per file."""
    import json

    from nctrans import check as _check
    from nctrans.interp.unmodelled import not_analysed_rules
    _check_dialect(args.from_)
    base_machine = pipeline.load_machine(args.machine, args.from_) if args.machine else None
    files = list(pipeline.iter_inputs(args.paths))
    if not files:
        raise UsageError("no NC files found in " + " ".join(args.paths))
    if files.count(_source.STDIN) > 1:
        raise UsageError("'-' (stdin) can be given once")
    all_diags: list[Diagnostic] = []
    times: dict[str, dict] = {}
    findings: list[dict] = []
    text_times: list[str] = []
    status = EXIT_OK
    for f in files:
        try:
            ld = pipeline.load(f, args.from_, stream=True)
            m = _check.with_extra_solids(base_machine or pipeline.load_machine(None, ld.dialect),
                                         args.fixture or [], args.stock)
            diags, result = _check.check_loaded(ld, m)
        except pipeline.PipelineError as e:
            _err(str(e))
            status = EXIT_USAGE
            continue
        all_diags.extend(d for d in diags if d.rule.startswith("NC3") or d.severity == "error"
                         or d.rule in not_analysed_rules())
        if result is not None:
            times[ld.label] = result.cycle.to_dict()
            findings.extend(x.to_dict() for x in result.findings)
            text_times.append(f"{ld.label}: {result.moves} moves checked on {m.name!r}; "
                              f"estimated cycle time\n{result.cycle.report()}")
    if args.format == "text":
        _print_text_diags(all_diags, sys.stdout)
        sys.stdout.write("".join(text_times))
    elif args.format == "json":
        doc = json.loads(_output.render("json", all_diags, len(times)))
        doc["findings"] = findings          # with position and amount, for plots and scripts
        doc["cycle_time"] = times
        sys.stdout.write(json.dumps(doc, indent=2) + "\n")
    else:
        sys.stdout.write(_output.render(args.format, all_diags, len(times)))
        sys.stderr.write("".join(text_times))
    sys.stdout.flush()
    if status == EXIT_OK and _at_or_above(all_diags, args.fail_on):
        status = EXIT_DIAGNOSTICS
    return status


# --------------------------------------------------------------------------- equiv

def cmd_equiv(args) -> int:
    if args.a == _source.STDIN and args.b == _source.STDIN:
        raise UsageError("only one of A and B can be '-' (stdin)")
    machine = pipeline.load_machine(args.machine) if args.machine else None
    tol = api.DEFAULT_TOL if args.tol is None else args.tol
    try:
        result = api.equiv(_cli_source(args.a), _cli_source(args.b), tol=tol, read_a=args.from_a,
                           read_b=args.from_b, machine=machine, profile=args.profile,
                           profile_b=args.profile_b)
    except api.NCInputError as e:
        raise UsageError(str(e).replace("tol must", "--tol must")) from None
    _print_text_diags(result.diagnostics, sys.stderr)
    if not result.equivalent and result.difference is None:
        _err("cannot compare: an input did not parse")
        return EXIT_DIAGNOSTICS
    if not result:
        print(f"different: {result.message}")
        return EXIT_DIAGNOSTICS
    print(result.message)
    return EXIT_DIAGNOSTICS if _at_or_above(result.diagnostics, "error") else EXIT_OK


# --------------------------------------------------------------------------- backplot

def _plot_input(path: str, dialect: Optional[str], machine_path: Optional[str]):
    """(loaded file, machine, toolpath records) of one backplot input."""
    _check_dialect(dialect)
    ld = pipeline.load(path, dialect, stream=True)
    machine = pipeline.load_machine(machine_path, ld.dialect)
    records = list(pipeline.toolpath_of(ld, machine))   # a finished run completes ld.diagnostics
    return ld, machine, records


def _machine_check(records, machine) -> list:
    """`backplot --check`: the machine check's findings (with their positions) over the records."""
    from nctrans import check as _check
    from nctrans.machine import MachineError
    try:
        return _check.check_records(records, machine).findings
    except MachineError as e:
        raise UsageError(str(e)) from None


def cmd_backplot(args) -> int:
    from nctrans import backplot
    fmt = backplot.format_for(args.output)
    if fmt is None:
        raise UsageError(f"-o {args.output}: the ending must be one of {', '.join(backplot.FORMATS)}")
    out = Path(args.output)
    if out.is_dir():
        raise UsageError(f"{out}: is a directory")
    for src in [args.src] + ([args.compare] if args.compare else []):
        if src != _source.STDIN and set(_file_keys(out)) & set(_file_keys(Path(src))):
            raise UsageError(f"refusing to overwrite the input {src} with the output {out}")
    if args.tol is not None and not args.tol > 0:
        raise UsageError("--tol must be a positive number of mm")
    ld, machine, records = _plot_input(args.src, args.from_, args.machine)
    status = EXIT_OK
    diags = list(ld.diagnostics)
    if ld.program is None:
        _print_text_diags(diags, sys.stderr)
        _err(f"{ld.label}: not plotted (errors above)")
        return EXIT_DIAGNOSTICS
    plotted = list(diags)       # lint findings, then the machine check's (which carry positions)
    if args.check:
        found = _machine_check(records, machine)
        diags += [f.to_diagnostic() for f in found]
        plotted += [f.to_dict() for f in found]
    scene = backplot.build_scene(records, ld.label, plotted)
    diags += backplot.left_out_diagnostics(scene)
    sources = {ld.label: ld.source.text}
    comparison = None
    if args.compare:
        from nctrans.equivalence import DEFAULT_TOL
        from nctrans.backplot.compare import compare_scenes
        lb, _mb, records_b = _plot_input(args.compare, args.from_b, args.machine)
        diags += lb.diagnostics
        if lb.program is None:
            _print_text_diags(diags, sys.stderr)
            _err(f"{lb.label}: not plotted (errors above)")
            return EXIT_DIAGNOSTICS
        scene_b = backplot.build_scene(records_b, lb.label, lb.diagnostics)
        diags += backplot.left_out_diagnostics(scene_b)
        sources.setdefault(lb.label, lb.source.text)
        comparison = compare_scenes(scene, scene_b, records, records_b, args.tol or DEFAULT_TOL)
    _print_text_diags(diags, sys.stderr)
    if scene.empty and (comparison is None or comparison.b.empty):
        _err(f"{ld.label}: the toolpath has no moves: nothing to plot")
        return EXIT_DIAGNOSTICS
    for sc in [scene] + ([comparison.b] if comparison else []):
        for f in sc.files():
            if f not in sources:
                try:
                    sources[f] = _source.read_source(f).text
                except _source.SourceError:
                    pass
        for w in sc.warnings:
            _err(f"{sc.label}: note: {w}")
    try:
        data = backplot.render(fmt, scene, view=args.view or scene.default_view(), comparison=comparison,
                               machine=machine,
                               sources=sources)
    except backplot.BackplotError as e:
        raise UsageError(str(e)) from None
    try:
        write_atomic(out, data)
    except OSError as e:
        _err(f"{out}: cannot write: {e.strerror or e}")
        return EXIT_USAGE
    moves = len(scene.moves) + (len(comparison.b.moves) if comparison else 0)
    print(f"wrote {out} ({fmt}, {moves} moves)")
    if comparison is not None:
        print("equivalent" if comparison.equivalent else f"different: {comparison.marks[0].message}")
        if not comparison.equivalent:
            status = EXIT_DIAGNOSTICS
    if _at_or_above(diags, "error"):
        status = EXIT_DIAGNOSTICS
    return status


# --------------------------------------------------------------------------- detect, rules, stubs

def cmd_detect(args) -> int:
    status = EXIT_OK
    for f in args.files:
        label = _source.label_for(f)
        try:
            src = _source.read_head(f, pipeline.DETECT_HEAD)     # the head tells the dialect
        except _source.SourceError as e:
            _err(str(e))
            status = EXIT_USAGE
            continue
        if not src.ok:
            _print_text_diags(src.diagnostics, sys.stderr)
            status = max(status, EXIT_DIAGNOSTICS)
            continue
        from nctrans import detection as _detect
        g = _detect.detect(src.text, None if f == _source.STDIN else f)
        if g.ambiguous:
            print(f"{label}: ambiguous ({g.describe()}): use --from DIALECT")
            status = EXIT_USAGE
        else:
            print(f"{label}: {g.dialect} (confidence {g.confidence:.2f})")
    return status


def cmd_rules(args) -> int:
    from nctrans import catalogue as _catalogue
    cat = _catalogue.load()
    if args.rule:
        r = cat.get(args.rule)
        if r is None:
            raise UsageError(f"no rule {args.rule!r} (`nctrans rules` lists them)")
        print(_catalogue.format_rule(r))
    else:
        print(_catalogue.format_catalogue(cat))
    return EXIT_OK


def cmd_not_implemented(args) -> int:
    print(f"nctrans {args.command}: not implemented yet (issue pending)", file=sys.stderr)
    return EXIT_USAGE


# --------------------------------------------------------------------------- parser

def _add_search_path(p: argparse.ArgumentParser) -> None:
    p.add_argument("--search-path", action="append", default=[], metavar="DIR",
                   help="directory searched for called subprograms and definition files after the "
                        "source's own directory (repeatable; also NCTRANS_PATH)")


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="nctrans",
                                 description="Transpiler and static analyzer between CNC part-program dialects.")
    ap.add_argument("--version", action="version", version=f"nctrans {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser("convert", help="translate programs into another dialect")
    p.add_argument("src", nargs="+", metavar="SRC", help="source files ('-' = stdin)")
    p.add_argument("--to", required=True, metavar="DIALECT", help="target dialect")
    p.add_argument("--from", dest="from_", metavar="DIALECT", help="source dialect (detected when omitted)")
    p.add_argument("-o", dest="output", metavar="OUT", help="output file for a single source ('-' = stdout)")
    p.add_argument("--out-dir", metavar="DIR", help="directory for the outputs (one per source)")
    p.add_argument("--overwrite", action="store_true",
                   help="with --out-dir: replace files that exist there (refused otherwise)")
    p.add_argument("--strict", action="store_true", help="turn every lowering (NC401) into an error")
    p.add_argument("--flatten", action="store_true", help="emit plain motion only (no macros, loops, calls, cycles)")
    p.add_argument("--machine", metavar="MACHINE.toml", help="machine for --flatten (offsets, tools)")
    p.add_argument("--profile", metavar="NAME", help="control of the source's family (profiles of its rules table); "
                   "detected from the header comments when omitted; a profile of the target's table names the "
                   "control the output is written for (ISO milling: linuxcnc)")
    _add_search_path(p)
    p.set_defaults(func=cmd_convert)

    p = sub.add_parser("lint", help="report diagnostics")
    p.add_argument("paths", nargs="+", metavar="PATH", help="files or directories (recursed); '-' = stdin")
    p.add_argument("--from", dest="from_", metavar="DIALECT")
    p.add_argument("--format", choices=_output.FORMATS, default="text")
    p.add_argument("--machine", metavar="MACHINE.toml")
    p.add_argument("--select", action="append", metavar="RULES", help="only these rules (prefixes, comma-separated)")
    p.add_argument("--ignore", action="append", metavar="RULES", help="drop these rules (prefixes, comma-separated)")
    p.add_argument("--fail-on", choices=("error", "warning", "info"), default=None,
                   help="lowest severity that makes the exit code 1 (default error)")
    p.add_argument("--target", metavar="DIALECT",
                   help="also report what converting to DIALECT would lower or refuse (NC4xx)")
    p.add_argument("--config", metavar="FILE",
                   help="project configuration (default: nctrans.toml or pyproject.toml [tool.nctrans] "
                        "found from the working directory up)")
    _add_search_path(p)
    p.set_defaults(func=cmd_lint)

    p = sub.add_parser("check", help="check a program against a machine: limits, collisions, cycle time")
    p.add_argument("paths", nargs="+", metavar="PATH", help="files or directories (recursed); '-' = stdin")
    p.add_argument("--from", dest="from_", metavar="DIALECT")
    p.add_argument("--machine", metavar="MACHINE.toml", help="machine model (default: the built-in machine)")
    p.add_argument("--fixture", action="append", metavar="F.stl",
                   help="a fixture mesh in machine coordinates (STL/OBJ/PLY; repeatable)")
    p.add_argument("--stock", metavar="S.stl", help="the stock as a mesh in machine coordinates")
    p.add_argument("--format", choices=_output.FORMATS, default="text")
    p.add_argument("--fail-on", choices=("error", "warning", "info"), default="warning",
                   help="exit 1 on findings at or above this severity (default: warning)")
    _add_search_path(p)
    p.set_defaults(func=cmd_check)

    p = sub.add_parser("toolpath", help="print the canonical toolpath")
    p.add_argument("src", metavar="SRC")
    p.add_argument("--from", dest="from_", metavar="DIALECT")
    p.add_argument("--machine", metavar="MACHINE.toml")
    p.add_argument("--format", choices=("jsonl", "csv"), default="jsonl")
    p.add_argument("--summary", action="store_true",
                   help="print a short summary (counts, lengths, bounding box, tools, cycle time) instead")
    p.add_argument("--profile", metavar="NAME", help="control of the source's family that runs it (profiles of "
                   "its rules table, e.g. linuxcnc); detected from the header comments when omitted")
    p.add_argument("--fail-on", choices=("error", "warning", "info"), default="error",
                   help="exit 1 when a diagnostic at or above this severity was reported")
    _add_search_path(p)
    p.set_defaults(func=cmd_toolpath)

    p = sub.add_parser("equiv", help="compare two programs' toolpaths")
    p.add_argument("a", metavar="A")
    p.add_argument("b", metavar="B")
    p.add_argument("--from-a", metavar="DIALECT")
    p.add_argument("--from-b", metavar="DIALECT")
    p.add_argument("--machine", metavar="MACHINE.toml")
    p.add_argument("--tol", type=float, default=None, metavar="MM",
                   help="tolerance in mm (default 0.001)")
    p.add_argument("--profile", metavar="NAME", help="control of A's family that runs it (profiles of its "
                   "rules table, e.g. linuxcnc), and B's too where B's table names it; detected from the "
                   "header comments when omitted")
    p.add_argument("--profile-b", metavar="NAME", help="control of B's family that runs it (default: "
                   "--profile where B's table names it, else detected)")
    _add_search_path(p)
    p.set_defaults(func=cmd_equiv)

    p = sub.add_parser("backplot", help="plot the toolpath (svg, png, glb or an html viewer)")
    p.add_argument("src", metavar="SRC", help="source file ('-' = stdin)")
    p.add_argument("-o", dest="output", required=True, metavar="OUT",
                   help="output file; the format is its ending: .svg .png .glb .html")
    p.add_argument("--from", dest="from_", metavar="DIALECT")
    p.add_argument("--view", choices=("top", "front", "side", "iso"), default=None,
                   help="2D view for svg/png, first view of the html viewer (default top; front "
                        "when nothing moves in Y, as on a lathe)")
    p.add_argument("--machine", metavar="MACHINE.toml", help="machine (offsets, tools; stock and fixtures in glb)")
    p.add_argument("--check", action="store_true",
                   help="run the machine check (as `nctrans check`) and mark its findings on the plot")
    p.add_argument("--compare", metavar="B", help="overlay a second program and mark where the toolpaths differ")
    p.add_argument("--from-b", metavar="DIALECT", help="dialect of the --compare program")
    p.add_argument("--tol", type=float, default=None, metavar="MM", help="--compare tolerance in mm (default 0.001)")
    _add_search_path(p)
    p.set_defaults(func=cmd_backplot)

    p = sub.add_parser("detect", help="guess the dialect of files")
    p.add_argument("files", nargs="+", metavar="FILE")
    p.set_defaults(func=cmd_detect)

    p = sub.add_parser("rules", help="the lint-rule catalogue, or one rule's documentation")
    p.add_argument("rule", nargs="?", metavar="RULE")
    p.set_defaults(func=cmd_rules)

    for name in NOT_IMPLEMENTED:
        p = sub.add_parser(name, help="(not implemented yet)", add_help=False)
        p.add_argument("rest", nargs=argparse.REMAINDER)
        p.set_defaults(func=cmd_not_implemented)
    return ap


def _main(argv: Optional[list[str]]) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not args.command:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    for d in getattr(args, "search_path", []):
        if not os.path.isdir(d):
            _err(f"--search-path {d}: not a directory")
            return EXIT_USAGE
    pipeline.SEARCH_PATHS[:] = getattr(args, "search_path", [])
    from nctrans.limits import environment_errors
    for problem in environment_errors():
        _err(problem)
        return EXIT_USAGE
    try:
        return args.func(args)
    except (UsageError, pipeline.PipelineError, api.NCError) as e:
        _err(str(e))
        return EXIT_USAGE


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so the same unwinding removes temporary output files."""


def _on_sigterm(signum, frame) -> None:
    raise _Terminated()


def main(argv: Optional[list[str]] = None) -> int:
    """Entry point: never lets a traceback out (unless NCTRANS_DEBUG=1)."""
    import signal
    import threading
    if argv is None:
        # Run as the `nctrans` command: what importing made (classes, tables, patterns) lives until
        # the process ends; frozen, no garbage collection walks it again (~10 ms of a run).
        import gc
        gc.freeze()
        # a command reads at most two whole programs it keeps to the end (equiv); more (lint DIR)
        # are read one after another and must be freed
        pipeline.FREEZE_BUDGET = 2
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        return _main(argv)
    except _Terminated:
        _err("terminated")
        return 128 + 15
    except KeyboardInterrupt:
        _err("interrupted")
        return EXIT_USAGE
    except BrokenPipeError:
        # the reader went away (| head): stop quietly; keep Python from complaining at exit
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError):
            pass
        return EXIT_DIAGNOSTICS
    except SystemExit:
        raise
    except Exception as e:
        _internal("", e)
        return EXIT_USAGE
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":
    sys.exit(main())
