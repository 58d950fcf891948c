"""Fagor call-frame parameters (P0..P99) and V.P. user variables converted to Sinumerik as DEF'd
variables of the unit they live in (nctrans.lower.frame_locals): the program keeps its structure
(before, every such program was lowered whole to plain motion, or its lines refused in place)."""
from __future__ import annotations

from pathlib import Path

import pytest

from nctrans import api

CORPUS = Path(__file__).resolve().parent.parent / "corpus" / "fagor"

LOOP = ("%LOOP\nG0 X0 Y0 Z5\nP1=0\n$WHILE P1<3\nG1 X[P1*10+10] F100\nP1=P1+1\n$ENDWHILE\n"
        "V.P.DEPTH=-2\nG1 Z[V.P.DEPTH]\nM30\n")


def _convert(tmp_path, text, name="p.nc"):
    src = tmp_path / name
    src.write_text(text)
    conv = api.transpile(src, read="fagor", write="sinumerik")
    out = tmp_path / (name + ".mpf")
    out.write_text(conv.text)
    return src, out, conv


def test_loop_counter_and_user_variable_are_defd(tmp_path):
    src, out, conv = _convert(tmp_path, LOOP)
    lines = conv.text.splitlines()
    assert "DEF REAL P_1, V_P_DEPTH" in lines
    assert "WHILE P_1<3" in lines and "flattened" not in conv.text
    # hand: P1 = 0, 1, 2 -> X = 0*10+10, 1*10+10, 2*10+10 = 10, 20, 30; then Z = V.P.DEPTH = -2
    ends = [(r.end["X"], r.end["Z"]) for r in api.toolpath(out) if r.kind == "linear"]
    assert ends == [(10.0, 5.0), (20.0, 5.0), (30.0, 5.0), (30.0, -2.0)]
    assert api.equiv(src, out, read_a="fagor").equivalent


@pytest.mark.parametrize("name", ["02-parameters.nc", "03-flow.nc", "12-machine-test.nc"])
def test_corpus_programs_keep_their_structure(tmp_path, name):
    src = CORPUS / name
    conv = api.transpile(src, read="fagor", write="sinumerik")
    assert "flattened by nctrans" not in conv.text
    assert not [d for d in conv.diagnostics if "program was lowered to plain motion" in d.message]
    assert "DEF REAL P_" in conv.text
    out = tmp_path / (name + ".mpf")
    out.write_text(conv.text)
    assert api.equiv(src, out, read_a="fagor").equivalent


def test_subroutine_local_is_its_own(tmp_path):
    # %L WARMUP sets P20 by its $FOR before reading it, and nothing else names P20: DEF in the PROC
    conv = api.transpile(CORPUS / "12-machine-test.nc", read="fagor", write="sinumerik")
    lines = conv.text.splitlines()
    at = lines.index("PROC WARMUP LOCAL")
    assert lines[at + 1] == "DEF REAL P_20"


def test_not_declared_where_a_subroutine_may_see_them(tmp_path):
    # V.P. is seen by a subroutine it calls; P1 is shared with a #CALL'd file not in the program;
    # V.S. outlives the program: none is a DEF'd local (unchanged: lowered or refused as before)
    for text, key in (('V.P.D=1\n#PCALL "SUB.NC" A1\nG1 X[V.P.D] F100\nM30\n', "V_P_D"),
                      ('P1=1\n#CALL "SUB.NC"\nG1 XP1 F100\nM30\n', "P_1"),
                      ("V.S.D=1\nG1 X[V.S.D] F100\nM30\n", "V_S_D")):
        conv = api.transpile(text, read="fagor", write="sinumerik")
        assert f"DEF REAL {key}" not in (conv.text or "")


def test_pcall_subroutine_becomes_a_proc_with_its_parameters(tmp_path):
    # corpus 07-calls: HOLE is called only by #PCALL/#MCALL (a new frame, A = P0, B = P1); PATTERN
    # shares the main frame by #CALL but sets its P10 itself; main's P0 = 99 is its own frame's
    src = CORPUS / "07-calls.nc"
    conv = api.transpile(src, read="fagor", write="sinumerik")
    lines = conv.text.splitlines()
    assert "flattened by nctrans" not in conv.text
    assert "PROC HOLE(REAL P_0, REAL P_1) LOCAL" in lines
    assert "HOLE(50, -1)" in lines and "MCALL HOLE(7, -2)" in lines
    assert "  HOLE(P_10*10, -3)" in lines
    out = tmp_path / "07.mpf"
    out.write_text(conv.text)
    # hand: HOLE A50 B-1 plunges at X50 to Z-1; main's P0 is still 99 after the call (its own frame)
    feeds = [(r.end["X"], r.end["Z"]) for r in api.toolpath(out) if r.kind == "linear"]
    assert feeds[:2] == [(50.0, -1.0), (99.0, 2.0)]
    # PATTERN: P10 = 0, 1, 2 -> holes at X 0, 10, 20 to Z-3
    assert [x for x, z in feeds if z == -3.0] == [0.0, 10.0, 20.0]
    assert api.equiv(src, out, read_a="fagor").equivalent


def test_pcall_leaving_out_an_argument_the_body_reads_is_not_a_proc():
    # the second call passes no B: Fagor stops reading P1 (never set); a PROC parameter reads 0
    text = ("%L HOLE\nG00 XP0 Y0 Z2\nG01 ZP1 F100\n#RET\n%MAIN\n#PCALL HOLE A50 B-1\n"
            "#PCALL HOLE A60\nM30\n")
    conv = api.transpile(text, read="fagor", write="sinumerik")
    assert "PROC HOLE(REAL P_0, REAL P_1)" not in (conv.text or "")


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@settings(max_examples=25, deadline=None)
@given(start=st.integers(0, 3), stop=st.integers(1, 5), step=st.integers(1, 2),
       scale=st.integers(1, 9), depth=st.integers(-5, -1))
def test_property_counting_programs_convert_with_structure(tmp_path_factory, start, stop, step, scale, depth):
    # a counting loop over a local parameter, a user variable and a #PCALL'd subroutine with two
    # arguments: the Sinumerik program keeps the loop (WHILE over P_1) and drives the same path
    text = (f"%L HOLE\nG00 XP0 Y0 Z2\nG01 ZP1 F100\nG00 Z2\n#RET\n%PROG\nG0 X0 Y0 Z5\n"
            f"V.P.DEPTH={depth}\nP1={start}\n$WHILE P1<={stop}\n"
            f"#PCALL HOLE A[P1*{scale}] B[V.P.DEPTH]\nP1=P1+{step}\n$ENDWHILE\nM30\n")
    tmp = tmp_path_factory.mktemp("prop")
    src = tmp / "p.nc"
    src.write_text(text)
    conv = api.transpile(src, read="fagor", write="sinumerik")
    assert "flattened" not in conv.text
    out = tmp / "p.mpf"
    out.write_text(conv.text)
    # hand: one plunge per P1 = start, start+step, ... <= stop, at X = P1*scale to Z = depth
    expect = [(p * scale, depth) for p in range(start, stop + 1, step)]
    got = [(r.end["X"], r.end["Z"]) for r in api.toolpath(out) if r.kind == "linear"]
    assert got == [(float(x), float(z)) for x, z in expect]
    assert api.equiv(src, out, read_a="fagor").equivalent
