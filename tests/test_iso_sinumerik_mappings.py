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
    Row("radius offset register written (#2402)",
        "G90 G17 G21\n#2402=2.\nG0 X0 Y0 Z5\nG1 G41 D2 X10 Y0 F100\nY10\nG40 X20\nM30\n",
        ("$TC_DP6[2]=2.", "F100 G41 D2 G1 X10 Y0")),
    Row("length offset register written and read (#2001)",
        "G90 G17 G21\n#2001=.004\n#101=#2001*2\nG0 X#101 Y0\nM30\n",
        ("$TC_DP3[1]=.004", "R101=$TC_DP3[1]*2")),
    Row("radius register computed from another (#2403 from #2402)",
        "G90 G17 G21\n#2402=1.5\n#2403=#2402+.5\nG0 X0 Y0\nG1 G42 D3 X10 F50\nX20\nG40 X30\nM30\n",
        ("$TC_DP6[2]=1.5", "$TC_DP6[3]=$TC_DP6[2]+.5", "F50 G42 D3 G1 X10")),
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
