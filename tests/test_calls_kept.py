"""Calls kept across dialects: a call of a subprogram that is not in the program is written as a
call in the target (NC404), and a Sinumerik PROC file becomes the ISO O-number subprogram that call
reaches, so the two converted files together run as the two sources did."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import nctrans
from conftest import CORPUS
from nctrans.dialects.iso_m.plan import stable_number

CALLER = "G17 G90 G71\nG0 X0 Y0 Z10\nWIDEN(3, 4)\nG0 X1\nM30\n"
PROC = "PROC WIDEN(REAL DX, REAL DY)\nG1 X=DX Y=DY F100\nG0 Z=DX+DY\nRET\n"


def test_unknown_call_is_kept_with_a_warning_not_refused():
    conv = nctrans.transpile(CALLER, read="sinumerik", write="iso-m")
    assert conv.ok, [d.format_text() for d in conv.diagnostics]
    number = stable_number("WIDEN", set())
    assert f"G65 P{number} A3. B4." in conv.text.splitlines()
    warn = [d for d in conv.diagnostics if d.rule == "NC404"]
    assert [(d.line, d.severity) for d in warn] == [(3, "warning")]
    assert f"O{number}" in warn[0].message


def test_proc_file_and_its_caller_convert_to_files_that_run_together(tmp_path):
    src = tmp_path / "sin"
    out = tmp_path / "iso"
    src.mkdir()
    out.mkdir()
    (src / "MAIN.MPF").write_text(CALLER)
    (src / "WIDEN.SPF").write_text(PROC)
    number = stable_number("WIDEN", set())
    proc = nctrans.transpile(src / "WIDEN.SPF", read="sinumerik", write="iso-m")
    assert proc.ok and proc.text.splitlines()[1] == f"O{number} (WIDEN)"
    # converted on its own, the caller keeps the call (NC404) to the number the PROC file took
    main = nctrans.transpile(CALLER, read="sinumerik", write="iso-m")
    (out / "main.nc").write_text(main.text)
    (out / f"O{number}.nc").write_text(proc.text)
    same = nctrans.equiv(src / "MAIN.MPF", out / "main.nc", read_a="sinumerik", read_b="iso-m")
    assert same, same.message
    # moves of the subprogram are there: X3 Y4, then Z7
    records = [r for r in nctrans.toolpath(out / "main.nc", dialect="iso-m") if r.kind in ("linear", "rapid")]
    assert any(r.end["X"] == 3.0 and r.end["Y"] == 4.0 for r in records)
    assert any(r.end["Z"] == 7.0 for r in records)


def test_corpus_caller_and_proc_file_are_equivalent_converted(tmp_path):
    daily, warmup = CORPUS / "sinumerik" / "syil-DAILY.MPF", CORPUS / "sinumerik" / "syil-WARMUP_CYCLE.SPF"
    if not (daily.is_file() and warmup.is_file()):
        pytest.skip("syil programs not in the shared corpus")
    src, out = tmp_path / "sin", tmp_path / "iso"
    src.mkdir()
    out.mkdir()
    shutil.copy(daily, src / "DAILY.MPF")
    shutil.copy(warmup, src / "WARMUP_CYCLE.SPF")
    number = stable_number("WARMUP_CYCLE", set())
    main = nctrans.transpile(daily, read="sinumerik", write="iso-m")      # WARMUP_CYCLE not beside it
    assert main.ok, [d.format_text() for d in main.diagnostics if d.severity == "error"]
    assert any(d.rule == "NC404" for d in main.diagnostics)
    proc = nctrans.transpile(warmup, read="sinumerik", write="iso-m")
    assert proc.ok
    (out / "daily.nc").write_text(main.text)
    (out / f"O{number}.nc").write_text(proc.text)
    same = nctrans.equiv(src / "DAILY.MPF", out / "daily.nc", read_a="sinumerik", read_b="iso-m")
    assert same, same.message


# ---------------------------------------------------------------- equiv with kept calls

def test_unresolved_call_is_an_opaque_event_in_the_toolpath():
    records = list(nctrans.toolpath(CALLER, dialect="sinumerik"))
    kinds = [r.kind for r in records]
    call = records[kinds.index("call")]
    assert (call.call, call.args, call.line) == ("WIDEN", [3.0, 4.0], 3)
    assert kinds.index("call") > 0 and "rapid" in kinds[kinds.index("call"):]


def test_equiv_compares_kept_calls_by_identity_and_arguments():
    conv = nctrans.transpile(CALLER, read="sinumerik", write="iso-m")
    same = nctrans.equiv(CALLER, conv.text, read_a="sinumerik", read_b="iso-m")
    assert same, same.message
    number = stable_number("WIDEN", set())
    changed = conv.text.replace(f"G65 P{number} A3. B4.", f"G65 P{number} A3. B5.")
    assert changed != conv.text
    other = nctrans.equiv(CALLER, changed, read_a="sinumerik", read_b="iso-m")
    assert not other and "call" in other.message
    elsewhere = conv.text.replace(f"G65 P{number}", f"G65 P{number + 1}")
    assert not nctrans.equiv(CALLER, elsewhere, read_a="sinumerik", read_b="iso-m")


# ---------------------------------------------------------------- M99 at the end of a main program

def test_m99_main_program_repeats_as_a_loop_never_one_pass():
    conv = nctrans.transpile("G0 X0 Y0\nG1 X10 F100\nG0 X0\nM99\n", read="iso-m", write="sinumerik")
    assert conv.ok, [d.format_text() for d in conv.diagnostics]
    lines = [ln.strip() for ln in conv.text.splitlines()]
    assert lines.index("LOOP") < lines.index("F100 G1 X10") < lines.index("ENDLOOP")
    assert not any(ln in ("M30", "M2", "M17") for ln in lines)
    assert any(d.rule == "NC401" and "LOOP" in d.message for d in conv.diagnostics)


def test_m99_of_a_macro_reading_its_arguments_is_its_return():
    conv = nctrans.transpile("G1 X#24 Y#25 F100\nM99\n", read="iso-m", write="sinumerik")
    assert conv.ok, [d.format_text() for d in conv.diagnostics]
    assert "LOOP" not in conv.text and conv.text.splitlines()[-1].strip() in ("M17", "RET")
