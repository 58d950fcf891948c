"""An ISO macro file linted or run on its own (no G65 caller): its M99 is its return, not a
restart (it used to be NC205 "the program restarts"), and the vacant arguments are said once
(NC227 at the first line reading one), not per line."""
from __future__ import annotations

from nctrans import api, cli

# the Renishaw O9810 pattern (test_macro_vacancy_flags.MACRO): Z vacant -> #26 = 5 -> G1 Z-5
O9810 = ("O9810\n#1=#5003\nIF[#26EQ#0]GOTO10\n#26=#26+1.\nN10\nIF[#26EQ#0]THEN#26=5.\n"
         "G1 Z-#26 F100.\nM99\n")
O9005 = "O9005\nG0 X#24 Y#25\nG1 Z-#26 F100.\nG0 Z5.\nM99\n"
MAIN_M99 = "O1000\nG0 X1.\nM99\n"


def test_o9810_alone_says_its_argument_once_and_no_restart(tmp_path, capsys):
    f = tmp_path / "O9810.nc"
    f.write_text(O9810)
    assert cli.main(["lint", str(f), "--from", "iso-m", "--fail-on", "warning"]) == 0
    out = capsys.readouterr().out
    assert "NC205" not in out
    assert out.count("[NC227]") == 1 and "O9810.nc:3:1: info[NC227]" in out and "#26 (Z)" in out


def test_every_argument_named_once_and_the_run_ends_at_m99():
    diags = api.lint(O9005, "iso-m")
    notes = [d for d in diags if d.rule == "NC227"]
    assert [(d.line, d.severity) for d in notes] == [(2, "info")]
    assert "#24 (X), #25 (Y), #26 (Z)" in notes[0].message
    assert not [d for d in diags if d.rule == "NC205"]
    recs = list(api.toolpath(O9005, "iso-m"))
    # vacant X/Y/Z: G0 to X0 Y0 (no move), G1 Z-[vacant] = Z0 (Fanuc: a vacant word is no word),
    # G0 Z5, then the stop at M99 (line 5) and nothing after
    assert [(r.line, r.kind) for r in recs][-2:] == [(4, "rapid"), (5, "stop")]
    assert recs[-2].end["Z"] == 5.0


def test_a_main_program_ending_m99_still_restarts():
    diags = api.lint(MAIN_M99, "iso-m")
    assert [d.rule for d in diags if d.rule in ("NC205", "NC227")] == ["NC205"]


def test_equiv_of_a_macro_file_with_itself_ends_at_m99():
    result = api.equiv(O9810, O9810, read_a="iso-m", read_b="iso-m")
    assert result.equivalent, result.message
    # one pass: the G1 Z-5 and the stop at M99 (it restarted until the step budget: 285715 records)
    assert "(2 and 2 toolpath records)" in result.message


def test_a_feed_from_an_argument_is_no_error_alone():
    # F#9: vacant when the file runs alone, the caller's G65 F.. otherwise: NC202 is the warning a
    # subprogram file gets (it moves at its caller's feed), not an error failing lint
    macro = "O9006\nG1 Z-#26 F#9\nM99\n"
    diags = [(d.rule, d.line, d.severity) for d in api.lint(macro, "iso-m")]
    assert ("NC202", 2, "warning") in diags and ("NC202", 2, "error") not in diags
    # a main program with no F is still the error
    assert ("NC202", 2, "error") in [(d.rule, d.line, d.severity)
                                     for d in api.lint("O1000\nG1 Z-5.\nM30\n", "iso-m")]
