"""What a shop configures: suppression comments, the dialect pragma, the project configuration
file, --select/--ignore/--fail-on and --target, through the CLI as a user runs it."""
from __future__ import annotations

import json
import os
import re

import pytest

from nctrans import cli
from nctrans.linting import suppress

RULE = re.compile(r":(\d+):\d+: \w+\[(NC\d{3})\]")


def lint(capsys, *argv) -> tuple[int, list[tuple[int, str]]]:
    """(exit status, [(line, rule)]) of `nctrans lint ...` in text format."""
    capsys.readouterr()
    status = cli.main(["lint", *argv])
    out = capsys.readouterr()
    return status, [(int(l), r) for l, r in RULE.findall(out.out)]


@pytest.fixture
def shop(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / ".git").mkdir()             # the configuration search stops at the repository root
    return tmp_path


# --------------------------------------------------------------------------- suppressions

def test_suppression_comment_drops_only_its_rule_on_its_line(shop, capsys):
    (shop / "a.nc").write_text("G1 X10 ; nctrans: ignore NC202\nG90 G91 X5 F100\nM30\n")
    status, found = lint(capsys, "a.nc")
    assert found == [(2, "NC201")] and status == 0          # NC201 is a warning
    (shop / "b.nc").write_text("G1 X10 ; nctrans: ignore NC201\nM30\n")
    status, found = lint(capsys, "b.nc")
    assert (1, "NC202") in found and (1, "NC502") in found and status == 1


def test_parenthesis_form_prefixes_and_bare_ignore(shop, capsys):
    (shop / "a.nc").write_text("G1 X10 (nctrans: ignore NC2)\nG90 G91 X5 F100 ( nctrans: ignore )\nM30\n")
    assert lint(capsys, "a.nc") == (0, [])


def test_sinumerik_semicolon_suppression(shop, capsys):
    (shop / "a.mpf").write_text('DEF STRING[4] TXT\nTXT="ABCDEFGH" ; nctrans: ignore NC110, NC109\nM30\n')
    assert lint(capsys, "a.mpf") == (0, [])


def test_file_wide_suppression_and_malformed_codes(shop, capsys):
    (shop / "a.nc").write_text("; nctrans: ignore-file NC501\ng1 x10 f100\ng1 x20 ; nctrans: ignore feed\nm30\n")
    status, found = lint(capsys, "a.nc", "--from", "iso-m")
    assert found == [(3, "NC503")]


def test_scan_reports_lines_and_columns():
    sup = suppress.scan("G0 X0\n\nG1 X1 ; nctrans: ignore NC201, NC2\n", "f.nc")
    assert sup.by_line == {3: ("NC201", "NC2")} and sup.where[3] == 7


# --------------------------------------------------------------------------- dialect pragma

def test_first_line_pragma_chooses_the_dialect(shop, capsys):
    text = "DEF REAL LEN=5\nG1 X=LEN F100\nM30\n"
    (shop / "a.nc").write_text("; nctrans: dialect=sinumerik\n" + text)
    assert lint(capsys, "a.nc") == (0, [])
    # an ISO program in a file whose ending says Sinumerik; "(...)" is the ISO comment
    (shop / "b.mpf").write_text("%\n( nctrans: dialect iso-m )\n#1=5\nG1 X#1 F100\nM30\n%\n")
    assert lint(capsys, "b.mpf") == (0, [])
    (shop / "c.nc").write_text("; nctrans: dialect=klingon\n" + text)
    assert lint(capsys, "c.nc")[0] == 2


def test_from_overrides_the_pragma(shop, capsys):
    (shop / "a.nc").write_text("; nctrans: dialect=sinumerik\nG1 X10 F100\nM30\n")
    status, found = lint(capsys, "a.nc", "--from", "iso-m")
    assert status == 0


# --------------------------------------------------------------------------- configuration

SIEMENS_AS_NC = "DEF REAL LEN, WIDTH\nLEN=5\nG1 X=LEN F100\nG1 Y=WIDTH\nM30\n"   # WIDTH: NC111


def test_nctrans_toml_dialects_select_ignore_fail_on(shop, capsys):
    (shop / "cell2").mkdir()
    (shop / "cell2" / "part.nc").write_text(SIEMENS_AS_NC)
    (shop / "nctrans.toml").write_text('dialects = { "cell2/*.nc" = "sinumerik" }\nfail-on = "warning"\n')
    status, found = lint(capsys, "cell2")
    assert found == [(4, "NC111")] and status == 1           # warning fails with fail-on = warning
    assert lint(capsys, "cell2", "--fail-on", "error")[0] == 0   # the command line wins
    (shop / "nctrans.toml").write_text('dialects = { "cell2/*.nc" = "sinumerik" }\nignore = ["NC111"]\n')
    assert lint(capsys, "cell2") == (0, [])
    (shop / "nctrans.toml").write_text('dialects = { "cell2/*.nc" = "sinumerik" }\nselect = ["NC2"]\n')
    assert lint(capsys, "cell2") == (0, [])
    assert lint(capsys, "cell2", "--select", "NC1")[1] == [(4, "NC111")]


def test_pyproject_section_and_per_file_ignores(shop, capsys):
    (shop / "legacy").mkdir()
    (shop / "legacy" / "old.nc").write_text("g1 x10 f100\nm30\n")
    (shop / "new.nc").write_text("g1 x10 f100\nm30\n")
    (shop / "pyproject.toml").write_text('[project]\nname = "x"\n\n[tool.nctrans]\n'
                                         'per-file-ignores = { "legacy/*" = ["NC501"] }\n')
    status, found = lint(capsys, ".")
    assert found == [(1, "NC501")]
    capsys.readouterr()
    cli.main(["lint", ".", "--format", "json"])
    doc = json.loads(capsys.readouterr().out)
    assert [os.path.normpath(d["file"]) for d in doc["diagnostics"]] == ["new.nc"]


def test_config_machine_is_relative_to_the_file(shop, capsys):
    (shop / "cfg").mkdir()
    (shop / "cfg" / "vmc.toml").write_text(
        'name = "m"\nkind = "mill"\n[axes.X]\nkind = "linear"\nmin = 0.0\nmax = 1.0\n'
        '[[tools]]\nnumber = 1\nlength = 10.0\nradius = 3.0\n')
    (shop / "nctrans.toml").write_text('machine = "cfg/vmc.toml"\n')
    # an entry move of 2 mm: too short only for a tool of radius 3, which the configured machine has
    (shop / "a.nc").write_text("G17 G0 X0 Y0\nT1 M6\nS1000 M3\nG41 D1 G1 X2 Y0 F100\nG1 X20\nG40 G1 X30 Y-10\nM30\n")
    assert (4, "NC204") in lint(capsys, "a.nc")[1]            # the configured tool has a radius
    os.remove(shop / "cfg" / "vmc.toml")
    assert lint(capsys, "a.nc")[0] == 2


def test_invalid_configuration_is_a_usage_error(shop, capsys):
    (shop / "a.nc").write_text("G1 X10 F100\nM30\n")
    (shop / "nctrans.toml").write_text('selekt = ["NC1"]\n')
    capsys.readouterr()
    assert cli.main(["lint", "a.nc"]) == 2
    err = capsys.readouterr().err
    assert "nctrans.toml" in err and "selekt" in err
    (shop / "nctrans.toml").write_text('fail-on = "sometimes"\n')
    assert cli.main(["lint", "a.nc"]) == 2


def test_configuration_search_stops_at_the_repository_root(tmp_path, monkeypatch, capsys):
    (tmp_path / "nctrans.toml").write_text('ignore = ["NC2"]\n')      # outside the repository
    repo = tmp_path / "repo"
    (repo / ".git").mkdir(parents=True)
    (repo / "a.nc").write_text("G1 X10\nM30\n")
    monkeypatch.chdir(repo)
    assert lint(capsys, "a.nc")[1] == [(1, "NC202")]


# --------------------------------------------------------------------------- --target

def test_target_reports_what_the_conversion_would_lower(shop, capsys):
    (shop / "a.nc").write_text("G90 G0 X0 Y0 Z5\nG83 X10 Y10 Z-10 R2 Q2 F100\nG80\nM30\n")
    status, found = lint(capsys, "a.nc")
    assert not [r for _, r in found if r.startswith("NC4")]
    status, found = lint(capsys, "a.nc", "--target", "sinumerik")
    assert (2, "NC401") in found and status == 0
    assert not (shop / "a.mpf").exists()                        # nothing is written
    assert lint(capsys, "a.nc", "--target", "nosuch")[0] == 2
