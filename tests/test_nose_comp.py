"""Tool-nose radius compensation on a lathe (G41/G42 with the tip direction, nctrans.interp.nose).

The records hold the imaginary tool tip: the nose centre runs at the radius from the contour, the
tip lies at the tip direction's corner of the nose. Checked by hand on an OD chamfer, against
LinuxCNC's rs274 (its tool orientation is Fanuc's with X mirrored) for every tip direction, and
through conversion to Sinumerik and back."""
from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import rs274 as h
from conftest import CORPUS
from nctrans.dialects.base import get
from nctrans.interp.cutter_comp import CutterCompensator, PlannedMove
from nctrans.interp.interpreter import interpret
from nctrans.interp.nose import NoseCompensator, tip_offset
from nctrans.machine import MachineError, Tool, default_lathe, load

REPO = Path(__file__).resolve().parent.parent
needs_rs274 = pytest.mark.skipif(shutil.which("rs274") is None, reason="LinuxCNC rs274 not installed")
# Fanuc/Haas tip direction -> LinuxCNC tool orientation (the same picture with X pointing down)
LINUXCNC_ORIENTATION = {0: 0, 1: 4, 2: 3, 3: 2, 4: 1, 5: 5, 6: 8, 7: 7, 8: 6, 9: 9}

CHAMFER = "G18 G21 G99\nT0101\nG00 X20. Z5.\nG42 G01 Z0. F0.1\nX30. Z-5.\nZ-20.\nG40 G00 X50.\nM30\n"


def lathe(radius=0.8, tip=3):
    m = default_lathe()
    m.tools = [Tool(1, radius=radius, tip=tip)]
    return m


def run(text, machine):
    res = get("iso-t").parse(text, "nose.nc")
    diags = list(res.diagnostics)
    recs = [r for r in interpret(res.program, machine, diagnostics=diags)
            if r.kind in ("rapid", "linear", "arc")]
    return recs, diags


def rounded(p):
    return {k: round(v, 6) for k, v in p.items()}


def test_od_chamfer_with_tip_3_by_hand():
    """Nose radius 0.8, tip 3 (tip = centre - 0.8 in X and Z), G42 along -Z (radii: X10 -> 15).
    Entry ends where the offset lines X = 10.8 and X + Z = 10 + 0.8*sqrt2 meet (concave):
    centre (10.8, 0.331371), tip (10, -0.468629). The chamfer's offset end is the corner plus
    0.8/sqrt2 along (X+, Z+): centre (15.565685, -4.434315). The convex corner gets an arc of 0.8
    round (15, -5) to centre (15.8, -5); the Z cut runs its tip on X15 and ends at Z-20.8; G40
    ends at the programmed point."""
    recs, diags = run(CHAMFER, lathe())
    assert not diags, diags
    got = [(r.line, r.kind, rounded(r.end)) for r in recs]
    assert got == [(3, "rapid", {"X": 10.0, "Z": 5.0}),
                   (4, "linear", {"X": 10.0, "Z": -0.468629}),
                   (5, "linear", {"X": 14.765685, "Z": -5.234315}),
                   (6, "arc", {"X": 15.0, "Z": -5.8}),
                   (6, "linear", {"X": 15.0, "Z": -20.8}),
                   (7, "rapid", {"X": 25.0, "Z": -20.0})]
    arc = recs[3]
    assert rounded(arc.center) == {"X": 14.2, "Z": -5.8, "Y": 0.0} and arc.direction == "ccw"
    assert [rounded(r.start) for r in recs[1:]] == [rounded(r.end) for r in recs[:-1]]


def test_tip_0_and_9_control_the_nose_centre_as_on_a_mill():
    centre, _ = run(CHAMFER, lathe(tip=9))
    zero, _ = run(CHAMFER, lathe(tip=0))
    assert [rounded(r.end) for r in centre] == [rounded(r.end) for r in zero]
    assert rounded(centre[1].end) == {"X": 10.8, "Z": 0.331371}       # the offset lines' meeting
    assert rounded(centre[-2].end) == {"X": 15.8, "Z": -20.0}


@pytest.mark.parametrize("tip", range(10))
def test_tip_offset_is_radius_along_the_tip_vector(tip):
    dx, dz = tip_offset(tip, 0.4)
    if tip in (0, 9):
        assert (dx, dz) == (0, 0)
    else:
        assert math.isclose(math.hypot(dx, dz), 0.4 * (math.sqrt(2) if tip <= 4 else 1.0))


def test_no_tip_direction_is_nc235_and_taken_as_the_centre():
    m = default_lathe()
    m.tools = [Tool(1, radius=0.8)]
    recs, diags = run(CHAMFER, m)
    assert [(d.rule, d.line, d.severity) for d in diags] == [("NC235", 4, "warning")]
    centre, _ = run(CHAMFER, lathe(tip=0))
    assert [rounded(r.end) for r in recs] == [rounded(r.end) for r in centre]


def test_zero_nose_radius_runs_the_programmed_path_whatever_the_tip():
    recs, diags = run(CHAMFER, lathe(radius=0.0, tip=3))
    assert not diags
    assert [rounded(r.end) for r in recs][1:4] == [{"X": 10.0, "Z": 0.0}, {"X": 15.0, "Z": -5.0},
                                                   {"X": 15.0, "Z": -20.0}]


def test_machine_toml_tip_out_of_range_is_refused(tmp_path):
    p = tmp_path / "lathe.toml"
    p.write_text('kind = "lathe"\n[[tools]]\nnumber = 1\nradius = 0.8\ntip = 12\n')
    with pytest.raises(MachineError, match="tip"):
        load(p)
    p.write_text('kind = "lathe"\ntip_directions = { 1 = 2 }\nradius_offsets = { 1 = 0.4 }\n')
    m = load(p)
    assert m.tip_direction(1) == 2 and m.radius_offset(1) == 0.4 and m.tip_direction(3) is None


# ------------------------------------------------------------------------------ against rs274

CONTOURS = {
    # (Z, X) moves in radius after the start: OD with chamfer, convex and concave arcs, face down
    "od-arcs": ((5.0, 12.0), [("G1", 0.0, 10.0), ("G1", -5.0, 15.0), ("G2", -10.0, 20.0, -10.0, 15.0),
                              ("G1", -20.0, 20.0), ("G3", -25.0, 25.0, -20.0, 25.0), ("G1", -30.0, 25.0)],
                (-30.0, 40.0)),
    "face-down": ((2.0, 30.0), [("G1", 0.0, 25.0), ("G1", 0.0, 5.0), ("G1", -3.0, 2.0), ("G1", -10.0, 2.0)],
                  (-10.0, 0.0)),
}


def _program(start, segs, side, exit_pt):
    lines = ["G18 G21 G90 G40", "T1 M6", f"G0 Z{start[0]} X{start[1]}", "(BEGIN)",
             "G42" if side == "right" else "G41"]
    prev = start
    for s in segs:
        if s[0] == "G1":
            lines.append(f"G1 Z{s[1]} X{s[2]} F100")
        else:
            lines.append(f"{s[0]} Z{s[1]} X{s[2]} K{s[3] - prev[0]} I{s[4] - prev[1]} F100")
        prev = (s[1], s[2])
    lines += [f"G40 G1 Z{exit_pt[0]} X{exit_pt[1]}", "(END)", "M2"]
    return "\n".join(lines) + "\n"


def _nose_moves(start, segs, side, exit_pt, radius, tip):
    comp = NoseCompensator(side, radius, tip)
    pos = {"Z": start[0], "X": start[1], "Y": 0.0}
    out = []
    for s in segs:
        end = {**pos, "Z": s[1], "X": s[2]}
        if s[0] == "G1":
            mv = PlannedMove("linear", dict(pos), end)
        else:
            mv = PlannedMove("arc", dict(pos), end, center={"Z": s[3], "X": s[4]},
                             direction="cw" if s[0] == "G2" else "ccw")
        out += comp.push(mv)
        pos = end
    out += comp.finish(PlannedMove("linear", dict(pos), {**pos, "Z": exit_pt[0], "X": exit_pt[1]}))
    assert not comp.problems
    return out


@needs_rs274
@pytest.mark.rs274
@pytest.mark.parametrize("tip", range(10))
@pytest.mark.parametrize("name,side", [("od-arcs", "right"), ("face-down", "left")])
def test_matches_rs274_with_the_tool_orientation(tmp_path, name, side, tip):
    start, segs, exit_pt = CONTOURS[name]
    radius = 0.8
    table = f"T1 P1 Z0 D{2 * radius / 25.4:.12f} Q{LINUXCNC_ORIENTATION[tip]} ;\n"
    calls, message = h.calls_between_markers(tmp_path, _program(start, segs, side, exit_pt), table)
    want = []
    for call, args in calls:
        if call in ("STRAIGHT_FEED", "STRAIGHT_TRAVERSE", "ARC_FEED"):
            v = [float(x) for x in args.split(",")]
        if call in ("STRAIGHT_FEED", "STRAIGHT_TRAVERSE"):
            want.append(("linear", (v[2], v[0]), None))
        elif call == "ARC_FEED":
            want.append(("arc", (v[0], v[1]), (v[2], v[3])))
    got = [(m.kind, (m.end["Z"], m.end["X"]), None if m.center is None else (m.center["Z"], m.center["X"]))
           for m in _nose_moves(start, segs, side, exit_pt, radius, tip)]
    assert [g[0] for g in got] == [w[0] for w in want], (got, want, message)
    for g, w in zip(got, want):
        assert all(abs(a - b) <= 1e-4 for a, b in zip(g[1], w[1])), (g, w)
        if w[2] is not None:
            assert all(abs(a - b) <= 1e-4 for a, b in zip(g[2], w[2])), (g, w)


def test_tip_path_is_the_centre_path_moved_by_the_tip_vector_except_entry_start_and_exit_end():
    start, segs, exit_pt = CONTOURS["od-arcs"]
    centre = CutterCompensator("right", 0.8, "ZX")
    pos = {"Z": start[0], "X": start[1]}
    plain = []
    for s in segs:
        end = {**pos, "Z": s[1], "X": s[2]}
        mv = (PlannedMove("linear", dict(pos), end) if s[0] == "G1" else
              PlannedMove("arc", dict(pos), end, center={"Z": s[3], "X": s[4]},
                          direction="cw" if s[0] == "G2" else "ccw"))
        plain += centre.push(mv)
        pos = end
    plain += centre.finish(PlannedMove("linear", dict(pos), {**pos, "Z": exit_pt[0], "X": exit_pt[1]}))
    tipped = _nose_moves(start, segs, "right", exit_pt, 0.8, 2)      # tip 2: +X, -Z
    assert len(plain) == len(tipped)
    for i, (a, b) in enumerate(zip(plain, tipped)):
        dx_end = 0.0 if i == len(plain) - 1 else 0.8
        assert math.isclose(b.end["X"], a.end["X"] + dx_end, abs_tol=1e-9)
        assert math.isclose(b.end["Z"], a.end["Z"] - dx_end, abs_tol=1e-9)
        dx_start = 0.0 if i == 0 else 0.8
        assert math.isclose(b.start["X"], a.start["X"] + dx_start, abs_tol=1e-9)


# ------------------------------------------------------------------------------ conversion

def _cli(*args):
    return subprocess.run([sys.executable, "-m", "nctrans", *args], capture_output=True, text=True,
                          cwd=REPO, timeout=120)


def test_corpus_g42_program_keeps_its_nose_path_through_sinumerik(tmp_path):
    """enier-haas-o20013 turns with G42 and T0101 (inch): with a 1/64" nose radius, tip 3, the
    Sinumerik conversion (G42 with D1) and the way back run the same tip path."""
    machine = tmp_path / "lathe.toml"
    machine.write_text('kind = "lathe"\n[spindle]\nmax_rpm = 4000\n'
                       '[[tools]]\nnumber = 1\nradius = 0.396875\ntip = 3\n'
                       '[[tools]]\nnumber = 2\nradius = 0.2\ntip = 3\n')
    src = CORPUS / "iso-turn" / "enier-haas-o20013.nc"
    m = load(machine)
    recs, _ = run(src.read_text(encoding="utf-8"), m)
    plain, _ = run(src.read_text(encoding="utf-8"), default_lathe())
    assert [r.end for r in recs] != [r.end for r in plain]          # compensation moved the path
    mpf, back = tmp_path / "a.mpf", tmp_path / "b.nc"
    p = _cli("convert", "--from", "iso-t", str(src), "--to", "sinumerik", "-o", str(mpf))
    assert p.returncode == 0, p.stdout + p.stderr
    assert "G42" in mpf.read_text()
    p = _cli("equiv", "--machine", str(machine), "--from-a", "iso-t", "--from-b", "sinumerik",
             str(src), str(mpf))
    assert p.returncode == 0, p.stdout + p.stderr
    p = _cli("convert", "--from", "sinumerik", str(mpf), "--to", "iso-t", "-o", str(back))
    assert p.returncode == 0, p.stdout + p.stderr
    p = _cli("equiv", "--machine", str(machine), "--from-a", "iso-t", "--from-b", "iso-t",
             str(src), str(back))
    assert p.returncode == 0, p.stdout + p.stderr


@pytest.mark.rs274
def test_flattened_nose_path_runs_in_rs274_with_the_same_moves(rs274, rs274_cache):
    """--flatten folds the nose compensation into the tip path: rs274 runs it as plain moves."""
    from nctrans.lower.flatten import flatten
    from test_flatten import rs274_run
    machine = lathe()
    text = CHAMFER.replace("T0101\n", "T0101\nG97 S500 M03\n")        # rs274 feeds per rev only turning
    src = get("iso-t").parse(text, "nose.nc").program
    records = [r for r in interpret(src, machine, diagnostics=[]) if r.kind in ("rapid", "linear", "arc")]
    flat = flatten(src, machine, diagnostics=[])
    res = get("iso-m").emit(flat)
    assert "G42" not in res.text and not [d for d in res.diagnostics if d.severity == "error"]
    result = rs274_run(res.text, "isot-nose", machine, rs274_cache)
    assert result.completed, result.message
    problem = h.compare(result.moves, [h.Motion.of(r) for r in records], "nose.nc")
    assert problem is None, problem
