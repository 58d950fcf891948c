"""ISO -> Sinumerik structural mappings of issue 9, as a table of constructs (the shape of
tests/test_constructs_table.py): each row is an ISO program using one construct and the Sinumerik
lines the conversion must write for it, written by hand from the manuals (spec sinumerik.md 8.4
flat D numbers `$TC_DPx[d]`; seed sinumerik-840d-advanced-programming L1467-1552 indirect G code
`G[<group>]=<variable>`, arithmetic not allowed there; L5110-5130 indirect `CALL <string variable>`).
Every row is converted, read back with no error, and proven with `equiv` against its source."""
from __future__ import annotations

from dataclasses import dataclass

import pytest

import nctrans
from nctrans.dialects.base import get


@dataclass
class Row:
    name: str
    iso: str
    lines: tuple[str, ...]          # Sinumerik lines the conversion must contain, in this order


ROWS = [
    # G43 H<n> with D<n>: a Sinumerik edge D<n> gives length and radius register n together (an
    # ISO radius without the same length has no edge: tests/test_edge_selection.py)
    Row("radius offset register written (#2402)",
        "G90 G17 G21\n#2402=2.\nG43 H2\nG0 X0 Y0 Z5\nG1 G41 D2 X10 Y0 F100\nY10\nG40 X20\nM30\n",
        ("$TC_DP6[2]=2.", "D2", "F100 G41 G1 X10 Y0")),
    Row("length offset register written and read (#2001)",
        "G90 G17 G21\n#2001=.004\n#101=#2001*2\nG0 X#101 Y0\nM30\n",
        ("$TC_DP3[1]=.004", "R101=$TC_DP3[1]*2")),
    Row("radius register computed from another (#2403 from #2402)",
        "G90 G17 G21\n#2402=1.5\n#2403=#2402+.5\nG43 H3\nG0 X0 Y0\nG1 G42 D3 X10 F50\nX20\nG40 X30\nM30\n",
        ("$TC_DP6[2]=1.5", "$TC_DP6[3]=$TC_DP6[2]+.5", "D3", "F50 G42 G1 X10")),
    # G40/G41/G42 are places 1/2/3 of Sinumerik G group 7: index = #143 - 39
    Row("computed G word of one group (G#143, #143 = 41 or 42)",
        "G90 G17 G21\n#2402=1.\n#143=42\nG43 H2\nIF[#1EQ1]GOTO5\n#143=41\nN5 G0 X0 Y0\n"
        "G1 G#143 X10 Y0 D2 F100\nY10\nG40 X20\nM30\n",
        ("DEF INT INDEX_G7_143", "R143=42", "R143=41", "INDEX_G7_143=R143-39",
         "G[7]=INDEX_G7_143 G1 X10 Y0")),
    # G17/G18/G19 are places 1/2/3 of group 6: index = #5 - 16
    Row("computed plane (G#5, #5 = 17 or 18)",
        "G90 G21\n#5=18\nG#5\nG0 X0 Z0\nG2 X10 Z0 R5 F100\n#5=17\nG#5\nG2 X0 Y0 R5\nM30\n",
        ("DEF INT INDEX_G6_5", "INDEX_G6_5=R5-16", "G[6]=INDEX_G6_5")),
    Row("computed program number of M98 (M98 P#144)",
        "G90 G17 G21\n#144=1000\nG0 X0 Y0\nM98 P#144\nG1 X5 F100\nM30\nO1000\nG1 Y5 F10\nM99\n",
        ("DEF INT CALL_NUMBER", "DEF STRING[32] CALL_NAME", "CALL_NUMBER=R144",
         'CALL_NAME="L"<<CALL_NUMBER', "CALL CALL_NAME")),
    Row("computed call of a program the target control provides (kept as a call event)",
        "G90 G17 G21\n#144=9010\nG0 X0 Y0\nM98 P#144\n#144=9011\nM98 P#144\nM30\n",
        ("CALL_NUMBER=R144", "CALL CALL_NAME", "R144=9011", "CALL CALL_NAME")),
]


def _convert(src: str):
    conv = nctrans.transpile(src, read="iso-m", write="sinumerik")
    assert conv.ok, [d.format_text() for d in conv.diagnostics if d.severity == "error"]
    back = get("sinumerik").parse(conv.text, "out.mpf")
    assert not [d for d in back.diagnostics if d.severity == "error"], conv.text
    return conv


@pytest.mark.parametrize("row", ROWS, ids=lambda r: r.name)
def test_mapping_is_written_and_equivalent(row: Row, tmp_path):
    conv = _convert(row.iso)
    lines = [line.split(";")[0].strip() for line in conv.text.splitlines()]
    at = 0
    for want in row.lines:
        assert want in lines[at:], (want, conv.text)
        at = lines.index(want, at) + 1
    assert not any(d.rule == "NC402" for d in conv.diagnostics)
    a, b = tmp_path / "a.nc", tmp_path / "b.mpf"
    a.write_text(row.iso)
    b.write_text(conv.text)
    same = nctrans.equiv(a, b, read_a="iso-m", read_b="sinumerik")
    assert same, same.message


def _toolpath(text: str, dialect: str) -> list:
    return [r for r in nctrans.toolpath(text, dialect) if r.kind != "stop"]


def test_flat_edge_radius_write_moves_the_compensated_path():
    # hand-computed: G41 (left of +X travel) with radius 2 puts the tool at Y=+2 on the X move
    got = _toolpath("G17 G90 G71\n$TC_DP6[4]=2\nG0 X0 Y0\nG41 D4 G1 X10 Y0 F100\nX20\nG40 X30\nM30\n",
                    "sinumerik")
    assert got[1].end["Y"] == pytest.approx(2.0)
    plain = _toolpath("G17 G90 G71\nG0 X0 Y0\nG41 D4 G1 X10 Y0 F100\nX20\nG40 X30\nM30\n", "sinumerik")
    assert plain[1].end["Y"] == pytest.approx(0.0)      # the register was 0 before the write


def test_flat_edge_data_reads_back_in_the_programs_units():
    # G700: system data in inch, so 0.1 written reads 0.1 and compensates by 2.54 mm
    got = _toolpath("G17 G90 G700\n$TC_DP6[1]=0.1\nR1=$TC_DP6[1]*10\nG0 X=R1 Y0\n"
                    "G41 D1 G1 X2 Y0 F10\nX3\nG40 X4\nM30\n", "sinumerik")
    assert got[0].end["X"] == pytest.approx(25.4)
    assert got[1].end["Y"] == pytest.approx(2.54)


def test_edge_write_with_unknown_number_is_said_not_dropped():
    # a timer's value is not known to the analysis: the write says so at its line
    tp = nctrans.toolpath("G17 G90\n$TC_DP6[$AC_TIME+1]=2\nG0 X0\nM30\n", "sinumerik")
    list(tp)
    assert any(d.rule == "NC107" and d.line == 2 for d in tp.diagnostics), tp.diagnostics


@pytest.mark.parametrize("iso, why", [
    ("#1=41\nG#1\n#1=54\nG#1\nG0 X0\nM30\n", "two groups"),
    ("#1=#4007\nG#1\nG0 X0\nM30\n", "not constants"),
    ("#1=41\nG#[#1]\nG0 X0\nM30\n", "an expression, not one variable"),
])
def test_computed_g_the_program_does_not_pin_to_one_group_is_refused_at_its_line(iso, why):
    conv = nctrans.transpile(iso, read="iso-m", write="sinumerik", strict=True)
    assert not conv.ok
    assert any(d.rule == "NC402" and d.severity == "error" and "G#" in d.message
               for d in conv.diagnostics), (why, conv.diagnostics)


def test_iso_computed_g_selects_the_code_it_names():
    # hand-computed: G42 with radius 1 runs right of the +X move (Y=-1); G#1 = 38 is no modelled
    # code (NC220, nothing selected); a vacant #2 leaves the word out (the control ignores it)
    tp = nctrans.toolpath("G90 G17 G21\n#2402=1.\n#143=42\nG0 X0 Y0\nG1 G#143 X10 Y0 D2 F100\n"
                          "X20\nG40 X30\n#1=38\nG#1\nG#2\nM30\n", "iso-m")
    moves = [r for r in tp if r.kind == "linear"]
    assert moves[0].end["Y"] == pytest.approx(-1.0)
    assert moves[-1].end["Y"] == pytest.approx(0.0)
    rules = [(d.rule, d.line) for d in tp.diagnostics]
    assert ("NC220", 9) in rules and not any(line == 10 for _, line in rules)


def test_sinumerik_indirect_call_runs_the_named_program():
    text = ('DEF STRING[32] PNAME\nG90 G17 G71\nPNAME="/_N_WCS_DIR/_N_PART1_SPF"\nG0 X0 Y0\n'
            "CALL PNAME\nM30\n%_N_PART1_SPF\nPROC PART1\nG1 X7 F100\nRET\n")
    tp = nctrans.toolpath(text, "sinumerik")
    moves = [r for r in tp if r.kind == "linear"]
    assert [m.end["X"] for m in moves] == [pytest.approx(7.0)]
    unknown = nctrans.toolpath("DEF STRING[8] PNAME\nG0 X0\nCALL PNAME\nM30\n", "sinumerik")
    list(unknown)
    assert any(d.rule == "NC107" and d.line == 3 for d in unknown.diagnostics), unknown.diagnostics
