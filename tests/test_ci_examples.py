"""The documented GitHub Actions workflow (docs/github-actions-nctrans.yml): its lint steps run as
written, in a directory of programs, and the SARIF it uploads validates against the official schema
and carries the catalogue and fingerprints."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import jsonschema
import pytest

from conftest import CORPUS, DATA

ROOT = Path(__file__).resolve().parents[1]
WORKFLOW = ROOT / "docs" / "github-actions-nctrans.yml"


def _steps() -> dict[str, dict]:
    import yaml
    doc = yaml.safe_load(WORKFLOW.read_text())
    return {s.get("name", s.get("uses", "")): s for s in doc["jobs"]["lint"]["steps"]}


def test_workflow_uploads_the_sarif_file_it_writes():
    steps = _steps()
    upload = next(s for s in steps.values() if "upload-sarif" in s.get("uses", ""))
    lint = steps["Lint (SARIF for code scanning)"]
    assert f"> {upload['with']['sarif_file']}" in lint["run"]
    assert upload.get("if") == "always()"


def _bash(script: str, cwd: Path, github_env: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, GITHUB_ENV=str(github_env),
               PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}")
    return subprocess.run(["bash", "-e", "-c", script], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=300)


def test_lint_steps_run_as_written(tmp_path):
    repo = tmp_path / "programs"
    repo.mkdir()
    shutil.copy(CORPUS / "iso-mill" / "kiely-haas-step-part.nc", repo / "step.nc")
    (repo / "bad.nc").write_text("G0 X0 Y0\nG1 X10\nM30\n")          # NC202
    github_env = tmp_path / "github_env"
    github_env.write_text("")
    steps = _steps()
    run = _bash(steps["Lint (SARIF for code scanning)"]["run"], repo, github_env)
    assert run.returncode == 0, run.stderr                  # the step records the failure instead
    assert "NCTRANS_FAILED=1" in github_env.read_text()
    doc = json.loads((repo / "nctrans.sarif").read_text())
    jsonschema.validate(doc, json.loads((DATA / "sarif-schema-2.1.0.json").read_text()))
    results = doc["runs"][0]["results"]
    bad = [r for r in results if r["ruleId"] == "NC202"]
    assert bad and bad[0]["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] == "bad.nc"
    assert all(r.get("partialFingerprints") for r in results)
    assert {r["id"] for r in doc["runs"][0]["tool"]["driver"]["rules"]} >= {"NC202", "NC001"}

    notes = _bash(steps["Annotate the pull request"]["run"], repo, github_env)
    assert "::error file=bad.nc,line=2" in notes.stdout
