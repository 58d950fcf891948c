"""Throughput and memory of lint and toolpath on the largest ISO milling corpus programs (`make bench`).

For each program: lines/s in-process (parse + interpret, and parse + interpret + JSONL serialisation
to a null sink, with the whole IR; then the streamed path the CLI takes: pipeline.load(stream=True)
+ toolpath_io.write_jsonl with the native plain-run kernel, and the same without it, "py strm"),
the CLI end to end (subprocess wall time and CPU time, user + system, output to /dev/null), LinuxCNC
rs274 on the same file in the same run and the CLI/rs274 ratios of both. Then peak memory (tracemalloc)
for one program and for the same program repeated 10x: the full parse holds the IR (it grows with
the text) and the interpreter's peak is measured above it; the streamed parse + run + serialisation
(source text held by the caller) must stay flat. Then lint as users run it (lines/s in-process
and through the CLI) and the per-file start-up of `nctrans lint` on small ISO and Sinumerik programs.
Last, the peak resident memory of the CLI's `convert` (to every target, with and without --flatten)
and `equiv` at 1x and 10x the program, and of the program written as Fagor read back (toolpath,
lint, convert); the same for the program made structured (loops, calls, a drilling cycle between
its CAM stretches), as ISO and as Sinumerik (toolpath, lint, convert, equiv), and the Sinumerik one
with its whole body under G70 converted to ISO (a construct lowered over the CAM runs), and programs
that jump back into their body (the ISO program ending with M99, written as one Sinumerik LOOP or Fagor
$WHILE; the Sinumerik one run twice by a label loop, to ISO): memory must stay flat (10x/1x near 1;
what still grows is the source text each process holds) (`--peaks` runs only that table). Plain-text table; no assertions.
"""
from __future__ import annotations

import argparse
import gc
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
CORPUS = SHARED / "corpus" / "iso-mill"
PROGRAMS = ("mheaton-fusion-adaptive-1001.nc", "camotics-flower_mold.nc", "camotics-bear.nc")
# a small Sinumerik program (26 lines): `lint` on it is nearly all start-up (imports, grammar, tables)
STARTUP_PROGRAM = SHARED / "corpus" / "sinumerik" / "syil-DAILY.MPF"
RS274 = shutil.which("rs274") or "/usr/bin/rs274"
NCTRANS = [str(Path(sys.executable).with_name("nctrans"))]
if not Path(NCTRANS[0]).exists():
    NCTRANS = [sys.executable, "-m", "nctrans.cli"]


class NullSink:
    def write(self, s: str) -> int:
        return len(s)


def read_text(path: Path) -> str:
    from nctrans import source
    return source.decode(path.read_bytes(), path.name).text


def parse(text: str, name: str):
    from nctrans.dialects.base import get
    return get("iso-m").parse(text, name)


def interpret(program, diagnostics: list):
    from nctrans.interp import interpret as run
    return run(program, None, diagnostics=diagnostics)


def lint_in_process(text: str, name: str) -> int:
    """What lint computes: parse diagnostics plus the interpreter's (records are discarded)."""
    res = parse(text, name)
    diags = list(res.diagnostics)
    for _ in interpret(res.program, diags):
        pass
    return len(diags)


def toolpath_in_process(text: str, name: str) -> int:
    """Parse + interpret + one JSON line per record to a null sink."""
    res = parse(text, name)
    sink = NullSink()
    n = 0
    dumps = json.JSONEncoder(separators=(",", ":")).encode
    for rec in interpret(res.program, list(res.diagnostics)):
        sink.write(dumps(rec.to_dict()) + "\n")
        n += 1
    return n


def stream_in_process(text: str, name: str, kernel: bool = True) -> int:
    """What `nctrans toolpath --from iso-m` runs: streamed parse + interpret + jsonl writer, with
    the native plain-run kernel (or, kernel=False, the pure-Python path it specialises)."""
    from nctrans import pipeline, plainrun, source, toolpath_io
    saved = plainrun.native
    if not kernel:
        plainrun.native = None
    try:
        ld = pipeline.load_source(source.decode(text.encode("utf-8"), name), name, "iso-m", stream=True)
        return toolpath_io.write_jsonl(pipeline.toolpath_of(ld, pipeline.load_machine(None, "iso-m"),
                                                            fast_sink="jsonl"), NullSink())
    finally:
        plainrun.native = saved


def stream_peak(text: str, name: str) -> float:
    """Peak MiB of the streamed load + run + jsonl, above the decoded source text."""
    from nctrans import pipeline, source, toolpath_io
    src = source.decode(text.encode("utf-8"), name)
    machine = pipeline.load_machine(None, "iso-m")
    gc.collect()
    tracemalloc.start()
    ld = pipeline.load_source(src, name, "iso-m", stream=True)
    toolpath_io.write_jsonl(pipeline.toolpath_of(ld, machine, fast_sink="jsonl"), NullSink())
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak / 2**20


def best_time(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        gc.collect()
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _children_cpu() -> float:
    """User + system seconds of this process's children that have ended and been waited for."""
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def timed(cmd: list[str], repeat: int) -> tuple[float, float, int]:
    """(best wall time, best CPU time (user + system of the child), exit code); exit 3 stands for a
    crash (traceback on stderr). On a loaded machine the wall time includes waiting for a core; the
    CPU time is the work the command did, so ratios of CPU times stay meaningful there."""
    best, best_cpu, rc = float("inf"), float("inf"), 0
    for _ in range(repeat):
        c0 = _children_cpu()
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        best = min(best, time.perf_counter() - t0)
        best_cpu = min(best_cpu, _children_cpu() - c0)
        rc = 3 if b"Traceback" in proc.stderr else proc.returncode
    return best, best_cpu, rc


def wall(cmd: list[str], repeat: int) -> tuple[float, int]:
    """Best wall time and the exit code (see timed)."""
    t, _cpu, rc = timed(cmd, repeat)
    return t, rc


def rs274_timed(path: Path, repeat: int, tmp: Path) -> tuple[float | None, float | None]:
    """(best wall, best CPU) seconds of LinuxCNC rs274 on the file; None, None without rs274."""
    if not Path(RS274).exists():
        return None, None
    tbl = tmp / "zero.tbl"
    if not tbl.exists():
        tbl.write_text("".join(f"T{n} P{n} Z0 D0 ;\n" for n in range(1, 100)))
    t, cpu, _ = timed([RS274, "-t", str(tbl), "-g", str(path), str(tmp / "rs274.out")], repeat)
    return t, cpu


def rs274_time(path: Path, repeat: int, tmp: Path) -> float | None:
    return rs274_timed(path, repeat, tmp)[0]


def repeated(text: str, times: int) -> str:
    """The program body `times` over, one header and one end, so the interpreter runs it all."""
    end = re.compile(r"^\s*(%|O\d+.*|.*\bM0*(2|30)\b.*)\s*$", re.IGNORECASE)
    body = "\n".join(line for line in text.splitlines() if not end.match(line))
    return "%\n" + "\n".join([body] * times) + "\nM30\n%\n"


# What makes a CAM program structured (bench `--peaks`, second table): a subprogram called
# twice, a G28 and a WHILE loop of peck drilling (G73: Sinumerik and Fagor lower it), then the
# subprogram after M30, so the program is parsed whole (compact for runs, Dialect.parse_compact).
STRUCTURE = ("G40 G80 G90\nM98 P2000 L2\nG28 G91 Z0\nG90\n#1=0\nWHILE[#1LT3]DO1\nG0 X[#1*10] Y0 Z5.\n"
             "G99 G73 X1. Y1. Z-5. R1. Q0.5 F100.\nG80\n#1=#1+1\nEND1\n")


def structured(text: str, times: int) -> str:
    """repeated() with STRUCTURE after the body and the subprogram it calls after M30."""
    body = repeated(text, times).removesuffix("\nM30\n%\n")
    return body + "\n" + STRUCTURE + "M30\nO2000\nG91 G1 X1. F100.\nY1.\nG90\nM99\n%\n"


# The Sinumerik counterpart (bench `--peaks`, third table): a WHILE loop around a drilling cycle, a
# FOR loop calling a subprogram of the same file and an IF, in the middle of the CAM body.
SINUMERIK_STRUCTURE = ("R1=0\nWHILE R1<3\nG0 X=R1*10 Y0 Z5\nCYCLE83(5,0,1,-5,,-2,,1,0.5,0,1,0)\nR1=R1+1\n"
                       "ENDWHILE\nFOR COUNT=1 TO 2\nL2000\nENDFOR\nIF R1>2\nG0 Z20\nENDIF\n")


def structured_sinumerik(text: str) -> str:
    """A Sinumerik program (the CAM program converted) with SINUMERIK_STRUCTURE in the middle of
    its body and the subprogram it calls as a second unit of the file after M30."""
    lines = text.rstrip("\n").split("\n")
    end = max(i for i, line in enumerate(lines) if re.search(r"\bM(30|2)\b", line))
    body = [line for line in lines[:end] if not line.startswith(";")]
    mid = len(body) // 2
    body = body[:mid] + SINUMERIK_STRUCTURE.rstrip("\n").split("\n") + body[mid:]
    return ("%_N_PART_MPF\nDEF INT COUNT\n" + "\n".join(body)
            + "\nM30\n%_N_L2000_SPF\nG91 G1 X1 F100\nY1\nG90\nM17\n")


# A loop of its own (a local counter: nothing outlives the program) after the G70 stretch.
INCH_STRETCH_LOOP = "G71\nCNT=0\nWHILE CNT<2\nG0 X=CNT Y0 Z5\nCNT=CNT+1\nENDWHILE\n"


def sinumerik_inch_stretch(text: str) -> str:
    """The CAM program converted to Sinumerik with the first half of its body under G70 (inch
    lengths, which ISO lacks) and a WHILE loop after it: converting it to ISO lowers the stretch
    from G70 to G71 to plain motion, its CAM runs included, and keeps the loop (before
    nctrans.lower.compact_constructs, only the whole parse could). Its own G700/G710 are left out,
    so the stretch holds half the body."""
    lines = re.sub(r"\bG7[01]0\b", "", text).rstrip("\n").split("\n")
    end = max(i for i, line in enumerate(lines) if re.search(r"\bM(30|2)\b", line))
    body = [line for line in lines[:end] if not line.startswith(";")]
    mid = len(body) // 2
    return ("%_N_PART_MPF\nDEF INT CNT\nG70\n" + "\n".join(body[:mid]) + "\n" + INCH_STRETCH_LOOP
            + "\n".join(body[mid:]) + "\nM30\n")


def peaks(text: str, name: str) -> tuple[float, float]:
    """(peak MiB while parsing, peak MiB above the parsed IR while interpreting + serialising)."""
    gc.collect()
    tracemalloc.start()
    res = parse(text, name)
    parse_peak = tracemalloc.get_traced_memory()[1]
    held = tracemalloc.get_traced_memory()[0]
    tracemalloc.reset_peak()
    sink = NullSink()
    for rec in interpret(res.program, list(res.diagnostics)):
        sink.write(json.dumps(rec.to_dict()))
    interp_peak = tracemalloc.get_traced_memory()[1] - held
    tracemalloc.stop()
    return parse_peak / 2**20, interp_peak / 2**20


# Issue #7 "Done when": the targets `targets()` prints its measurements against.
TARGET_ISO_X10 = 0.35          # ISO program x10: CLI toolpath time / rs274 on the same file
TARGET_SINUMERIK = 2.0         # the program as Sinumerik: CLI toolpath / rs274 on the ISO original
TARGET_SINUMERIK_MEMORY = 1.5  # Sinumerik x10 / x1: peak resident memory of the CLI toolpath
# The project standard "memory flat in program size" for Fagor sources too (x10 / x1 peak RSS).
TARGET_FAGOR_MEMORY = 1.5


def conditions() -> str:
    """What the machine was doing: wall times on a shared machine include waiting for a core."""
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    return f"{os.cpu_count()} cores, load average {load}"


def targets(base: Path, repeat: int, tmp: Path) -> None:
    """The issue #7 targets in one run, side by side with rs274: the ISO program repeated ten
    times; the same program written as Sinumerik (nctrans convert --to sinumerik: `;` comments,
    G74 homing, tool length from D) against rs274 on the ISO original; the Sinumerik program's
    peak memory at 10x against 1x; the same for the program written as Fagor (nctrans convert
    --to fagor: `;` comments, D offsets), its time against rs274 on the ISO original and its
    memory at 10x against 1x; and the per-file start-up of `lint` on a small Sinumerik file.
    Times are shown as wall and CPU (user + system of the process); a target is judged on the CPU
    ratio, which waiting for a core on a loaded machine does not inflate."""
    text = read_text(base)
    iso = {1: base, 10: tmp / "target-x10.nc"}
    iso[10].write_text(repeated(text, 10))
    sin, fag = {}, {}
    for times, path in iso.items():
        sin[times] = tmp / f"target-x{times}.mpf"
        fag[times] = tmp / f"target-x{times}-fagor.nc"
        for dialect, out in (("sinumerik", sin[times]), ("fagor", fag[times])):
            subprocess.run(NCTRANS + ["convert", str(path), "--from", "iso-m", "--to", dialect, "-o",
                                      str(out), "--overwrite"], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
    rows = []

    def toolpath(path: Path, dialect: str):
        t, cpu, rc = timed(NCTRANS + ["toolpath", str(path), "--from", dialect, "--format", "jsonl"], repeat)
        return (t, cpu) if rc < 2 else (None, None)

    def ratio(a, b):
        return a / b if a is not None and b else None

    def timed_row(label, ours, theirs, target):
        """A row of wall times, then the same measure as CPU times (the one the target judges)."""
        rows.append((label + " wall s", ours[0], theirs[0], ratio(ours[0], theirs[0]), None))
        rows.append((label + " CPU s", ours[1], theirs[1], ratio(ours[1], theirs[1]), target))

    timed_row(f"ISO x10 ({iso[10].read_text().count(chr(10))} lines): toolpath", toolpath(iso[10], "iso-m"),
              rs274_timed(iso[10], repeat, tmp), TARGET_ISO_X10)
    rs1 = rs274_timed(base, repeat, tmp)
    timed_row("ISO x1: toolpath", toolpath(base, "iso-m"), rs1, None)
    if sin[1].exists():
        timed_row("Sinumerik x1: toolpath (rs274: ISO x1)", toolpath(sin[1], "sinumerik"), rs1, TARGET_SINUMERIK)
    if fag[1].exists():
        timed_row("Fagor x1: toolpath (rs274: ISO x1)", toolpath(fag[1], "fagor"), rs1, None)
    for label, files, dialect, target in (("Sinumerik", sin, "sinumerik", TARGET_SINUMERIK_MEMORY),
                                          ("Fagor", fag, "fagor", TARGET_FAGOR_MEMORY)):
        mem = {}
        for times, path in files.items():
            if path.exists():
                peaks_ = [peak_rss(NCTRANS + ["toolpath", str(path), "--from", dialect, "--format", "jsonl",
                                              ])[0] for _ in range(max(1, min(repeat, 3)))]
                mem[times] = min(peaks_)
        if len(mem) == 2:
            rows.append((f"{label} toolpath max RSS MiB: x10 vs x1", mem[10], mem[1], ratio(mem[10], mem[1]),
                         target))
    small = STARTUP_PROGRAM
    if small.exists():
        t, cpu, rc = timed(NCTRANS + ["lint", str(small)], repeat)
        floor, floor_cpu, _ = timed([sys.executable, "-c", "pass"], repeat)
        label = f"lint start-up, {small.name} ({read_text(small).count(chr(10))} lines)"
        rows.append((label + " wall s (vs python -c pass)", t if rc < 2 else None, floor, None, None))
        rows.append((label + " CPU s", cpu if rc < 2 else None, floor_cpu, None, None))
    print(f"issue #7 targets on {base.name} ({conditions()}; best of {repeat}; "
          "a target is judged on CPU time, user + system of the process)")
    print(f"{'measure':58} {'nctrans':>8} {'rs274':>8} {'ratio':>6} {'target':>7} {'met':>4}")
    for label, ours, theirs, r, target in rows:
        met = "" if target is None or r is None else ("yes" if r <= target else "NO")
        print(f"{label[:58]:58} {fmt(ours, '.3f'):>8} {fmt(theirs, '.3f'):>8} {fmt(r, '.2f'):>6} "
              f"{'' if target is None else '<=' + format(target, 'g'):>7} {met:>4}")
    print()


def fmt(v, spec=",.0f"):
    return "n/a" if v is None else format(v, spec)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs per measurement; the best is shown")
    ap.add_argument("--peak", nargs=2, metavar=("PROGRAM", "TIMES"), help=argparse.SUPPRESS)
    ap.add_argument("--targets", action="store_true", help="only the issue #7 targets (first program)")
    ap.add_argument("--peaks", action="store_true", help="only the CLI peak memory of convert and equiv "
                    "at 1x and 10x (first program)")
    ap.add_argument("programs", nargs="*", help="programs (default: the three largest iso-mill ones)")
    args = ap.parse_args(argv)
    if args.peak:                                   # child process of the memory measurement
        path, times = Path(args.peak[0]), int(args.peak[1])
        text = read_text(path)
        peaks(text, path.name)                      # warm-up: one-time caches are not the program's
        stream_peak(text, path.name)
        t = repeated(text, times) if times > 1 else text
        p, i = peaks(t, path.name)
        sp = stream_peak(t, path.name)
        print(t.count("\n"), p, i, sp)
        return 0
    paths = [Path(p) for p in args.programs] or [CORPUS / p for p in PROGRAMS]
    paths = [p for p in paths if p.exists()]
    if not paths:
        print(f"no programs found (corpus expected at {CORPUS})")
        return 0
    print(f"python {sys.version.split()[0]}, rs274 {'found' if Path(RS274).exists() else 'missing'}, "
          f"best of {args.repeat}; lines/s = source lines / seconds; {conditions()}")
    if args.peaks:
        notes: list[str] = []
        with tempfile.TemporaryDirectory() as d:
            cli_peaks(paths[0], Path(d), notes)
        for n in notes:
            print("note:", n)
        return 0
    with tempfile.TemporaryDirectory() as d:
        targets(paths[0], args.repeat, Path(d))
    if args.targets:
        return 0
    head = (f"{'program':34} {'lines':>6} {'records':>8} {'lint l/s':>10} {'toolpath l/s':>12} {'stream l/s':>10} "
            f"{'py strm l/s':>11} "
            f"{'CLI lint s':>10} {'CLI tp s':>9} {'CLI tp l/s':>10} {'rs274 s':>8} {'CLI/rs274':>9} "
            f"{'tp CPU s':>8} {'rs CPU s':>8} {'CPU ratio':>9}")
    print(head)
    print("-" * len(head))
    notes = []
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        for path in paths:
            text = read_text(path)
            lines = text.count("\n") or 1
            records = lint_rate = tp_rate = st_rate = py_rate = None
            try:
                records = toolpath_in_process(text, path.name)
                lint_rate = lines / best_time(lambda: lint_in_process(text, path.name), args.repeat)
                tp_rate = lines / best_time(lambda: toolpath_in_process(text, path.name), args.repeat)
                st_rate = lines / best_time(lambda: stream_in_process(text, path.name), args.repeat)
                py_rate = lines / best_time(lambda: stream_in_process(text, path.name, False), args.repeat)
            except Exception as e:                      # a missing stage: report, keep benchmarking
                notes.append(f"{path.name}: in-process: {type(e).__name__}: {e}")
            cli_lint, rc_l = wall(NCTRANS + ["lint", str(path), "--from", "iso-m"], args.repeat)
            cli_tp, cli_cpu, rc_t = timed(NCTRANS + ["toolpath", str(path), "--from", "iso-m", "--format",
                                                     "jsonl"], args.repeat)
            if rc_t >= 2:
                notes.append(f"{path.name}: CLI toolpath exit {rc_t}")
                cli_tp = cli_cpu = None
            if rc_l >= 2:
                notes.append(f"{path.name}: CLI lint exit {rc_l}")
                cli_lint = None
            rs, rs_cpu = rs274_timed(path, args.repeat, tmp)
            ratio = cli_tp / rs if cli_tp and rs else None
            cpu_ratio = cli_cpu / rs_cpu if cli_cpu and rs_cpu else None
            print(f"{path.name[:34]:34} {lines:>6} {fmt(records):>8} {fmt(lint_rate):>10} {fmt(tp_rate):>12} "
                  f"{fmt(st_rate):>10} {fmt(py_rate):>11} "
                  f"{fmt(cli_lint, '.3f'):>10} {fmt(cli_tp, '.3f'):>9} "
                  f"{fmt(lines / cli_tp if cli_tp else None):>10} {fmt(rs, '.3f'):>8} {fmt(ratio, '.2f'):>9} "
                  f"{fmt(cli_cpu, '.3f'):>8} {fmt(rs_cpu, '.3f'):>8} {fmt(cpu_ratio, '.2f'):>9}")
        print()
        print("peak memory (tracemalloc, MiB; fresh process, after one warm-up run): the full parse holds")
        print("the IR, interpret+serialise is measured above it; streamed = parse+run+jsonl as the CLI does")
        print(f"{'program':40} {'lines':>7} {'parse peak':>11} {'interp peak':>12} {'streamed peak':>14}")
        base = paths[0]
        for times in (1, 10):
            label = base.name + (f" x{times}" if times > 1 else "")
            proc = subprocess.run([sys.executable, __file__, "--peak", str(base), str(times)],
                                  capture_output=True, text=True)
            try:
                lines, p, i, sp = proc.stdout.split()
                print(f"{label[:40]:40} {int(lines):>7} {float(p):>11.1f} {float(i):>12.2f} {float(sp):>14.2f}")
            except ValueError:
                print(f"{label[:40]:40} {'n/a':>7} {'n/a':>11} {'n/a':>12} {'n/a':>14}")
                notes.append(f"memory: {(proc.stderr.strip().splitlines() or ['?'])[-1]}")
        print()
        cli_peaks(paths[0], tmp, notes)
    if STARTUP_PROGRAM.exists():
        t, rc = wall(NCTRANS + ["lint", str(STARTUP_PROGRAM)], args.repeat)
        print()
        print(f"start-up: CLI lint of {STARTUP_PROGRAM.name} ({read_text(STARTUP_PROGRAM).count(chr(10))} lines, "
              f"Sinumerik): {fmt(t, '.3f')} s (exit {rc})")
    lint_table(paths, args.repeat, notes)
    for n in notes:
        print("note:", n)
    return 0


# Small programs for per-file start-up: what pre-commit and editors pay on every file.
STARTUP = (ROOT / "corpus" / "iso-m" / "sample-pocket.nc", ROOT / "corpus" / "sinumerik" / "variables.mpf")


def lint_table(paths: list[Path], repeat: int, notes: list[str]) -> None:
    """Lint as users run it (nctrans.api.lint: parse, interpreter, IR analyses, suppressions):
    lines/s in-process and through the CLI on the largest programs, then per-file start-up."""
    from nctrans import api as _api
    print()
    print("lint (nctrans.api.lint and `nctrans lint`, text output to /dev/null)")
    print(f"{'program':34} {'lines':>6} {'diags':>6} {'lint l/s':>10} {'CLI lint s':>10} {'CLI lint l/s':>12}")
    for path in paths:
        lines = read_text(path).count("\n") or 1
        try:
            n = len(_api.lint(path, "iso-m"))
            rate = lines / best_time(lambda: _api.lint(path, "iso-m"), repeat)
        except Exception as e:
            notes.append(f"{path.name}: api.lint: {type(e).__name__}: {e}")
            n = rate = None
        cli, rc = wall(NCTRANS + ["lint", str(path), "--from", "iso-m"], repeat)
        if rc >= 2:
            notes.append(f"{path.name}: CLI lint exit {rc}")
            cli = None
        print(f"{path.name[:34]:34} {lines:>6} {fmt(n):>6} {fmt(rate):>10} {fmt(cli, '.3f'):>10} "
              f"{fmt(lines / cli if cli else None):>12}")
    print()
    print("per-file start-up: `nctrans lint FILE` wall time on a small program (ms, best of the runs)")
    print(f"{'program':34} {'lines':>6} {'text ms':>8} {'sarif ms':>9}")
    for path in STARTUP:
        if not path.exists():
            continue
        lines = read_text(path).count("\n")
        text_s, _ = wall(NCTRANS + ["lint", str(path)], repeat)
        sarif_s, _ = wall(NCTRANS + ["lint", str(path), "--format", "sarif"], repeat)
        print(f"{path.name[:34]:34} {lines:>6} {fmt(text_s * 1000 if text_s else None):>8} "
              f"{fmt(sarif_s * 1000 if sarif_s else None):>9}")


# A child's peak resident size starts from its parent's at the fork (the kernel counts the shared
# pages up to the exec), so a command started from this process (tens of MiB, nctrans imported)
# would show at least that much. The command is started from this small probe instead (python -S,
# no imports beyond os and resource: a few MiB), which reports the peak of its one child.
_RSS_PROBE = """import os, resource, sys
pid = os.posix_spawnp(sys.argv[1], sys.argv[1:], os.environ,
                      file_actions=[(os.POSIX_SPAWN_OPEN, 1, os.devnull, os.O_WRONLY, 0),
                                    (os.POSIX_SPAWN_OPEN, 2, os.devnull, os.O_WRONLY, 0)])
status = os.waitpid(pid, 0)[1]
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, os.waitstatus_to_exitcode(status))
"""


# Programs that jump back into their main body (`--peaks`, last two tables): converted on the compact
# parse, each written as one structure the target writer may still take back, so its output lines
# go to a temporary file (nctrans.spilled.OutputLines) instead of growing with the program.
def restarting(text: str, times: int) -> str:
    """repeated() ending with M99 instead of M30: a main program that starts again for ever
    (Sinumerik writes its whole body in one LOOP)."""
    return repeated(text, times).replace("\nM30\n%\n", "\nM99\n%\n")


def sinumerik_label_loop(text: str) -> str:
    """The CAM program converted to Sinumerik, its body run twice by a label loop (a jump back
    to TOP: at its start)."""
    lines = text.rstrip("\n").split("\n")
    end = max(i for i, line in enumerate(lines) if re.search(r"\bM(30|2)\b", line))
    body = [line for line in lines[:end] if not line.startswith(";")]
    return ("%_N_PART_MPF\nDEF INT CNT\nCNT=0\nTOP:\n" + "\n".join(body)
            + "\nCNT=CNT+1\nIF CNT<2 GOTOB TOP\nM30\n")


RESTART_PEAK_RUNS = (
    ("convert --to sinumerik (LOOP)", ["convert", "SRC", "--from", "iso-m", "--to", "sinumerik", "-o", "OUT"]),
    ("convert --to fagor ($WHILE)", ["convert", "SRC", "--from", "iso-m", "--to", "fagor", "-o", "OUT"]),
)
LABEL_LOOP_PEAK_RUNS = (
    ("convert --to iso-m (GOTO)", ["convert", "SRC", "--from", "sinumerik", "--to", "iso-m", "-o", "OUT"]),
)


def peak_rss(cmd: list[str]) -> tuple[float, float, int]:
    """(peak resident MiB, wall seconds, exit code) of one CLI run (see _RSS_PROBE)."""
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-S", "-c", _RSS_PROBE, *cmd], capture_output=True, text=True)
    elapsed = time.perf_counter() - t0
    try:
        kib, rc = proc.stdout.split()
        return int(kib) / 1024, elapsed, int(rc)
    except ValueError:
        return float("nan"), elapsed, 3


# (label, command after `nctrans`) of each CLI run whose peak memory `cli_peaks` measures; SRC is
# the ISO program, MPF its conversion to Sinumerik (written by the first row), FAG its conversion
# to Fagor, OUT a scratch output.
PEAK_RUNS = (
    ("convert --to sinumerik", ["convert", "SRC", "--from", "iso-m", "--to", "sinumerik", "-o", "MPF"]),
    ("convert --to iso-m", ["convert", "SRC", "--from", "iso-m", "--to", "iso-m", "-o", "OUT"]),
    ("convert --flatten --to iso-m", ["convert", "SRC", "--from", "iso-m", "--to", "iso-m", "--flatten",
                                      "-o", "OUT"]),
    ("convert --flatten --to sinumerik", ["convert", "SRC", "--from", "iso-m", "--to", "sinumerik",
                                          "--flatten", "-o", "OUT"]),
    # the program's G28 blocks (and Fagor's missing cycles) are lowered to plain motion on their
    # own, streamed (nctrans.lower.stream_constructs)
    ("convert --to fagor", ["convert", "SRC", "--from", "iso-m", "--to", "fagor", "-o", "FAG"]),
    ("convert --flatten --to fagor", ["convert", "SRC", "--from", "iso-m", "--to", "fagor", "--flatten",
                                      "-o", "OUT"]),
    ("convert --to iso-t", ["convert", "SRC", "--from", "iso-m", "--to", "iso-t", "-o", "OUT"]),
    ("convert --flatten --to iso-t", ["convert", "SRC", "--from", "iso-m", "--to", "iso-t", "--flatten",
                                      "-o", "OUT"]),
    # the program as Fagor (FAG, written by the `convert --to fagor` row) read back: streamed
    ("toolpath --from fagor", ["toolpath", "FAG", "--from", "fagor", "--format", "jsonl"]),
    ("lint --from fagor", ["lint", "FAG", "--from", "fagor"]),
    ("convert --from fagor --to iso-m", ["convert", "FAG", "--from", "fagor", "--to", "iso-m", "-o", "OUT"]),
    ("equiv iso-m iso-m", ["equiv", "SRC", "SRC", "--from-a", "iso-m", "--from-b", "iso-m"]),
    ("equiv iso-m sinumerik", ["equiv", "SRC", "MPF", "--from-a", "iso-m", "--from-b", "sinumerik"]),
)
# The runs of the structured Sinumerik program (SRC: structured_sinumerik() of the straight table's
# Sinumerik conversion).
SINUMERIK_PEAK_RUNS = (
    ("toolpath --from sinumerik", ["toolpath", "SRC", "--from", "sinumerik", "--format", "jsonl"]),
    ("lint --from sinumerik", ["lint", "SRC", "--from", "sinumerik"]),
    ("convert --to sinumerik", ["convert", "SRC", "--from", "sinumerik", "--to", "sinumerik", "-o", "OUT"]),
    ("convert --to iso-m", ["convert", "SRC", "--from", "sinumerik", "--to", "iso-m", "-o", "OUT"]),
    ("convert --flatten --to iso-m", ["convert", "SRC", "--from", "sinumerik", "--to", "iso-m", "--flatten",
                                      "-o", "OUT"]),
    ("equiv sinumerik sinumerik", ["equiv", "SRC", "SRC", "--from-a", "sinumerik", "--from-b", "sinumerik"]),
)


# The run of the same program with half its CAM body under Sinumerik G70 (sinumerik_inch_stretch): a
# construct lowered on its own over the runs of plain blocks, once a whole-parse fallback.
INCH_STRETCH_PEAK_RUNS = (
    ("convert --to iso-m (G70 over CAM)", ["convert", "SRC", "--from", "sinumerik", "--to", "iso-m",
                                                "-o", "OUT"]),
)


def cli_peaks(base: Path, tmp: Path, notes: list) -> None:
    """Peak memory (max RSS) of `convert` and `equiv` through the CLI at 1x and 10x the program:
    streamed, they must stay flat (10x/1x near 1; what grows is the source text each process
    holds, 0.6 MB -> 5.7 MB here)."""
    print("CLI peak memory (max RSS of the process, MiB) and wall time at 1x and 10x the program")
    text = read_text(base)
    for kind in ("straight", "structured", "structured sinumerik", "sinumerik inch stretch", "restart",
                 "sinumerik label loop"):
        _peak_table(kind, base, text, tmp, notes)


def _peak_table(kind: str, base: Path, text: str, tmp: Path, notes: list) -> None:
    """cli_peaks of the program as it is (straight) or made structured (structured())."""
    sizes = []
    runs = PEAK_RUNS
    stem, ending = kind.replace(" ", "-"), ".mpf" if "sinumerik" in kind else ".nc"
    for times in (1, 10):
        src = tmp / f"peak-{stem}-x{times}{ending}"
        if kind in ("structured sinumerik", "sinumerik inch stretch", "sinumerik label loop"):
            # the straight table's conversion to Sinumerik (its first row), made structured
            straight = tmp / f"peak-straight-x{times}.mpf"
            if not straight.exists():
                notes.append(f"{kind}: no Sinumerik conversion of the straight program x{times}")
                return
            make, runs = {"structured sinumerik": (structured_sinumerik, SINUMERIK_PEAK_RUNS),
                          "sinumerik inch stretch": (sinumerik_inch_stretch, INCH_STRETCH_PEAK_RUNS),
                          "sinumerik label loop": (sinumerik_label_loop, LABEL_LOOP_PEAK_RUNS)}[kind]
            src.write_text(make(straight.read_text()))
        elif kind == "restart":
            src.write_text(restarting(text, times))
            runs = RESTART_PEAK_RUNS
        elif kind == "structured":
            src.write_text(structured(text, times))
        else:
            src.write_text(repeated(text, times) if times > 1 else text)
        sizes.append(src.stat().st_size / 2**20)
    print(f"{base.name} ({kind}): {sizes[0]:.1f} MB and {sizes[1]:.1f} MB")
    print(f"{'run':34} {'1x MiB':>8} {'10x MiB':>8} {'10x/1x':>7} {'1x s':>7} {'10x s':>7}")
    for label, cmd in runs:
        mem, secs = [], []
        for times in (1, 10):
            names = {"SRC": tmp / f"peak-{stem}-x{times}{ending}", "MPF": tmp / f"peak-{kind}-x{times}.mpf",
                     "FAG": tmp / f"peak-{kind}-x{times}-fagor.nc", "OUT": tmp / f"peak-{kind}-out-x{times}.nc"}
            m, s, rc = peak_rss(NCTRANS + [str(names.get(a, a)) for a in cmd])
            if rc >= 2:
                notes.append(f"{kind} {label} x{times}: exit {rc}")
            mem.append(m)
            secs.append(s)
        print(f"{label:34} {mem[0]:>8.1f} {mem[1]:>8.1f} {mem[1] / mem[0]:>7.2f} {secs[0]:>7.2f} {secs[1]:>7.2f}")


if __name__ == "__main__":
    sys.exit(main())
