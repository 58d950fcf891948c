"""Standard cycles nctrans does not model (issue 8): each is reported at its line as not modelled
and moves nothing; a PROC of the same name beside the program runs instead; --flatten refuses."""
from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from nctrans import api, cli, pipeline
from nctrans.source import from_text

ROOT = Path(__file__).resolve().parents[1]
TABLE = tomllib.loads((ROOT / "rules" / "cycles.toml").read_text()).get("unmodelled", [])
UNMODELLED = [u["name"] for u in TABLE if u.get("moves", True)]
MODELLED = [m["name"] for m in tomllib.loads((ROOT / "rules" / "cycles.toml").read_text()).get("milling", [])]


def test_the_issue_cycles_are_listed():
    # each is either modelled (rules [[milling]], tests/test_milling_cycles.py) or listed here
    for name in ("CYCLE71", "CYCLE72", "CYCLE76", "CYCLE77", "CYCLE90", "CYCLE93", "CYCLE95",
                 "CYCLE97", "POCKET1", "POCKET2", "POCKET3", "POCKET4", "SLOT1", "SLOT2",
                 "LONGHOLE"):
        assert (name in UNMODELLED) != (name in MODELLED), name


@pytest.mark.parametrize("name", UNMODELLED)
def test_unmodelled_cycle_is_reported_at_its_line_and_moves_nothing(name):
    text = f"G17 G90 G0 X0 Y0 Z20 F100 S1000 M3\n{name}(10, 0, 2, -5, 30, 20, 5)\nG0 X1\nM30\n"
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear", "arc")]
    assert [r.line for r in recs] == [1, 3]
    said = [d for d in ld.diagnostics if d.line == 2 and d.severity == "warning"]
    assert len(said) == 1 and "does not model" in said[0].message and name in said[0].message


def test_fail_on_warning_and_flatten_refuse(tmp_path, capsys):
    src = tmp_path / "p.mpf"
    src.write_text("G17 G90 G0 X0 Y0 Z20 F100 S1000 M3\nCYCLE72(\"KONTUR\", 10, 0, 2, -5)\nM30\n")
    assert cli.main(["lint", str(src), "--from", "sinumerik", "--fail-on", "warning"]) == 1
    conv = api.transpile(src.read_text(), "sinumerik", "iso-m", flatten=True)
    assert conv.text is None and any(d.rule == "NC402" and d.line == 2 for d in conv.diagnostics)


def test_a_proc_beside_the_program_runs_instead(tmp_path):
    (tmp_path / "CYCLE71.SPF").write_text("PROC CYCLE71(REAL RTP, REAL RFP, REAL SDIS, REAL DP)\n"
                                          "G1 X=RTP Y=RFP Z=DP\nRET\n")
    (tmp_path / "MAIN.MPF").write_text("G17 G90 G0 X0 Y0 Z20 F100\nCYCLE71(10, 3, 2, -1)\nM30\n")
    ld = pipeline.load(str(tmp_path / "MAIN.MPF"), "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind == "linear"]
    assert [(r.end["X"], r.end["Y"], r.end["Z"]) for r in recs] == [(10, 3, -1)]
    assert not [d for d in ld.diagnostics if d.severity in ("warning", "error")]


def test_settings_cycle_passes_without_a_warning():
    # CYCLE832 sets tolerance and continuous-path mode: no path of its own, nothing to report
    assert "CYCLE832" in [u["name"] for u in TABLE if u.get("moves") is False]
    text = "G17 G90 G0 X0 Y0 Z20 F100\nCYCLE832(0.01, 1, 1)\nG1 X5\nM30\n"
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear")]
    assert [r.end["X"] for r in recs] == [0, 5]
    assert not [d for d in ld.diagnostics if d.severity in ("warning", "error")]
