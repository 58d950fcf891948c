"""An ISO macro file (an O-number program that reads G65 arguments and returns with M99) converted
to Sinumerik on its own is the PROC its converted callers call: every argument letter a parameter in
the order a converted G65 call passes them (nctrans.calls.LETTER_LOCALS: A B C D E F H M Q R S T U V
W X Y Z I J K), so caller and macro file, each converted by itself, still make the same call.
Proven with equiv on the pair (ISO caller + O9001 beside it vs converted caller + L9001.spf)."""
from __future__ import annotations

from pathlib import Path

from nctrans import api

MACRO = "%\nO9001 (LINE TO)\nG1 X#24 Y#25 F#9\nIF[#26EQ#0]GOTO10\nG1 Z#26\nN10 #10=#1*2\nG0 X#10\nM99\n%\n"
CALLER = ("%\nO1000\nG0 X0 Y0 Z5\nG65 P9001 X10. Y5. F100. Z-2. A3.\n"
          "G65 P9001 X20. Y7. F200. Z-1. A1.\nM30\n%\n")
LETTERS = "A B C D E F H M Q R S T U V W X Y Z I J K".split()


def _sinumerik(text: str, read: str = "iso-m"):
    conv = api.transpile(text, read=read, write="sinumerik")
    assert conv.ok, [d.format_text() for d in conv.diagnostics if d.severity == "error"]
    return conv


def test_macro_file_is_a_proc_with_every_letter_in_call_order():
    conv = _sinumerik(MACRO)
    lines = conv.text.splitlines()
    body = [x for x in lines if not x.startswith(";")]
    assert body[0] == "PROC L9001(" + ", ".join(f"REAL ARG_{x}" for x in LETTERS) + ")"
    assert body[1] == "DEF REAL LOC10"
    # no power-on modes: a subprogram runs in its caller's
    assert not [x for x in body if x.startswith("G0 G54")]
    # X, Y, F are used bare (ISO drops the word when vacant): checked on entry; A is not, and Z
    # is used bare only after the macro's own vacancy test `IF[#26EQ#0]GOTO10` (no false stop)
    for letter, pos in (("F", 6), ("X", 16), ("Y", 17)):
        i = body.index(f"IF NOT $P_SUBPAR[{pos}]")
        assert body[i + 1].strip() == f'SETAL(65001, "ARGUMENT {letter} NOT PASSED")'
    assert "IF NOT $P_SUBPAR[1]" not in body
    assert "ARGUMENT Z NOT PASSED" not in conv.text
    assert "IF NOT $P_SUBPAR[18] GOTO N10" in body       # the vacancy test, as written in ISO
    assert "N10 LOC10=ARG_A*2" in body and body[-1] in ("RET", "M17")
    assert not [d for d in conv.diagnostics if d.rule == "NC414"]


def test_external_call_passes_letters_by_position():
    conv = _sinumerik(CALLER)
    # A=3 at 1, F=100 at 6, X at 16, Y at 17, Z at 18 (hand-counted in LETTERS)
    assert "L9001(3., , , , , 100., , , , , , , , , , 10., 5., -2.)" in conv.text.splitlines()
    assert "L9001(1., , , , , 200., , , , , , , , , , 20., 7., -1.)" in conv.text.splitlines()


def test_corpus_caller_o2001(tmp_path):
    from conftest import CORPUS
    src = CORPUS / "iso-mill" / "donpayne-haas-O2001-advanced-arcs.cnc"
    if not src.is_file():
        import pytest
        pytest.skip("shared corpus not found")
    conv = api.transpile(src, read="iso-m", write="sinumerik")
    # G65 P9001 A.125 C.625 V10100.: V is the 14th letter
    assert "L9001(.125, , .625, , , , , , , , , , , 10100.)" in conv.text.splitlines()


def _pair(tmp_path: Path, caller: str):
    iso, sin = tmp_path / "iso", tmp_path / "sin"
    iso.mkdir()
    sin.mkdir()
    (iso / "O1000.nc").write_text(caller)
    (iso / "O9001.nc").write_text(MACRO)
    (sin / "L9001.spf").write_text(_sinumerik(MACRO).text)
    (sin / "O1000.mpf").write_text(_sinumerik(caller).text)
    return iso / "O1000.nc", sin / "O1000.mpf"


def test_caller_and_macro_file_converted_apart_are_equivalent(tmp_path):
    iso, sin = _pair(tmp_path, CALLER)
    result = api.equiv(iso, sin)
    assert result.equivalent, result
    ends = [(r.kind, r.end) for r in api.toolpath(sin) if r.kind in ("linear", "rapid")]
    # hand-computed from the macro: each call feeds to X Y, down to Z, then rapid X = 2*A
    assert ends == [("rapid", {"X": 0.0, "Y": 0.0, "Z": 5.0}),
                    ("linear", {"X": 10.0, "Y": 5.0, "Z": 5.0}), ("linear", {"X": 10.0, "Y": 5.0, "Z": -2.0}),
                    ("rapid", {"X": 6.0, "Y": 5.0, "Z": -2.0}),
                    ("linear", {"X": 20.0, "Y": 7.0, "Z": -2.0}), ("linear", {"X": 20.0, "Y": 7.0, "Z": -1.0}),
                    ("rapid", {"X": 2.0, "Y": 7.0, "Z": -1.0})]


def test_a_left_out_argument_used_bare_stops_instead_of_moving_to_zero(tmp_path):
    # the first call leaves X out: ISO drops the X word of `G1 X#24 Y#25`; the PROC cannot tell a
    # dropped word from X0, so it stops with the alarm on entry, before any move of that call
    caller = CALLER.replace(" X10.", "")
    iso, sin = _pair(tmp_path, caller)
    tp = api.toolpath(sin)
    records = list(tp)
    assert [r.kind for r in records if r.kind in ("linear", "rapid")] == ["rapid"]
    assert any("65001" in d.message for d in tp.diagnostics)
    assert not api.equiv(iso, sin).equivalent


def test_a_left_out_argument_the_macro_tests_itself_runs_as_in_iso(tmp_path):
    # the first call leaves Z out: the macro's own `IF[#26EQ#0]GOTO10` skips `G1 Z#26` in ISO, and
    # the PROC's `IF NOT $P_SUBPAR[18] GOTO N10` does the same: no alarm on entry (was a false stop)
    caller = CALLER.replace(" Z-2.", "")
    iso, sin = _pair(tmp_path, caller)
    tp = api.toolpath(sin)
    ends = [(r.kind, r.end) for r in tp if r.kind in ("linear", "rapid")]
    assert not any("65001" in d.message for d in tp.diagnostics)
    # hand-computed: call 1 feeds to X10 Y5 at Z5, no Z move, rapid X = 2*3; call 2 as before
    assert ends == [("rapid", {"X": 0.0, "Y": 0.0, "Z": 5.0}),
                    ("linear", {"X": 10.0, "Y": 5.0, "Z": 5.0}),
                    ("rapid", {"X": 6.0, "Y": 5.0, "Z": 5.0}),
                    ("linear", {"X": 20.0, "Y": 7.0, "Z": 5.0}), ("linear", {"X": 20.0, "Y": 7.0, "Z": -1.0}),
                    ("rapid", {"X": 2.0, "Y": 7.0, "Z": -1.0})]
    assert api.equiv(iso, sin).equivalent


def test_macro_file_that_cannot_be_a_proc_says_so():
    conv = _sinumerik("O9002\n#[#1]=5\nG1 X#24 F100\nM99\n")
    found = [d for d in conv.diagnostics if d.rule == "NC414"]
    assert [(d.line, d.severity) for d in found] == [(1, "warning")]
    assert "computed number" in found[0].message
    assert "PROC" not in conv.text


def test_modal_g66_call_of_a_macro_file_is_mcall_with_the_same_parameters(tmp_path):
    macro = "%\nO9002\nG1 Z[#26-1.] F#9\nG0 Z5.\nM99\n%\n"
    caller = "%\nO1000\nG0 X0 Y0 Z5\nG66 P9002 Z-2. F50.\nG0 X10.\nG0 X20. Y5.\nG67\nG0 X0 Y0\nM30\n%\n"
    iso, sin = tmp_path / "iso", tmp_path / "sin"
    iso.mkdir()
    sin.mkdir()
    (iso / "O1000.nc").write_text(caller)
    (iso / "O9002.nc").write_text(macro)
    (sin / "L9002.spf").write_text(_sinumerik(macro).text)
    converted = _sinumerik(caller).text
    (sin / "O1000.mpf").write_text(converted)
    assert "MCALL L9002(, , , , , 50., , , , , , , , , , , , -2.)" in converted.splitlines()
    assert api.equiv(iso / "O1000.nc", sin / "O1000.mpf").equivalent
    # after each move the macro feeds to Z = -2 - 1 and back up (hand-computed)
    downs = [r.end for r in api.toolpath(sin / "O1000.mpf") if r.kind == "linear"]
    assert downs == [{"X": 10.0, "Y": 0.0, "Z": -3.0}, {"X": 20.0, "Y": 5.0, "Z": -3.0}]


def test_every_m99_of_a_macro_file_is_its_return(tmp_path):
    # an early M99 (a Renishaw-style macro returns from several places) was refused in place as
    # "a program restart in the middle of a main program": the PROC stopped there with alarm 65002.
    # Call A5: X5 then return; call A20: jump to N5, X10, return; then Y3 (hand-computed)
    macro = "%\nO9003\nIF[#1GT10]GOTO5\nG0 X#1\nM99\nN5 G0 X10\nM99\n%\n"
    caller = "%\nO1000\nG21 G90 G17\nG65 P9003 A5.\nG65 P9003 A20.\nG0 Y3\nM30\n%\n"
    conv = _sinumerik(macro)
    body = [x for x in conv.text.splitlines() if not x.startswith(";")]
    assert body.count("RET") + body.count("M17") == 2 and "65002" not in conv.text
    iso, sin = tmp_path / "iso", tmp_path / "sin"
    iso.mkdir()
    sin.mkdir()
    (iso / "O1000.nc").write_text(caller)
    (iso / "O9003.nc").write_text(macro)
    (sin / "L9003.spf").write_text(conv.text)
    (sin / "O1000.mpf").write_text(_sinumerik(caller).text)
    ends = [r.end["X"] for r in api.toolpath(sin / "O1000.mpf") if r.kind == "rapid"]
    assert ends == [5.0, 10.0, 10.0]
    assert api.equiv(iso / "O1000.nc", sin / "O1000.mpf").equivalent
