"""Each diagnostic once at its file:line. Linting a caller with its macro file reported the macro's
own line twice (once reached through the caller's G65 run, once in the file's own run); a missing
#PCALL file's reason was repeated in the refusal of the next line as if it were that line's."""
from __future__ import annotations

from pathlib import Path

from nctrans import api, cli

# line 4 divides by zero: NC106 at O9005.nc:4, whichever run reaches it
MACRO = "O9005\n#100=1\nG1 X#24 F100.\nG1 X[#24/0]\nN9 M99\n"
CALLER = "O1000\nG0 X0 Y0 Z5.\nG65 P9005 X10.\nM30\n"
FAGOR = 'G0 X0 Y0 Z5\n#PCALL "SUBX.NC" A1\n#PCALL "SUBY.NC" A1 B2\nM30\n'


def _files(tmp_path: Path) -> tuple[Path, Path]:
    (tmp_path / "O9005.nc").write_text(MACRO)
    (tmp_path / "O1000.nc").write_text(CALLER)
    return tmp_path / "O1000.nc", tmp_path / "O9005.nc"


def test_api_lint_of_caller_and_macro_reports_the_macro_line_once(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    caller, macro = _files(tmp_path)
    alone = [d for d in api.lint(macro) if d.rule == "NC106"]
    assert [(Path(d.file).name, d.line) for d in alone] == [("O9005.nc", 4)]
    both = [d for d in api.lint([caller, macro]) if d.rule == "NC106"]
    assert [(Path(d.file).name, d.line) for d in both] == [("O9005.nc", 4)]


def test_cli_lint_of_caller_and_macro_prints_it_once(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    _files(tmp_path)
    cli.main(["lint", "O1000.nc", "O9005.nc"])
    out = capsys.readouterr().out
    assert out.count("error[NC106]") == 1 and "O9005.nc:4:1: error[NC106]" in out


def test_missing_pcall_file_reported_once_per_call(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "main.pim").write_text(FAGOR)
    nc103 = [(d.line, d.message) for d in api.lint(tmp_path / "main.pim") if d.rule == "NC103"]
    assert nc103 == [(2, "subprogram SUBX.NC not found; the call is skipped"),
                     (3, "subprogram SUBY.NC not found; the call is skipped")]
    cli.main(["lint", "main.pim", "--target", "iso-m"])
    out = capsys.readouterr().out
    assert out.count("[NC103]") == 2
    # line 3's refusal names line 2 as where its reason is, not as if line 3's file were SUBX.NC
    refusal3 = next(x for x in out.splitlines() if x.startswith("main.pim:3:1: error[NC402]"))
    assert "at line 2, subprogram SUBX.NC not found" in refusal3


def test_equiv_of_a_program_with_itself_reports_once(tmp_path):
    (tmp_path / "main.pim").write_text(FAGOR)
    result = api.equiv(tmp_path / "main.pim", tmp_path / "main.pim")
    # both sides read the same file: lines 2 and 3 once each, not twice
    assert sorted(d.line for d in result.diagnostics if d.rule == "NC103") == [2, 3]
