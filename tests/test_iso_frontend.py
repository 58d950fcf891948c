"""ISO milling front end: corpus programs parse clean, constructs lower to the agreed IR, bad input
gives located diagnostics instead of exceptions."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

from nctrans.dialects.iso_m import parse
from nctrans.ir import nodes as n
from nctrans.rules import load_table
from conftest import CORPUS

ISO_FILES = sorted((CORPUS / "iso-mill").glob("*"))
LINUXCNC_FILES = sorted((CORPUS / "linuxcnc").glob("*"))


def read(path: Path) -> str:
    data = path.read_bytes()
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("cp1252", errors="replace")


def body(text: str) -> list:
    return parse(text, "t.nc").program.body


def stmts(text: str) -> list:
    """Statements of the single block in `text`."""
    blocks = [b for b in body(text) if isinstance(b, n.Block)]
    assert len(blocks) == 1, blocks
    return blocks[0].body


def kinds(text: str) -> list[str]:
    return [type(s).__name__ for s in stmts(text)]


def diags(text: str) -> list:
    return parse(text, "t.nc").diagnostics


# --------------------------------------------------------------------- corpus

@pytest.mark.parametrize("path", ISO_FILES, ids=lambda p: p.name)
def test_iso_mill_corpus_parses_without_syntax_errors(path):
    result = parse(read(path), str(path))
    bad = [d.format_text() for d in result.diagnostics if d.rule.startswith("NC0")]
    assert bad == []
    assert result.program.body or result.program.subprograms


@pytest.mark.parametrize("path", LINUXCNC_FILES, ids=lambda p: p.name)
def test_linuxcnc_corpus_never_crashes(path):
    result = parse(read(path), str(path))
    assert all(d.line >= 1 and d.column >= 1 for d in result.diagnostics)


def test_rules_table_defaults_match_rs274_start_state():
    d = load_table("iso-m").defaults()
    assert d["units"] == "mm" and d["plane"] == "XY" and d["distance"] == "absolute"
    assert d["feed_mode"] == "per_min" and d["cutter_comp"] == "off" and d["tool_length"] == "off"
    assert d["cycle"] == "off" and d["cycle_retract"] == "initial" and d["work_offset"] == "G54"
    assert d["path_mode"] == "continuous"


# --------------------------------------------------------------------- lexical

def test_nested_comments_hide_words_inside():
    b = body("N15 (a(b) X100) Y100\n")[0]
    assert b.comment == "a(b) X100"
    assert b.body[0].target.keys() == {"Y"}


def test_flat_comment_reading_when_nesting_never_closes():
    # Fanuc does not nest: the comment ends at the first ")" (safetydav3-CIRCLE line 27).
    result = parse("(G0G40X0Y#140+.25(move up)\n", "t.nc")
    assert not [d for d in result.diagnostics if d.rule.startswith("NC0")]
    assert result.program.body[0].comment == "G0G40X0Y#140+.25(move up"


def test_semicolon_comment_and_bare_eob():
    assert body("G0 X1. ; G01 Y2.\n")[0].comment == "G01 Y2."
    assert body("G0 X1. ;\n")[0].comment is None


def test_compact_spaced_lowercase_and_crlf_words_agree():
    forms = ["G1X0.001Y2F8.\r\n", "g1 x0.001 y2 f8.\r\n", "G 1 X 0.001 Y 2 F 8.\n", "G1\tX0.001\x1aY2F8.\n"]
    results = [[(type(s).__name__, getattr(s, "target", None)) for s in stmts(t)] for t in forms]
    assert all(r == results[0] for r in results)


def test_block_skip_levels_leading_and_mid_block():
    blocks = body("/N10 G0 X1.\n/3 Y2.\nN20 X1. /2 Y5.\n")
    assert [b.skip for b in blocks] == [0, 3, None, 2]
    assert blocks[0].number == "10"
    assert blocks[3].body[0].target.keys() == {"Y"}


def test_percent_and_program_number_and_text_after_trailer():
    p = parse("%\nO1234 (PART)\nG0 X1.\n%\nthis is not program text\n", "t.nc").program
    assert p.name == "O1234" and p.meta["program_number"] == 1234 and p.meta["percent"]
    assert len(p.body) == 1


def test_decimal_g_codes_and_extended_work_offset():
    mc = [s for s in stmts("G54.1 P7 G0 X1.\n") if isinstance(s, n.ModeChange)]
    assert ("work_offset", "G54.1P7") in [(m.group, m.value) for m in mc]


# --------------------------------------------------------------------- statement order and motion

def test_statements_follow_rs274_execution_order():
    got = kinds("N5 G1 X1. F100. S2000 M3 T2 M6 G43 H2 G90 M8\n")
    assert got == ["Feed", "SpindleSpeed", "ToolSelect", "ToolChange", "ModeChange", "ModeChange",
                   "ModeChange", "OffsetSelect", "ModeChange", "ModeChange", "Motion"]


def test_arc_center_radius_and_turns():
    arc = stmts("G17 G2 X1. Y0. I0.5 J0. L3\n")[-1]
    assert arc.center.keys() == {"I", "J"} and arc.turns.value == 2
    arc_r = stmts("G3 X1. Y1. R-5.\n")[-1]
    assert arc_r.radius.value == -5.0


def test_g90_1_makes_arc_centres_absolute():
    blocks = body("G90.1\nG2 X1. Y1. I3. J4.\n")
    assert blocks[1].body[-1].center["I"].mode == "abs"


def test_same_group_twice_last_wins_with_nc201():
    result = parse("G0 G1 X1.\n", "t.nc")
    mc = [s for s in result.program.body[0].body if isinstance(s, n.ModeChange)]
    assert [(m.group, m.value) for m in mc] == [("motion", "linear")]
    assert any(d.rule == "NC201" for d in result.diagnostics)


def test_g53_motion_in_machine_coordinates():
    assert stmts("G53 Z0.\n")[-1].machine_coords is True


# --------------------------------------------------------------------- cycles

def test_canned_cycle_params_and_static_cycle_mode():
    blocks = body("G99 G81 X1. Y2. Z-3. R1. F50. K2\nX5.\nG80\nG2 X1. Y1. R2.\n")
    first = blocks[0].body
    assert ("cycle", "drill") in [(s.group, s.value) for s in first if isinstance(s, n.ModeChange)]
    params = [s for s in first if isinstance(s, n.CycleParams)][0].values
    assert params["r_plane"].value == 1.0 and params["repeat"].value == 2
    assert isinstance(blocks[1].body[0], n.Motion)
    assert blocks[3].body[-1].radius.value == 2.0        # R after G80 is an arc radius


def test_cycle_dwell_peck_and_shift():
    p82 = [s for s in stmts("G82 X0 Y0 Z-1. R1. P300\n") if isinstance(s, n.CycleParams)][0].values
    assert p82["dwell"].value == pytest.approx(0.3)
    p76 = [s for s in stmts("G76 X0 Y0 Z-1. R1. Q0.5\n") if isinstance(s, n.CycleParams)][0].values
    assert "shift" in p76
    p83 = [s for s in stmts("G83 X0 Y0 Z-1. R1. Q0.5\n") if isinstance(s, n.CycleParams)][0].values
    assert "peck" in p83


def test_group_one_cancels_cycle_mode():
    blocks = body("G81 X0 Y0 Z-1. R1.\nG1 X2. R3.\n")
    assert not any(isinstance(s, n.CycleParams) for s in blocks[1].body)


# --------------------------------------------------------------------- non-modal functions

def test_dwell_p_is_milliseconds_and_x_is_seconds():
    assert stmts("G4 P1500\n")[0].seconds.value == 1.5
    assert stmts("G04 X2.5\n")[0].seconds.value == 2.5


def test_home_set_position_local_offset():
    home = [s for s in stmts("G91 G28 Z0.\n") if isinstance(s, n.HomeReturn)][0]
    assert home.ref == 1 and home.via.keys() == {"Z"}
    assert isinstance(stmts("G92 X0 Y0\n")[0], n.SetPosition)
    local = stmts("G52 X10. Y0\n")[0]
    assert local.op == "trans" and local.local and local.values["X"].value == 10


def test_g10_data_setting_forms():
    ds = stmts("G10 L2 P1 X10. Y-5.\n")[0]
    assert isinstance(ds, n.DataSetting) and ds.kind == "work_offset" and ds.index.value == 1
    ds = stmts("G10 L20 P7 X1.\n")[0]
    assert ds.extended
    ds = stmts("G10 L12 P3 R0.25\n")[0]
    assert ds.kind == "tool_radius" and ds.values["value"].value == 0.25


def test_frames_rotation_scaling_mirror():
    rot = stmts("G68 X1. Y2. R30.\n")[0]
    assert rot.op == "rot" and rot.angle.value == 30 and rot.center.keys() == {"X", "Y"}
    assert stmts("G69\n")[0].clear
    scale = stmts("G51 X0 Y0 P1500\n")[0]
    assert scale.values["X"].value == 1.5
    mirror = stmts("G51.1 X5.\n")[0]
    assert mirror.op == "mirror" and mirror.center["X"].value.value == 5
    assert stmts("G50.1 X0\n")[0].clear


# --------------------------------------------------------------------- calls and subprograms

def test_m98_packing_and_same_file_subprograms():
    p = parse("O1\nM98 P30021\nM98 P1000 L2\nM30\nO1000\nG0 X1.\nM99\n%\n", "t.nc").program
    calls = [b.body[0] for b in p.body[:2]]
    assert calls[0].name == "O21" and calls[0].repeat.value == 3
    assert calls[1].name == "O1000" and calls[1].repeat.value == 2
    assert "O1000" in p.subprograms
    assert isinstance(p.subprograms["O1000"].body[-1].body[0], n.Return)


def test_m99_in_main_program_restarts():
    assert isinstance(body("G0 X1.\nM99\n")[-1].body[0], n.ProgramEnd)


def test_g65_type_one_and_type_two_bindings():
    call = stmts("G65 P9001 L2 A1. B2. I-3. I4. D5.\n")[-1]
    assert call.name == "O9001" and call.kind == "g65" and call.repeat.value == 2
    assert call.bindings["A"] == n.Var("num", 1)
    assert call.bindings["I1"] == n.Var("num", 4)
    assert call.bindings["I2"] == n.Var("num", 7) and call.bindings["D"] == n.Var("num", 7)
    sets = stmts("G65 P1 I10. J10. K30. J22. K55. I44. K33.\n")[-1].bindings
    assert {k: v.key for k, v in sets.items()} == {"I1": 4, "J1": 5, "K1": 6, "J2": 8, "K2": 9,
                                                    "I3": 10, "K3": 12}


def test_g66_modal_call_and_g67():
    call = stmts("G66 P200 X1.\n")[-1]
    assert call.modal == "after_move"
    assert isinstance(stmts("G67\n")[0], n.ModalCallOff)


# --------------------------------------------------------------------- macro B

def test_macro_assignments_expressions_and_functions():
    a = stmts("#1=ATAN[1]/[2]+SQRT[#2]*#[#3+1]\n")[0]
    assert isinstance(a, n.Assign) and a.value.op == "+"
    assert a.value.left == n.Func("atan2", [n.Num(1.0, "1"), n.Num(2.0, "2")])
    multi = stmts("#114=0#115=0#116=0\n")
    assert [s.target.key for s in multi] == [114, 115, 116]


def test_if_goto_if_then_while_and_goto():
    prog = body("N1 #1=0\nWHILE[#1LT3]DO1\n#1=#1+1\nIF[#1EQ2]THEN#5=1\nEND1\n"
                "IF[#1EQ3]AND[#2NE0]GOTO10\nGOTO1\n")
    loop = prog[1]
    assert isinstance(loop, n.While) and loop.label == "1" and len(loop.body) == 2
    assert isinstance(loop.body[1], n.If)
    g = prog[2].body[0]
    assert isinstance(g, n.Goto) and g.target == "10" and g.cond.op == "and"
    assert prog[3].body[0].cond is None


def test_address_values_from_expressions():
    m = stmts("G1 X#140/2+#142 Y[#1*2] Z-#3\n")[-1]
    assert isinstance(m.target["X"].value, n.Binary)
    assert m.target["Z"].value == n.Unary("-", n.Var("num", 3))


# --------------------------------------------------------------------- passthrough and bad input

def test_unknown_g_code_block_is_passthrough_with_nc403():
    result = parse("N535 G47 P0 (CADE KIELY) X.01 Y-2.95 SA0\n", "t.nc")
    b = result.program.body[0]
    assert b.number == "535" and isinstance(b.body[0], n.Passthrough)
    assert "CADE KIELY" in b.body[0].text
    assert [d.rule for d in result.diagnostics] == ["NC403"]


def test_meaningless_m_code_is_kept():
    pt = [s for s in stmts("M74 G0 X1.\n") if isinstance(s, n.Passthrough)]
    assert pt[0].text == "M74"


@pytest.mark.parametrize("text, rule, col", [
    ("G01 X[1+2 Y3\n", "NC003", 6),
    ("G01 X10 Y*5\n", "NC002", 10),
    ("G0 X1. (open comment\n", "NC003", 8),
    ("WHILE[#1LT3]DO1\n#1=#1+1\n", "NC006", 1),
    ("END2\n", "NC002", 1),
    ("", "NC004", 1),
])
def test_bad_input_gives_located_diagnostics(text, rule, col):
    found = [d for d in diags(text) if d.rule == rule]
    assert found and found[0].column == col and found[0].line >= 1


@settings(max_examples=200, deadline=None)
@given(st.text(alphabet=st.sampled_from(list("GXYZIJKRFNMPQ#[]()=/;.-+0123456789 \t\r\nEQIFGOTOWHILEDO%O$,")),
               max_size=80))
def test_garbage_never_raises(text):
    result = parse(text, "fuzz.nc")
    assert all(d.line >= 1 and d.column >= 1 for d in result.diagnostics)


def test_sniff_separates_iso_from_sinumerik():
    from nctrans.dialects.iso_m import sniff
    assert min(sniff(read(p)) for p in ISO_FILES) >= 0.9
    assert max(sniff(read(p)) for p in sorted((CORPUS / "sinumerik").glob("*"))) < 0.5
