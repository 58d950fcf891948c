"""Backplot cost on 100k-move programs (`make bench`): each output format through the CLI (wall time,
peak RSS, file size), then the HTML viewer in headless Chromium (page open, script, frame and
click-to-highlight times) when chromium is installed. Programs: a generated zig-zag pocket (100k
moves, arcs every ninth move) and the 116k-move Sinumerik corpus program dubovikov-konus.mpf.
Plain-text table; no assertions (the tests check behaviour, not speed).
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import browser                                                    # noqa: E402
from test_backplot_viewer import _generated_program, open_viewer  # noqa: E402

KONUS = ROOT.parent / "shared" / "corpus" / "sinumerik" / "dubovikov-konus.mpf"
FORMATS = ("html", "svg", "png", "glb")


def cli(src: Path, out: Path) -> tuple[float, float]:
    """(wall seconds, peak RSS MiB of the child) of one `nctrans backplot`."""
    t = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "nctrans", "backplot", str(src), "-o", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _pid, status, usage = os.wait4(proc.pid, 0)      # this child's own peak, not the children's max
    proc.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - t
    if not out.exists():
        raise SystemExit(f"backplot failed on {src} (exit {proc.returncode})")
    return wall, usage.ru_maxrss / 1024


def main() -> None:
    tmp = Path(tempfile.mkdtemp(prefix="nctrans-bench-backplot-"))
    gen = tmp / "generated-100k.nc"
    _generated_program(gen, 100_000)
    programs = [gen] + ([KONUS] if KONUS.exists() else [])
    print(f"{'program':28} {'format':6} {'wall s':>7} {'peak MiB':>9} {'size MB':>8}")
    for src in programs:
        for fmt in FORMATS:
            out = tmp / f"{src.stem}.{fmt}"
            wall, rss = cli(src, out)
            print(f"{src.name:28} {fmt:6} {wall:7.2f} {rss:9.0f} {out.stat().st_size / 1e6:8.2f}")
    if not browser.CHROMIUM:
        print("chromium not installed: viewer timings skipped")
        return
    b = browser.Browser()
    try:
        print(f"\n{'program':28} {'moves':>7} {'segments':>8} {'open s':>7} {'script ms':>9} "
              f"{'frame ms':>8} {'click ms':>8}")
        for src in programs:
            page, open_s = open_viewer(b, tmp / f"{src.stem}.html", timeout=300)
            n = page.evaluate("ncViewer.programs[0].n")
            segs = page.evaluate("ncViewer.programs[0].segs")
            script = page.evaluate("ncViewer.state.loadMs")
            frame = page.evaluate("ncViewer.timeFrames(20)")
            x, y = page.evaluate(f"ncViewer.screenOfMove(0, {n - 2})")
            t = time.perf_counter()
            page.click(x, y)
            page.wait_for("ncViewer.state.selected !== null", 60)
            click = (time.perf_counter() - t) * 1000
            print(f"{src.name:28} {n:7d} {segs:8d} {open_s:7.2f} {script:9.0f} {frame:8.1f} {click:8.0f}"
                  + (f"  errors: {page.errors}" if page.errors else ""))
            page.close()
    finally:
        b.close()


if __name__ == "__main__":
    main()
