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


def test_vacant_arguments_are_asked_with_p_subpar(tmp_path):
    # B left out is vacant in ISO: `#2 EQ 0` is false and `#2 NE 2` true, though a PROC
    # parameter left out reads 0; A left out takes the #0 branch
    src = ("O0001\nG90 G17 G21\nG65 P1000 A5. B2. Z1.\nG65 P1000 A7. Z3.\nG65 P1000 Z4. B0\nM30\n"
           "O1000\nIF[#1 EQ #0] GOTO 20\n#10=#1+#2\nIF[#2 EQ 0] GOTO 10\nIF[#2 NE 2] GOTO 10\n"
           "G1 X#10 Z-#26 F100\nN10 M99\nN20 G1 X-1 Y-1 Z-#26\nM99\n")
    conv = _converted(src)
    lines = conv.text.splitlines()
    assert "L1000(7., , 3.)" in lines and "L1000(, 0, 4.)" in lines
    assert "IF NOT $P_SUBPAR[1] GOTO N20" in lines
    assert "IF $P_SUBPAR[2] AND (ARG_B==0) GOTO N10" in lines
    assert "IF NOT $P_SUBPAR[2] OR (ARG_B<>2) GOTO N10" in lines
    _equiv(tmp_path, src, conv.text)
    # the first call moves (X7), the second jumps to N10 (B vacant), the third takes N20
    moves = [r for r in nctrans.toolpath(conv.text, dialect="sinumerik") if r.kind == "linear"]
    assert [(r.end["X"], r.end["Z"]) for r in moves] == [(7.0, -1.0), (-1.0, -4.0)]


def test_call_leaving_out_an_argument_used_bare_is_lowered_alone(tmp_path):
    # `Y#2` drops the word when B is vacant; neither a PROC parameter left out (0) nor an R
    # parameter (the value of before) says that: that call is lowered to plain motion, the other
    # call and the macro keep their structure
    src = ("O0001\nG90 G17 G21\nG0 X0 Y0\nG65 P1000 A5. B2.\nG0 X0 Y0\nG65 P1000 A7.\nM30\n"
           "O1000\nG1 X#1 Y#2 F100\nM99\n")
    conv = _converted(src)
    assert "L1000(5., 2.)" in conv.text.splitlines()
    assert any(d.rule == "NC401" and d.line == 6 and "leaves out #2" in d.message
               for d in conv.diagnostics)
    _equiv(tmp_path, src, conv.text)


def test_locals_a_g65_call_leaves_out_start_at_zero_in_r_parameters(tmp_path):
    # M98 shares the caller's locals, so O1000 stays on R parameters; its G65 calls clear the
    # locals they leave out that the macro reads as numbers (vacant is 0 in arithmetic), but not
    # #4, which it sets before reading
    src = ("O0001\nG90 G17 G21\nG0 X0 Y0\nM98 P1000\nG65 P1000 A5. B2.\nG0 X0 Y0\nG65 P1000 A7.\n"
           "M30\nO1000\n#3=#3+1\n#4=#1*2\nG1 X#4 Y[#2+#3] F100\nM99\n")
    conv = _converted(src)
    lines = conv.text.splitlines()
    assert "R1=5. R2=2. R3=0 L1000" in lines and "R1=7. R2=0 R3=0 L1000" in lines
    _equiv(tmp_path, src, conv.text)


def test_subprogram_also_called_by_m98_keeps_r_parameters():
    # M98 shares the caller's locals: such a subprogram is no PROC
    src = "G90 G21\n#1=3.\nM98 P1000\nG65 P1000 A5.\nM30\nO1000\nG1 X#1 F100\nM99\n"
    conv = _converted(src)
    assert "PROC L1000\n" in conv.text + "\n" and "R1=5. L1000" in conv.text


_LETTERS = {"A": 1, "B": 2, "C": 3, "X": 24, "Y": 25, "Z": 26, "R": 18}


@settings(max_examples=25, deadline=None)
@given(calls=st.lists(st.fixed_dictionaries({}, optional={k: st.integers(-50, 50) for k in _LETTERS}),
                      min_size=1, max_size=3))
def test_any_g65_arguments_move_the_same_as_proc_parameters(tmp_path_factory, calls):
    body = "".join("G65 P7000 " + " ".join(f"{k}{v}." for k, v in sorted(c.items())) + "\n"
                   for c in calls)
    src = ("G90 G17 G21 G0 X0 Y0 Z0\n" + body + "M30\nO7000\n"
           "IF[#18 EQ #0] GOTO 5\nIF[#1 NE 3] GOTO 5\nG0 Z[#18+1]\nN5 G1 X[#24+#1] Y[#25-#2] Z[#26*#3+#18] F200\n"
           "M99\n")
    conv = _converted(src)
    assert "PROC L7000(" in conv.text
    _equiv(tmp_path_factory.mktemp("g65"), src, conv.text)


# ---------------------------------------------------------------- modal-state numbers

def test_modal_state_numbers_read_the_g_group_index(tmp_path):
    # (T1 M6: an ISO register D1 with no tool change before it has no Sinumerik D, test_register_without_tool)
    src = ("G90 G17 G21 G54\nT1 M6\n#100=#4007\nG1 G41 D1 X1 F100\n#101=#4007\nG55 G18\n"
           "IF[#4014 EQ 55] GOTO 10\nG1 X99\nN10 G0 X[#100+#101+#4002+#4003]\nG40 G17 X0\nM30\n")
    conv = _converted(src)
    # hand-derived: G40/G41/G42 are indexes 1-3 of group 7, G500/G54..G57 1-5 of group 8,
    # G17/G18/G19 1-3 of group 6, G90/G91 1-2 of group 14
    assert "R100=($P_GG[7]+39)" in conv.text
    assert "IF ($P_GG[8]+52)==55 GOTO N10" in conv.text
    assert "($P_GG[6]+16)+($P_GG[14]+89)" in conv.text
    _equiv(tmp_path, src, conv.text)
    end = [r for r in nctrans.toolpath(conv.text, dialect="sinumerik") if r.kind == "rapid"][0]
    assert end.end["X"] == 40 + 41 + 18 + 90


def test_modal_number_off_the_index_line_is_refused_at_its_line():
    # G54.1 P1 reads 54.1 in ISO; its Sinumerik code G505 is index 6 of group 8 (6 + 52 = 58)
    conv = nctrans.transpile("G90 G21 G54\nG54.1 P1\n#100=#4014\nG0 X#100\nM30\n",
                             read="iso-m", write="sinumerik")
    assert any("cannot express the system variable #4014 (work_offset)" in d.message and d.line == 3
               for d in conv.diagnostics)
    assert "$P_GG" not in (conv.text or "")


_MODES = {"plane": ["G17", "G18", "G19"], "distance": ["G90", "G91"], "comp": ["G40", "G41 D1"],
          "offset": ["G54", "G55", "G56", "G57"]}


@settings(max_examples=25, deadline=None)
@given(picks=st.lists(st.tuples(*(st.sampled_from(v) for v in _MODES.values())), min_size=1,
                      max_size=3),
       number=st.sampled_from([4002, 4003, 4007, 4014]))
def test_any_modal_state_reads_the_same_number_converted(tmp_path_factory, picks, number):
    body = "".join(f"{' '.join(p)}\n#100=#100*2+#{number}\nG1 X0.5 F100\nG40 G90\n" for p in picks)
    src = f"G90 G17 G21 G54\nT1 M6\n#100=0\n{body}G0 X[#100/1000]\nM30\n"
    conv = _converted(src)
    assert "$P_GG[" in conv.text
    _equiv(tmp_path_factory.mktemp("modal"), src, conv.text)
