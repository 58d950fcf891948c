"""Sinumerik -> ISO with the structure kept, for what real Sinumerik programs use that ISO has no
word for: arrays of the control's definition files (GUD) the program does not declare, messages
with values, DEF without a value, string arguments of kept calls. Each converted program is
`equiv` to its source (kept calls compared as opaque events), on hand-written cases and on every
corpus program and PROC file that converts."""
from __future__ import annotations

import shutil
from functools import lru_cache
from itertools import islice
from pathlib import Path

import pytest

import nctrans
from conftest import CORPUS
from nctrans import api, equivalence, pipeline
from nctrans.dialects.base import get
from nctrans.dialects.iso_m.plan import NOT_CONVERTED_ALARM, stable_number
from nctrans.interp import interpret
from nctrans.machine import default_mill


def _convert(src: str):
    conv = api.transpile(src, read="sinumerik", write="iso-m")
    assert conv.ok, [d.format_text() for d in conv.diagnostics if d.severity == "error"]
    return conv


def _reads_back_clean(text: str, lint: bool = True) -> None:
    """No error reading the output back and no NC0xx (syntax, lexical) from linting it; for long
    corpus runs the reading only (NC0xx come from there)."""
    back = get("iso-m").parse(text, "out.nc")
    assert not [d for d in back.diagnostics if d.severity == "error" or d.rule.startswith("NC0")], \
        [d.format_text() for d in back.diagnostics]
    if lint:
        found = api.lint(text, dialect="iso-m")
        assert not [d for d in found if d.rule.startswith("NC0")], found


# ---------------------------------------------------------------- undeclared (GUD) arrays

GUD_USER = "INI[53]=40\nINI[2]=INI[53]/2\nG1 X=INI[2] Y=INI[53] F100\nINI[53]=INI[53]+1\nG1 X=INI[53]\nM30\n"


def test_undeclared_array_elements_each_get_a_common_variable_named_in_the_table(tmp_path):
    # the control declares INI in its definition file; the program only uses it
    (tmp_path / "GUD.DEF").write_text("DEF NCK REAL INI[200]\nM30\n")
    (tmp_path / "USER.MPF").write_text(GUD_USER)
    conv = nctrans.transpile(tmp_path / "USER.MPF", read="sinumerik", write="iso-m")
    assert conv.ok, [d.format_text() for d in conv.diagnostics if d.severity == "error"]
    lines = conv.text.splitlines()
    # hand-checked: first element met takes #500 (no R parameter used), the next #501
    assert [x for x in lines if x.startswith("(VAR ")] == ["(VAR INI[53] = #500)", "(VAR INI[2] = #501)"]
    assert "#500=40" in lines and "#501=#500/2" in lines and "#500=#500+1" in lines
    warn = [d for d in conv.diagnostics if d.rule == "NC410"]
    assert [(d.line, d.severity) for d in warn] == [(1, "warning")]         # once per array
    assert "INI" in warn[0].message and "this program only" in warn[0].message
    _reads_back_clean(conv.text)
    (tmp_path / "user.nc").write_text(conv.text)
    same = api.equiv(tmp_path / "USER.MPF", tmp_path / "user.nc", read_a="sinumerik", read_b="iso-m")
    assert same, same.message
    moves = [r.end for r in nctrans.toolpath(conv.text, dialect="iso-m") if r.kind == "linear"]
    assert (moves[0]["X"], moves[0]["Y"], moves[1]["X"]) == (20.0, 40.0, 41.0)


def test_undeclared_array_indexed_at_run_time_is_a_block_with_its_indices_checked(tmp_path):
    # INI is declared by the control (GUD.DEF beside); the program indexes it with a variable
    (tmp_path / "GUD.DEF").write_text("DEF NCK REAL INI[200]\nM30\n")
    src = "DEF INT IX=3\nINI[IX]=7\nINI[IX+1]=INI[IX]*2\nG1 X=INI[IX] Y=INI[4] F100\nM30\n"
    (tmp_path / "USER.MPF").write_text(src)
    conv = nctrans.transpile(tmp_path / "USER.MPF", read="sinumerik", write="iso-m")
    assert conv.ok, [d.format_text() for d in conv.diagnostics if d.severity == "error"]
    lines = conv.text.splitlines()
    # hand-checked: 1-D, largest constant index 4 -> 100 rows (the cap) from #500 (no R used);
    # an index is checked in 0..99 as |i - 49.5| <= 49.5 before the line that uses it
    assert "(VAR INI[100] = #500..#599 ASSUMED)" in lines
    check = "IF[ABS[[#100]-49.5]GT49.5]THEN#3000=101(INI INDEX OUT OF RANGE)"
    at = lines.index("#[500+#100]=7")
    assert lines[at - 1] == check
    assert lines[-4:-1] == [check, "G1 F100. X#[500+#100] Y#504", "M30"]
    warn = [d for d in conv.diagnostics if d.rule == "NC410"]
    assert [(d.line, d.severity) for d in warn] == [(2, "warning")] and "run time" in warn[0].message
    _reads_back_clean(conv.text)
    (tmp_path / "user.nc").write_text(conv.text)
    same = api.equiv(tmp_path / "USER.MPF", tmp_path / "user.nc", read_a="sinumerik", read_b="iso-m")
    assert same, same.message
    moves = [r.end for r in nctrans.toolpath(conv.text, dialect="iso-m") if r.kind == "linear"]
    assert (moves[0]["X"], moves[0]["Y"]) == (7.0, 14.0)
    # an index past the assumed extent stops the ISO program (the source, with INI[200], runs on)
    found: list = []
    beyond = conv.text.replace("#100=3", "#100=150")
    records = list(interpret(get("iso-m").parse(beyond, "b.nc").program, default_mill(), diagnostics=found))
    assert not [r for r in records if r.kind == "linear"]
    assert [d.rule for d in found if d.severity == "error"] == ["NC221"] and "alarm 101" in found[0].message


def test_two_dimensional_global_array_rows_share_the_room_left():
    # second extent max(2 + 1, 8) = 8; 500 free variables / 8 = 62 rows (under the 100-row cap)
    src = "DEF INT IX=3\nTAB[IX,2]=5\nG1 X=TAB[IX,2] F100\nM30\n"
    conv = _convert(src)
    lines = conv.text.splitlines()
    assert "(VAR TAB[62,8] = #500..#995 ASSUMED)" in lines and "#[500+[#100*8+2]]=5" in lines
    assert "IF[ABS[[#100]-30.5]GT30.5]THEN#3000=101(TAB INDEX OUT OF RANGE)" in lines
    _reads_back_clean(conv.text)
    moves = [r.end["X"] for r in nctrans.toolpath(conv.text, dialect="iso-m") if r.kind == "linear"]
    assert moves == [5.0]


def test_global_array_element_only_shown_in_a_message_is_named_in_the_comment():
    # a text array of the definition files (KOMENTAR) has no ISO place; a message is a comment
    src = 'DEF INT IX=2\nMSG("phase-" << KOMENTAR[IX])\nG1 X1 F100\nM30\n'
    conv = _convert(src)
    assert "(MSG, phase-<KOMENTAR[#100]>)" in conv.text.splitlines()
    assert not [d for d in conv.diagnostics if d.rule == "NC410"]      # nothing laid out for it


def test_no_room_left_for_undeclared_elements_is_refused_not_wrapped():
    # 500 elements fill #500..#999; the 501st has no place
    src = "".join(f"TAB[{i}]={i}\n" for i in range(501)) + "M30\n"
    out = get("iso-m").emit(get("sinumerik").parse(src, "a.mpf").program)
    refused = [d for d in out.diagnostics if d.rule == "NC402"]
    assert [d.line for d in refused] == [501] and "no room" in refused[0].message


# ---------------------------------------------------------------- messages, DEF without a value

def test_message_with_values_is_a_comment_naming_the_expressions():
    src = 'DEF REAL YPOS=2.5\nMSG("Y: " << YPOS << " mm")\nG1 X=YPOS F100\nM30\n'
    conv = _convert(src)
    assert "(MSG, Y: <#100> mm)" in conv.text.splitlines()
    _reads_back_clean(conv.text)
    assert api.equiv(src, conv.text, read_a="sinumerik", read_b="iso-m")


def test_def_without_a_value_starts_at_zero_in_iso_too():
    # a vacant common is not 0 in ISO: #100 EQ 0 is false while #100 is vacant
    src = "DEF REAL AA\nIF AA==0\nG1 X10 F100\nELSE\nG1 X20 F100\nENDIF\nM30\n"
    conv = _convert(src)
    assert "#100=0" in conv.text.splitlines()
    same = api.equiv(src, conv.text, read_a="sinumerik", read_b="iso-m")
    assert same, same.message
    moves = [r.end["X"] for r in nctrans.toolpath(conv.text, dialect="iso-m") if r.kind == "linear"]
    assert moves == [10.0]


def test_absolute_arc_centre_from_a_start_known_at_run_time_is_written_under_g90_1():
    # the start point changes each pass: no constant incremental centre exists
    src = "DEF INT KK\nG0 X0 Y0\nFOR KK=1 TO 2\nG1 X=10*KK Y0 F100\nG3 X=-10*KK Y0 I=AC(0) J=AC(0)\nENDFOR\nM30\n"
    conv = _convert(src)
    lines = conv.text.splitlines()
    arc = next(i for i, x in enumerate(lines) if x.startswith("G3"))
    assert lines[arc] == "G3 G90.1 X[-10*#100] Y0. I0. J0." and lines[arc + 1] == "G91.1"
    _reads_back_clean(conv.text)
    same = api.equiv(src, conv.text, read_a="sinumerik", read_b="iso-m")
    assert same, same.message
    arcs = [r for r in nctrans.toolpath(conv.text, dialect="iso-m") if r.kind == "arc"]
    assert [(r.end["X"], r.center["X"], r.center["Y"]) for r in arcs] == [(-10.0, 0.0, 0.0), (-20.0, 0.0, 0.0)]


def test_a_parameter_a_call_leaves_out_reads_zero_in_iso_too():
    # Sinumerik: an unprogrammed parameter is 0 (X0); a vacant G65 local would drop the X word
    src = "G0 X5 Y5\nP1(,3)\nM30\nPROC P1(REAL XA, REAL YB)\nG1 X=XA Y=YB F100\nRET\n"
    conv = _convert(src)
    lines = conv.text.splitlines()
    assert lines[lines.index("IF[#1EQ#0]THEN#1=0") + 1] == "IF[#2EQ#0]THEN#2=0"
    same = api.equiv(src, conv.text, read_a="sinumerik", read_b="iso-m")
    assert same, same.message
    moves = [r.end for r in nctrans.toolpath(conv.text, dialect="iso-m") if r.kind == "linear"]
    assert [(m["X"], m["Y"]) for m in moves] == [(0.0, 3.0)]


# ---------------------------------------------------------------- ROT about a named axis

ROT_Y = "G17 G90 G0 X0 Y0 Z0\nTRANS X5\nROT Y90\nG1 X10 F100\nG1 Y5 Z3\nTRANS\nG0 Z50\nM30\n"


def test_rot_about_y_is_g68_in_the_zx_plane_with_the_frame_cancelled_around_it():
    conv = _convert(ROT_Y)
    lines = conv.text.splitlines()
    rot = lines.index("G18 G68 Z0. X0. R90.")
    # ROT replaces the whole programmable frame: the TRANS shift goes first
    assert lines[rot - 1] == "G52 X0. Y0. Z0."
    end = lines.index("G0 Z50.")
    assert lines[end - 1] == "G17" and "G69" in lines[rot:end]
    _reads_back_clean(conv.text)
    same = api.equiv(ROT_Y, conv.text, read_a="sinumerik", read_b="iso-m")
    assert same, same.message
    # by hand: ROT Y90 turns X10 into Z-10 (right-hand rule about Y), then Y5 Z3 into X3 Y5 Z-10
    moves = [r.end for r in nctrans.toolpath(conv.text, dialect="iso-m") if r.kind in ("linear", "rapid")]
    assert [(m["X"], m["Y"], m["Z"]) for m in moves] == [(0.0, 0.0, 0.0), (0.0, 0.0, -10.0), (3.0, 5.0, -10.0),
                                                          (3.0, 5.0, 50.0)]


def test_rot_about_the_plane_normal_needs_no_plane_change():
    src = "G17 G0 X0 Y0\nROT Z30\nG1 X10 F100\nROT\nM30\n"
    conv = _convert(src)
    assert "G68 X0. Y0. R30." in conv.text.splitlines() and "G18" not in conv.text
    assert api.equiv(src, conv.text, read_a="sinumerik", read_b="iso-m")


def test_an_arc_while_the_rotation_holds_another_plane_is_refused_at_its_line():
    src = "G17 G0 X0 Y0\nROT Y90\nG1 X10 F100\nG2 X20 Y0 CR=5\nROT\nM30\n"
    out = get("iso-m").emit(get("sinumerik").parse(src, "a.mpf").program)
    refused = [d for d in out.diagnostics if d.rule == "NC402"]
    assert [d.line for d in refused] == [4] and "plane" in refused[0].message


# ---------------------------------------------------------------- string arguments of kept calls

CALLS_WITH_STRINGS = 'G0 X0 Y0\n_APPROACH("krug1",1,0,"")\nG0 X5\nM30\n'


def test_string_argument_of_a_kept_call_is_passed_as_its_string_number():
    conv = _convert(CALLS_WITH_STRINGS)
    number = stable_number("_APPROACH", set())
    # CRC-32 of b"krug1" is 0xc0ae8eb7 = 3232665271 (binascii, outside nctrans), mod 10**7 = 2665271;
    # the empty string is 0
    assert f"G65 P{number} A2665271. B1. C0. D0" in conv.text.splitlines()
    assert '(STRING "krug1" = 2665271)' in conv.text.splitlines()
    assert [d.line for d in conv.diagnostics if d.rule == "NC411"] == [2]        # the two of line 2 in one
    _reads_back_clean(conv.text)
    same = api.equiv(CALLS_WITH_STRINGS, conv.text, read_a="sinumerik", read_b="iso-m")
    assert same, same.message
    other = api.equiv(CALLS_WITH_STRINGS.replace("krug1", "krug2"), conv.text, read_a="sinumerik", read_b="iso-m")
    assert not other and "call" in other.message


def test_a_numbered_subprogram_is_called_by_its_own_number():
    src = "G0 X0\nL140(1)\nG0 X5\nM30\n"
    conv = _convert(src)
    assert "G65 P140 A1." in conv.text.splitlines()
    assert api.equiv(src, conv.text, read_a="sinumerik", read_b="iso-m")


def test_an_omitted_argument_between_others_keeps_the_letters_in_place():
    # CALL(1,,3) passes A and C; the call event counts letters in PROC order, B left out
    src = "G0 X0\nTOOLSET(1,,3)\nM30\n"
    conv = _convert(src)
    assert f"G65 P{stable_number('TOOLSET', set())} A1. C3." in conv.text.splitlines()
    same = api.equiv(src, conv.text, read_a="sinumerik", read_b="iso-m")
    assert same, same.message
    assert not api.equiv("G0 X0\nTOOLSET(1,3)\nM30\n", conv.text, read_a="sinumerik", read_b="iso-m")
    call = next(r for r in nctrans.toolpath("G65 P9001 A1. B2. D4. I5.\nM30\n", dialect="iso-m") if r.kind == "call")
    # A B C D ... Z then I J K: D is the 4th, I the 19th
    assert call.args == [1.0, 2.0, None, 4.0] + [None] * 14 + [5.0]


def test_a_proc_file_names_its_variables_after_its_o_number():
    src = "PROC SETUP(REAL AA)\nDEF REAL KK\nINI[4]=AA\nKK=INI[4]*2\nG1 X=KK F100\nM17\n"
    conv = _convert(src)
    lines = conv.text.splitlines()
    assert lines[1] == f"O{stable_number('SETUP', set())} (SETUP)"
    table = [x for x in lines if x.startswith("(VAR ")]
    assert "(VAR INI[4] = #500)" in table and lines.index(table[0]) < lines.index("#500=#1")


def test_arguments_past_the_g65_letters_are_in_the_call_event():
    # 20 arguments: 18 letters, the last two in spill slots #[#149+150], #[#149+151], ended by a
    # vacant #[#149+152] before the call and the first slot vacated after it
    args = ",".join(str(i + 1) for i in range(20))
    src = f"G0 X0\nBIG({args})\nSMALL(7)\nM30\n"
    conv = _convert(src)
    lines = conv.text.splitlines()
    call = next(i for i, x in enumerate(lines) if x.startswith("G65 P") and "A1." in x)
    assert lines[call - 3:call] == ["#[#149+150]=19", "#[#149+151]=20", "#[#149+152]=#0"]
    assert lines[call + 1] == "#[#149+150]=#0"
    same = api.equiv(src, conv.text, read_a="sinumerik", read_b="iso-m")
    assert same, same.message
    events = [r.args for r in nctrans.toolpath(conv.text, dialect="iso-m") if r.kind == "call"]
    assert events == [[float(i + 1) for i in range(20)], [7.0]]      # SMALL gets no stale slots
    # a call that does not use all 18 letters spilled nothing: a value left in a slot is not its
    stale = "%\nO1\n#150=5.\nG65 P9999 A1.\nM30\n%\n"
    assert [r.args for r in nctrans.toolpath(stale, dialect="iso-m") if r.kind == "call"] == [[1.0]]
    # a spilled argument that differs is a difference
    other = api.equiv(src, conv.text.replace("#[#149+151]=20", "#[#149+151]=21"), read_a="sinumerik",
                      read_b="iso-m")
    assert not other and "call" in other.message


def test_omitted_trailing_arguments_are_the_same_call():
    src = "G0 X0\nTOOLSET(1,2,,)\nM30\n"
    conv = _convert(src)
    assert api.equiv(src, conv.text, read_a="sinumerik", read_b="iso-m")
    assert not api.equiv("G0 X0\nTOOLSET(1,2,3)\nM30\n", conv.text, read_a="sinumerik", read_b="iso-m")


# ---------------------------------------------------------------- the corpus

SINUMERIK = sorted(p for p in (CORPUS / "sinumerik").glob("*")
                   if p.suffix.lower() in (".mpf", ".spf", ".drs")) if CORPUS.is_dir() else []
# kept calls with arrays by reference: their elements go on the spill stack (plan.py) and the G65
# letters of the scalars after them shift, so the call event does not line up with the source's
# (calls with more than 18 arguments do: the spilled ones follow the letters in the event)
SPILLED_ARGUMENTS = {"rhoden-SINULORENZ.MPF": "LORENZ_RUKU4 takes two arrays by reference"}


@lru_cache(maxsize=None)
def _converted(path: Path):
    """(conversion, parsed source) of a corpus file, once for both tests below."""
    conv = nctrans.transpile(path, read="sinumerik", write="iso-m")
    source = get("sinumerik").parse(path.read_text(encoding="utf-8", errors="replace"), str(path)).program
    return conv, source


def _library(program):
    entry = (program.meta or {}).get("entry")
    if entry in program.subprograms and all(not getattr(b, "body", None) for b in program.body):
        return entry
    return None


# records compared per corpus program: the first few thousand hold every construct these programs
# convert (their long runs repeat a loop), and keep the test fast
PREFIX = 3000


def _records(program, folder: Path, dialect: str, diagnostics=None) -> list:
    return list(islice(interpret(program, default_mill(), diagnostics=[] if diagnostics is None else diagnostics,
                                 resolver=pipeline.make_resolver(str(folder), dialect)), PREFIX))


@pytest.mark.parametrize("path", SINUMERIK, ids=lambda p: p.name)
def test_corpus_conversion_is_equivalent_with_its_kept_calls(path):
    conv, source = _converted(path)
    if conv.text is None:
        pytest.skip("refused (bench_structure lists why)")
    _reads_back_clean(conv.text, lint=False)
    if _library(source) is not None:
        pytest.skip("a PROC file: proved through a caller below")
    if path.name in SPILLED_ARGUMENTS:
        pytest.xfail(SPILLED_ARGUMENTS[path.name])
    want = _records(source, path.parent, "sinumerik")
    ran: list = []
    got = _records(get("iso-m").parse(conv.text, path.name + ".nc").program, path.parent, "iso-m", ran)
    if any(d.rule == "NC412" for d in conv.diagnostics):
        # a subprogram file's construct refused in place (a .SPF without PROC too): the run stops
        # at its alarm, after agreeing with the source on everything before it
        assert any(d.rule == "NC221" and f"alarm {NOT_CONVERTED_ALARM}" in d.message for d in ran)
        diff = equivalence.compare(want, got)
        assert diff is None or diff.at_end, diff.format()
        return
    if len(got) < PREFIX and got[-1].kind == "stop" and not (want and want[-1].kind == "stop"):
        # M17 in a main program file: M99 is its return in ISO too, but run on its own as a main
        # program the ISO interpreter reads M99 as the end of one pass
        got = got[:-1]
    diff = equivalence.compare(want, got)
    assert diff is None, diff.format()


PROC_FILES = [p for p in SINUMERIK if p.suffix.lower() == ".spf"]


@pytest.mark.parametrize("path", PROC_FILES, ids=lambda p: p.name)
def test_corpus_proc_file_runs_as_its_source_through_a_caller(path, tmp_path):
    conv, source = _converted(path)
    if conv.text is None:
        pytest.skip("refused (bench_structure lists why)")
    entry = _library(source)
    if entry is None:
        pytest.skip("not a PROC file")
    params = source.subprograms[entry].params
    if any(p.by_ref or p.dims or p.type not in ("REAL", "INT") for p in params):
        pytest.skip("by-reference, array or non-numeric parameters")
    src, out = tmp_path / "sin", tmp_path / "iso"
    src.mkdir()
    out.mkdir()
    shutil.copy(path, src / f"{entry}.SPF")
    args = ",".join(str(i + 1) for i in range(len(params)))
    caller = f"G17 G90 G71\nG0 X0 Y0 Z50\n{entry}({args})\nG0 Z60\nM30\n"
    (src / "MAIN.MPF").write_text(caller)
    main = nctrans.transpile(caller, read="sinumerik", write="iso-m")     # the call kept (NC404)
    assert main.ok
    (out / "main.nc").write_text(main.text)
    number = stable_number(entry, set())
    assert conv.text.splitlines()[1].startswith(f"O{number} ")
    (out / f"O{number}.nc").write_text(conv.text)
    want = _records(get("sinumerik").parse(caller, str(src / "MAIN.MPF")).program, src, "sinumerik")
    found: list = []
    got = _records(get("iso-m").parse(main.text, str(out / "main.nc")).program, out, "iso-m", found)
    alarms = [d for d in found if d.rule == "NC221" and f"alarm {NOT_CONVERTED_ALARM}:" in d.message]
    if alarms:
        # a construct refused in place (NC412): the ISO subprogram stops with the alarm there, and
        # runs as its source up to it
        assert any(d.rule == "NC412" for d in conv.diagnostics) and len(got) < len(want)
        want = want[:len(got)]
    diff = equivalence.compare(want, got)
    assert diff is None, diff.format()
