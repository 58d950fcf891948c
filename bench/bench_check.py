"""Speed and memory of `nctrans check` on the largest ISO milling corpus program (`make bench`).

The machine: the set-up the program's header describes (a 10-inch piece, the 3/4-inch end mill
with its holder as two cylinders), four clamps and a vise jaw (a mesh of a few thousand
triangles) beside the part, and the piece as stock. Three runs, each the streamed parse + interpreter the CLI uses: the toolpath alone
(records drained), the check with limits and cycle time only, and the full check (also
collisions and the stock Z-map). Moves/s = motion records / seconds, best of --repeat.
Memory is measured on the command as a user runs it: `nctrans check FILE --machine M.toml` in a
subprocess, its peak resident set (os.wait4), for a 30-line head of the program (what the
imports, the machine and its meshes cost), the program, and the program 10x over, each with the
limits-only and the full machine. Records stream through and the Z-map is fixed by the stock's
size, so the only part that grows is the program's text, held once (~1 byte per character).
No assertions.
"""
from __future__ import annotations

import argparse
import gc
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))

from bench import CORPUS, read_text, repeated  # noqa: E402

PROGRAM = "mheaton-fusion-adaptive-1001.nc"


def records(text: str, name: str, machine):
    from nctrans import pipeline, source
    ld = pipeline.load_source(source.decode(text.encode(), name), name, "iso-m", stream=True)
    return pipeline.toolpath_of(ld, machine)


def extent(text: str, name: str, machine):
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    n = 0
    for r in records(text, name, machine):
        if r.kind in ("rapid", "linear", "arc"):
            n += 1
            for i, a in enumerate("XYZ"):
                v = r.end.get(a, 0.0)
                lo[i], hi[i] = min(lo[i], v), max(hi[i], v)
    return lo, hi, n


def build_machine(tmp: Path, text: str, name: str):
    """The set-up the program's header describes: a 10-inch square piece, Z0 on its top, XY0 in its
    centre, a 3/4-inch end mill with 3 inches of flute; G54 puts the part 300 mm below home."""
    import trimesh

    from nctrans import machine as m
    head = ('[offsets.G54]\nX = 0.0\nY = 0.0\nZ = -300.0\n'
            '[axes.X]\nmin = -400.0\nmax = 400.0\nmax_feed = 10000.0\nrapid = 30000.0\naccel = 2000.0\n'
            '[axes.Y]\nmin = -300.0\nmax = 300.0\nmax_feed = 10000.0\nrapid = 30000.0\naccel = 2000.0\n'
            '[axes.Z]\nmin = -500.0\nmax = 0.0\nmax_feed = 10000.0\nrapid = 30000.0\naccel = 2000.0\n')
    tools = "".join(f"[[tools]]\nnumber = {n}\nlength = 120.0\nradius = 9.525\ncutting_length = 76.2\n"
                    f"holder = [{{ radius = 16.0, length = 20.0 }}, {{ radius = 25.0, length = 40.0 }}]\n"
                    for n in range(0, 100))
    (tmp / "tools.toml").write_text(head + tools)
    limits_only = m.load(tmp / "tools.toml")
    lo, hi, _ = extent(text, name, limits_only)
    # toolpath extents are gauge-line positions in machine coordinates: back to the part's frame
    lo = [lo[0], lo[1], lo[2] + 300.0 - 120.0]
    hi = [hi[0], hi[1], hi[2] + 300.0 - 120.0]
    fixtures = ""
    # four clamps at the corners, 5 mm outside what the holder reaches, and a vise jaw (a mesh of
    # a few thousand triangles) along the front, all placed in G54
    reach = 25.0 / math.cos(math.pi / 24) + 5.0
    for i, (x, y) in enumerate([(lo[0] - reach - 20, lo[1] - reach - 20), (hi[0] + reach, lo[1] - reach - 20),
                                (lo[0] - reach - 20, hi[1] + reach), (hi[0] + reach, hi[1] + reach)]):
        fixtures += (f'[[fixtures]]\nname = "clamp {i + 1}"\nframe = "G54"\n'
                     f"box = {{ min = [{x}, {y}, -100.0], max = [{x + 20}, {y + 20}, -10.0] }}\n")
    jaw = trimesh.creation.cylinder(radius=8.0, height=hi[0] - lo[0] + 40, sections=400)
    jaw.apply_transform(trimesh.transformations.rotation_matrix(math.pi / 2, [0, 1, 0]))
    jaw.apply_translation([(lo[0] + hi[0]) / 2, lo[1] - reach - 8.0, -60.0])
    jaw = jaw.subdivide()
    jaw.export(tmp / "jaw.stl")
    fixtures += '[[fixtures]]\nname = "vise jaw"\nframe = "G54"\nmesh = "jaw.stl"\n'
    stock = '[stock]\nframe = "G54"\nbox = { min = [-127.0, -127.0, -80.0], max = [127.0, 127.0, 0.0] }\n'
    (tmp / "full.toml").write_text(head + tools + fixtures + stock)
    return limits_only, m.load(tmp / "full.toml"), len(jaw.faces)


def drain(text, name, machine) -> int:
    n = 0
    for r in records(text, name, machine):
        n += r.kind in ("rapid", "linear", "arc")
    return n


def run_check(text, name, machine):
    from nctrans.check import MachineCheck
    mc = MachineCheck(machine)
    for r in records(text, name, machine):
        mc.add(r)
    return mc.finish()


def best(fn, repeat: int) -> float:
    out = math.inf
    for _ in range(repeat):
        gc.collect()
        t = time.perf_counter()
        fn()
        out = min(out, time.perf_counter() - t)
    return out


# A forked child's peak RSS counts the parent it was forked from until exec (Linux keeps
# ru_maxrss across exec), and this process holds trimesh and the meshes: a small fresh Python
# starts the command and reports that child's peak alone.
_LAUNCH = ("import os, subprocess, sys, time\n"
           "t = time.perf_counter()\n"
           "p = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)\n"
           "_, status, usage = os.wait4(p.pid, 0)\n"
           "print(usage.ru_maxrss / 1024, time.perf_counter() - t, os.waitstatus_to_exitcode(status))\n")


def peak_rss(cmd: list[str]) -> tuple[float, float, int]:
    """(peak resident MiB, wall seconds, exit code) of one CLI run, as measured by _LAUNCH."""
    out = subprocess.run([sys.executable, "-c", _LAUNCH] + cmd, capture_output=True, text=True, check=True)
    mib, seconds, code = out.stdout.split()
    return float(mib), float(seconds), int(code)


def cli_memory(tmp: Path, text: str) -> list[tuple[str, float, tuple, tuple]]:
    """Rows (program, size MiB, (limits MiB, s, exit), (full MiB, s, exit)) of `nctrans check`."""
    nctrans = [sys.executable, "-m", "nctrans"]
    head = "\n".join(text.splitlines()[:30]) + "\nM30\n"
    rows = []
    for label, body in (("30-line head", head), ("program", text), ("program x10", repeated(text, 10))):
        src = tmp / f"check-{label.replace(' ', '-')}.nc"
        src.write_text(body)
        runs = tuple(peak_rss(nctrans + ["check", str(src), "--from", "iso-m", "--machine", str(tmp / toml)])
                     for toml in ("tools.toml", "full.toml"))
        rows.append((label, src.stat().st_size / 2**20) + runs)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    path = CORPUS / PROGRAM
    if not path.exists():
        print(f"bench_check: {path} not found; skipped")
        return 0
    text = read_text(path)
    with tempfile.TemporaryDirectory() as d:
        limits_only, full, jaw_faces = build_machine(Path(d), text, path.name)
        moves = drain(text, path.name, limits_only)
        res = run_check(text, path.name, full)
        t_tp = best(lambda: drain(text, path.name, full), args.repeat)
        t_lim = best(lambda: run_check(text, path.name, limits_only), args.repeat)
        t_full = best(lambda: run_check(text, path.name, full), args.repeat)
        rows = cli_memory(Path(d), text)
    print(f"\nnctrans check on {PROGRAM} ({len(text.splitlines()):,} lines, {moves:,} moves; "
          f"{len(full.fixtures)} fixtures, one a {jaw_faces:,}-triangle mesh; stock Z-map; best of {args.repeat})")
    print(f"{'run':<34}{'seconds':>9}{'moves/s':>11}")
    for label, t in (("toolpath only (streamed, Python)", t_tp), ("check: limits + cycle time", t_lim),
                     ("check: + collisions + stock", t_full)):
        print(f"{label:<34}{t:>9.2f}{moves / t:>11,.0f}")
    print(f"findings on this set-up: {len(res.findings)}; cycle time {res.cycle.total_s / 60:.1f} min")
    print("\n`nctrans check FILE --machine M.toml` as a user runs it: peak RSS of the process (MiB), wall s")
    print(f"{'input':<16}{'file MiB':>9}{'limits MiB':>12}{'s':>7}{'full MiB':>10}{'s':>7}")
    for label, size, (lm, ls, lrc), (fm, fs, frc) in rows:
        bad = "" if lrc < 2 and frc < 2 else f"  (exit {lrc}/{frc}: failed)"
        print(f"{label:<16}{size:>9.1f}{lm:>12.1f}{ls:>7.2f}{fm:>10.1f}{fs:>7.2f}{bad}")
    (_, _, (l1, _, _), (f1, _, _)), (_, _, (l10, _, _), (f10, _, _)) = rows[1], rows[2]
    print(f"10x / 1x: limits {l10 / l1:.2f}x, full {f10 / f1:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
