"""`nctrans backplot`: SVG, PNG and GLB structure, the command line's errors, and --compare.

Counts are checked against the toolpath (`nctrans toolpath`, the stream the backplot reads); the
shapes against facts worked out by hand from corpus/iso-m/sample-pocket.nc:
  moves 0-2 rapids (N30 line 6, N40 line 7, N50 line 8), 3 linear N60 (line 9), 4 N70 (line 10),
  5 N80 X40 (line 11: X0 Y0 -> X40 Y0), 6 arc N90 G03 R10 (line 12: X40 Y0 -> X50 Y10, centre X40 Y10),
  7 N100 (line 13), 8 arc N110 G02 I-10 (line 14: X50 Y30 -> X40 Y40 clockwise about X40 Y30, 270 deg);
  T1 is loaded before the first move and T2 at line 18, so one tool-change marker (T2).
"""
from __future__ import annotations

import io
import json
import math
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "corpus" / "iso-m" / "sample-pocket.nc"
NCTRANS = [sys.executable, "-m", "nctrans"]
SVG_NS = "{http://www.w3.org/2000/svg}"
MOTION = ("rapid", "linear", "arc")


def run(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([*NCTRANS, *map(str, args)], capture_output=True, text=True, timeout=300,
                          cwd=cwd)


def toolpath(src: Path, *extra) -> list[dict]:
    r = run("toolpath", src, *extra)
    assert r.returncode in (0, 1), r.stderr
    return [json.loads(line) for line in r.stdout.splitlines()]


def moves_of(src: Path, *extra) -> list[dict]:
    return [r for r in toolpath(src, *extra) if r["kind"] in MOTION]


@pytest.fixture(scope="module")
def sample_svg(tmp_path_factory) -> ET.Element:
    out = tmp_path_factory.mktemp("bp") / "sample.svg"
    r = run("backplot", SAMPLE, "-o", out)
    assert r.returncode == 0, r.stderr
    return ET.parse(out).getroot()


def _move_paths(root: ET.Element, gid: str = "moves") -> list[ET.Element]:
    group = root.find(f".//{SVG_NS}g[@id='{gid}']")
    assert group is not None
    return group.findall(f"{SVG_NS}path")


def _numbers(d: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?", d)]


# --------------------------------------------------------------------------- SVG

def test_svg_has_one_path_per_move_in_program_order(sample_svg):
    moves = moves_of(SAMPLE)
    paths = _move_paths(sample_svg)
    assert len(paths) == len(moves) == int(sample_svg.get("data-moves"))
    for k, (p, m) in enumerate(zip(paths, moves)):
        assert p.get("data-move") == str(k)
        assert p.get("data-line") == str(m["line"])
        assert p.get("class").split()[0] == m["kind"]
        assert f"t{m['tool']}" in p.get("class").split()


def test_svg_arcs_are_true_arcs_with_hand_computed_radius_and_direction(sample_svg):
    paths = _move_paths(sample_svg)
    x0, y0, x1, y1 = _numbers(paths[5].get("d"))          # N80: X0 Y0 -> X40 Y0
    scale = (x1 - x0) / 40.0
    assert y1 == pytest.approx(y0) and scale > 0
    g03, g02 = paths[6].get("d"), paths[8].get("d")
    assert "L" not in g03 and "L" not in g02               # no chords
    arcs3 = re.findall(r"A(\S+) (\S+) 0 0 ([01]) (\S+) (\S+)", g03)
    arcs2 = re.findall(r"A(\S+) (\S+) 0 0 ([01]) (\S+) (\S+)", g02)
    for rx, ry, *_ in arcs3 + arcs2:
        assert float(rx) == pytest.approx(10 * scale, abs=0.01) == pytest.approx(float(ry), abs=0.01)
    # G03 counter-clockwise on the page is the negative-angle sweep (page y points down): flag 0;
    # G02 clockwise: flag 1. The G02 turns 270 degrees, so it needs at least two pieces under 180.
    assert {a[2] for a in arcs3} == {"0"}
    assert {a[2] for a in arcs2} == {"1"} and len(arcs2) >= 2
    # N110 ends at X40 Y40: 40 mm right of and 40 mm above N80's start (X0 Y0)
    ex, ey = float(arcs2[-1][3]), float(arcs2[-1][4])
    assert ex == pytest.approx(x0 + 40 * scale, abs=0.02)
    assert ey == pytest.approx(y0 - 40 * scale, abs=0.02)


def test_svg_front_view_draws_an_xy_arc_edge_on_as_a_polyline(tmp_path):
    out = tmp_path / "front.svg"
    assert run("backplot", SAMPLE, "-o", out, "--view", "front").returncode == 0
    paths = _move_paths(ET.parse(out).getroot())
    d = paths[6].get("d")
    assert "A" not in d and "L" in d
    ys = _numbers(d)[1::2]
    assert max(ys) - min(ys) < 0.01                      # the arc lies at one Z: a flat line in front view


def test_svg_marks_start_tool_change_scale_bar_and_triad(sample_svg):
    starts = sample_svg.findall(f".//{SVG_NS}g[@class='start']")
    changes = sample_svg.findall(f".//{SVG_NS}g[@class='tool-change']")
    assert len(starts) == 1 and "T1" in "".join(starts[0].itertext())
    assert len(changes) == 1 and changes[0].get("data-line") == "18"
    assert "T2" in "".join(changes[0].itertext())
    scale = sample_svg.find(f".//{SVG_NS}g[@id='scale-bar']")
    assert re.fullmatch(r"\d+(\.\d+)? mm", "".join(scale.itertext()).strip())
    triad = "".join(sample_svg.find(f".//{SVG_NS}g[@id='axis-triad']").itertext()).split()
    assert triad == ["X", "Y"]                                 # top view: Z is seen end-on
    style = "".join(sample_svg.find(f"{SVG_NS}style").itertext())
    assert re.search(r"\.rapid\{stroke-dasharray", style)


def test_svg_scale_bar_length_matches_the_drawing_scale(sample_svg):
    paths = _move_paths(sample_svg)
    x0, _, x1, _ = _numbers(paths[5].get("d"))
    px_per_mm = (x1 - x0) / 40.0
    bar = sample_svg.find(f".//{SVG_NS}g[@id='scale-bar']")
    mm = float("".join(bar.itertext()).split()[0])
    h = re.search(r"h(\d+(?:\.\d+)?)", bar.find(f"{SVG_NS}path").get("d"))
    assert float(h.group(1)) == pytest.approx(mm * px_per_mm, abs=0.02)


@pytest.mark.parametrize("rel", ["iso-mill/efgarro-fusion-6656.nc", "sinumerik/dubovikov-slot.mpf"])
def test_svg_counts_on_corpus_programs(corpus_dir, tmp_path, rel):
    src = corpus_dir / rel
    out = tmp_path / "plot.svg"
    r = run("backplot", src, "-o", out, "--view", "iso")
    assert r.returncode in (0, 1), r.stderr
    moves = moves_of(src)
    paths = _move_paths(ET.parse(out).getroot())
    assert len(paths) == len(moves) > 100
    assert [p.get("class").split()[0] for p in paths] == [m["kind"] for m in moves]


# --------------------------------------------------------------------------- PNG

def test_png_is_the_svg_layout_rasterised_and_not_blank(tmp_path, sample_svg):
    from PIL import Image
    out = tmp_path / "sample.png"
    r = run("backplot", SAMPLE, "-o", out)
    assert r.returncode == 0, r.stderr
    img = Image.open(out)
    assert img.size == (int(sample_svg.get("width")), int(sample_svg.get("height")))
    assert img.text["nctrans:moves"] == str(len(moves_of(SAMPLE)))
    rgb = img.convert("RGB")
    colours = rgb.getcolors(1 << 20)
    inked = sum(n for n, c in colours if c != (255, 255, 255))
    assert inked > 2000
    # N80 (X0 Y0 -> X40 Y0, tool 1, solid) passes through X20 Y0: its pixel is T1's blue (#1f77b4)
    paths = _move_paths(sample_svg)
    x0, y0, x1, _ = _numbers(paths[5].get("d"))
    px = rgb.getpixel((round((x0 + x1) / 2), round(y0)))
    assert px[2] > px[0] + 60, px                       # blue dominates


# --------------------------------------------------------------------------- GLB

def test_glb_has_every_move_once_with_its_geometry(tmp_path):
    import numpy as np
    import trimesh
    out = tmp_path / "sample.glb"
    assert run("backplot", SAMPLE, "-o", out).returncode == 0
    scene = trimesh.load(out)
    moves = moves_of(SAMPLE)
    seen: dict[int, str] = {}
    for name, g in scene.geometry.items():
        meta = g.metadata
        if meta.get("kind") not in MOTION:
            continue
        assert name.startswith(meta["kind"])
        verts = np.asarray(g.vertices)
        assert len(verts) == 2 * sum(n - 1 for n in meta["points"])   # GL_LINES: two per segment
        at = 0
        for i, line, n in zip(meta["moves"], meta["lines"], meta["points"]):
            m = moves[i]
            assert i not in seen and m["kind"] == meta["kind"] and m["line"] == line and m["tool"] == meta["tool"]
            seen[i] = meta["kind"]
            start = [m["start"].get(a, 0.0) for a in "XYZ"]
            end = [m["end"].get(a, 0.0) for a in "XYZ"]
            assert verts[at] == pytest.approx(start, abs=1e-4)
            assert verts[at + 2 * (n - 1) - 1] == pytest.approx(end, abs=1e-4)
            at += 2 * (n - 1)
    assert sorted(seen) == list(range(len(moves)))
    assert sum(1 for k in seen.values() if k == "arc") == 2


def test_glb_carries_the_machine_stock_box(tmp_path):
    import trimesh
    machine = tmp_path / "m.toml"
    machine.write_text('name = "m"\n[stock]\nbox = { min = [-20.0, -20.0, -10.0], max = [60.0, 50.0, 0.0] }\n')
    out = tmp_path / "s.glb"
    r = run("backplot", SAMPLE, "-o", out, "--machine", machine)
    assert r.returncode == 0, r.stderr
    stock = trimesh.load(out).geometry["stock"]
    assert stock.bounds.tolist() == [[-20.0, -20.0, -10.0], [60.0, 50.0, 0.0]]


def test_glb_unreadable_fixture_is_a_clear_error(tmp_path):
    machine = tmp_path / "m.toml"
    machine.write_text('name = "m"\n[[fixtures]]\nmesh = "missing-vise.stl"\n')
    out = tmp_path / "s.glb"
    r = run("backplot", SAMPLE, "-o", out, "--machine", machine)
    assert r.returncode == 2
    assert "missing-vise.stl" in r.stderr and "Traceback" not in r.stderr and "internal" not in r.stderr
    assert not out.exists()


# --------------------------------------------------------------------------- command line

def test_unknown_ending_is_a_usage_error(tmp_path):
    r = run("backplot", SAMPLE, "-o", tmp_path / "plot.pdf")
    assert r.returncode == 2 and ".svg" in r.stderr and "Traceback" not in r.stderr


def test_refuses_to_overwrite_the_input(tmp_path):
    src = tmp_path / "p.svg"           # a program whose name ends like an output
    src.write_text(SAMPLE.read_text())
    before = src.read_bytes()
    r = run("backplot", src, "--from", "iso-m", "-o", src)
    assert r.returncode == 2 and "refusing to overwrite" in r.stderr
    assert src.read_bytes() == before


def test_missing_input_and_unknown_view(tmp_path):
    r = run("backplot", tmp_path / "nope.nc", "-o", tmp_path / "x.svg")
    assert r.returncode == 2 and "nope.nc" in r.stderr and "Traceback" not in r.stderr
    r = run("backplot", SAMPLE, "-o", tmp_path / "x.svg", "--view", "bottom")
    assert r.returncode == 2
    assert not (tmp_path / "x.svg").exists()


def test_program_without_moves_writes_nothing(tmp_path):
    src = tmp_path / "empty.nc"
    src.write_text("%\nO1\nG21 G90\nM30\n%\n")
    out = tmp_path / "e.html"
    r = run("backplot", src, "-o", out)
    assert r.returncode == 1 and "no moves" in r.stderr
    assert not out.exists()


def test_output_is_written_atomically_over_an_old_file(tmp_path):
    out = tmp_path / "p.svg"
    out.write_text("old")
    assert run("backplot", SAMPLE, "-o", out).returncode == 0
    assert out.read_text().startswith("<svg")
    assert [p.name for p in tmp_path.iterdir()] == ["p.svg"]          # no temp file left behind


def test_rotary_axis_moves_are_announced_not_hidden(tmp_path):
    src = tmp_path / "rot.nc"
    src.write_text("%\nO1\nG21 G90 G17\nG0 X0 Y0 Z5\nG1 X10 A90 F100\nM30\n%\n")
    out = tmp_path / "rot.svg"
    r = run("backplot", src, "-o", out)
    assert r.returncode == 0, r.stderr
    assert "moves A" in r.stderr
    notes = ET.parse(out).getroot().find(f".//{SVG_NS}g[@id='notes']")
    assert notes is not None and "A" in "".join(notes.itertext())


# --------------------------------------------------------------------------- --compare

def test_compare_a_program_with_its_conversion_is_equivalent(tmp_path):
    conv = tmp_path / "sample.mpf"
    r = run("convert", SAMPLE, "--to", "sinumerik", "-o", conv)
    assert r.returncode == 0, r.stderr
    out = tmp_path / "cmp.svg"
    r = run("backplot", SAMPLE, "--compare", conv, "-o", out)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "equivalent" in r.stdout
    root = ET.parse(out).getroot()
    assert len(_move_paths(root, "moves")) == len(moves_of(SAMPLE))
    assert len(_move_paths(root, "moves-b")) == len(moves_of(conv))
    assert not root.findall(f".//{SVG_NS}g[@class='difference']")


def test_compare_marks_where_an_edited_program_differs(tmp_path):
    edited = tmp_path / "edited.nc"
    text = SAMPLE.read_text().replace("N180 X40.", "N180 X42.")     # line 21: the second hole moves
    assert text != SAMPLE.read_text()
    edited.write_text(text)
    out = tmp_path / "cmp.svg"
    r = run("backplot", SAMPLE, "--compare", edited, "-o", out)
    assert r.returncode == 1, r.stderr
    assert r.stdout.count("different:") == 1
    assert f"{SAMPLE.name}:21:" in r.stdout and "edited.nc:21:" in r.stdout
    marks = ET.parse(out).getroot().findall(f".//{SVG_NS}g[@class='difference']")
    assert [m.get("data-line") for m in marks[:2]] == ["21", "21"]      # A's mark, then B's


# --------------------------------------------------------------------------- findings

FINDING_PROGRAM = "%\nO1\nG21 G90 G17\nG0 X0 Y0 Z5\nG0 G1 X10 F100\nM30\n%\n"     # NC201 on line 5


def test_lint_findings_are_marked_where_their_line_moves_the_tool(tmp_path):
    src = tmp_path / "f.nc"
    src.write_text(FINDING_PROGRAM)
    out = tmp_path / "f.svg"
    r = run("backplot", src, "-o", out)
    assert r.returncode == 0 and "NC201" in r.stderr
    root = ET.parse(out).getroot()
    marks = root.findall(f".//{SVG_NS}g[@class='finding warning']")
    assert [m.get("data-line") for m in marks] == ["5"]
    assert "NC201" in "".join(marks[0].itertext())
    # drawn at the end of line 5's move (X10 Y0): the end point of that move's path
    move = [p for p in _move_paths(root) if p.get("data-line") == "5"][0]
    ex, ey = _numbers(move.get("d"))[-2:]
    rect = marks[0].find(f"{SVG_NS}rect")
    assert float(rect.get("x")) + 5 == pytest.approx(ex) and float(rect.get("y")) + 5 == pytest.approx(ey)


def test_findings_interface_takes_plain_records_with_or_without_a_position():
    from nctrans.backplot import build_scene
    from nctrans.toolpath import ToolpathRecord
    recs = [ToolpathRecord(1, "p.nc", 4, "rapid", {"X": 0.0, "Y": 0.0, "Z": 5.0}, {"X": 0.0, "Y": 0.0, "Z": 1.0}),
            ToolpathRecord(2, "p.nc", 6, "linear", {"X": 0.0, "Y": 0.0, "Z": 1.0}, {"X": 8.0, "Y": 0.0, "Z": 1.0})]
    scene = build_scene(recs, "p.nc", [
        {"line": 5, "severity": "error", "code": "NC301", "message": "overtravel"},     # no move on line 5
        {"line": 6, "severity": "warning", "code": "NC302", "message": "collision", "position": [4.0, 0.0, 1.0]},
    ])
    a, b = scene.findings
    assert a.position == (8.0, 0.0, 1.0)          # the first move at or after line 5 ends there
    assert b.position == (4.0, 0.0, 1.0) and b.file == "p.nc"


def test_a_program_without_y_motion_is_drawn_from_the_front(tmp_path):
    src = tmp_path / "xz.nc"
    src.write_text("%\nO1\nG21 G90 G18\nG0 X20 Z5\nG1 Z-10 F100\nX30\nM30\n%\n")
    out = tmp_path / "xz.svg"
    assert run("backplot", src, "--from", "iso-m", "-o", out).returncode == 0
    assert ET.parse(out).getroot().get("data-view") == "front"


def test_a_program_with_an_error_is_plotted_with_the_error_marked_and_exit_1(tmp_path):
    src = tmp_path / "bad.nc"
    src.write_text("%\nO1\nG21 G90 G17\nG0 X0 Y0 Z5\nG1 X10 F100\nG2 X20 Y0 I3 J0\nM30\n%\n")   # radii 3 and 7
    out = tmp_path / "bad.svg"
    r = run("backplot", src, "-o", out)
    assert r.returncode == 1 and "NC203" in r.stderr
    marks = ET.parse(out).getroot().findall(f".//{SVG_NS}g[@class='finding error']")
    assert [m.get("data-line") for m in marks] == ["6"]


def test_glb_compare_carries_both_toolpaths(tmp_path):
    import trimesh
    edited = tmp_path / "edited.nc"
    edited.write_text(SAMPLE.read_text().replace("N180 X40.", "N180 X42."))
    out = tmp_path / "cmp.glb"
    assert run("backplot", SAMPLE, "--compare", edited, "-o", out).returncode == 1
    geoms = trimesh.load(out).geometry
    a = sum(len(g.metadata["moves"]) for n, g in geoms.items() if g.metadata.get("kind") and not n.startswith("B-"))
    b = sum(len(g.metadata["moves"]) for n, g in geoms.items() if g.metadata.get("kind") and n.startswith("B-"))
    assert a == len(moves_of(SAMPLE)) and b == len(moves_of(edited))
    assert any(n.startswith("difference") for n in geoms)


def test_a_move_with_a_non_finite_coordinate_is_left_out_and_said():
    from nctrans.backplot import build_scene, render
    from nctrans.toolpath import ToolpathRecord
    nan = float("nan")
    recs = [ToolpathRecord(1, "p.nc", 4, "linear", {"X": 0.0, "Y": 0.0, "Z": 0.0}, {"X": 5.0, "Y": 0.0, "Z": 0.0}),
            ToolpathRecord(2, "p.nc", 5, "linear", {"X": 5.0, "Y": 0.0, "Z": 0.0}, {"X": nan, "Y": 0.0, "Z": 0.0})]
    scene = build_scene(recs, "p.nc")
    assert len(scene.moves) == 1 and "line 5" in scene.warnings[0]
    page = render("html", scene, sources={"p.nc": "G1 X5\nG1 X#1\n"}).decode()
    assert "NaN" not in page


def test_check_findings_are_marked_at_their_position(tmp_path):
    machine = tmp_path / "m.toml"
    machine.write_text('name = "small"\n[axes.X]\nmin = -20.0\nmax = 45.0\n[axes.Y]\nmin = -20.0\nmax = 45.0\n'
                       '[axes.Z]\nmin = -50.0\nmax = 30.0\n')
    out = tmp_path / "chk.svg"
    r = run("backplot", SAMPLE, "--machine", machine, "--check", "-o", out)
    assert r.returncode == 1 and "NC301" in r.stderr          # X travel ends at 45; the pocket reaches X50
    root = ET.parse(out).getroot()
    marks = root.findall(f".//{SVG_NS}g[@class='finding error']")
    assert marks and marks[0].get("data-line") == "12" and "NC301" in "".join(marks[0].itertext())
    # N90 G03 (line 12) is the first move past X45: it ends at X50 Y10, where its path ends
    ex, ey = _numbers(_move_paths(root)[6].get("d"))[-2:]
    rect = marks[0].find(f"{SVG_NS}rect")
    assert float(rect.get("x")) + 5 == pytest.approx(ex, abs=0.01)
    assert float(rect.get("y")) + 5 == pytest.approx(ey, abs=0.01)
