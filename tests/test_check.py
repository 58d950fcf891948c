"""`nctrans check`: each finding kind at a known line, and a near miss that gives nothing.

Expected positions and amounts are worked out by hand from the machine below (G54 is zero, so
machine X/Y are program X/Y; after G43 H1 program Z is the tip of T1 and the controlled point the
toolpath gives, the gauge line, is 100 mm above it). Meshes are made in the test with trimesh.creation and written as STL files.
"""
from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

from nctrans import pipeline
from nctrans.check import check_loaded, check_records
from nctrans.check.findings import RULES
from nctrans.machine import default_lathe, default_mill
from nctrans.toolpath import ToolpathRecord

ROOT = Path(__file__).resolve().parents[1]

MACHINE = """
name = "test-vmc"
kind = "mill"
[axes.X]
min = -300.0
max = 300.0
max_feed = 5000.0
rapid = 30000.0
[axes.Y]
min = -200.0
max = 200.0
max_feed = 5000.0
rapid = 30000.0
[axes.Z]
min = -200.0
max = 250.0
max_feed = 5000.0
rapid = 30000.0
[spindle]
max_rpm = 12000
[[tools]]
number = 1
length = 100.0
radius = 5.0
cutting_length = 30.0
holder_radius = 20.0
holder_length = 60.0
[[tools]]
number = 2
length = 60.0
radius = 3.0
cutting_length = 10.0
holder = [{ radius = 15.0, length = 40.0 }]
"""

HEAD = "G21 G90 G17 G54\nT1 M6\nS5000 M3\nG43 H1 G0 Z100\n"     # lines 1-4; tip at Z100


def check(tmp_path: Path, program: str, extra: str = "", dialect: str = "iso-m", name: str = "p.nc"):
    (tmp_path / name).write_text(program)
    (tmp_path / "m.toml").write_text(MACHINE + extra)
    machine = pipeline.load_machine(str(tmp_path / "m.toml"))
    ld = pipeline.load(str(tmp_path / name), dialect, stream=True)
    diags, result = check_loaded(ld, machine)
    assert not [d for d in diags if d.severity == "error" and not d.rule.startswith("NC3")], diags
    return result.findings


def only(findings, rule):
    return [f for f in findings if f.rule == rule]


def clamp_stl(tmp_path: Path, lo, hi, name="clamp.stl") -> str:
    import trimesh
    trimesh.creation.box(bounds=[lo, hi]).export(tmp_path / name)
    return name


# --------------------------------------------------------------------------- travel

def test_overtravel_at_an_end_point_names_line_axis_and_amount(tmp_path):
    found = check(tmp_path, HEAD + "G0 X250\nG1 X350 F1000\nG1 X300\nM30\n")
    [f] = only(found, "NC301")
    assert (f.line, f.subject) == (6, "X")
    assert f.amount == pytest.approx(50.0)
    assert f.position["X"] == pytest.approx(350.0)
    # the Z travel: tip at Z150 puts the gauge line on its limit (250): a near miss
    assert not only(check(tmp_path, HEAD + "G0 Z150\nM30\n"), "NC301")
    [z] = only(check(tmp_path, HEAD + "G0 Z150.5\nM30\n"), "NC301")      # 150.5 + 100 = 250.5
    assert (z.line, z.subject) == (5, "Z") and z.amount == pytest.approx(0.5)


def test_overtravel_inside_an_arc_sweep_between_legal_end_points(tmp_path):
    # centre (290, 0), radius sqrt(5^2 + 10^2) = 11.1803: the arc crosses angle 0 at X301.1803
    prog = HEAD + "G0 X295 Y-10\nG3 X295 Y10 I-5 J10 F1000\nM30\n"
    [f] = only(check(tmp_path, prog), "NC301")
    assert f.line == 6 and f.subject == "X" and "sweep" in f.message
    assert f.amount == pytest.approx(math.hypot(5, 10) - 10, abs=1e-6)
    assert f.position["X"] == pytest.approx(290 + math.hypot(5, 10)) and f.position["Y"] == pytest.approx(0, abs=1e-9)
    # near miss: centre (285, 0), radius 14.142: X reaches 299.142
    assert not only(check(tmp_path, HEAD + "G0 X295 Y-10\nG3 X295 Y10 I-10 J10 F1000\nM30\n"), "NC301")
    # the same end points clockwise go the long way round, away from the X limit
    assert not only(check(tmp_path, HEAD + "G0 X295 Y-10\nG2 X295 Y10 I-5 J10 F1000\nM30\n"), "NC301")


def test_overtravel_is_found_the_same_way_in_sinumerik(tmp_path):
    prog = "G90 G17 G54\nT1 D1\nM6\nG0 Z100\nG0 X295 Y-10\nG3 X295 Y10 I-5 J10 F1000\nM30\n"
    [f] = only(check(tmp_path, prog, dialect="sinumerik", name="p.mpf"), "NC301")
    assert f.line == 6 and f.subject == "X"


def test_programmable_limits_records(tmp_path):
    m = default_mill()
    recs = [ToolpathRecord(1, "p", 3, "limits", {"X": -10.0}, {"X": 100.0}),
            ToolpathRecord(2, "p", 4, "rapid", {"X": 0.0}, {"X": 99.0}),
            ToolpathRecord(3, "p", 5, "rapid", {"X": 99.0}, {"X": 120.0}),
            ToolpathRecord(4, "p", 6, "limits"),
            ToolpathRecord(5, "p", 7, "rapid", {"X": 120.0}, {"X": 130.0})]
    [f] = only(check_records(recs, m).findings, "NC302")
    assert (f.line, f.subject) == (5, "X") and f.amount == pytest.approx(20.0)


# --------------------------------------------------------------------------- feed and spindle

def test_feed_over_an_axis_maximum(tmp_path):
    [f] = only(check(tmp_path, HEAD + "G1 X100 F6000\nM30\n"), "NC303")
    assert (f.line, f.subject) == (5, "X") and f.amount == pytest.approx(1000.0)
    # 45 degrees at F6000: each axis runs at 6000 / sqrt(2) = 4243 mm/min, under 5000
    assert not only(check(tmp_path, HEAD + "G1 X100 Y100 F6000\nM30\n"), "NC303")


def test_spindle_over_its_maximum_where_it_is_set(tmp_path):
    found = check(tmp_path, HEAD + "G1 X10 F500\nS13000\nG1 X20\nG1 X30\nM30\n")
    [f] = only(found, "NC304")
    assert f.line == 6 and f.amount == pytest.approx(1000.0)
    assert not only(check(tmp_path, HEAD + "S12000\nG1 X10 F500\nM30\n"), "NC304")


def test_spindle_over_its_maximum_through_constant_surface_speed():
    m = default_mill()
    m.spindle.max_rpm = 4000.0
    css = 200.0                       # m/min: 200000 / (2 pi r) rpm at radius r mm

    def face(line, x0, x1, limit=None):
        return ToolpathRecord(line, "t", line, "linear", {"X": x0, "Z": 0.0}, {"X": x1, "Z": 0.0},
                              feed=0.2, feed_mode="per_rev", spindle=1000.0, css=css, spindle_limit=limit)
    # X50 -> X10: at most 200000 / (2 pi 10) = 3183 rpm; X10 -> X1: 31831 rpm at X1
    found = check_records([face(1, 50.0, 10.0), face(2, 10.0, 1.0), face(3, 1.0, 0.5)], m).findings
    [f] = only(found, "NC304")
    assert f.line == 2 and f.amount == pytest.approx(css * 1000 / (2 * math.pi) - 4000.0, rel=1e-6)
    # to the centre with a limit of 3000 rpm (G50 S3000 / LIMS=3000): nothing
    assert not only(check_records([face(1, 50.0, 0.0, limit=3000.0)], m).findings, "NC304")
    # to the centre without a limit: the spindle would run away
    [runaway] = only(check_records([face(1, 50.0, 0.0)], m).findings, "NC304")
    assert runaway.line == 1 and "run away" in runaway.message


# --------------------------------------------------------------------------- fixtures

CLAMP_LO, CLAMP_HI = (40.0, -10.0, 0.0), (60.0, 10.0, 50.0)


def fixture_toml(tmp_path):
    return f'[[fixtures]]\nname = "clamp"\nmesh = "{clamp_stl(tmp_path, CLAMP_LO, CLAMP_HI)}"\n'


def test_tool_against_a_clamp_mesh(tmp_path):
    prog = HEAD + "G0 X0 Y0\nG1 Z20 F500\nG1 X50\nM30\n"            # tip at Z20 crosses the clamp
    [f] = only(check(tmp_path, prog, fixture_toml(tmp_path)), "NC310")
    assert (f.line, f.subject) == (7, "clamp")
    # contact begins when the cutter's side (radius 5, drawn as a polygon around it) reaches X40
    assert 34.9 < f.position["X"] < 35.01 and f.position["Z"] == pytest.approx(120.0)
    assert f.amount == pytest.approx(50.0 - f.position["X"])
    near = HEAD + "G0 X0 Y0\nG1 Z20 F500\nG1 X34.9\nG1 Y30\nG1 X50\nM30\n"   # stops short, goes round
    assert not only(check(tmp_path, near, fixture_toml(tmp_path)), "NC310")


def test_a_fixture_wholly_inside_the_swept_volume_is_a_collision(tmp_path):
    import trimesh
    trimesh.creation.box(bounds=[(49.0, -1.0, 10.0), (51.0, 1.0, 12.0)]).export(tmp_path / "bolt.stl")
    prog = HEAD + "G0 X0 Y0 Z10\nG0 X100\nM30\n"            # the cutter sweeps Z10..40 across it
    [f] = only(check(tmp_path, prog, '[[fixtures]]\nmesh = "bolt.stl"\n'), "NC310")
    assert f.line == 6 and f.subject == "bolt.stl"


def test_holder_against_a_clamp_mesh_while_the_cutter_is_clear(tmp_path):
    # at X25 the cutter reaches X30 (clear of X40); the holder (radius 20, from 30 mm above the
    # tip) reaches X45: going down it meets the clamp top (Z50) when the tip is at Z20
    prog = HEAD + "G0 X25 Y0\nG1 Z10 F500\nM30\n"
    found = check(tmp_path, prog, fixture_toml(tmp_path))
    [f] = only(found, "NC311")
    assert not only(found, "NC310")
    assert f.line == 6 and f.position["Z"] == pytest.approx(120.0, abs=0.05)
    near = HEAD + "G0 X19.5 Y0\nG1 Z10 F500\nM30\n"       # holder edge at 39.5 (+0.17 polygon)
    assert not [f for f in check(tmp_path, near, fixture_toml(tmp_path)) if f.rule in ("NC310", "NC311")]


def test_an_arc_through_a_clamp(tmp_path):
    # centre (0, 0), from (-50, 0) clockwise over (0, 50) to (50, 0): ends inside the clamp's X
    # span at Y0; the near miss (radius 28) ends at X28 + 5 = 33, clear of X40
    prog = HEAD + "G0 X-50 Y0\nG1 Z20 F500\nG2 X50 Y0 I50 J0\nM30\n"
    [f] = only(check(tmp_path, prog, fixture_toml(tmp_path)), "NC310")
    assert f.line == 7
    near = HEAD + "G0 X-28 Y0\nG1 Z20 F500\nG2 X28 Y0 I28 J0\nM30\n"
    assert not only(check(tmp_path, near, fixture_toml(tmp_path)), "NC310")


# --------------------------------------------------------------------------- stock

STOCK = "[stock]\nbox = { min = [-50, -50, -20], max = [30, 50, 0] }\n"


def test_rapid_out_of_a_fresh_slot_is_fine_and_a_rapid_into_uncut_stock_is_not(tmp_path):
    prog = HEAD + (
        "G0 X-70 Y0 Z5\n"        # 5  tip 5 above the stock
        "G1 Z-5 F200\n"          # 6  tip -5, beside the stock
        "G1 X0 F500\n"           # 7  a slot 5 deep from the edge to X0
        "G0 Z5\n"                # 8  retract out of the slot: fine
        "G0 X-20\n"              # 9  above the stock
        "G0 Z-4.5\n"             # 10 back down into the slot just cut: fine
        "G0 Z5\n"                # 11
        "G0 X10\n"               # 12 above uncut stock
        "G0 Z-5\n"               # 13 rapid 5 mm into it
        "M30\n")
    found = check(tmp_path, prog, STOCK)
    [f] = only(found, "NC313")
    assert f.line == 13 and f.subject == "stock"
    assert f.amount == pytest.approx(5.0, abs=1e-6)
    # where it enters: the tip passing the stock's top (Z0), the gauge line 100 above
    assert f.position["X"] == pytest.approx(10.0) and f.position["Z"] == pytest.approx(100.0, abs=0.02)


def test_rapid_sideways_through_uncut_stock(tmp_path):
    prog = HEAD + "G0 X-70 Y0 Z-2\nG0 X0\nM30\n"               # tip -2 through the side of the stock
    [f] = only(check(tmp_path, prog, STOCK), "NC313")
    assert f.line == 6 and f.amount == pytest.approx(2.0)
    assert -56.0 < f.position["X"] < -50.0 and f.position["Z"] == pytest.approx(98.0)   # the side at X-50
    near = HEAD + "G0 X-70 Y0 Z0.5\nG0 X0\nM30\n"             # 0.5 above the top
    assert not only(check(tmp_path, near, STOCK), "NC313")


def test_holder_against_the_stock_past_the_cutting_length(tmp_path):
    # T2: length 60, cutting length 10, holder radius 15 from 10 mm above the tip
    t2 = "G21 G90 G17 G54\nT2 M6\nS5000 M3\nG43 H2 G0 Z50\nG0 X-10 Y0\n"   # lines 1-5
    deep = t2 + "G1 Z-12 F200\nM30\n"              # tip -12: holder bottom -2 in uncut stock
    [f] = only(check(tmp_path, deep, STOCK), "NC312")
    assert f.line == 6 and f.amount == pytest.approx(2.0)
    shallow = t2 + "G1 Z-9 F200\nM30\n"            # tip -9: holder bottom at +1
    assert not only(check(tmp_path, shallow, STOCK), "NC312")


@settings(max_examples=25, deadline=None)
@given(pts=st.lists(st.tuples(st.floats(-40, 20), st.floats(-40, 40), st.floats(-15, -1)),
                    min_size=1, max_size=6),
       cell=st.sampled_from([0.25, 0.5, 0.77]))
def test_retract_straight_up_after_any_cut_is_never_a_rapid_into_stock(pts, cell):
    """Property: after feed moves anywhere in the stock, a rapid straight up from where the tool
    stopped finds no uncut material (it only leaves what it just cut)."""
    from nctrans.machine import Mesh, Tool
    m = default_mill()
    m.tools = [Tool(number=1, length=0.0, radius=4.0)]
    m.stock = Mesh(box={"min": [-50.0, -50.0, -20.0], "max": [30.0, 50.0, 0.0]}, cell=cell)
    recs, here, seq = [], {"X": pts[0][0], "Y": pts[0][1], "Z": 10.0}, 0

    def move(kind, to):
        nonlocal here, seq
        seq += 1
        recs.append(ToolpathRecord(seq, "p", seq, kind, here, to, feed=100.0, feed_mode="per_min", tool=1))
        here = to
    for x, y, z in pts:
        move("linear", {"X": x, "Y": y, "Z": z})
    move("rapid", {**here, "Z": 10.0})
    assert not only(check_records(recs, m).findings, "NC313")


# --------------------------------------------------------------------------- a real CAM program

def _box_of(records):
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    for r in records:
        if r.kind in ("rapid", "linear", "arc"):
            for p in (r.start, r.end):
                for i, a in enumerate("XYZ"):
                    lo[i], hi[i] = min(lo[i], p.get(a, 0.0)), max(hi[i], p.get(a, 0.0))
    return lo, hi


def test_real_cam_program_with_a_clamp_beside_the_part(tmp_path, corpus_dir):
    src = corpus_dir / "iso-mill" / "nickburrill-fusion360-sample.nc"
    tools = "".join(f"[[tools]]\nnumber = {n}\nlength = 80.0\nradius = 5.0\ncutting_length = 25.0\n"
                    f"holder_radius = 20.0\nholder_length = 40.0\n" for n in range(1, 41))
    (tmp_path / "m.toml").write_text(tools)
    machine = pipeline.load_machine(str(tmp_path / "m.toml"))
    lo, hi = _box_of(pipeline.toolpath_of(pipeline.load(str(src), "iso-m"), machine))
    tip_lo = lo[2] - 80.0
    # a clamp beside the part, 2 mm clear of the holder's reach (radius 20), as tall as the tools
    # reach down (60 mm above the lowest tip position)
    x0 = hi[0] + 22.0
    beside = clamp_stl(tmp_path, (x0, lo[1], tip_lo - 10), (x0 + 20, hi[1], tip_lo + 60), "beside.stl")
    (tmp_path / "m.toml").write_text(tools + f'[[fixtures]]\nmesh = "{beside}"\n')
    machine = pipeline.load_machine(str(tmp_path / "m.toml"))
    diags, res = check_loaded(pipeline.load(str(src), "iso-m", stream=True), machine)
    assert res.moves > 500
    assert not [f for f in res.findings if f.rule in ("NC310", "NC311")]
    # the same clamp 3 mm further in is within the holder's reach
    onto = clamp_stl(tmp_path, (x0 - 3, lo[1], tip_lo - 10), (x0 + 17, hi[1], tip_lo + 60), "onto.stl")
    (tmp_path / "m.toml").write_text(tools + f'[[fixtures]]\nmesh = "{onto}"\n')
    machine = pipeline.load_machine(str(tmp_path / "m.toml"))
    diags, res = check_loaded(pipeline.load(str(src), "iso-m", stream=True), machine)
    assert [f for f in res.findings if f.rule in ("NC310", "NC311")]


# --------------------------------------------------------------------------- cycle time

def test_cycle_time_by_hand():
    m = default_mill()                     # rapid 30000 mm/min on every axis
    recs = [ToolpathRecord(1, "p", 1, "tool_change", tool=3),
            ToolpathRecord(2, "p", 2, "rapid", {"X": 0.0, "Y": 0.0, "Z": 0.0}, {"X": 100.0, "Y": 0.0, "Z": 0.0}, tool=3),
            ToolpathRecord(3, "p", 3, "linear", {"X": 100.0, "Y": 0.0, "Z": 0.0}, {"X": 200.0, "Y": 0.0, "Z": 0.0},
                           feed=600.0, feed_mode="per_min", tool=3),
            ToolpathRecord(4, "p", 4, "dwell", dwell_s=2.0, tool=3)]
    ct = check_records(recs, m).cycle
    assert ct.rapid_s == pytest.approx(0.2) and ct.feed_s == pytest.approx(10.0)
    assert ct.per_tool == {3: pytest.approx(12.2)} and ct.total_s == pytest.approx(12.2)
    # with 1000 mm/s^2: the feed move gains v/a = 0.01 s; the rapid (500 mm/s) never reaches full
    # speed in 100 mm: a triangle, 2 * sqrt(100 / 1000) s
    for ax in m.axes.values():
        ax.accel = 1000.0
    ct = check_records(recs, m).cycle
    assert ct.feed_s == pytest.approx(10.01)
    assert ct.rapid_s == pytest.approx(2 * math.sqrt(0.1))


def test_cycle_time_keeps_speed_through_a_straight_junction():
    m = default_mill()
    for ax in m.axes.values():
        ax.accel = 1000.0
    line = lambda i, x0, x1: ToolpathRecord(i, "p", i, "linear", {"X": x0, "Y": 0.0, "Z": 0.0},
                                            {"X": x1, "Y": 0.0, "Z": 0.0}, feed=600.0, feed_mode="per_min")
    one = check_records([line(1, 0.0, 100.0)], m).cycle.feed_s
    two = check_records([line(1, 0.0, 50.0), line(2, 50.0, 100.0)], m).cycle.feed_s
    assert two == pytest.approx(one)


# --------------------------------------------------------------------------- machine file and CLI

def test_rule_table_matches_the_catalogue():
    from nctrans import catalogue
    cat = catalogue.load()
    for code, (name, severity) in RULES.items():
        r = cat.get(code)
        assert r is not None and (r.name, r.severity) == (name, severity)


def run_cli(*args, cwd, monkeypatch, capsys):
    """The CLI in process (as `nctrans ARGS` run in `cwd`): (exit code, stdout, stderr)."""
    from nctrans import cli
    monkeypatch.chdir(cwd)
    capsys.readouterr()
    rc = cli.main(list(args))
    out, err = capsys.readouterr()
    return rc, out, err


def test_cli_check_lint_and_formats(tmp_path, monkeypatch, capsys):
    (tmp_path / "m.toml").write_text(MACHINE + fixture_toml(tmp_path))
    (tmp_path / "p.nc").write_text(HEAD + "G0 X0 Y0\nG1 Z20 F500\nG1 X50\nG0 X350\nM30\n")
    rc, out, err = run_cli("check", "p.nc", "--machine", "m.toml", cwd=tmp_path, monkeypatch=monkeypatch, capsys=capsys)
    assert rc == 1, err
    assert "p.nc:7:1: error[NC310]" in out and "p.nc:8:1: error[NC301]" in out
    assert "estimated cycle time" in out and "T1" in out and "total" in out
    rc, out, _ = run_cli("check", "p.nc", "--machine", "m.toml", "--format", "json", cwd=tmp_path, monkeypatch=monkeypatch, capsys=capsys)
    doc = json.loads(out)
    assert rc == 1 and {"NC301", "NC310"} <= {d["rule"] for d in doc["diagnostics"]}
    hit = next(f for f in doc["findings"] if f["rule"] == "NC310")
    assert hit["line"] == 7 and hit["kind"] == "tool-hits-fixture" and set(hit["position"]) == {"X", "Y", "Z"}
    assert doc["cycle_time"]["p.nc"]["total_s"] > 0
    rc, out, _ = run_cli("lint", "p.nc", "--machine", "m.toml", "--format", "github", cwd=tmp_path, monkeypatch=monkeypatch, capsys=capsys)
    assert rc == 1 and "line=7" in out and "title=NC310" in out
    rc, out, _ = run_cli("lint", "p.nc", cwd=tmp_path, monkeypatch=monkeypatch, capsys=capsys)          # no machine: no machine findings
    assert "NC3" not in out
    # a clean program exits 0 and still prints the cycle time
    (tmp_path / "ok.nc").write_text(HEAD + "G0 X0 Y0\nG1 X10 F500\nM30\n")
    rc, out, _ = run_cli("check", "ok.nc", "--machine", "m.toml", cwd=tmp_path, monkeypatch=monkeypatch, capsys=capsys)
    assert rc == 0 and "estimated cycle time" in out
    # --fixture from the command line
    rc, out, _ = run_cli("check", "p.nc", "--fixture", "clamp.stl", cwd=tmp_path, monkeypatch=monkeypatch, capsys=capsys)
    assert rc == 1 and "NC310" in out


def test_bad_machine_files_exit_2_with_the_key_path(tmp_path, monkeypatch, capsys):
    (tmp_path / "p.nc").write_text("G0 X1\nM30\n")
    (tmp_path / "bad.toml").write_text('[[tools]]\nnumber = 1\nradius = "wide"\n[axes.X]\nmin = 5\nmax = 1\n')
    rc, _, err = run_cli("check", "p.nc", "--machine", "bad.toml", cwd=tmp_path, monkeypatch=monkeypatch, capsys=capsys)
    assert rc == 2 and "tools[0].radius" in err and "axes.X" in err and "Traceback" not in err
    (tmp_path / "nomesh.toml").write_text('[[fixtures]]\nmesh = "missing.stl"\n')
    rc, _, err = run_cli("check", "p.nc", "--machine", "nomesh.toml", cwd=tmp_path, monkeypatch=monkeypatch, capsys=capsys)
    assert rc == 2 and "missing.stl" in err and "Traceback" not in err
    (tmp_path / "junk.stl").write_bytes(b"\x00\x01 not a mesh")
    (tmp_path / "junk.toml").write_text('[stock]\nmesh = "junk.stl"\n')
    rc, _, err = run_cli("check", "p.nc", "--machine", "junk.toml", cwd=tmp_path, monkeypatch=monkeypatch, capsys=capsys)
    assert rc == 2 and "junk.stl" in err and "Traceback" not in err
    (tmp_path / "both.toml").write_text('[stock]\nmesh = "a.stl"\nbox = { min = [0, 0, 0], max = [1, 1, 1] }\n')
    rc, _, err = run_cli("check", "p.nc", "--machine", "both.toml", cwd=tmp_path, monkeypatch=monkeypatch, capsys=capsys)
    assert rc == 2 and "stock" in err


def test_check_modules_name_no_dialect():
    out = subprocess.run([sys.executable, str(ROOT.parent / "shared" / "tools" / "dialect_leaks.py"),
                          str(ROOT / "nctrans" / "check"), "0"], capture_output=True, text=True)
    if out.returncode not in (0, 1) or "leaks" not in out.stdout:
        pytest.skip("dialect_leaks.py not available")
    assert "leaks 0" in out.stdout, out.stdout


# --------------------------------------------------------------------------- more solids and machines

def wedge_stl(tmp_path: Path) -> str:
    """A ramp of stock: X-50..30, Y-50..50, bottom Z-20, top falling from Z0 at X-50 to Z-20 at X30."""
    import trimesh
    v = [(-50, -50, -20), (30, -50, -20), (30, 50, -20), (-50, 50, -20), (-50, -50, 0), (-50, 50, 0)]
    f = [(0, 2, 1), (0, 3, 2), (0, 1, 4), (3, 5, 2), (0, 4, 5), (0, 5, 3), (1, 2, 5), (1, 5, 4)]
    trimesh.Trimesh(vertices=v, faces=f, process=True).export(tmp_path / "wedge.stl")
    return "wedge.stl"


def test_stock_from_a_mesh_follows_its_top(tmp_path):
    stock = f'[stock]\nmesh = "{wedge_stl(tmp_path)}"\ncell = 0.25\n'
    # the top is at Z = -(x + 50) / 4: at tip Z-10 the material begins at X-10; the cutter
    # (radius 5) reaches X-5 when its centre stops at X0 (clear), X-15 at X-10 (1.25 mm deep)
    near = HEAD + "G0 X20 Y0 Z5\nG0 Z-10\nG0 X0\nM30\n"
    assert not only(check(tmp_path, near, stock), "NC313")
    deep = HEAD + "G0 X20 Y0 Z5\nG0 Z-10\nG0 X-10\nM30\n"
    [f] = only(check(tmp_path, deep, stock), "NC313")
    assert f.line == 7 and f.amount == pytest.approx(1.25, abs=0.1)


@pytest.mark.parametrize("ending", ["obj", "ply"])
def test_fixtures_as_obj_and_ply(tmp_path, ending):
    import trimesh
    trimesh.creation.box(bounds=[CLAMP_LO, CLAMP_HI]).export(tmp_path / f"clamp.{ending}")
    prog = HEAD + "G0 X0 Y0\nG1 Z20 F500\nG1 X50\nM30\n"
    [f] = only(check(tmp_path, prog, f'[[fixtures]]\nmesh = "clamp.{ending}"\n'), "NC310")
    assert f.line == 7 and 34.9 < f.position["X"] < 35.01


def test_a_fixture_placed_in_a_work_offset(tmp_path):
    # the clamp is given in G55 coordinates (X+100): it sits at X140..160 on the machine
    extra = ('[offsets.G55]\nX = 100.0\nY = 0.0\nZ = 0.0\n[[fixtures]]\nname = "clamp"\nframe = "G55"\n'
             'box = { min = [40, -10, 0], max = [60, 10, 50] }\n')
    prog = HEAD + "G0 X0 Y0\nG1 Z20 F500\nG1 X100\nG1 X150\nM30\n"
    [f] = only(check(tmp_path, prog, extra), "NC310")
    assert f.line == 8 and 134.9 < f.position["X"] < 135.01


def test_what_the_check_does_not_model_is_said():
    from nctrans.machine import Mesh
    m = default_mill()
    m.fixtures = [Mesh(box={"min": [40.0, -10.0, 0.0], "max": [60.0, 10.0, 50.0]})]
    recs = [ToolpathRecord(1, "p", 3, "rapid", {"X": 0.0, "Y": 0.0, "Z": 20.0, "A": 0.0},
                           {"X": 0.0, "Y": 0.0, "Z": 20.0, "A": 0.0}),
            ToolpathRecord(2, "p", 4, "rapid", {"X": 0.0, "Y": 0.0, "Z": 20.0, "A": 0.0},
                           {"X": 50.0, "Y": 0.0, "Z": 20.0, "A": 90.0})]
    found = check_records(recs, m).findings
    [axis] = only(found, "NC305")
    [skip] = only(found, "NC306")
    assert (axis.line, axis.subject) == (4, "A") and skip.line == 4
    assert not only(found, "NC310")          # not judged, and said so
    lathe = default_lathe()
    lathe.fixtures = list(m.fixtures)
    [note] = only(check_records(recs[:1], lathe).findings, "NC306")
    assert "lathe" in note.message


def test_constant_surface_speed_of_a_real_lathe_program(tmp_path):
    """corpus/iso-t/u-w-g50-css.nc: G96 S200 (m/min) limited by G50 S2000. G50 X100 shifts X, so
    the radius is program X, not machine X. Line 9 ends at radius 25 (200000 / (2 pi 25) = 1273 rpm),
    line 10 at radius 5 (6366 rpm, held to 2000 by G50 S2000)."""
    src = ROOT / "corpus" / "iso-t" / "u-w-g50-css.nc"
    if not src.exists():
        pytest.skip("iso-t conformance programs not present")

    def findings(max_rpm):
        (tmp_path / "lathe.toml").write_text(
            f'kind = "lathe"\n[axes.X]\nmin = -300.0\nmax = 300.0\n[axes.Z]\nmin = -300.0\nmax = 300.0\n'
            f'[spindle]\nmax_rpm = {max_rpm}\n')
        machine = pipeline.load_machine(str(tmp_path / "lathe.toml"))
        return only(check_loaded(pipeline.load(str(src), "iso-t", stream=True), machine)[1].findings, "NC304")
    [f] = findings(1500)               # 2000 rpm allowed by G50 over a 1500 rpm spindle
    assert f.line == 10 and f.amount == pytest.approx(500.0) and "surface speed" in f.message
    [f] = findings(1200)               # 1273 rpm already at radius 25
    assert f.line == 9 and f.amount == pytest.approx(200000 / (2 * math.pi * 25) - 1200, rel=1e-6)
    assert not findings(2500)          # G50 S2000 keeps it under the spindle's maximum
