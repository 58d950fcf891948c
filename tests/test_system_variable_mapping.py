"""System variables converted through their neutral meaning (nctrans.ir.vocabulary.SYSTEM_VARIABLES,
each rules table's [system_variables]): an ISO #number becomes the Sinumerik $variable of the same
meaning and back, reading the same value; one without an equivalent is refused at its line."""
from __future__ import annotations

import pytest

from nctrans import api
from nctrans.dialects.base import get
from nctrans.rules import load_table, system_meaning, system_spelling

ISO = load_table("iso-m").system_variables
MAPPED = [(int(sp[1:]), m) for sp, m in ISO.items() if system_spelling("sinumerik", int(sp[1:]))]


def test_the_table_maps_positions_modal_words_probing_and_counters():
    # hand-written expectations (Fanuc macro manual numbering; Sinumerik seed / table)
    expected = {5021: "$AA_IM[X]", 5003: "$P_EP[Z]", 5043: "$P_EP[Z]", 5062: "$AA_MW[Y]",
                4109: "$P_F", 4119: "$P_S", 4120: "$P_TOOLP", 4107: "$P_TOOL", 3901: "$AC_ACTUAL_PARTS",
                3902: "$AC_REQUIRED_PARTS"}
    for number, spelling in expected.items():
        name, axis = system_spelling("sinumerik", number)
        assert (f"{name}[{axis}]" if axis else name) == spelling, number
    assert len(MAPPED) >= 30


@pytest.mark.parametrize("number,meaning", MAPPED, ids=[f"#{k}" for k, _ in MAPPED])
def test_each_mapped_number_converts_both_ways_to_the_same_meaning(number, meaning):
    program = f"#1=#{number}\nM30\n"
    there = api.transpile(program, read="iso-m", write="sinumerik")
    assert there.ok, [d.format_text() for d in there.diagnostics]
    line = next(x for x in there.text.splitlines() if x.startswith("R1="))
    spelled = line[3:]
    name, _, axis = spelled.partition("[")
    assert system_meaning(name) + (f".{axis.rstrip(']')}" if axis else "") == meaning
    back = api.transpile(there.text, read="sinumerik", write="iso-m")
    assert back.ok, [d.format_text() for d in back.diagnostics]
    again = next(x for x in back.text.splitlines() if x.startswith("#") and "=#" in x)
    assert system_meaning(int(again.split("=#")[1])) == meaning


def test_converted_system_variables_read_the_same_values():
    # position (machine, work, end of block), feed, speed and programmed tool drive one move:
    # X = 3 + 4 + 3 + 250/100 + 1200/1000 + 7 = 20.7 (hand-computed), in both dialects
    iso = ("G21 G90 G0 X3 Y4 Z5\nF250\nS1200 M3\nT7\n#1=#5021+#5042+#5001+#4109/100+#4119/1000+#4120\n"
           "G1 X#1\nM30\n")
    sin = api.transpile(iso, read="iso-m", write="sinumerik")
    assert "$AA_IM[X]" in sin.text and "$P_TOOLP" in sin.text
    moves = [r for r in api.toolpath(sin.text, "sinumerik") if r.kind == "linear"]
    assert moves[-1].end["X"] == pytest.approx(20.7)
    assert api.equiv(iso, sin.text, read_a="iso-m", read_b="sinumerik")
    back = api.transpile(sin.text, read="sinumerik", write="iso-m")
    assert api.equiv(iso, back.text, read_a="iso-m", read_b="iso-m")


def test_probing_positions_convert_and_stay_unknown():
    iso = "G21 G90 G0 X0 Y0 Z5\n#1=#5063\nG1 Z#1 F100\nM30\n"
    sin = api.transpile(iso, read="iso-m", write="sinumerik")
    assert sin.ok and "R1=$AA_MW[Z]" in sin.text
    moved = next(i for i, x in enumerate(sin.text.splitlines(), 1) if "G1 Z=R1" in x)
    assert any(d.rule == "NC107" and d.line == moved for d in api.lint(sin.text, "sinumerik"))


def _refusals(text: str, src: str, dst: str) -> list:
    out = get(dst).emit(get(src).parse(text, "a").program)
    return [d for d in out.diagnostics if d.rule == "NC402"]


def test_system_variables_without_an_equivalent_are_refused_at_their_line():
    # #4009 (modal canned cycle: no Sinumerik G group holds it; #4014 now maps to $P_GG[8]+52,
    # tests/test_iso_to_sinumerik_structure.py), #2201 (length wear of offset H1: a wear write
    # adds to the geometry in the analysis, no edge datum of Sinumerik is proven the same; the
    # geometry registers #2001/#2401 map to $TC_DP3[d]/$TC_DP6[d], test_iso_sinumerik_mappings.py)
    for number in (4009, 2201):
        found = _refusals(f"G0 X0\n#1=#{number}\nM30\n", "iso-m", "sinumerik")
        assert found and found[0].line == 2 and f"#{number}" in found[0].message
    # a write to a position is refused, not turned into a write of $AA_IM
    assert _refusals("#5021=1\nM30\n", "iso-m", "sinumerik")
    found = _refusals("G0 X0\nR1=$P_GG[8]\nM30\n", "sinumerik", "iso-m")
    assert found and found[0].line == 2 and "$P_GG" in found[0].message
