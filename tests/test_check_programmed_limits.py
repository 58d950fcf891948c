"""Travel limits the program sets, enforced by `nctrans check` (NC302), in every dialect that has
them: Fagor G198/G199 (machine axis positions, G91 relative to the limit in force, 0/0 lifts an
axis's limits), Sinumerik G25/G26 under WALIMON (the tool tip, work offsets not applied), ISO G22
(a box the tool tip must not enter; G23 lifts it).

The machine: T1 is 100 mm long, G54 is zero, so under tool-length compensation the controlled
point the toolpath gives (the gauge line) is the programmed tip + 100 in Z. Every expected line
and amount is worked out by hand from the program text.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from nctrans import pipeline
from nctrans.check import check_loaded

MACHINE = """
name = "limits-vmc"
[axes.X]
min = -300.0
max = 300.0
[axes.Y]
min = -200.0
max = 200.0
[axes.Z]
min = -200.0
max = 300.0
[[tools]]
number = 1
length = 100.0
radius = 5.0
"""


def findings(tmp_path: Path, program: str, dialect: str, name: str):
    (tmp_path / name).write_text(program)
    (tmp_path / "m.toml").write_text(MACHINE)
    machine = pipeline.load_machine(str(tmp_path / "m.toml"))
    ld = pipeline.load(str(tmp_path / name), dialect, stream=True)
    diags, result = check_loaded(ld, machine)
    assert not [d for d in diags if d.severity == "error" and not d.rule.startswith("NC3")], diags
    return [f for f in result.findings if f.rule == "NC302"]


def lines(found) -> list[tuple[int, str]]:
    return sorted((f.line, f.subject) for f in found)


# --------------------------------------------------------------------------- Fagor G198/G199

def fagor(tmp_path, body: str):
    return findings(tmp_path, "%LIM\n" + body + "M30\n", "fagor", "p.nc")


def test_fagor_software_limits_at_the_block_that_breaks_them(tmp_path):
    # lines: 2 G198, 3 G199, 4 inside, 5 over X by 20, 6 under Y by 5
    found = fagor(tmp_path, "G90 G198 X-100 Y-50\nG199 X100 Y50\nG01 X100 Y50 F1000\n"
                            "G01 X120\nG00 X0 Y-55\n")
    assert lines(found) == [(5, "X"), (6, "Y")]
    amounts = {f.line: f.amount for f in found}
    assert amounts[5] == pytest.approx(20.0) and amounts[6] == pytest.approx(5.0)


def test_fagor_limits_are_machine_positions_whatever_the_work_offset(tmp_path):
    # G159 / work offsets do not move a software limit: here G92 shifts the program zero by 30,
    # so program X75 is machine X105 (over the limit 100) and program X65 is machine X95
    near = fagor(tmp_path, "G90 G199 X100\nG00 X30\nG92 X0\nG00 X65\n")
    over = fagor(tmp_path, "G90 G199 X100\nG00 X30\nG92 X0\nG00 X75\n")
    assert not near
    assert lines(over) == [(5, "X")] and over[0].amount == pytest.approx(5.0)


def test_fagor_incremental_limits_count_from_the_limit_in_force(tmp_path):
    # the manual's example: G90 G198 X-800, then G91 G198 X-700 makes the lower limit -1500 ...
    # on this machine: G198 X-100, then G91 G198 X50 makes it -50
    found = fagor(tmp_path, "G90 G198 X-100\nG91 G198 X50\nG90 G00 X-49\nG00 X-60\n")
    assert lines(found) == [(5, "X")] and found[0].amount == pytest.approx(10.0)


def test_fagor_zero_limits_lift_the_axis_and_computed_values_count(tmp_path):
    body = "P1=40\nG90 G199 X[P1*2]\nG00 X90\nG198 X0\nG199 X0\nG00 X200\n"
    assert lines(fagor(tmp_path, body)) == [(4, "X")]          # X80 from P1*2; lifted at line 6


# --------------------------------------------------------------------------- Sinumerik G25/G26

def sinumerik(tmp_path, body: str):
    return findings(tmp_path, "G90 G17 G54\nT1 D1\nM6\n" + body + "M30\n", "sinumerik", "p.mpf")


def test_sinumerik_working_area_bounds_the_tool_tip(tmp_path):
    # lines 4-5 set the area (the axis words are limits: nothing moves); the tip may reach Z10:
    # line 6 tip Z10 (gauge Z110) is on the limit, line 7 tip Z12 is 2 mm over, line 8 X is 5 over
    found = sinumerik(tmp_path, "G25 X-50 Y-50 Z-100\nG26 X50 Y50 Z10\nG0 Z10\nG0 Z12\nG0 Z5 X55\n")
    assert lines(found) == [(7, "Z"), (8, "X")]
    assert [round(f.amount, 6) for f in sorted(found, key=lambda f: f.line)] == [2.0, 5.0]


def test_sinumerik_walimof_switches_the_working_area_off_and_walimon_on(tmp_path):
    body = "G25 X-50\nG26 X50\nWALIMOF\nG0 X80\nWALIMON\nG0 X70\nG0 X40\n"
    assert lines(sinumerik(tmp_path, body)) == [(9, "X")]       # X80 at line 7 is under WALIMOF


def test_sinumerik_working_area_words_move_nothing(tmp_path):
    (tmp_path / "p.mpf").write_text("G0 X0 Y0\nG25 X-10 Y-10\nG26 X10 Y10\nM30\n")
    ld = pipeline.load(str(tmp_path / "p.mpf"), "sinumerik", stream=True)
    moves = [r for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear", "arc")]
    assert [r.line for r in moves] == [1]


# --------------------------------------------------------------------------- ISO G22/G23

def iso(tmp_path, body: str):
    return findings(tmp_path, "G21 G90 G17 G54\nT1 M6\nG43 H1 G0 Z50\n" + body + "M30\n", "iso-m", "p.nc")


def test_iso_g22_zone_is_found_where_a_straight_move_crosses_it(tmp_path):
    # the zone X-10..10 Y-10..10 Z-20..0 (tip); line 5 stays above it, line 6 goes down at
    # X-30 (outside), line 7 crosses it at Z-5 with both end points outside: 5 mm deep in Z
    body = "G22 X-10 Y-10 Z-20 I10 J10 K0\nG0 X-30 Y0\nG1 Z-5 F500\nG1 X30\n"
    found = iso(tmp_path, body)
    assert lines(found) == [(7, "zone")]
    assert found[0].amount == pytest.approx(5.0)
    assert found[0].position["Z"] == pytest.approx(95.0)         # the gauge line, tip Z-5


def test_iso_g22_near_miss_and_g23(tmp_path):
    assert not iso(tmp_path, "G22 X-10 Y-10 Z-20 I10 J10 K0\nG0 X-30 Y0\nG1 Z-5 F500\nG1 Y-10.5\n"
                             "G1 X30\n")
    assert not iso(tmp_path, "G22 X-10 Y-10 Z-20 I10 J10 K0\nG23\nG0 X-30 Y0\nG1 Z-5 F500\nG1 X30\n")
    # G22 alone switches the stored zone on again
    assert lines(iso(tmp_path, "G22 X-10 Y-10 Z-20 I10 J10 K0\nG23\nG0 X-30 Y0\nG1 Z-5 F500\n"
                               "G22\nG1 X30\n")) == [(9, "zone")]


def test_iso_g22_zone_in_an_arc_sweep(tmp_path):
    # a half circle about (0, -30) of radius 30 from (-30, -30) to (30, -30) counter-clockwise
    # passes (0, -60); clockwise it passes (0, 0), through the zone X-10..10 Y-10..10
    zone = "G22 X-10 Y-10 Z-20 I10 J10 K0\nG0 X-30 Y-30\nG1 Z-5 F500\n"
    assert not iso(tmp_path, zone + "G3 X30 Y-30 I30 J0\n")
    found = iso(tmp_path, zone + "G2 X30 Y-30 I30 J0\n")
    assert lines(found) == [(7, "zone")]
    assert found[0].amount == pytest.approx(5.0, abs=0.01)     # Z-5 is the shallowest side


def test_iso_g22_round_trips(tmp_path):
    from nctrans import api
    text = "G21 G90\nG22 X-10 Y-10 Z-20 I10 J10 K0\nG0 X5\nG23\nM30\n"
    out = api.transpile(text, "iso-m", "iso-m").text
    assert "G22 X-10 Y-10 Z-20 I10 J10 K0" in out and "\nG23" in out


def test_limits_from_another_control_are_not_written_as_if_they_meant_the_same(tmp_path):
    from nctrans import api
    res = api.transpile("%LIM\nG90 G198 X-100\nG00 X10\nM30\n", "fagor", "sinumerik")
    assert "G198" not in res.text.replace("NC402 fagor: G198", "")
    assert "G25" not in res.text
    assert any("G198" in d.message for d in res.diagnostics)


# --------------------------------------------------------------------------- not modelled

def test_sinumerik_protection_zones_are_reported_at_their_activation_not_passed(tmp_path, capsys):
    from nctrans import cli
    prog = ("G90 G17 G54\nNPROTDEF(1,FALSE,3,TRUE,FALSE)\nG0 X0 Y0\nG1 X100\nG1 Y100\nG1 X0\n"
            "G1 Y0\nEXECUTE(ERR)\nNPROT(1,2,0,0,0)\nG0 X50 Y50\nCPROT(1,0,0,0,0)\nM30\n")
    (tmp_path / "z.mpf").write_text(prog)
    (tmp_path / "m.toml").write_text(MACHINE)
    machine = pipeline.load_machine(str(tmp_path / "m.toml"))
    diags, result = check_loaded(pipeline.load(str(tmp_path / "z.mpf"), "sinumerik", stream=True), machine)
    assert sorted(f.line for f in result.findings if f.rule == "NC307") == [9, 11]
    assert {d.line for d in diags if d.rule == "NC220"} >= {2, 9, 11}
    code = cli.main(["check", str(tmp_path / "z.mpf"), "--from", "sinumerik", "--machine", str(tmp_path / "m.toml")])
    assert code == 1 and "z.mpf:9:1: warning[NC307]" in capsys.readouterr().out
