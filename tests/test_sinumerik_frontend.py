"""Sinumerik front end: concrete IR facts per feature area (spec sections 1-9) and bad input."""
from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from nctrans.dialects import base
from nctrans.dialects.sinumerik.frontend import parse
from nctrans.ir import nodes as ir


def body(text: str):
    res = parse(text, "t.mpf")
    assert not [d for d in res.diagnostics if d.rule.startswith("NC0")], res.diagnostics
    return res.program


def stmts(text: str) -> list:
    """Statements of the first block of a one-line program."""
    blocks = [b for b in body(text).body if isinstance(b, ir.Block)]
    return blocks[0].body


def first(text: str, cls):
    found = [s for s in stmts(text) if isinstance(s, cls)]
    assert found, stmts(text)
    return found[0]


# --------------------------------------------------------------------------- registry, structure

def test_registered_dialect_parses_and_emits():
    d = base.get("sinumerik")
    assert d.name == "sinumerik" and ".mpf" in d.extensions and ".SPF" in d.extensions
    assert d.sniff("DEF REAL A\nIF R1>2 GOTOF L1\nENDIF\nSTOPRE") > 0.5
    assert d.sniff("G0 X0 Y0\n") < 0.5


def test_header_path_and_defaults_in_meta():
    p = body("%_N_SHAFT_MPF\n;$PATH=/_N_WKS_DIR/_N_SHAFT_WPD\nG0 X1\nM2\n")
    assert p.meta["header"] == "_N_SHAFT_MPF"
    assert p.meta["path"] == "/_N_WKS_DIR/_N_SHAFT_WPD"
    assert p.name == "SHAFT"
    assert p.meta["defaults"]["motion"] == "linear"
    assert p.meta["defaults"]["work_offset"] == "G53"     # G500: no settable offset
    assert p.meta["defaults"]["units"] == "mm"


def test_proc_with_value_and_reference_parameters():
    p = body("; cycle\nPROC BORDER(REAL LEN, VAR REAL W[,2], STRING[8] NAME) SAVE DISPLOF\nG0 X=LEN\nRET\n")
    sub = p.subprograms["BORDER"]
    assert p.meta["entry"] == "BORDER"
    assert [(q.name, q.type, q.by_ref, q.dims) for q in sub.params] == [
        ("LEN", "REAL", False, []), ("W", "REAL", True, [0, 2]), ("NAME", "STRING", False, [])]
    assert sub.attrs == ["SAVE", "DISPLOF"]
    assert isinstance(sub.body[-1].body[0], ir.Return)
    assert p.body[0].comment == " cycle"           # the comment before PROC stays in the file body


def test_program_ends_and_returns():
    assert first("M30", ir.ProgramEnd).kind == "end_rewind"
    assert first("M2", ir.ProgramEnd).kind == "end"
    assert isinstance(first("M17", ir.Return), ir.Return)
    assert isinstance(first("RET", ir.Return), ir.Return)
    assert first("M1", ir.Stop).optional is True


def test_archive_members_become_subprograms():
    p = body("G0 X1\nL10\nM30\n%_N_L10_SPF\nPROC L10\nG0 X2\nM17\n")
    assert "L10" in p.subprograms
    assert first("L10", ir.SubCall).name == "L10"


# --------------------------------------------------------------------------- lexical rules

def test_block_number_label_comment_skip():
    b = body("/3 N120 _G54: G54 ; select offset\n").body[0]
    assert (b.skip, b.number, b.label, b.comment) == (3, "120", "_G54", " select offset")
    assert b.body == [ir.ModeChange("work_offset", "G54", "G54")]
    b = body(":20 G1 X1\n").body[0]
    assert b.number == "20"
    assert body("/ G1 X1\n").body[0].skip == 0


def test_semicolon_inside_string_is_not_a_comment():
    b = body('MSG("a;b") ; real comment\n').body[0]
    assert b.body == [ir.Message(ir.Str("a;b"))] and b.comment == " real comment"


def test_numbers_exponent_hex_binary():
    a = first("R1=1.5EX-3+'H1F'+'B101'", ir.Assign)
    left = a.value.left
    assert left.left.value == pytest.approx(0.0015)
    assert left.right.value == 31 and a.value.right.value == 5


def test_equals_required_for_expressions_and_extended_addresses():
    m = first("G1 X=R1+2 Y-3.5", ir.Motion)
    assert m.target["X"].value == ir.Binary("+", ir.Var("R", 1), ir.Num(2.0, "2"))
    assert m.target["Y"].value.value == -3.5
    sp = first("S1=300", ir.SpindleSpeed)
    assert (sp.spindle, sp.value.value) == (1, 300.0)
    assert first("S2=1000", ir.SpindleSpeed).spindle == 2
    assert first('T="DRILL"', ir.ToolSelect).tool == ir.Str("DRILL")


def test_glued_words_and_lowercase_keywords():
    s = stmts("g0X-170y5")
    assert s[0] == ir.ModeChange("motion", "rapid", "G0")
    assert {k: v.value.value for k, v in s[1].target.items()} == {"X": -170.0, "Y": 5.0}
    g = first("if r1==2 gotof ende", ir.Goto)
    assert (g.target, g.direction) == ("ENDE", "forward")


def test_axis_names_from_rules_table():
    m = first("G1 XV=2*R1 X1=5", ir.Motion)
    assert set(m.target) == {"XV", "X1"}
    # a name that is not an axis is an assignment to a user variable
    a = first("ZZ=4", ir.Assign)
    assert a.target == ir.Var("name", "ZZ")


def test_macros_expand_after_definition():
    p = body("DEFINE LINE AS G1 G94 F300\nLINE X10\n")
    assert p.meta["macros"]["LINE"] == "G1 G94 F300"
    s = p.body[1].body
    assert ir.ModeChange("motion", "linear", "G1") in s and isinstance(s[-1], ir.Motion)
    assert isinstance(p.body[0].body[0], ir.Passthrough)


# --------------------------------------------------------------------------- data

def test_def_types_arrays_set_rep():
    decls = stmts("DEF REAL DEPTH=3.1, LENGTH, T[2,3]=SET(1,2,,4)")
    assert [d.name for d in decls] == ["DEPTH", "LENGTH", "T"]
    assert decls[0].init[0].value == pytest.approx(3.1)
    assert decls[2].dims == [2, 3]
    assert [x.value for x in decls[2].init] == [1, 2, 0, 4]          # gap -> 0
    d = first("DEF CHAN INT _C[4]=REP(-1)", ir.VarDecl)
    assert d.scope == "chan" and d.init == [ir.Func("REP", [ir.Num(-1.0, "-1")])]
    d = first('DEF STRING[6] M="BEGIN"', ir.VarDecl)
    assert (d.type, d.length, d.init) == ("STRING", 6, [ir.Str("BEGIN")])
    d = first("DEF AXIS AN=(X1)", ir.VarDecl)
    assert d.init == [ir.Var("name", "X1")]
    assert first("DEF FRAME F1", ir.VarDecl).type == "FRAME"
    assert first("DEF DOUBLE D1", ir.VarDecl).type == "REAL"       # spec Q: DOUBLE alias


def test_r_parameters_user_and_system_variables():
    a = first("R[R10+1]=$AA_IM[X]", ir.Assign)
    assert a.target == ir.Var("R", None, [ir.Binary("+", ir.Var("R", 10), ir.Num(1.0, "1"))])
    assert a.value == ir.Var("system", "$AA_IM", [ir.Var("name", "X")])
    a = first("TABLE[1,2]=R3", ir.Assign)
    assert a.target == ir.Var("name", "TABLE", [ir.Num(1.0, "1"), ir.Num(2.0, "2")])
    a = first("$P_PFRAME=CTRANS(X,10):CROT(Z,45)", ir.Assign)
    assert a.value.name == "frame_chain" and [f.name for f in a.value.args] == ["CTRANS", "CROT"]


# --------------------------------------------------------------------------- expressions

def test_comparisons_bind_weakest():
    # IF R1==1 AND R2==2 is R1 == (1 AND R2) == 2 on the controller (spec 4.1)
    g = first("IF R1==1 AND R2==2 GOTOF L", ir.Goto)
    assert g.cond == ir.Binary("==", ir.Binary("==", ir.Var("R", 1), ir.Binary(
        "and", ir.Num(1.0, "1"), ir.Var("R", 2))), ir.Num(2.0, "2"))
    g = first("IF (R1==1) AND (R2==2) GOTOF L", ir.Goto)
    assert g.cond.op == "and"


def test_arithmetic_functions_and_strings():
    v = first("R1=SIN(30)*POT(2) DIV 3 MOD 2", ir.Assign).value
    assert v.op == "mod" and v.left.op == "div"
    assert v.left.left.left == ir.Func("sin", [ir.Num(30.0, "30")])
    assert v.left.left.right == ir.Func("pow", [ir.Num(2.0, "2"), ir.Num(2.0, "2")])
    v = first('TXT="A" << R1 << "B"', ir.Assign).value
    assert v.op == "concat" and v.left.op == "concat"
    v = first("R1=NOT R2 B_AND 'H3'", ir.Assign).value
    assert v == ir.Binary("band", ir.Unary("not", ir.Var("R", 2)), ir.Num(3.0, "'H3'"))
    assert first("R1=ATAN2(1,2)", ir.Assign).value.name == "atan2"


# --------------------------------------------------------------------------- control flow

def test_structured_control_flow():
    p = body("IF R1>2\nG0 X1\nELSE\nG0 X2\nENDIF\nWHILE R1<5\nR1=R1+1\nENDWHILE\n"
             "FOR I=1 TO 3\nENDFOR\nLOOP\nGOTOF E\nENDLOOP\nREPEAT\nR2=R2+1\nUNTIL R2>=3\nE:\n")
    kinds = [type(n).__name__ for n in p.body]
    assert kinds == ["If", "While", "ForLoop", "Loop", "RepeatUntil", "Block"]
    i, w, f, lo, r, _ = p.body
    assert len(i.then) == 1 and len(i.orelse) == 1
    assert w.cond.op == "<" and f.var == ir.Var("name", "I") and f.end.value == 3
    assert r.cond.op == ">=" and lo.body[0].body[0].target == "E"


def test_one_line_goto_forms():
    g = first("IF R1>2 GOTOF L1", ir.Goto)
    assert (g.target, g.direction) == ("L1", "forward") and g.cond.op == ">"
    assert first("GOTOB START", ir.Goto).direction == "backward"
    assert first("GOTO N100", ir.Goto).target == "100"          # block number
    assert first("GOTOC MAYBE", ir.Goto).direction == "any"


def test_case_jump_table():
    c = body("CASE (R1+1) OF 1 GOTOF ONE 2 GOTOB TWO DEFAULT GOTOF OTHER\n").body[0]
    assert isinstance(c, ir.Case)
    assert [(v.value, t) for v, t in c.branches] == [(1, "ONE"), (2, "TWO")]
    assert c.default == "OTHER" and c.subject.op == "+"


def test_unbalanced_structures_are_diagnosed():
    res = parse("IF R1>1\nG0 X1\n", "t.mpf")
    assert [d.rule for d in res.diagnostics] == ["NC006"]
    res = parse("ENDWHILE\n", "t.mpf")
    assert res.diagnostics[0].rule == "NC002" and res.diagnostics[0].line == 1


# --------------------------------------------------------------------------- calls

def test_call_forms():
    c = first("BORDER(15.3, ,5) P3", ir.SubCall)
    assert c.name == "BORDER" and c.args[1] == ir.Num(0.0, "") and c.repeat.value == 3   # omitted
    c = first("L0123", ir.SubCall)
    assert (c.name, c.kind) == ("L0123", "l")                    # leading zeros kept
    c = first("MCALL L70", ir.SubCall)
    assert c.modal == "after_move" and c.name == "L70"
    assert isinstance(first("MCALL", ir.ModalCallOff), ir.ModalCallOff)
    assert first('CALL "PART1"', ir.SubCall).kind == "call"
    assert first('ISOCALL "O1000"', ir.SubCall).kind == "isocall"
    assert first("PCALL /_N_WKS_DIR/_N_SHAFT_WPD/SHAFT(1, 2)", ir.SubCall).name == "SHAFT"
    assert first("WARMUP", ir.SubCall).name == "WARMUP"
    ext = first("EXTERN BORDER(REAL, VAR REAL)", ir.Passthrough)
    assert ext.reason == "declaration"


def test_standard_cycles_and_unknown_cycles():
    c = first("MCALL CYCLE81(10, 0, 2, -5)", ir.CycleCall)
    assert (c.kind, c.modal, c.name) == ("drill", True, "CYCLE81")
    assert {k: v.value for k, v in c.params.items()} == {
        "retract_plane": 10, "r_plane": 0, "safety": 2, "bottom": -5}
    c = first("CYCLE83(10,0,2,-30,,-10,,5,0,0,1,0)", ir.CycleCall)
    assert c.kind == "chip_break" and "depth_rel" not in c.params       # VARI=0
    h = first("HOLES2(50, 50, 20, 0, 90, 4)", ir.CycleCall)
    assert h.kind == "holes_circle" and h.params["num"].value == 4
    u = first("CYCLE832(0.1, 1)", ir.SubCall)                 # unknown cycle: a call, no error
    assert u.name == "CYCLE832"


# --------------------------------------------------------------------------- motion and modes

def test_arc_words():
    s = stmts("G2 X10 Y0 I=AC(5) J0 TURN=2")
    assert s[0] == ir.ModeChange("motion", "arc_cw", "G2")
    m = s[1]
    assert m.center["I"].mode == "abs" and m.center["J"].mode is None and m.turns.value == 2
    assert first("G3 X0 Y10 CR=-10", ir.Motion).radius.value == -10
    assert first("G3 AR=90 I5 J0", ir.Motion).aperture.value == 90
    m = first("CIP X10 Y10 I1=5 J1=7", ir.Motion)
    assert {k: v.value.value for k, v in m.via.items()} == {"X": 5, "Y": 7}
    assert stmts("CT X5 Y5")[0] == ir.ModeChange("motion", "arc_tangent", "CT")
    m = first("G0 AP=45 RP=10", ir.Motion)
    assert m.polar["angle"].value == 45 and m.polar["radius"].value == 10


def test_ac_ic_per_word():
    m = first("G91 X=AC(10) Y=IC(-2) Z5", ir.Motion)
    assert (m.target["X"].mode, m.target["Y"].mode, m.target["Z"].mode) == ("abs", "inc", None)


def test_modes_map_to_neutral_values():
    s = stmts("G18 G42 G70 G91 G95 G64 G9 DIAMON")
    assert [(x.group, x.value) for x in s] == [
        ("plane", "ZX"), ("cutter_comp", "right"), ("units", "inch_geometry"), ("distance", "incremental"),
        ("feed_mode", "per_rev"), ("path_mode", "continuous"), ("exact_stop_once", "on"),
        ("diameter", "diameter")]
    assert stmts("G700")[0] == ir.ModeChange("units", "inch", "G700")


def test_work_offsets():
    assert stmts("G57")[0].value == "G57"
    assert stmts("G505")[0].value == "G54.1P1"
    assert stmts("G599")[0].value == "G54.1P95"
    assert stmts("G500")[0].value == "G53"
    for sup in ("G53", "G153", "SUPA"):
        assert first(f"G0 {sup} Z0", ir.Motion).machine_coords is True


def test_execution_order_inside_a_block():
    s = stmts("G1 X10 F100 M3 S500 T2 D1 M6 R1=4 G17 M30")
    kinds = [type(x).__name__ for x in s]
    assert kinds.index("Assign") < kinds.index("ModeChange") < kinds.index("Feed")
    assert kinds.index("ToolSelect") < kinds.index("ToolChange") < kinds.index("Motion")
    assert kinds[-1] == "ProgramEnd"
    spindle = next(x for x in s if isinstance(x, ir.ModeChange) and x.group == "spindle")
    assert s.index(spindle) < kinds.index("Motion")


def test_reference_and_fixed_point_approach():
    h = first("G74 X1=0 Z1=0", ir.HomeReturn)
    assert h.ref == 1 and set(h.via) == {"X", "Z"}
    assert all(v.mode == "inc" and v.value.value == 0 for v in h.via.values())   # no intermediate move
    assert first("G75 FP=2 Z1=0", ir.HomeReturn).ref == 3


def test_dwell_tool_feed_message():
    assert first("G4 F2.5", ir.Dwell).seconds.value == 2.5
    d = first("G4 S10", ir.Dwell)
    assert d.revolutions.value == 10 and d.seconds is None
    assert first("D2", ir.OffsetSelect) == ir.OffsetSelect("radius", ir.Num(2.0, "2"))
    assert first('MSG("Pos " << R1)', ir.Message).text.op == "concat"
    a = first("SETAL(65002)", ir.Alarm)
    assert a.number.value == 65002


# --------------------------------------------------------------------------- frames

def test_frame_instructions():
    f = first("TRANS X10 Y5", ir.FrameOp)
    assert (f.op, f.additive, {k: v.value for k, v in f.values.items()}) == ("trans", False, {"X": 10, "Y": 5})
    f = first("AROT RPL=30", ir.FrameOp)
    assert (f.op, f.additive, f.angle.value) == ("rot", True, 30)
    assert first("ROT Z45", ir.FrameOp).values["Z"].value == 45
    assert first("ASCALE X2 Y2", ir.FrameOp).op == "scale"
    assert first("AMIRROR X0", ir.FrameOp).values == {"X": ir.Num(0.0, "0")}
    assert first("TRANS", ir.FrameOp) == ir.FrameOp("all", clear=True)
    # frame words are not motion
    assert not [s for s in stmts("TRANS X10") if isinstance(s, ir.Motion)]


# --------------------------------------------------------------------------- kept verbatim

def test_synchronized_action_is_passthrough():
    p = first("ID=1 WHEN $AA_IM[X]>5 DO M8", ir.Passthrough)
    assert (p.reason, p.dialect) == ("synchronized action", "sinumerik")
    assert first("WHENEVER $R1<0 DO $AC_OVR=0", ir.Passthrough).reason == "synchronized action"


def test_protection_zone_data_in_meta():
    p = body("CPROTDEF(2, FALSE, 3, 10, -100)\nG1 X0 Y-10\nX40\nG3 X0 Y-10 I-20 J0\nEXECUTE(ERR)\n")
    zone = p.meta["protection_zones"][0]
    assert (zone["scope"], zone["number"], zone["applus"], zone["appminus"]) == ("chan", 2, 10, -100)
    assert [e["motion"] for e in zone["contour"]] == ["linear", "linear", "arc_ccw"]
    assert zone["contour"][2]["I"] == -20
    assert all(isinstance(b.body[0], ir.Passthrough) for b in p.body)   # not executed


def test_curve_table_section_is_not_executed():
    p = body("CTABDEF(Y,X,1,0)\nX0 Y0\nX10 Y5\nCTABEND\nG0 X1\n")
    assert [b.body[0].reason for b in p.body[:4]] == ["curve table definition"] * 4
    assert isinstance(p.body[4].body[-1], ir.Motion)


def test_iso_mode_section():
    p = body("G291\nG00 X10. Y10.\nG290\n")
    assert p.body[0].body[0].reason == "ISO dialect mode"
    inner = p.body[1].body
    iso = base.get("iso-m")
    if iso is None:
        assert inner[0].dialect == "iso-m"
    else:
        assert isinstance(inner[-1], ir.Motion) and inner[-1].target["X"].value.value == 10


def test_machine_commands_are_passthrough():
    for text, reason in [("STOPRE", "preprocessing stop"), ("SETINT(8) PRIO=1 ASUB1", "interrupt"),
                         ("TRAORI", "kinematic transformation"), ("G0 X1 MEAS=1", "measuring")]:
        assert any(isinstance(s, ir.Passthrough) and reason in s.reason for s in stmts(text)), text
    # SETINT takes the whole block: no call of the routine name
    assert not [s for s in stmts("SETINT(8) PRIO=1 ASUB1") if isinstance(s, ir.SubCall)]


# --------------------------------------------------------------------------- bad input

@pytest.mark.parametrize("text,rule,col", [
    ("G1 X=(1+2", "NC003", None),
    ('MSG("open', "NC003", 5),
    ("G1 X10 ?", "NC002", 8),
    ("DEF REAL", "NC002", None),
    ("IF", "NC002", None),
])
def test_bad_blocks_give_diagnostics_with_position(text, rule, col):
    res = parse("G0 X0\n" + text + "\nG0 X1\n", "bad.mpf")
    ds = [d for d in res.diagnostics if d.rule.startswith("NC0")]
    assert ds and ds[0].rule == rule and ds[0].line == 2 and ds[0].file == "bad.mpf"
    if col is not None:
        assert ds[0].column == col
    # the rest of the program is still there, the bad block kept verbatim
    blocks = res.program.body
    assert len(blocks) == 3 and isinstance(blocks[2].body[-1], ir.Motion)
    assert isinstance(blocks[1].body[0], ir.Passthrough)


def test_integer_addresses_reject_fractions():
    res = parse("G0 X0\nG1 X1 T1.5\n", "t.mpf")
    d = res.diagnostics[0]
    assert (d.rule, d.line, d.column) == ("NC007", 2, 7)
    assert not parse("G1 X1.5 F0.5 S100.5\n", "t.mpf").diagnostics


def test_syntax_error_lists_expected_tokens():
    d = parse("DEF REAL 5\n", "t.mpf").diagnostics[0]
    assert d.rule == "NC002" and "expected" in d.message


def test_empty_program():
    assert [d.rule for d in parse("", "e.mpf").diagnostics] == ["NC004"]


@settings(max_examples=200, deadline=None)
@given(st.text(alphabet=st.sampled_from(list("GXYZRN0123456789.=+-*/()[]<>;:$\"' \nIFENDWHLOPDCA_")),
               max_size=80))
def test_parse_never_raises(text):
    res = parse(text, "fuzz.mpf")
    assert isinstance(res.program, ir.Program)
    for d in res.diagnostics:
        assert d.line >= 1 and d.column >= 1


def test_motion_word_table_names_real_parts_of_a_block():
    """rules/sinumerik.toml [options.motion_words] drives the lowering of CR=, AR=, AP= ...: every
    part it names must exist, or a typo in the table would drop the word silently."""
    import dataclasses
    from nctrans.dialects.sinumerik.frontend import _Words
    from nctrans.rules import load_table
    fields = {f.name for f in dataclasses.fields(_Words)}
    table = load_table("sinumerik").options["motion_words"]
    assert table
    for name, part in table.items():
        assert part.startswith("polar.") or part in fields, (name, part)


def test_g70_inch_lengths_keep_feeds_metric_g700_converts_both():
    """Seed group 13: G70/G71 switch geometry only, feeds stay in the basic system (metric here);
    G700/G710 switch feeds too. 1 inch = 25.4 mm; F100 in/min = 2540 mm/min."""
    import nctrans
    text = "G70 G1 X1 F100\nG700 G1 X2 F100\nG71 G1 X0 F100\nM30\n"
    moves = [r for r in nctrans.toolpath(text, "sinumerik") if r.kind == "linear"]
    assert [(round(m.end["X"], 6), m.feed) for m in moves] == [
        (25.4, 100.0), (50.8, 2540.0), (0.0, 100.0)]
