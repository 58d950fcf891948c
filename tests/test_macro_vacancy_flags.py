"""An ISO macro that tests an argument for vacancy after setting it (the Renishaw O9810 pattern:
IF[#26EQ#0] after #26=#26+..) converts to a Sinumerik PROC whose flag GIVEN_<letter> carries the
vacancy ($P_SUBPAR[i] on entry, set at each assignment); before, the file was not even seen as a
macro file (it sets #26) and was flattened with every argument vacant, exit 0."""
from __future__ import annotations

import pytest

from nctrans import api

MACRO = ("O9810\n#1=#5003\nIF[#26EQ#0]GOTO10\n#26=#26+1.\nN10\nIF[#26EQ#0]THEN#26=5.\n"
         "G1 Z-#26 F100.\nM99\n")
CALLER = "O1000\nG0 X0 Y0 Z10.\nG65 P9810 Z2.\nG65 P9810\nM30\n"
# #26=#0 makes it vacant again; #25 copied bare from #26 is not used bare (only tested)
MACRO2 = ("O9811\nIF[#26EQ#0]GOTO20\n#26=#0\nN20\nIF[#26NE#0]GOTO30\n#26=7.\nN30\n"
          "G1 Z-#26 F100.\nM99\n")
CALLER2 = "O1001\nG0 X0 Y0 Z10.\nG65 P9811 Z2.\nG65 P9811\nM30\n"


def _write(tmp_path, macro, caller, mnum, cnum):
    iso, sin = tmp_path / "iso", tmp_path / "sin"
    iso.mkdir()
    sin.mkdir()
    (iso / f"O{mnum}.nc").write_text(macro)
    (iso / f"O{cnum}.nc").write_text(caller)
    proc = api.transpile(iso / f"O{mnum}.nc", read="iso-m", write="sinumerik")
    assert proc.text is not None and not [d for d in proc.diagnostics if d.rule in ("NC412", "NC402")]
    (sin / f"L{mnum}.SPF").write_text(proc.text)
    main = api.transpile(iso / f"O{cnum}.nc", read="iso-m", write="sinumerik")
    (sin / f"O{cnum}.MPF").write_text(main.text)
    return iso / f"O{cnum}.nc", sin / f"O{cnum}.MPF", proc.text


def _feeds(path):
    return [r.end["Z"] for r in api.toolpath(path) if r.kind == "linear"]


def test_o9810_pattern_keeps_its_vacancy(tmp_path):
    iso, sin, proc = _write(tmp_path, MACRO, CALLER, 9810, 1000)
    lines = proc.splitlines()
    assert "DEF BOOL GIVEN_Z" in lines and "GIVEN_Z=$P_SUBPAR[18]" in lines   # Z: 18th letter passed
    assert "IF NOT GIVEN_Z GOTO N10" in lines
    assert "ARG_Z=ARG_Z+1. GIVEN_Z=TRUE" in lines
    # hand: Z2. passed -> #26=2+1=3 -> G1 Z-3; nothing passed -> vacant -> N10, #26=5 -> G1 Z-5
    assert _feeds(iso) == [-3.0, -5.0]
    assert _feeds(sin) == [-3.0, -5.0]
    assert api.equiv(iso, sin).equivalent


def test_vacant_again_after_assigning_vacant(tmp_path):
    iso, sin, proc = _write(tmp_path, MACRO2, CALLER2, 9811, 1001)
    assert "ARG_Z=0 GIVEN_Z=FALSE" in proc.splitlines() or any(
        x.endswith("GIVEN_Z=FALSE") for x in proc.splitlines())
    # hand: Z2. passed -> #26=#0 (vacant) -> NE #0 false -> #26=7 -> Z-7;
    #       nothing passed -> N20 -> still vacant -> #26=7 -> Z-7
    assert _feeds(iso) == [-7.0, -7.0]
    assert _feeds(sin) == [-7.0, -7.0]
    assert api.equiv(iso, sin).equivalent


def test_argument_set_and_used_whole_is_not_a_proc():
    # G1 Z#26 drops the word when #26 is vacant; the procedure's parameter would read 0: refused
    conv = api.transpile("O9812\nG1 Z#26 F100.\n#26=#26+1.\nG1 Z#26\nM99\n", read="iso-m", write="sinumerik")
    nc414 = [d for d in conv.diagnostics if d.rule == "NC414"]
    assert nc414 and "uses the argument #26 as a whole value where it may be vacant and also sets it" in nc414[0].message


@pytest.mark.parametrize("macro", [MACRO, MACRO2])
def test_the_macro_file_is_no_longer_flattened(macro):
    # before: lowered to plain motion run with #26 vacant (G1 Z-5 / Z-7 for every call), exit 0
    conv = api.transpile(macro, read="iso-m", write="sinumerik")
    assert conv.text.lstrip("; ").splitlines()[1].startswith("PROC L98")
    assert "flattened" not in conv.text


# a loop guarded by the vacancy of an argument it counts down and then empties (#25=#0)
MACRO3 = ("O9813\nWHILE[#25NE#0]DO1\nG1 Y#25 F100.\nIF[#25GT5.]THEN#25=#25-5.\n"
          "IF[#25LE5.]THEN#25=#0\nEND1\nM99\n")
CALLER3 = "O1003\nG0 X0 Y0 Z10.\nG65 P9813 Y12.\nG65 P9813\nG65 P9813 Y3.\nM30\n"


def test_loop_on_an_argument_it_sets_vacant(tmp_path):
    iso, sin, proc = _write(tmp_path, MACRO3, CALLER3, 9813, 1003)
    lines = [x.strip() for x in proc.splitlines()]
    assert "WHILE GIVEN_Y" in lines and "ARG_Y=0 GIVEN_Y=FALSE" in lines
    # the bare Y#25 is guarded by the WHILE test on every path: no entry check (no SETAL(65001))
    assert "SETAL(65001" not in proc
    # hand: Y12 -> 12>5: #25=7 -> Y7 -> 7-5=2 <= 5: vacant, loop ends; no Y: no move;
    #       Y3 -> 3 <= 5: vacant, ends.  Feeds to Y 12, 7, 3
    ys = [r.end["Y"] for r in api.toolpath(iso) if r.kind == "linear"]
    assert ys == [12.0, 7.0, 3.0]
    assert [r.end["Y"] for r in api.toolpath(sin) if r.kind == "linear"] == ys
    assert api.equiv(iso, sin).equivalent


def test_flow_sees_a_set_argument_vacant_again():
    from nctrans.dialects.base import get
    from nctrans.lower import macro_procs
    # #26=#0 after the test: the bare Z#26 may be vacant again -> not a PROC (NC414), never Z0
    program = get("iso-m").parse("O9814\nIF[#26EQ#0]GOTO9\n#26=#0\nG1 Z#26 F100.\nN9 M99\n",
                                 "O9814.nc").program
    found, why = macro_procs.standalone(program)
    assert found is None and "#26" in why
    # #26=1. after the test: passed on every path to the use -> a PROC with a flag
    program = get("iso-m").parse("O9815\nIF[#26EQ#0]THEN#26=1.\nG1 Z#26 F100.\nM99\n",
                                 "O9815.nc").program
    found, why = macro_procs.standalone(program)
    assert found is not None and found.proc.vacancy_flags == {26} and found.bare == set()


def test_macro_file_to_fagor_returns_instead_of_looping(tmp_path):
    # before: the M99 of a macro file was written as $WHILE 1 ... $ENDWHILE: an endless loop
    iso, fag = tmp_path / "iso", tmp_path / "fagor"
    iso.mkdir()
    fag.mkdir()
    (iso / "O9006.nc").write_text("O9006\n#10=#24+1.\nG1 X#10 F100.\nM99\n")
    (iso / "O1006.nc").write_text("O1006\nG0 X0 Y0 Z10.\nG65 P9006 X5.\nM30\n")
    sub = api.transpile(iso / "O9006.nc", read="iso-m", write="fagor")
    assert "$WHILE" not in sub.text and sub.text.rstrip().splitlines()[-1] == "M17"
    (fag / "O9006.nc").write_text(sub.text)
    (fag / "O1006.nc").write_text(api.transpile(iso / "O1006.nc", read="iso-m", write="fagor").text)
    # hand: X5. passed -> #10 = 5+1 = 6 -> G1 X6
    xs = [r.end["X"] for r in api.toolpath(fag / "O1006.nc", "fagor") if r.kind == "linear"]
    assert xs == [6.0]
    assert api.equiv(iso / "O1006.nc", fag / "O1006.nc", read_b="fagor").equivalent
