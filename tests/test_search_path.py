"""Subprograms are found beside the caller, or on a configured search path — and nowhere else."""
import json
import os
import subprocess
import sys
from pathlib import Path


def _toolpath(tmp_path: Path, *extra: str, env=None):
    cmd = [sys.executable, "-m", "nctrans", "toolpath", str(tmp_path / "main" / "PART.MPF"),
           "--from", "sinumerik", *extra]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60,
                          env={**os.environ, **(env or {})})
    return proc, [json.loads(l) for l in proc.stdout.splitlines()]


def _setup(tmp_path: Path) -> None:
    (tmp_path / "lib").mkdir()
    (tmp_path / "main").mkdir()
    (tmp_path / "lib" / "SIDE.SPF").write_text("PROC SIDE(REAL L)\nG1 X=L F100\nRET\n")
    (tmp_path / "main" / "PART.MPF").write_text("G0 X0 Y0\nSIDE(25)\nM30\n")


def test_call_resolves_only_on_the_search_path(tmp_path):
    _setup(tmp_path)
    proc, records = _toolpath(tmp_path)
    assert "NC103" in proc.stderr and not [r for r in records if r["kind"] == "linear"]
    proc, records = _toolpath(tmp_path, "--search-path", str(tmp_path / "lib"))
    moves = [r for r in records if r["kind"] == "linear"]
    assert proc.returncode == 0 and moves[0]["end"]["X"] == 25.0
    assert moves[0]["file"].endswith("SIDE.SPF") and moves[0]["line"] == 2


def test_environment_search_path(tmp_path):
    _setup(tmp_path)
    _, records = _toolpath(tmp_path, env={"NCTRANS_PATH": str(tmp_path / "lib")})
    assert [r["end"]["X"] for r in records if r["kind"] == "linear"] == [25.0]


def test_a_missing_search_directory_is_a_usage_error(tmp_path):
    _setup(tmp_path)
    proc, _ = _toolpath(tmp_path, "--search-path", str(tmp_path / "nope"))
    assert proc.returncode == 2 and "not a directory" in proc.stderr and "Traceback" not in proc.stderr
