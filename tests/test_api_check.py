"""`nctrans.api.check`: the machine check from Python, with the answers `nctrans check` prints.

Expected findings are worked out by hand from the program text and the machine below (G54 zero,
no tool lengths: machine coordinates are program coordinates).
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from nctrans import api

MACHINE = """
name = "api-vmc"
[axes.X]
min = -100.0
max = 100.0
[axes.Y]
min = -100.0
max = 100.0
[axes.Z]
min = -100.0
max = 100.0
[spindle]
max_rpm = 10000
"""

PROGRAM = "G21 G90 G54\nT1 M6\nS12000 M3\nG0 X50 Y0 Z10\nG1 X120 F1000\nM30\n"


def test_check_text_finds_what_the_cli_finds(tmp_path):
    (tmp_path / "m.toml").write_text(MACHINE)
    res = api.check(PROGRAM, "iso-m", tmp_path / "m.toml")
    assert not res and res.machine == "api-vmc" and res.moves == 2
    got = sorted((f.rule, f.line, f.subject) for f in res.findings)
    assert got == [("NC301", 5, "X"), ("NC304", 3, "spindle")]
    over = next(f for f in res.findings if f.rule == "NC301")
    assert over.amount == pytest.approx(20.0) and over.position["X"] == pytest.approx(120.0)
    assert sorted(d.rule for d in res.diagnostics if d.rule.startswith("NC3")) == ["NC301", "NC304"]
    # 70 mm at F1000 = 4.2 s of feed; the cycle-time table is what the CLI prints after findings
    assert res.cycle_time["feed_s"] == pytest.approx(4.2, abs=0.01)
    assert "total" in res.report()
    # the same file through the CLI's JSON: the same findings
    (tmp_path / "p.nc").write_text(PROGRAM)
    out = subprocess.run([sys.executable, "-m", "nctrans", "check", str(tmp_path / "p.nc"), "--from", "iso-m",
                          "--machine", str(tmp_path / "m.toml"), "--format", "json"],
                         capture_output=True, text=True)
    cli = sorted((f["rule"], f["line"], f["subject"]) for f in json.loads(out.stdout)["findings"])
    assert out.returncode == 1 and cli == got
    path_res = api.check(tmp_path / "p.nc", "iso-m", tmp_path / "m.toml")
    assert sorted((f.rule, f.line) for f in path_res.findings) == [("NC301", 5), ("NC304", 3)]
    assert path_res.label.endswith("p.nc")


def test_a_clean_program_is_truthy_and_a_parsed_program_checks_too(tmp_path):
    (tmp_path / "m.toml").write_text(MACHINE)
    clean = "G21 G90 G54\nG0 X50 Y0 Z10\nG1 X100 F1000\nM30\n"       # X100 is on the limit
    assert api.check(clean, "iso-m", tmp_path / "m.toml")
    program = api.parse(PROGRAM, "iso-m")
    res = api.check(program, machine=tmp_path / "m.toml")
    assert sorted((f.rule, f.line) for f in res.findings) == [("NC301", 5), ("NC304", 3)]


def test_fixtures_from_arguments_and_errors(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    (tmp_path / "m.toml").write_text(MACHINE)
    trimesh.creation.box(bounds=[[70, -10, 0], [80, 10, 30]]).export(tmp_path / "clamp.stl")
    res = api.check("G21 G90 G54\nG0 X50 Y0 Z10\nG1 X90 F1000\nM30\n", "iso-m", tmp_path / "m.toml",
                    fixtures=[tmp_path / "clamp.stl"])
    assert [(f.rule, f.line) for f in res.findings] == [("NC310", 3)]
    with pytest.raises(api.NCInputError, match="not found"):
        api.check(PROGRAM, "iso-m", tmp_path / "m.toml", fixtures=[tmp_path / "missing.stl"])
    with pytest.raises(api.UnknownDialectError):
        api.check(PROGRAM, "no-such-dialect")
    with pytest.raises(api.NCProgramError) as e:
        api.check(PROGRAM, "iso-m", tmp_path / "m.toml", error_level=api.ErrorLevel.RAISE)
    assert {d.rule for d in e.value.diagnostics} >= {"NC301", "NC304"}


@pytest.mark.parametrize("dialect,text", [
    ("sinumerik", "G90 G54\nT1 D1\nM6\nS12000 M3\nG0 X50 Y0 Z10\nG1 X120 F1000\nM30\n"),
    ("fagor", "%P\nG90\nT1 D1\nM06\nS12000 M03\nG00 X50 Y0 Z10\nG01 X120 F1000\nM30\n"),
])
def test_every_dialect_the_same(tmp_path, dialect, text):
    (tmp_path / "m.toml").write_text(MACHINE)
    res = api.check(text, dialect, tmp_path / "m.toml")
    n = text.count("\n")
    assert sorted((f.rule, f.line) for f in res.findings) == sorted([("NC301", n - 1), ("NC304", n - 3)])
