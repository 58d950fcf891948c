"""ISO round trip: parse(emit(parse(x))) is parse(x) up to spans and number spellings, on generated
programs and on every iso-mill corpus file; plus the emitter's normal form and its NC40x reports."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

from nctrans.dialects.iso_m import emit, parse
from nctrans.ir import nodes as n
from conftest import CORPUS, examples
from roundtrip import assert_ir_round_trip

ISO_FILES = sorted((CORPUS / "iso-mill").glob("*"))


def assert_round_trip(text: str) -> str:
    return assert_ir_round_trip("iso-m", text, "t.nc", meta_ignored=("percent",), refusals=False)


# --------------------------------------------------------------------- generator of ISO programs

num = st.one_of(st.integers(-99999, 99999).map(str),
                st.floats(-9999, 9999, allow_nan=False).map(lambda v: f"{v:.4f}"),
                st.integers(0, 999).map(lambda v: f".{v}"))
pos_int = st.integers(1, 99).map(str)
var = st.sampled_from(["#1", "#24", "#100", "#500", "#[#1+1]"])
atom = st.one_of(num, var)
expr = st.recursive(atom, lambda e: st.one_of(
    # a negative right operand is bracketed: two signs in a row (`1--5`) are an NC002 error
    st.tuples(e, st.sampled_from(["+", "-", "*", "/", "OR", "AND"]), e).map(
        lambda t: f"[{t[0]}{t[1]}{f'[{t[2]}]' if t[2].startswith('-') else t[2]}]"),
    st.tuples(st.sampled_from(["SIN", "COS", "SQRT", "ABS", "FIX", "FUP", "ROUND"]), e).map(lambda t: f"{t[0]}[{t[1]}]"),
    st.tuples(e, e).map(lambda t: f"ATAN[{t[0]}]/[{t[1]}]"),
), max_leaves=4)
cond = st.tuples(expr, st.sampled_from(["EQ", "NE", "GT", "GE", "LT", "LE"]), expr).map(
    lambda t: f"[{t[0]}{t[1]}{t[2]}]")
value = st.one_of(num, num, var, expr.map(lambda e: e if e.startswith("[") else f"[{e}]"))


def axes(letters="XYZ"):
    return st.lists(st.tuples(st.sampled_from(list(letters)), value), min_size=1, max_size=3,
                    unique_by=lambda t: t[0]).map(lambda ws: " ".join(a + v for a, v in ws))


line_kind = st.one_of(
    st.tuples(st.sampled_from(["G0", "G00", "G1", "G01"]), axes("XYZAB")).map(" ".join),
    st.tuples(st.sampled_from(["G1"]), axes(), num).map(lambda t: f"{t[0]} {t[1]} F{t[2].lstrip('-')}"),
    st.tuples(st.sampled_from(["G2", "G3"]), axes("XY"), value, value).map(lambda t: f"G17 {t[0]} {t[1]} I{t[2]} J{t[3]}"),
    st.tuples(st.sampled_from(["G2", "G3"]), axes("XY"), num).map(lambda t: f"{t[0]} {t[1]} R{t[2]}"),
    axes("XYZ"),
    st.sampled_from(["G17", "G18", "G19", "G90", "G91", "G94", "G95", "G40", "G49", "G80", "G98", "G99",
                     "G54", "G55", "G59", "G61", "G64", "G15", "G69", "G50", "G50.1", "G67", "M5", "M9",
                     "M0", "M1", "M8", "G90.1", "G91.1", "G54.1 P3", "M74", "G10 L2 P1 X1. Y2."]),
    st.tuples(pos_int, pos_int).map(lambda t: f"G41 D{t[0]} G1 X1. Y{t[1]}."),
    st.tuples(pos_int, num).map(lambda t: f"G43 H{t[0]} Z{t[1]}"),
    st.tuples(pos_int, pos_int).map(lambda t: f"T{t[0]} M6 S{t[1]}00 M3"),
    st.tuples(st.sampled_from(["G81", "G82", "G83", "G73", "G76", "G85"]), axes("XY"), num, num, pos_int)
      .map(lambda t: f"G99 {t[0]} {t[1]} Z{t[2]} R{t[3]} Q0.5 P{t[4]}00 K2"),
    st.tuples(pos_int).map(lambda t: f"G4 P{t[0]}00"),
    st.tuples(num).map(lambda t: f"G91 G28 Z{t[0]}"),
    st.tuples(axes("XY")).map(lambda t: f"G92 {t[0]}"),
    st.tuples(axes("XY")).map(lambda t: f"G52 {t[0]}"),
    st.tuples(num).map(lambda t: f"G68 X0 Y0 R{t[0]}"),
    st.tuples(st.integers(1, 50000).map(str)).map(lambda t: f"G51 X0 Y0 P{t[0]}"),
    st.tuples(pos_int, value).map(lambda t: f"#{t[0]}={t[1]}"),
    st.tuples(cond, pos_int).map(lambda t: f"IF{t[0]}GOTO{t[1]}"),
    st.tuples(cond, pos_int, expr).map(lambda t: f"IF{t[0]}THEN#{t[1]}={t[2]}"),
    pos_int.map(lambda t: f"GOTO{t}"),
    st.tuples(pos_int, pos_int).map(lambda t: f"M98 P{t[0]}000 L{t[1]}"),
    st.tuples(pos_int, num, num).map(lambda t: f"G65 P{t[0]}00 A{t[1]} I{t[2]} J1. I3. X#24"),
)
prefix = st.tuples(st.sampled_from(["", "", "/", "/2 "]),
                   st.one_of(st.just(""), pos_int.map(lambda v: f"N{v} "), pos_int.map(lambda v: f"N0{v} ")))
comment = st.one_of(st.just(""), st.just(""), st.text(alphabet="ABC xyz123-.,:", max_size=12)
                    .map(lambda c: f" ({c})"), st.just(" (a(b)c)"), st.just(" ; note"))


@st.composite
def iso_program(draw):
    lines = ["%", "O" + draw(st.integers(1, 9999).map(str))]
    depth = 0
    for _ in range(draw(st.integers(1, 25))):
        if depth < 2 and draw(st.integers(0, 9)) == 0:
            depth += 1
            lines.append(f"WHILE{draw(cond)}DO{depth}")
            continue
        if depth and draw(st.integers(0, 5)) == 0:
            lines.append(f"END{depth}")
            depth -= 1
            continue
        skip, number = draw(prefix)
        lines.append(f"{skip}{number}{draw(line_kind)}{draw(comment)}")
    while depth:
        lines.append(f"END{depth}")
        depth -= 1
    lines.append("M30")
    return "\n".join(lines) + "\n%\n"


@pytest.mark.long_property
@settings(max_examples=examples(150, 60), deadline=None)
@given(iso_program())
def test_generated_programs_round_trip(text):
    assert_round_trip(text)


@pytest.mark.parametrize("path", ISO_FILES, ids=lambda p: p.name)
def test_corpus_round_trip(path):
    assert_round_trip(path.read_bytes().decode("utf-8", errors="replace"))


# --------------------------------------------------------------------- normal form

def test_emitter_writes_decimal_points_on_conversion_addresses_only():
    text = emit(parse("G1 X10 Y-2 F300 S1000 T1 M6 H1 D2\n", "t.nc").program).text
    assert "X10." in text and "Y-2." in text and "F300." in text
    assert "S1000" in text and "S1000." not in text and "T1 " in text


def test_subprograms_are_emitted_after_the_main_program():
    text = assert_round_trip("%\nO1\nM98 P1000\nM30\nO1000\nG0 X1.\nM99\n%\n")
    assert text.index("O1000") > text.index("M30")


def test_foreign_constructs_are_lowered_or_refused():
    span = n.Span("a.mpf", 7)
    prog = n.Program("a.mpf", "sinumerik", [
        n.ForLoop(span, n.Var("name", "I"), n.Num(1.0), n.Num(3.0),
                  [n.Block(span, [n.Assign(n.Var("R", 1), n.Var("name", "I"))])]),
        n.Block(span, [n.Message(n.Str("HELLO"))]),
        n.Block(span, [n.CycleCall("drill", {"depth": n.Num(5.0)}, name="CYCLE81")]),
    ])
    out = emit(prog)
    rules = sorted({d.rule for d in out.diagnostics})
    assert rules == ["NC401", "NC402"]
    refused = [d for d in out.diagnostics if d.rule == "NC402"]
    assert "CYCLE81" in refused[0].message and refused[0].line == 7
    assert "WHILE[#100LE1]DO1" in out.text.replace(".", "") or "WHILE[#100LE" in out.text
    assert "(MSG, HELLO)" in out.text
    reparsed = parse(out.text, "b.nc")
    assert not [d for d in reparsed.diagnostics if d.rule.startswith("NC0")]
