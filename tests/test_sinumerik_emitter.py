"""Sinumerik emitter: parse(emit(parse(x))) == parse(x) on real and generated programs, and the
lowerings of IR that comes from other dialects (R parameters, MCALL cycles, G65, passthrough)."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

from nctrans.dialects.sinumerik.emitter import emit
from nctrans.dialects.sinumerik.frontend import parse
from nctrans.ir import nodes as ir
from nctrans.source import read_source
from conftest import CORPUS, examples
from roundtrip import assert_ir_round_trip, ir_round_trip

REPO = Path(__file__).resolve().parents[1]
OWN = sorted((REPO / "corpus" / "sinumerik").glob("*"))
REAL = sorted((CORPUS / "sinumerik").glob("*"))


def roundtrip(text: str, file: str = "t.mpf"):
    return ir_round_trip("sinumerik", text, file)


def assert_roundtrip(text: str, file: str = "t.mpf") -> str:
    # numbers without their source spelling are written to 12 significant digits
    return assert_ir_round_trip("sinumerik", text, file, digits=9, meta_ignored=("defaults",))


@pytest.mark.parametrize("path", OWN, ids=lambda p: p.name)
def test_roundtrip_conformance_corpus(path):
    assert_roundtrip(read_source(path).text, str(path))


@pytest.mark.parametrize("path", REAL, ids=lambda p: p.name)
def test_roundtrip_shared_corpus(path):
    assert_roundtrip(read_source(path).text, str(path))


def test_shared_corpus_is_present():
    assert len(REAL) >= 30, "the shared Sinumerik corpus should be read in place from ../shared"


# --------------------------------------------------------------------------- idiomatic output

def test_output_is_idiomatic():
    text = assert_roundtrip(
        "DEF INT I\nIF (R1>2) AND (R2<1)\nG2 X10 Y0 CR=5\nELSE\nAROT RPL=30\nENDIF\n"
        "FOR I=1 TO 3\nENDFOR\nREPEAT\nR1=R1-1\nUNTIL R1<0\nLOOP\nGOTOF E\nENDLOOP\nE: M30 ; end\n")
    lines = [l.strip() for l in text.splitlines()]
    assert lines[0] == "DEF INT I"
    assert "IF (R1>2) AND (R2<1)" in lines and "ENDIF" in lines and "ELSE" in lines
    assert "G2 X10 Y0 CR=5" in lines and "AROT RPL=30" in lines
    assert "FOR I=1 TO 3" in lines and "ENDFOR" in lines and "UNTIL R1<0" in lines
    assert "E: M30 ;end" in lines[-1].replace("; ", ";")


def test_comparisons_are_parenthesised_inside_boolean_operators():
    prog = ir.Program("x", "iso-m", [ir.Block(ir.Span("x", 1), [ir.Goto("L1", "forward", ir.Binary(
        "and", ir.Binary("==", ir.Var("R", 1), ir.Num(1.0)), ir.Binary(">", ir.Var("R", 2), ir.Num(0.0))))])])
    text = emit(prog).text
    assert text.strip() == "IF (R1==1) AND (R2>0) GOTOF L1"
    g = parse(text, "x").program.body[0].body[0]
    assert g.cond.op == "and"


# --------------------------------------------------------------------------- lowerings from other dialects

def block(*stmts):
    return ir.Block(ir.Span("iso.nc", 1), list(stmts))


def test_iso_macro_variables_become_r_parameters():
    prog = ir.Program("iso.nc", "iso-m", [
        block(ir.Assign(ir.Var("num", 100), ir.Binary("*", ir.Var("num", 1), ir.Num(2.0)))),
        block(ir.Assign(ir.Var("num", None, [ir.Var("num", 3)]), ir.Num(1.0)))])
    out = emit(prog)
    assert out.text.splitlines() == ["R100=R1*2", "R[R3]=1"]
    assert [d.rule for d in out.diagnostics] == ["NC401"]
    bad = emit(ir.Program("iso.nc", "iso-m", [block(ir.Assign(ir.Var("num", 0), ir.Num(1.0)))]))
    assert [d.rule for d in bad.diagnostics if d.severity == "error"] == ["NC402"]


def test_g65_call_passes_arguments_in_r_parameters():
    call = ir.SubCall("O9001", named_args={"A": ir.Num(1.5), "B": ir.Num(2.0)}, kind="g65",
                      bindings={"A": ir.Var("num", 1), "B": ir.Var("num", 2)})
    sub = ir.Subprogram("O9001", ir.Span("iso.nc", 5), [block(ir.Return())])
    out = emit(ir.Program("iso.nc", "iso-m", [block(call)], {"O9001": sub}))
    lines = out.text.splitlines()
    assert lines[0] == "R1=1.5 R2=2 L9001"
    assert lines[1:] == ["%_N_L9001_SPF", "PROC L9001", "RET"]
    back = parse(out.text, "o.mpf").program
    assert "L9001" in back.subprograms


def test_iso_drill_cycle_becomes_mcall_cycle81():
    body = [
        block(ir.ModeChange("motion", "rapid"), ir.Motion({"Z": ir.AxisValue(ir.Num(10.0))})),
        block(ir.ModeChange("cycle_retract", "r_plane"), ir.ModeChange("cycle", "drill"),
              ir.CycleParams({"r_plane": ir.Num(2.0)}),
              ir.Motion({"X": ir.AxisValue(ir.Num(10.0)), "Y": ir.AxisValue(ir.Num(5.0)),
                         "Z": ir.AxisValue(ir.Num(-5.0))})),
        block(ir.Motion({"X": ir.AxisValue(ir.Num(20.0))})),
        block(ir.ModeChange("cycle", "off"))]
    out = emit(ir.Program("iso.nc", "iso-m", body))
    assert out.text.splitlines() == ["G0 Z10", "MCALL CYCLE81(2, 2, 0, -5)", "G0 X10 Y5", "G0 X20",
                                     "MCALL"]
    calls = [s for b in parse(out.text, "o.mpf").program.body for s in b.body
             if isinstance(s, ir.CycleCall)]
    assert calls[0].modal and calls[0].params["r_plane"].value == 2
    assert {d.rule for d in out.diagnostics} == {"NC401"}


def test_iso_initial_level_and_incremental_cycle_use_programmed_position():
    body = [block(ir.ModeChange("distance", "incremental"), ir.ModeChange("cycle_retract", "initial"),
                  ir.ModeChange("cycle", "drill_dwell"),
                  ir.CycleParams({"r_plane": ir.Num(-8.0), "dwell": ir.Num(0.5)}),
                  ir.Motion({"X": ir.AxisValue(ir.Num(10.0)), "Z": ir.AxisValue(ir.Num(-3.0))}))]
    line = emit(ir.Program("iso.nc", "iso-m", body)).text.splitlines()[1]
    assert line == "MCALL CYCLE82($P_EP[Z], $P_EP[Z]+(-8), 0, $P_EP[Z]+(-8)+(-3),, 0.5)"


def test_iso_initial_level_known_from_the_program_gives_plain_numbers():
    rapid_z = block(ir.ModeChange("motion", "rapid"), ir.Motion({"Z": ir.AxisValue(ir.Num(10.0))}))
    g98 = [rapid_z, block(ir.ModeChange("cycle", "drill"), ir.CycleParams({"r_plane": ir.Num(2.0)}),
                          ir.Motion({"X": ir.AxisValue(ir.Num(1.0)), "Z": ir.AxisValue(ir.Num(-5.0))}))]
    assert emit(ir.Program("iso.nc", "iso-m", g98)).text.splitlines()[1] == "MCALL CYCLE81(10, 2, 0, -5)"
    # G91: R is from the initial level (10-8=2), Z from R (2-3=-1); G98 returns to 10
    inc = [rapid_z, block(ir.ModeChange("distance", "incremental"), ir.ModeChange("cycle", "drill"),
                          ir.CycleParams({"r_plane": ir.Num(-8.0)}),
                          ir.Motion({"X": ir.AxisValue(ir.Num(1.0)), "Z": ir.AxisValue(ir.Num(-3.0))}))]
    assert emit(ir.Program("iso.nc", "iso-m", inc)).text.splitlines()[2] == "MCALL CYCLE81(10, 2, 0, -1)"


def test_iso_cycles_without_siemens_equivalent_are_refused():
    # G87 back boring: no standard cycle bores upwards (rules/cycle-mapping.toml `none`)
    body = [block(ir.ModeChange("cycle", "back_bore"), ir.CycleParams({"r_plane": ir.Num(2.0)}))]
    out = emit(ir.Program("iso.nc", "iso-m", body))
    assert any(d.rule == "NC402" and "--flatten" in d.message and "upwards" in d.message
               for d in out.diagnostics)


def test_foreign_passthrough_is_reported():
    # Haas G47 (engraving) is no Sinumerik word: never copied as if it meant something there
    out = emit(ir.Program("iso.nc", "iso-m", [block(ir.Passthrough("G47 X1", "engraving", "iso-m"))]))
    assert [d.rule for d in out.diagnostics] == ["NC402"] and out.text.strip().startswith(";")
    # foreign text that is a Sinumerik word of its own meaning is kept, with NC403
    out = emit(ir.Program("iso.nc", "iso-m", [block(ir.Passthrough("G64", "contouring", "iso-m"))]))
    assert [d.rule for d in out.diagnostics] == ["NC403"] and out.text.strip() == "G64"
    out = emit(ir.Program("iso.nc", "iso-m", [block(ir.Passthrough("#1=[#2 EQ 1]*", "odd", "iso-m"))]))
    assert [d.rule for d in out.diagnostics] == ["NC402"]
    assert out.text.strip().startswith(";")                 # kept as a comment, still parses
    assert not parse(out.text, "o.mpf").diagnostics


def test_iso_frames_and_g92_are_lowered():
    body = [block(ir.FrameOp("rot", center={"X": ir.AxisValue(ir.Num(10.0)), "Y": ir.AxisValue(ir.Num(5.0))},
                             angle=ir.Num(30.0))),
            block(ir.SetPosition({"X": ir.AxisValue(ir.Num(0.0))})),
            block(ir.FrameOp("rot", clear=True))]
    out = emit(ir.Program("iso.nc", "iso-m", body))
    assert out.text.splitlines()[:4] == ["ATRANS X=10 Y=5", "AROT RPL=30", "ATRANS X=-(10) Y=-(5)",
                                         "ATRANS X=$P_EP[X]-(0)"]
    assert not [d for d in parse(out.text, "o.mpf").diagnostics if d.rule.startswith("NC0")]
    # G69 ends the rotation only; the G92 shift stays (ISO), while the TRANS it would need clears
    # the whole programmable frame: refused (the conversion lowers or refuses that stretch)
    assert "TRANS" not in out.text.splitlines()
    assert [d.rule for d in out.diagnostics if "stays in force" in d.message] == ["NC402"]


def test_for_loop_with_step_becomes_while():
    loop = ir.ForLoop(ir.Span("x", 1), ir.Var("name", "I"), ir.Num(0.0), ir.Num(10.0),
                      [block(ir.Motion({"X": ir.AxisValue(ir.Var("name", "I"))}))], step=ir.Num(2.0))
    text = emit(ir.Program("x", "pnc", [loop])).text
    assert text.splitlines() == ["I=0", "WHILE I<=10", "  X=(I)", "  I=I+2", "ENDWHILE"]


# --------------------------------------------------------------------------- generated programs

_VARS = ["R1", "R2", "R17", "DEPTH", "CNT"]
_NUMS = st.one_of(st.integers(-999, 999).map(str),
                  st.decimals(-999, 999, places=3, allow_nan=False, allow_infinity=False).map(
                      lambda d: format(d, "f")))


def _expr(depth: int = 2):
    atom = st.one_of(_NUMS, st.sampled_from(_VARS), st.sampled_from(["$P_EP[X]", "TAB[1,2]", "'H1F'"]))
    if depth == 0:
        return atom
    sub = _expr(depth - 1)
    return st.one_of(
        atom,
        st.tuples(sub, st.sampled_from(["+", "-", "*", "/", " DIV ", " MOD "]), sub).map(
            lambda t: f"({t[0]}{t[1]}{t[2]})"),
        st.tuples(st.sampled_from(["SIN", "COS", "SQRT", "ABS", "TRUNC", "POT"]), sub).map(
            lambda t: f"{t[0]}({t[1]})"),
        sub.map(lambda e: f"-{e}" if not e.startswith("-") else e))


def _cond():
    cmp = st.tuples(_expr(1), st.sampled_from(["==", "<>", "<", ">", "<=", ">="]), _expr(1)).map(
        lambda t: f"({t[0]}{t[1]}{t[2]})")
    return st.one_of(cmp, st.tuples(cmp, st.sampled_from([" AND ", " OR ", " XOR "]), cmp).map(
        lambda t: t[0] + t[1] + t[2]))


def _simple_block():
    num = _NUMS
    return st.one_of(
        st.tuples(st.sampled_from(["G0", "G1", ""]), num, _expr()).map(lambda t: f"{t[0]} X{t[1]} Y={t[2]}"),
        st.tuples(st.sampled_from(["G2", "G3"]), num, num, num).map(lambda t: f"{t[0]} X{t[1]} Y{t[2]} CR={t[3]}"),
        st.tuples(num, num).map(lambda t: f"G2 X{t[0]} Y0 I=AC({t[1]}) J0 TURN=1"),
        st.tuples(st.sampled_from(_VARS), _expr()).map(lambda t: f"{t[0]}={t[1]}"),
        st.tuples(st.sampled_from(["TRANS", "ATRANS", "SCALE"]), num).map(lambda t: f"{t[0]} X{t[1]} Y2"),
        num.map(lambda n: f"AROT RPL={n}"),
        st.sampled_from(["G17 G90 G54", "G18 G91 G505", "G40 G500 G94", "T1 D1 M6", "S1200 M3 M8",
                         "F=R1*2", "G4 F2", "M5 M9", "STOPRE", "MCALL CYCLE81(10,0,2,-5)", "MCALL",
                         'MSG("n=" << R1)', "SUB_A(1, ,R2) P2", "L100", "G0 SUPA Z0", "CIP X1 Y2 I1=3 J1=4",
                         "ID=1 WHEN $AA_IM[X]>5 DO M8", "TRANS", "DIAMON", "GOTOF END_LBL"]))


def _blocks(depth: int):
    simple = _simple_block().map(lambda b: [b])
    if depth == 0:
        return simple
    inner = st.lists(_blocks(depth - 1), min_size=1, max_size=3).map(lambda ls: [b for l in ls for b in l])
    return st.one_of(
        simple, simple, simple,
        st.tuples(_cond(), inner).map(lambda t: [f"IF {t[0]}"] + t[1] + ["ENDIF"]),
        st.tuples(_cond(), inner, inner).map(lambda t: [f"IF {t[0]}"] + t[1] + ["ELSE"] + t[2] + ["ENDIF"]),
        st.tuples(_cond(), inner).map(lambda t: [f"WHILE {t[0]}"] + t[1] + ["ENDWHILE"]),
        st.tuples(st.integers(1, 9), inner).map(lambda t: [f"FOR CNT=1 TO {t[0]}"] + t[1] + ["ENDFOR"]),
        st.tuples(inner, _cond()).map(lambda t: ["REPEAT"] + t[0] + [f"UNTIL {t[1]}"]),
        inner.map(lambda b: ["LOOP"] + b + ["ENDLOOP"]),
        st.tuples(_cond(), st.sampled_from(["GOTOF", "GOTOB", "GOTO"])).map(
            lambda t: [f"IF {t[0]} {t[1]} END_LBL"]),
        st.just(["CASE R1 OF 1 GOTOF END_LBL 2 GOTOB END_LBL DEFAULT GOTOF END_LBL"]))


@st.composite
def programs(draw):
    lines = ["DEF REAL DEPTH=1.5, TAB[2,3]", "DEF INT CNT"]
    body = draw(st.lists(_blocks(2), min_size=1, max_size=6))
    n = 10
    for group in body:
        for line in group:
            deco = draw(st.sampled_from(["", "number", "comment", "skip"]))
            if deco == "number" and not line.split()[0] in ("IF", "ELSE", "ENDIF", "WHILE", "ENDWHILE",
                                                          "FOR", "ENDFOR", "LOOP", "ENDLOOP", "REPEAT",
                                                          "UNTIL", "CASE"):
                line = f"N{n} {line}"
                n += 10
            elif deco == "comment":
                line += " ; note " + str(n)
            lines.append(line)
    lines += ["END_LBL: M30"]
    return "\n".join(lines) + "\n"


@pytest.mark.long_property
@settings(max_examples=examples(80, 30), deadline=None)
@given(programs())
def test_roundtrip_generated_programs(text):
    first = parse(text, "gen.mpf")
    assert not [d for d in first.diagnostics if d.rule.startswith("NC0")], (text, first.diagnostics)
    assert_roundtrip(text, "gen.mpf")


# --------------------------------------------------------------------------- ISO programs to Sinumerik

ISO_FILES = sorted((CORPUS / "iso-mill").glob("*")) + sorted((CORPUS / "linuxcnc").glob("*"))
# programs with no refused construct whose toolpath must not change (the others use cycles or macro
# system variables the emitter refuses, or rely on MCALL firing on a G0 block without motion)
SAME_TOOLPATH = ["brianhooper-fusion-1001.nc", "camotics-scorpion.nc", "kiely-haas-stepblock-steps.nc",
                 "kiely-haas-teammachine-engrave.nc", "lmhdpro-JPM-abs-handwritten.nc",
                 "safetydav3-fusion-inch-annotated.nc", "stcline-writing-program-example.nc",
                 "linuxcnc-lathe_pawn.ngc"]


def _iso():
    from nctrans.dialects import base
    try:
        return base.get("iso-m")
    except Exception:       # the iso-m package is not importable in this checkout
        return None


@pytest.mark.skipif(_iso() is None, reason="iso-m front end not installed")
@pytest.mark.parametrize("path", ISO_FILES, ids=lambda p: p.name)
def test_iso_programs_emit_valid_sinumerik(path):
    prog = _iso().parse(read_source(path).text, str(path)).program
    out = emit(prog)
    back = parse(out.text, "out.mpf")
    assert not [d for d in back.diagnostics if d.rule.startswith("NC0")], \
        [d.format_text() for d in back.diagnostics][:3]
    assert all(d.rule.startswith("NC4") for d in out.diagnostics)


@pytest.mark.skipif(_iso() is None, reason="iso-m front end not installed")
@pytest.mark.parametrize("name", SAME_TOOLPATH)
def test_iso_programs_keep_their_toolpath(name):
    import itertools
    from nctrans.interp import interpret
    path = next(p for p in ISO_FILES if p.name == name)
    prog = _iso().parse(read_source(path).text, str(path)).program
    out = emit(prog)
    assert not [d for d in out.diagnostics if d.severity == "error"]

    def ends(p):
        recs = interpret(p, diagnostics=[], max_steps=200_000)
        return [(r.kind, tuple(round(r.end.get(a, 0.0), 3) for a in "XYZ"))
                for r in itertools.islice(recs, 5000) if r.end]

    assert ends(parse(out.text, "out.mpf").program) == ends(prog)
