"""Interpreter semantics real Sinumerik programs need: SET/REP arrays, AXIS values, frame
expressions ($P_PFRAME = CTRANS..:CROT..), VAR (by-reference) parameters, MCALL triggers, PROC
SAVE and preloaded GUD definition files. Expected values are computed by hand in the comments."""
from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs

from nctrans import pipeline
from nctrans.dialects.sinumerik.frontend import parse
from nctrans.interp import interpret
from conftest import CORPUS



def run(text: str, preload=()):
    res = parse(text.strip() + "\n", "t.mpf")
    diags: list = []
    recs = list(interpret(res.program, diagnostics=diags, preload=preload))
    return recs, diags


def ends(recs):
    return [tuple(round(r.end[a], 4) for a in ("X", "Y", "Z"))
            for r in recs if r.kind in ("rapid", "linear", "arc")]


def errors(diags):
    return [d.format_text() for d in diags if d.severity == "error"]


# --------------------------------------------------------------------------- SET / REP

def test_def_set_with_gap_and_rep_fill_whole_array():
    recs, diags = run("""
DEF REAL TABLE[2,3]=SET(1,2,,4)
DEF INT FIELD[5]=REP(9)
G0 X=TABLE[0,1] Y=TABLE[0,2] Z=TABLE[1,0]
G0 X=FIELD[0] Y=FIELD[4] Z=TABLE[1,2]
M30""")
    assert errors(diags) == []
    # SET(1,2,,4): [0,0]=1 [0,1]=2 [0,2]=gap->0 [1,0]=4, rest 0; REP(9) everywhere
    assert ends(recs) == [(2, 0, 4), (9, 9, 0)]


def test_runtime_set_writes_consecutive_elements_in_storage_order():
    recs, diags = run("""
DEF REAL T[2,3]=REP(7)
T[0,2]=SET(10,11,12)
G0 X=T[0,2] Y=T[1,0] Z=T[1,1]
G0 X=T[1,2] Y=T[0,1]
M30""")
    assert errors(diags) == []
    # from [0,2]: [0,2]=10, [1,0]=11, [1,1]=12; untouched [1,2] and [0,1] keep REP(7)
    assert ends(recs) == [(10, 11, 12), (7, 7, 12)]


def test_runtime_rep_fills_from_index_to_end():
    recs, diags = run("""
DEF INT F[5]=SET(1,2,3,4,5)
F[2]=REP(0)
G0 X=F[1] Y=F[2] Z=F[4]
M30""")
    assert errors(diags) == []
    assert ends(recs) == [(2, 0, 0)]


def test_set_past_the_end_is_a_range_error():
    _, diags = run("""
DEF INT F[3]
F[1]=SET(1,2,3)
M30""")
    assert any(d.rule == "NC105" for d in diags)


@settings(max_examples=40, deadline=None)
@given(hs.integers(1, 4), hs.integers(1, 4), hs.data())
def test_set_from_any_index_matches_row_major_model(rows, cols, data):
    start = data.draw(hs.integers(0, rows * cols - 1))
    count = data.draw(hs.integers(1, rows * cols - start))
    vals = list(range(100, 100 + count))
    i, j = divmod(start, cols)
    reads = " ".join(f"R{k}=A[{k // cols},{k % cols}]" for k in range(rows * cols))
    res = parse(f"DEF REAL A[{rows},{cols}]=REP(-1)\nA[{i},{j}]=SET({','.join(map(str, vals))})\n"
                f"{reads}\nM30\n", "t.mpf")
    from nctrans.interp.interpreter import Interpreter
    diags: list = []
    it = Interpreter(res.program, diagnostics=diags)
    list(it.run())
    model = [-1] * (rows * cols)
    model[start:start + count] = vals
    assert [it.ev.R.get(k) for k in range(rows * cols)] == model
    assert errors(diags) == []


# --------------------------------------------------------------------------- AXIS values

def test_axis_variable_compares_and_indexes_position():
    recs, diags = run("""
DEF AXIS AXNAME=(X)
DEF AXIS OTHER="Y"
G0 X12 Y3
R1=$AA_IM[AXNAME]
R2=$P_EP[OTHER]
IF AXNAME==X GOTOF SAME
G0 X999
SAME:
IF AXNAME==OTHER GOTOF DIFF
G0 X=R1+1 Y=R2+1
DIFF:
M30""")
    assert errors(diags) == []
    # $AA_IM[X]=12 (no offsets), $P_EP[Y]=3; X==X jumps over X999, X<>Y does not jump
    assert ends(recs) == [(12, 3, 0), (13, 4, 0)]


def test_axis_variables_in_variables_corpus_program_are_clean():
    ld = pipeline.load(str(Path(__file__).resolve().parents[1] / "corpus/sinumerik/variables.mpf"),
                       "sinumerik")
    diags = pipeline.lint(ld)
    assert [d for d in diags if d.rule.startswith("NC1")] == []


# --------------------------------------------------------------------------- frames

def test_pframe_chain_equals_trans_then_arot():
    recs_a, da = run("""
G0 X0 Y0
$P_PFRAME=CTRANS(X,10,Y,5):CROT(Z,90)
G0 X5 Y0
M30""")
    recs_b, db = run("""
G0 X0 Y0
TRANS X10 Y5
AROT Z90
G0 X5 Y0
M30""")
    assert errors(da) == [] and errors(db) == []
    # T(10,5)·Rz(90): program (5,0) -> rotated (0,5) -> shifted (10,10)
    assert ends(recs_a) == ends(recs_b) == [(0, 0, 0), (10, 10, 0)]


@settings(max_examples=30, deadline=None)
@given(hs.integers(-50, 50), hs.integers(-50, 50), hs.integers(-180, 180), hs.integers(1, 3))
def test_frame_expression_matches_frame_instructions(tx, ty, ang, sc):
    a, _ = run(f"$P_PFRAME=CTRANS(X,{tx},Y,{ty}):CROT(Z,{ang}):CSCALE(X,{sc},Y,{sc})\n"
               "G0 X7 Y-3\nM30")
    b, _ = run(f"TRANS X{tx} Y{ty}\nAROT Z{ang}\nASCALE X{sc} Y{sc}\nG0 X7 Y-3\nM30")
    assert ends(a) == ends(b)
    # hand model: p = T + Rz(ang)·(sc·(7,-3))
    c, s = math.cos(math.radians(ang)), math.sin(math.radians(ang))
    x, y = 7 * sc, -3 * sc
    assert ends(a)[0][:2] == pytest.approx((tx + c * x - s * y, ty + s * x + c * y), abs=1e-3)


def test_frame_variable_neutral_frame_and_read_back():
    recs, diags = run("""
DEF FRAME BEVEL
DEF FRAME KEEP
BEVEL=CTRANS(X,5):CMIRROR(X)
$P_PFRAME=BEVEL
G0 X2 Y1
KEEP=$P_PFRAME
$P_PFRAME=TRANS()
G0 X2 Y1
$P_PFRAME=KEEP:CTRANS(Y,10)
G0 X2 Y1
M30""")
    assert errors(diags) == []
    # T(5)·Mirror(X): (2,1) -> (-2,1) -> (3,1); neutral: (2,1); KEEP then ATRANS Y10 (mirror
    # does not touch Y): (2,11) -> (-2,11) -> (3,11)
    assert ends(recs) == [(3, 1, 0), (2, 1, 0), (3, 11, 0)]


def test_frame_component_write_keeps_the_frame_with_a_note():
    recs, diags = run("TRANS X10\n$P_PFRAME[X,TR]=25\nG0 X1\nM30")
    assert ends(recs) == [(11, 0, 0)]
    assert [d.rule for d in diags] == ["NC237"]        # a warning: the frame is kept as it was


def test_frame_value_in_arithmetic_is_a_type_error():
    _, diags = run("R1=CTRANS(X,1)+1\nM30")
    assert any(d.rule == "NC104" for d in diags)


# --------------------------------------------------------------------------- VAR parameters

def test_var_parameters_write_back_names_r_and_elements():
    recs, diags = run("""
DEF REAL W=4
DEF REAL A[3]=SET(1,2,3)
R5=1
ADD2(W, R5, A[1], 10)
G0 X=W Y=R5 Z=A[1]
M30
%_N_ADD2_SPF
PROC ADD2(VAR REAL PP, VAR REAL QQ, VAR REAL EL, REAL VAL)
PP=PP+2
QQ=QQ+VAL
EL=EL*VAL
VAL=0
RET""")
    assert errors(diags) == []
    # W=4+2, R5=1+10, A[1]=2*10; the by-value VAL=0 stays in the callee
    assert ends(recs) == [(6, 11, 20)]


def test_var_array_parameter_aliases_the_whole_array():
    recs, diags = run("""
DEF INT A[3]
FILL(A)
G0 X=A[0] Y=A[2]
M30
%_N_FILL_SPF
PROC FILL(VAR INT B[3])
B[0]=REP(5)
B[2]=8
RET""")
    assert errors(diags) == []
    assert ends(recs) == [(5, 8, 0)]


def test_var_parameter_passed_on_through_two_levels():
    recs, diags = run("""
DEF REAL W=1
OUTER(W)
G0 X=W
M30
%_N_OUTER_SPF
PROC OUTER(VAR REAL PP)
INNER(PP)
RET
%_N_INNER_SPF
PROC INNER(VAR REAL QQ)
QQ=QQ+41
RET""")
    assert errors(diags) == []
    assert ends(recs) == [(42, 0, 0)]


# --------------------------------------------------------------------------- MCALL

def test_mcall_fires_after_g0_alone_and_after_feed_in_g1():
    recs, _ = run("""
G90 G0 X0 Y0 Z0
MCALL L48
G0
G1 F100
S1000
G0 G90
MCALL
G0
M30
%_N_L48_SPF
PROC L48
G0 Z=IC(1)
M17""")
    zs = [p[2] for p in ends(recs)]
    # G0 alone: call; G1 F100: call; S1000 with G1 active: call; G0 G90: call; after MCALL off: none
    assert zs == [0, 1, 2, 3, 4]


def test_iso_g66_is_not_triggered_by_a_mode_alone():
    from nctrans.dialects import base
    d = base.get("iso-m")
    if d is None:
        pytest.skip("iso-m front end not installed")
    res = d.parse("O1\nG90 G0 X0 Y0 Z0\nG66 P9\nG0\nG67\nM30\nO9\nG91 G0 Z1\nM99\n", "t.nc")
    diags: list = []
    recs = list(interpret(res.program, diagnostics=diags))
    assert ends(recs) == [(0, 0, 0)]


# --------------------------------------------------------------------------- SAVE

def test_save_restores_modes_and_frames_on_return():
    recs, diags = run("""
G90 G17 G0 X0 Y0 Z0
TRANS X100
SUB1
G0 X1 Y1
SUB2
G0 X1 Y1
M30
%_N_SUB1_SPF
PROC SUB1 SAVE
G91 G18
TRANS X5
G0 X1
RET
%_N_SUB2_SPF
PROC SUB2
G91
G0 X1
RET""")
    assert errors(diags) == []
    # SUB1 (SAVE): TRANS X5 puts machine 0 at program X-5; incremental X1 -> machine 1;
    # back: G90 and TRANS X100 again -> (101,1). SUB2 (no SAVE): G91 X1 -> 102, then G91 stays
    # in force -> X+1 Y+1 -> (103, 2)
    assert ends(recs) == [(0, 0, 0), (1, 0, 0), (101, 1, 0), (102, 1, 0), (103, 2, 0)]


# --------------------------------------------------------------------------- GUD preload

def test_preloaded_definitions_are_global_variables():
    gud = parse("DEF CHAN REAL _OFS[3]=SET(1,2,3)\nDEF NCK INT _COUNT=5\n", "GUD.DEF").program
    recs, diags = run("G0 X=_OFS[2] Y=_COUNT\n_COUNT=_COUNT+1\nG0 Z=_COUNT\nM30", preload=[gud])
    assert errors(diags) == []
    assert ends(recs) == [(3, 5, 0), (3, 5, 6)]
    _, diags = run("G0 X=_OFS[2]\nM30")
    assert [d.rule for d in diags if d.severity == "error"] == ["NC101"]


def test_pipeline_preloads_def_files_of_the_source_directory(tmp_path):
    (tmp_path / "MYGUD.DEF").write_text("DEF CHAN REAL IZMERENO_XT[3]=REP(2.5)\n")
    prog = tmp_path / "P1.SPF"
    prog.write_text("G0 X=IZMERENO_XT[1]\nM17\n")
    ld = pipeline.load(str(prog), "sinumerik")
    recs = list(pipeline.toolpath_of(ld))
    assert [d for d in ld.diagnostics if d.rule == "NC101"] == []
    assert ends(recs) == [(2.5, 0, 0)]


def test_gud_file_of_the_real_corpus_runs_its_rep_initialisers():
    ld = pipeline.load(str(CORPUS / "sinumerik" / "nadj-fb422-PGUD.DEF"), "sinumerik")
    diags = pipeline.lint(ld)
    assert [d.format_text() for d in diags if d.rule == "NC104"] == []
    # what is left are names from Siemens definition modules not in the corpus (_N_SMAC_DEF
    # macros _SC_NO_VAL/_SC_A_NO_VAL, and NO_AXIS, which the seed does not document)
    undefined = {d.message.split()[1] for d in diags if d.rule == "NC101"}
    assert undefined == {"_SC_NO_VAL", "_SC_A_NO_VAL", "NO_AXIS"}


# --------------------------------------------------------------------------- ROT about several axes

def _rx(a, p):
    c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
    return (p[0], c * p[1] - s * p[2], s * p[1] + c * p[2])


def _ry(b, p):
    c, s = math.cos(math.radians(b)), math.sin(math.radians(b))
    return (c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2])


def _rz(c_, p):
    c, s = math.cos(math.radians(c_)), math.sin(math.radians(c_))
    return (c * p[0] - s * p[1], s * p[0] + c * p[1], p[2])


@pytest.mark.parametrize("spelling", ["ROT X30 Y20 Z10", "ROT Z10 Y20 X30", "ROT Y20 X30 Z10",
                                      "$P_PFRAME=CROT(X,30,Y,20,Z,10)",
                                      "$P_PFRAME=CROT(Z,10,X,30,Y,20)"])
def test_rotation_about_several_axes_is_rpy_whatever_the_written_order(spelling):
    # spec sinumerik.md (ROT X a Y b Z c): R = Rz(c)·Ry(b)·Rx(a), the written order does not matter
    recs, diags = run(f"{spelling}\nG0 X3 Y10 Z1\nM30")
    assert not errors(diags)
    want = _rz(10, _ry(20, _rx(30, (3.0, 10.0, 1.0))))
    assert ends(recs) == [tuple(round(v, 4) for v in want)]


def test_additive_rotation_about_several_axes_chains_rpy_in_the_rotated_system():
    # ROT Z90 then AROT X90 Y90: Rz(90)·Ry(90)·Rx(90); program (3, 10, 1) -> (1, 10, -3) by hand
    recs, _ = run("ROT Z90\nAROT X90 Y90\nG0 X3 Y10 Z1\nM30")
    assert ends(recs) == [(1.0, 10.0, -3.0)]
