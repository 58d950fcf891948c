"""ISO -> Sinumerik: a construct Sinumerik cannot express and that cannot be lowered to plain motion
(on its own, nor with the whole program) is refused at its place: `SETAL(65002, ..)` stands where
it was (NC412 warning, exit 0, as a Sinumerik subprogram file's construct converted to ISO), the
rest keeps its structure, and the converted run agrees with the source on everything before the
alarm. Its meaning is never guessed (a Haas G47, an unknown G41.2, a PLC input the path depends
on); a syntax error still refuses the conversion."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import nctrans
from conftest import CORPUS
from nctrans.dialects.base import get
from nctrans.dialects.sinumerik.emitter import NOT_CONVERTED_ALARM

ISO = CORPUS / "iso-mill"


def _alarm(line: int) -> str:
    return f'SETAL({NOT_CONVERTED_ALARM}, "NOT CONVERTED: SOURCE LINE {line}")'


def _convert(src):
    conv = nctrans.transpile(src, read="iso-m", write="sinumerik")
    assert conv.text is not None, [d.message for d in conv.diagnostics if d.severity == "error"]
    assert not [d for d in conv.diagnostics if d.rule == "NC402"]
    back = get("sinumerik").parse(conv.text, "out.mpf")
    assert not [d for d in back.diagnostics if d.severity == "error"]
    return conv


def _in_place(conv) -> list[int]:
    return sorted(d.line for d in conv.diagnostics if d.rule == "NC412")


def _stops_at_alarm(src, conv, out_line: int, read_a: str = "iso-m"):
    """The source and its conversion agree on everything the conversion runs; it stops with
    alarm 65002 at `out_line` of its text."""
    same = nctrans.equiv(src, conv.text, read_a=read_a, read_b="sinumerik")
    stops = [(d.line, d.message) for d in same.diagnostics if d.rule == "NC221" and d.file != str(src)]
    assert (out_line, f"the program raises alarm {NOT_CONVERTED_ALARM}") in [
        (line, m.split(":")[0]) for line, m in stops], stops
    assert not same and same.difference is not None and same.difference.at_end, same.message


# ------------------------------------------------------------------ by hand

G47 = "G0 X0 Y0 Z5\nG1 Z-1 F100\nX10\nG47 P0 (AB) X1 Y1 I0 J.1 R.05 Z-.005 F15 E10\nG0 Z5\nX20\nM30\n"


def test_an_unmodelled_code_is_an_alarm_at_its_place_and_the_rest_is_kept():
    conv = _convert(G47)
    assert _in_place(conv) == [4]
    assert "G47" in next(d.message for d in conv.diagnostics if d.rule == "NC412")
    assert conv.text.splitlines()[1:] == [
        "G0 G54 G64", "G0 X0 Y0 Z5", "F100 G1 Z-1", "X10", _alarm(4), "G0 Z5", "X20", "M30"]
    # the run: rapid to (0,0,5), feed to Z-1, feed to X10, then the alarm (hand)
    moves = [(r.kind, r.end["X"], r.end["Z"]) for r in nctrans.toolpath(conv.text, "sinumerik")
             if r.kind in ("rapid", "linear")]
    assert moves == [("rapid", 0.0, 5.0), ("linear", 0.0, -1.0), ("linear", 10.0, -1.0)]
    _stops_at_alarm(G47, conv, 6)


def test_strict_refuses_what_is_refused_in_place():
    conv = nctrans.transpile(G47, read="iso-m", write="sinumerik", strict=True)
    assert conv.text is None
    assert 4 in [d.line for d in conv.diagnostics if d.severity == "error"]


def test_cli_exit_code_is_that_of_a_subprogram_file_refused_in_place(tmp_path):
    src = tmp_path / "part.nc"
    src.write_text(G47)
    out = tmp_path / "part.mpf"
    run = subprocess.run([sys.executable, "-m", "nctrans", "convert", str(src), "--to", "sinumerik",
                          "-o", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert f"{src}:4:1: warning[NC412]" in run.stderr
    assert _alarm(4) in out.read_text().splitlines()
    assert src.read_text() == G47


def test_a_branch_on_a_plc_input_is_refused_in_place_never_run_one_way():
    # before: lowered to plain motion with the condition taken as false (`G1 X5` then `X10`), a
    # guess at what only the machine knows; now the IF is the alarm and the rest stays as written
    src = "G0 X0 Y0 Z5\nIF [#1005 EQ 1] GOTO 10\nG1 X5 F100\nN10 G1 X10 F100\nM30\n"
    conv = _convert(src)
    assert _in_place(conv) == [2]
    assert "#1005" in next(d.message for d in conv.diagnostics if d.rule == "NC412")
    assert conv.text.splitlines()[1:] == [
        "G0 G54 G64", "G0 X0 Y0 Z5", _alarm(2), "F100 G1 X5", "N10 F100 G1 X10", "M30"]
    assert not [d for d in conv.diagnostics if "plain motion here" in d.message]
    # a target that does not refuse in place refuses the conversion instead of guessing
    fagor = nctrans.transpile(src, read="iso-m", write="fagor")
    assert fagor.text is None and [d.line for d in fagor.diagnostics if d.rule == "NC402"] == [2]


def test_a_loop_on_a_plc_input_is_one_alarm_for_the_whole_loop():
    src = "#1=0\nG0 X0 Y0 Z5\nWHILE [#1005 EQ 0] DO1\nG0 X1\nEND1\nG1 X10 F100\nM30\n"
    conv = _convert(src)
    assert _in_place(conv) == [3]
    assert conv.text.splitlines()[1:] == [
        "G0 G54 G64", "R1=0", "G0 X0 Y0 Z5", _alarm(3), "F100 G1 X10", "M30"]
    _stops_at_alarm(src, conv, 5)


def test_a_syntax_error_is_never_refused_in_place(tmp_path):
    src = "G0 X0 Y0\nG1 [your start] F10\nX5\nM30\n"
    conv = nctrans.transpile(src, read="iso-m", write="sinumerik")
    assert conv.text is None
    assert [(d.rule, d.line) for d in conv.diagnostics if d.severity == "error"] == [("NC402", 2)]
    assert not [d for d in conv.diagnostics if d.rule == "NC412"]
    (tmp_path / "t.nc").write_text(src)
    run = subprocess.run([sys.executable, "-m", "nctrans", "convert", str(tmp_path / "t.nc"), "--to",
                          "sinumerik", "-o", str(tmp_path / "t.mpf")], capture_output=True, text=True)
    assert run.returncode != 0 and not (tmp_path / "t.mpf").exists()


# ------------------------------------------------------------------ the real corpus

def _corpus(name: str) -> Path:
    path = ISO / name
    if not path.is_file():
        pytest.skip("shared corpus not found")
    return path


def _out_line(conv, source_line: int) -> int:
    return conv.text.splitlines().index(_alarm(source_line)) + 1


def test_haas_g47_engraving_is_refused_at_its_line():
    src = _corpus("kiely-haas-4x3-block.nc")
    conv = _convert(src)
    assert _in_place(conv) == [140]
    lines = conv.text.splitlines()
    at = lines.index("N535 " + _alarm(140))
    assert lines[at - 1].startswith("N530 S4000 M3") and lines[at + 1].startswith("N540 T2 M6")
    _stops_at_alarm(src, conv, at + 1)


def test_unknown_g41_2_is_refused_at_its_line():
    src = _corpus("lmhdpro-titan-tormach-ready-edited.nc")
    conv = _convert(src)
    assert _in_place(conv) == [3332]
    _stops_at_alarm(src, conv, _out_line(conv, 3332))


def test_plc_inputs_and_offset_writes_of_a_pallet_program_are_refused_in_place():
    src = _corpus("mojimould-O80000001-main")
    conv = _convert(src)
    found = _in_place(conv)
    # #1005, #1004 (PLC inputs), then the G10 offset writes of palette 1 and 2 (lines 48-52, 63-67)
    assert found[:8] == [20, 24, 46, 48, 49, 50, 51, 52] and 63 in found and 67 in found
    _stops_at_alarm(src, conv, _out_line(conv, 20))


def test_cncsimulator_g12_and_a_subprograms_g73_are_refused_in_place():
    # G12 (a CNCSimulator hole pattern no seed defines) cannot be lowered, so neither can the
    # whole program that would have carried the G73 of subprogram O1000: both alarms; the run
    # stops at the G73, in the first call of O1000 (source line 21)
    src = _corpus("donpayne-cncsimulator-example.cnc")
    conv = _convert(src)
    assert _in_place(conv) == [61, 70]
    _stops_at_alarm(src, conv, _out_line(conv, 70))


def test_a_template_with_placeholders_stays_refused():
    conv = nctrans.transpile(_corpus("stcline-maze-G91-incremental.nc"), read="iso-m", write="sinumerik")
    assert conv.text is None
    assert [d.line for d in conv.diagnostics if d.rule == "NC402"] == [13, 19]


def test_written_as_it_goes_the_text_is_the_same(tmp_path):
    from nctrans.outfile import OutputFile
    src = _corpus("kiely-haas-4x3-block.nc")
    whole = nctrans.transpile(src, read="iso-m", write="sinumerik")
    target = tmp_path / "out.mpf"
    out = OutputFile(target)
    streamed = nctrans.transpile(src, read="iso-m", write="sinumerik", out=out)
    assert streamed.text == ""
    out.commit()
    assert target.read_text() == whole.text
    assert _in_place(streamed) == [140]
