"""G98 after G99 holes: how the tool reaches the next hole is the control's, keyed by profile (issue #8).

A Fanuc (iso-m default, ISO seed 5.1) positions the G98 hole at R and returns to the initial level
after drilling; LinuxCNC (rules/iso-m.toml [options.profiles.linuxcnc] cycle_positioning) moves in the
plane at the initial level, rising from R as it goes (rs274 2.9, checked below).
"""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

import rs274 as harness
from nctrans import api
from nctrans.machine import Machine, Tool

# initial level Zi = 10, R = 2, bottom -5; G99 hole at (1,2), then G98 holes at X3 and X5
PROGRAM = "G17 G90 G0 X0 Y0 Z10\nG99 G81 X1 Y2 Z-5 R2 F100\nG98 X3\nX5\nG80\nM2\n"


def _moves(profile):
    tp = api.toolpath(PROGRAM, "iso-m", machine=Machine(tools=[Tool(number=1, length=0.0, radius=1.0)]),
                      profile=profile)
    recs = [r for r in tp if r.kind in ("rapid", "linear")]
    return [(r.line, r.kind, r.end["X"], r.end["Y"], r.end["Z"]) for r in recs]


def test_fanuc_default_positions_the_g98_hole_at_r():
    hole3 = [m for m in _moves(None) if m[0] == 3]
    assert hole3 == [(3, "rapid", 3, 2, 2), (3, "linear", 3, 2, -5), (3, "rapid", 3, 2, 10)]


def test_linuxcnc_profile_rises_to_the_initial_level_on_the_way():
    hole3 = [m for m in _moves("linuxcnc") if m[0] == 3]
    assert hole3 == [(3, "rapid", 3, 2, 10), (3, "rapid", 3, 2, 2), (3, "linear", 3, 2, -5),
                     (3, "rapid", 3, 2, 10)]


def test_linuxcnc_profile_matches_rs274(rs274, rs274_cache):
    src = rs274_cache / "g98_after_g99.ngc"
    src.write_text(PROGRAM)
    table = harness.write_tool_table(rs274_cache / "g98_tools.tbl", [(1, 0.0, 1.0)])
    ref = harness.run_rs274(src, table, rs274_cache / "g98_after_g99.out")
    assert ref.completed, ref.message
    tp = api.toolpath(src, "iso-m", machine=Machine(tools=[Tool(number=1, length=0.0, radius=1.0)]),
                      profile="linuxcnc")
    got = [harness.Motion.of(r) for r in tp if r.kind in ("rapid", "linear", "arc")]
    assert harness.compare(ref.moves, got, "g98_after_g99") is None
    # and the Fanuc default is not rs274's here (the two differ at the G98 hole)
    fanuc = [harness.Motion.of(r) for r in api.toolpath(src, "iso-m") if r.kind in ("rapid", "linear", "arc")]
    assert harness.compare(ref.moves, fanuc, "fanuc") is not None


def test_toolpath_command_takes_the_profile(tmp_path):
    (tmp_path / "p.nc").write_text(PROGRAM)

    def run(*extra):
        return subprocess.run([sys.executable, "-m", "nctrans", "toolpath", "p.nc", *extra], cwd=tmp_path,
                              capture_output=True, text=True)
    out = run("--profile", "linuxcnc")
    assert out.returncode == 0, out.stderr
    line3 = [json.loads(x) for x in out.stdout.splitlines() if json.loads(x).get("line") == 3]
    assert line3[0]["end"]["Z"] == 10.0 and line3[0]["start"]["Z"] == 2.0
    bad = run("--profile", "bogus")
    assert bad.returncode == 2 and "haas, linuxcnc" in bad.stderr and "Traceback" not in bad.stderr


@pytest.mark.parametrize("dialect,profile,mode", [("iso-m", None, "current"), ("iso-m", "linuxcnc", "clear_level"),
                                                  ("iso-m", "haas", "current"), ("sinumerik", None, "current")])
def test_positioning_by_dialect_and_profile_is_data(dialect, profile, mode):
    from nctrans.interp.cycles import cycle_table
    assert cycle_table().position_at(dialect, profile) == mode
