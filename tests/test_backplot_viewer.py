"""The HTML backplot viewer in a real headless Chromium (tests/browser.py, DevTools protocol).

Each page is opened from a file:// URL in a browser started with --disable-background-networking:
it must draw a non-blank plot, print no console error, and a real mouse click on a move must
highlight that move's source line - checked against the toolpath (`nctrans toolpath`), not the
viewer's own data. Load and frame times of the 100k-move programs are printed (`pytest -s`), not
asserted.
"""
from __future__ import annotations

import io
import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "corpus" / "iso-m" / "sample-pocket.nc"
NCTRANS = [sys.executable, "-m", "nctrans"]
MOTION = ("rapid", "linear", "arc")


def backplot(src: Path, out: Path, *extra) -> float:
    t = time.perf_counter()
    r = subprocess.run([*NCTRANS, "backplot", str(src), "-o", str(out), *extra], capture_output=True,
                       text=True, timeout=600)
    assert r.returncode in (0, 1) and out.exists(), r.stderr
    return time.perf_counter() - t


def moves_of(src: Path) -> list[dict]:
    r = subprocess.run([*NCTRANS, "toolpath", str(src)], capture_output=True, text=True, timeout=600)
    return [m for m in map(json.loads, r.stdout.splitlines()) if m["kind"] in MOTION]


def open_viewer(chromium, html: Path, timeout: float = 120):
    page = chromium.new_page()
    t = time.perf_counter()
    page.navigate(html.resolve().as_uri(), timeout)
    page.wait_for("window.ncViewer && window.ncViewer.state.frames > 0", timeout)
    return page, time.perf_counter() - t


def inked_pixels(page) -> int:
    """Non-white pixels in a screenshot of the plot canvas (what a person sees)."""
    from PIL import Image
    rect = page.evaluate("(() => { const r = document.getElementById('canvas').getBoundingClientRect();"
                         " return {x: r.left, y: r.top, width: r.width, height: r.height}; })()")
    img = Image.open(io.BytesIO(page.screenshot(rect))).convert("RGB")
    return sum(n for n, c in img.getcolors(1 << 22) if sum(c) < 3 * 235)


def click_move(page, i: int) -> dict:
    x, y = page.evaluate(f"ncViewer.screenOfMove(0, {i})")
    page.evaluate("ncViewer.state.selected = null")
    page.click(x, y)
    page.wait_for("ncViewer.state.selected !== null", 30)
    return page.evaluate("({sel: ncViewer.state.selected,"
                         " hl: [...document.querySelectorAll('#src .src-line.hl')].map(e => +e.dataset.line)})")


def isolated_move(page, moves: list[dict], need_px: float = 12.0, tries: int = 60) -> int:
    """A move whose screen point stands apart from every move of another source line, so a click
    there can only mean it: of the longest straight moves, the one with the most room around it,
    with the view centred on it and zoomed until that room is need_px."""
    order = sorted((i for i, m in enumerate(moves) if m["kind"] != "arc"),
                   key=lambda i: -sum((moves[i]["end"].get(a, 0) - moves[i]["start"].get(a, 0)) ** 2
                                      for a in "XYZ"))[:tries]
    room = page.evaluate(f"{json.dumps(order)}.map(i => ncViewer.clearance(0, i))")
    best = max(range(len(order)), key=lambda k: room[k])
    assert room[best] > 0, "every candidate move lies on another move"
    i = order[best]
    page.evaluate(f"ncViewer.focusMove(0, {i}, {max(1.0, 2 * need_px / room[best])})")
    assert page.evaluate(f"ncViewer.clearance(0, {i})") >= need_px
    return i


# --------------------------------------------------------------------------- the sample, by hand

def test_sample_viewer_draws_and_links_moves_and_source(chromium, tmp_path):
    html = tmp_path / "sample.html"
    backplot(SAMPLE, html)
    n = len(moves_of(SAMPLE))
    page, _ = open_viewer(chromium, html)
    try:
        assert page.evaluate("ncViewer.programs[0].n") == n
        assert inked_pixels(page) > 500
        # move 8 is N110 G02 (line 14), move 6 is N90 G03 (line 12): see tests/test_backplot.py
        got = click_move(page, 8)
        assert got["sel"]["move"] == 8 and got["sel"]["line"] == 14 and got["hl"] == [14]
        page.evaluate("document.querySelector('#src .src-line[data-line=\"12\"]').click()")
        assert page.evaluate("ncViewer.state.highlight") == [{"program": 0, "moves": [6]}]
        # the slider at 5 shows moves 1..5; the 5th move is N70 on line 10
        page.evaluate("(() => { const s = document.getElementById('slider'); s.value = '5';"
                      " s.dispatchEvent(new Event('input')); })()")
        assert page.evaluate("document.getElementById('step').textContent") == f"move 5 / {n} · line 10"
        assert page.evaluate("[...document.querySelectorAll('#src .src-line.cur')].map(e => +e.dataset.line)") == [10]
        page.evaluate("document.getElementById('canvas').focus()")
        page.call("Input.dispatchKeyEvent", type="keyDown", key="ArrowRight", code="ArrowRight",
                  windowsVirtualKeyCode=39)
        assert page.evaluate("document.getElementById('step').textContent") == f"move 6 / {n} · line 11"
        # a click past the slider hits nothing drawn in full: N110 (move 8) is not selectable now
        x, y = page.evaluate("ncViewer.screenOfMove(0, 8)")
        page.evaluate("ncViewer.state.selected = null")
        page.click(x, y)
        assert page.evaluate("ncViewer.state.selected") is None
        for view in ("front", "side", "iso"):
            page.evaluate(f"ncViewer.setView('{view}')")
            page.evaluate("ncViewer.drawNow()")
            assert inked_pixels(page) > 300, view
        assert page.errors == []
    finally:
        page.close()


def test_viewer_page_needs_no_network(tmp_path):
    """Offline: no URL to anything outside the page (scripts, styles, fonts, images)."""
    html = tmp_path / "sample.html"
    backplot(SAMPLE, html)
    text = html.read_text()
    for pattern in ("http://", "https://", "//cdn", "<script src", "<link rel=\"stylesheet\"", "@import"):
        assert pattern not in text.replace("http://www.w3.org/", ""), pattern


def test_compare_viewer_marks_the_difference(chromium, tmp_path):
    edited = tmp_path / "edited.nc"
    edited.write_text(SAMPLE.read_text().replace("N180 X40.", "N180 X42."))     # line 21
    html = tmp_path / "cmp.html"
    backplot(SAMPLE, html, "--compare", str(edited))
    page, _ = open_viewer(chromium, html)
    try:
        assert page.evaluate("ncViewer.programs.length") == 2
        rows = page.evaluate("[...document.querySelectorAll('#lists .row.diff')].map(e => e.textContent)")
        assert rows and ":21:" in rows[0]
        page.evaluate("document.querySelector('#lists .row.diff').click()")
        assert page.evaluate("[...document.querySelectorAll('#src .src-line.hl')].map(e => +e.dataset.line)") == [21]
        assert inked_pixels(page) > 500
        assert page.errors == []
    finally:
        page.close()


def test_lint_findings_are_listed_marked_and_lead_to_their_line(chromium, tmp_path):
    src = tmp_path / "f.nc"
    src.write_text("%\nO1\nG21 G90 G17\nG0 X0 Y0 Z5\nG0 G1 X10 F100\nM30\n%\n")    # NC201 on line 5
    html = tmp_path / "f.html"
    backplot(src, html)
    page, _ = open_viewer(chromium, html)
    try:
        rows = page.evaluate("[...document.querySelectorAll('#lists .row.warning')].map(e => e.textContent)")
        assert len(rows) == 1 and ":5: warning[NC201]" in rows[0]
        assert page.evaluate("[...document.querySelectorAll('#src .src-line.warning')].map(e => +e.dataset.line)") == [5]
        page.evaluate("document.querySelector('#lists .row.warning').click()")
        assert page.evaluate("[...document.querySelectorAll('#src .src-line.hl')].map(e => +e.dataset.line)") == [5]
        assert page.evaluate("ncViewer.state.highlight") == [{"program": 0, "moves": [1]}]
        assert page.errors == []
    finally:
        page.close()


# --------------------------------------------------------------------------- real programs

@pytest.mark.parametrize("rel", ["iso-mill/efgarro-fusion-6656.nc", "sinumerik/dubovikov-slot.mpf"])
def test_corpus_program_viewer(chromium, corpus_dir, tmp_path, rel):
    src = corpus_dir / rel
    html = tmp_path / "plot.html"
    backplot(src, html)
    moves = moves_of(src)
    page, _ = open_viewer(chromium, html)
    try:
        assert page.evaluate("ncViewer.programs[0].n") == len(moves)
        assert inked_pixels(page) > 1000
        page.evaluate("ncViewer.setView('iso')")
        i = isolated_move(page, moves)
        got = click_move(page, i)
        assert got["sel"]["move"] == i
        assert got["sel"]["line"] == moves[i]["line"] and got["hl"] == [moves[i]["line"]]
        assert page.errors == []
    finally:
        page.close()


def _generated_program(path: Path, moves: int) -> None:
    """A CAM-like ISO program: a zig-zag pocket of straight cuts joined by half-circle arcs."""
    lines = ["%", "O2000", "G21 G17 G40 G49 G80 G90 G94", "T1 M06", "G54 G00 X0. Y0. S8000 M03",
             "G43 Z5. H01", "G01 Z-1. F300."]
    y, n, sign = 0.0, 0, 1
    while n < moves:
        for k in range(1, 9):
            lines.append(f"X{(k * 10.0 if sign > 0 else 80.0 - k * 10.0):.3f} Y{y:.3f}")
        y += 0.5
        lines.append(f"{'G03' if sign > 0 else 'G02'} X{80.0 if sign > 0 else 0.0:.3f} Y{y:.3f} R0.25")
        lines.append("G01")
        n += 9
        sign = -sign
    lines += ["G00 Z25.", "M30", "%"]
    path.write_text("\n".join(lines) + "\n")


def test_100k_move_program_stays_interactive(chromium, tmp_path):
    which = "generated-100k"
    src = tmp_path / "big.nc"
    _generated_program(src, 100_000)
    html = tmp_path / "big.html"
    cli_s = backplot(src, html)
    moves = moves_of(src)
    assert len(moves) >= 100_000
    page, open_s = open_viewer(chromium, html, timeout=300)
    try:
        n = page.evaluate("ncViewer.programs[0].n")
        assert n == len(moves)
        assert inked_pixels(page) > 1000
        frame_ms = page.evaluate("ncViewer.timeFrames(10)")
        load_ms = page.evaluate("ncViewer.state.loadMs")
        page.evaluate("ncViewer.setView('iso')")
        i = isolated_move(page, moves, tries=20)
        t = time.perf_counter()
        got = click_move(page, i)
        click_s = time.perf_counter() - t
        assert got["sel"]["line"] == moves[i]["line"] and got["hl"] == [moves[i]["line"]]
        assert page.errors == []
        segs = page.evaluate("ncViewer.programs[0].segs")
        print(f"\n[backplot 100k] {which}: {n} moves, {segs} segments; html {html.stat().st_size / 1e6:.1f} MB "
              f"written in {cli_s:.1f} s; page open {open_s:.2f} s (script {load_ms:.0f} ms); "
              f"{frame_ms:.1f} ms per frame; click-to-highlight {click_s * 1000:.0f} ms")
    finally:
        page.close()
