"""The pre-commit hook (.pre-commit-hooks.yaml), tried with pre-commit's own `try-repo` on a sample
repository in a temporary directory, as a shop would before adding it to its configuration.
pre-commit installs nctrans from this repository as a regular wheel in an environment of its own,
so this also proves the hook works from an installed package, outside the checkout."""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from nctrans.dialects import base

ROOT = Path(__file__).resolve().parents[1]
HOOKS = ROOT / ".pre-commit-hooks.yaml"
PRE_COMMIT = Path(sys.executable).with_name("pre-commit")


def _hook() -> dict:
    import yaml          # pre-commit's own dependency
    (hook,) = yaml.safe_load(HOOKS.read_text())
    return hook


def test_hook_matches_every_dialect_ending_in_any_case():
    pattern = re.compile(_hook()["files"])
    endings = {e for name in base.names() for e in base.get(name).extensions}
    assert endings
    for e in endings:
        for name in (f"part{e.lower()}", f"PART{e.upper()}", f"dir/Part{e.capitalize()}"):
            assert pattern.search(name), f"the hook does not match {name}"
    for name in ("notes.txt", "part.nc.bak", "setup.py"):
        assert not pattern.search(name)


def _git(repo: Path, *args: str) -> None:
    subprocess.run(["git", *args], cwd=repo, check=True, capture_output=True,
                   env={**os.environ, "GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t",
                        "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@t"})


@pytest.mark.skipif(not PRE_COMMIT.exists(), reason="pre-commit is in the dev extra")
def test_try_repo_on_a_sample_repository():
    base_dir = Path(tempfile.mkdtemp(prefix="nctrans-precommit-"))
    try:
        repo = base_dir / "shop"
        repo.mkdir()
        _git(repo, "init", "-q")
        (repo / "O1000.NC").write_text("G0 X0 Y0\nG1 X10\nM30\n")             # NC202: no feed
        (repo / "part.MPF").write_text("DEF REAL LEN=5\nG1 X=LEN F100\nM30\n")
        (repo / "readme.txt").write_text("G1 X10\n")                          # not an NC file
        _git(repo, "add", ".")
        env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
        env["PRE_COMMIT_HOME"] = str(base_dir / "cache")
        env["NCTRANS_CACHE_DIR"] = str(base_dir / "nctrans-cache")
        cmd = [str(PRE_COMMIT), "try-repo", str(ROOT), "nctrans-lint", "--all-files"]
        run = subprocess.run(cmd, cwd=repo, env=env, capture_output=True, text=True, timeout=600)
        out = run.stdout + run.stderr
        assert run.returncode == 1, out
        assert "O1000.NC:2:1: error[NC202]" in out, out
        assert "part.MPF" not in out.split("nctrans lint", 1)[-1] and "readme.txt" not in out, out

        (repo / "O1000.NC").write_text("G0 X0 Y0\nG1 X10 F100\nM30\n")
        _git(repo, "add", ".")
        run = subprocess.run(cmd, cwd=repo, env=env, capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, run.stdout + run.stderr
    finally:
        shutil.rmtree(base_dir, ignore_errors=True)
