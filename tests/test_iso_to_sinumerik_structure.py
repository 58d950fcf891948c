"""ISO -> Sinumerik conversions that keep structure where the two controls can say the same thing:
computed code words (M#501 -> M=R501), G65 macros as PROCs with named parameters, and system
variables through the one table of neutral meanings. Each conversion is proven with `equiv` and
read back with no error."""
from __future__ import annotations

import nctrans
from nctrans.dialects.base import get


def _converted(src: str):
    conv = nctrans.transpile(src, read="iso-m", write="sinumerik")
    assert conv.ok, [d.format_text() for d in conv.diagnostics if d.severity == "error"]
    back = get("sinumerik").parse(conv.text, "out.mpf")
    assert not [d for d in back.diagnostics if d.severity == "error"], conv.text
    return conv


def _equiv(tmp_path, iso: str, sin: str):
    a, b = tmp_path / "a.nc", tmp_path / "b.mpf"
    a.write_text(iso)
    b.write_text(sin)
    same = nctrans.equiv(a, b, read_a="iso-m", read_b="sinumerik")
    assert same, same.message


def test_computed_m_code_keeps_its_expression(tmp_path):
    src = "G90 G17 G21\n#501=107\nM#501\nG1 X10 F100\nM[#501+1]\nM30\n"
    conv = _converted(src)
    lines = conv.text.splitlines()
    assert "M=R501" in lines and "M=R501+1" in lines
    assert any(d.rule == "NC403" and d.line == 3 for d in conv.diagnostics)
    _equiv(tmp_path, src, conv.text)


# ---------------------------------------------------------------- G65 macros -> PROC

from hypothesis import given, settings, strategies as st  # noqa: E402

MACRO = ("O1000\n#10=#1+#2\n#27=#10*2\nIF[#2 EQ 0] GOTO 10\n"
         "G1 X#10 Y#27 Z-#26 F100\nN10 M99\n")


def test_g65_macro_becomes_a_proc_with_named_parameters(tmp_path):
    src = "O0001\nG90 G17 G21\nG65 P1000 A5. B2. Z1.\nG65 P1000 B0 A7. Z3. C4.\nM30\n" + MACRO
    conv = _converted(src)
    lines = conv.text.splitlines()
    # parameters in local order (#1 A, #2 B, #3 C passed once, #26 Z); #10 and #27 have no
    # letter: plain locals
    assert "PROC L1000(REAL ARG_A, REAL ARG_B, REAL ARG_C, REAL ARG_Z)" in lines
    assert "DEF REAL LOC10, LOC27" in lines
    assert "L1000(5., 2., , 1.)" in lines and "L1000(7., 0, 4., 3.)" in lines
    assert "LOC10=ARG_A+ARG_B" in lines
    assert not any(line.startswith("R1=") for line in lines)      # no global registers any more
    assert any(d.rule == "NC401" and "PROC L1000" in d.message for d in conv.diagnostics)
    _equiv(tmp_path, src, conv.text)


def test_nested_macro_keeps_its_callers_arguments(tmp_path):
    # Fanuc: each G65 level has its own #1..#33, so O2000's A survives the call of O3000 with A9.
    # Written with global R parameters, R1 would be overwritten; as PROCs it is not.
    src = ("G90 G17 G21\nG65 P2000 A4.\nM30\nO2000\nG65 P3000 A9.\nG1 X#1 F100\nM99\n"
           "O3000\nG1 Y#1 F100\nM99\n")
    conv = _converted(src)
    assert "PROC L2000(REAL ARG_A)" in conv.text and "PROC L3000(REAL ARG_A)" in conv.text
    _equiv(tmp_path, src, conv.text)
    moves = [r for r in nctrans.toolpath(conv.text, dialect="sinumerik") if r.kind == "linear"]
    assert [(r.end["X"], r.end["Y"]) for r in moves] == [(0.0, 9.0), (4.0, 9.0)]


def test_macro_called_without_an_argument_it_reads_keeps_r_parameters(tmp_path):
    # B left out is vacant in ISO (#2 EQ 0 is false) but a PROC parameter left out is 0: no PROC
    src = "O0001\nG90 G17 G21\nG65 P1000 A5. B2. Z1.\nG65 P1000 A7. Z3.\nM30\n" + MACRO
    conv = _converted(src)
    assert "PROC L1000\n" in conv.text and "PROC L1000(" not in conv.text


def test_subprogram_also_called_by_m98_keeps_r_parameters():
    # M98 shares the caller's locals: such a subprogram is no PROC
    src = "G90 G21\n#1=3.\nM98 P1000\nG65 P1000 A5.\nM30\nO1000\nG1 X#1 F100\nM99\n"
    conv = _converted(src)
    assert "PROC L1000\n" in conv.text + "\n" and "R1=5. L1000" in conv.text


_LETTERS = {"A": 1, "B": 2, "C": 3, "X": 24, "Y": 25, "Z": 26, "R": 18}


@settings(max_examples=25, deadline=None)
@given(calls=st.lists(st.fixed_dictionaries({k: st.integers(-50, 50) for k in _LETTERS},
                                            optional={"I": st.integers(-9, 9)}),
                      min_size=1, max_size=3))
def test_any_g65_arguments_move_the_same_as_proc_parameters(tmp_path_factory, calls):
    body = "".join("G65 P7000 " + " ".join(f"{k}{v}." for k, v in sorted(c.items())) + "\n"
                   for c in calls)
    src = ("G90 G17 G21 G0 X0 Y0 Z0\n" + body + "M30\nO7000\n"
           "G1 X[#24+#1] Y[#25-#2] Z[#26*#3+#18] F200\nM99\n")
    conv = _converted(src)
    assert "PROC L7000(" in conv.text
    _equiv(tmp_path_factory.mktemp("g65"), src, conv.text)
