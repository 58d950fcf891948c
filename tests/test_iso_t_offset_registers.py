"""ISO turning writes the offset register in the T word (T<tool><offset>), issue #8: a D (Sinumerik
edge, Fagor D, ISO-T T0102) that names another register than the T word in force is the tool's T word
again with it, never dropped; where no T word can say it (no tool known, an ISO mill's H and D that
differ) the block is refused at its line rather than written without its offset."""
from __future__ import annotations

import pytest

import nctrans


def t_words(text: str) -> list[str]:
    return [w for line in text.splitlines() for w in line.split() if w.startswith("T") and w[1:].isdigit()]


@pytest.mark.parametrize("src,dialect,want", [
    ("G18 G90\nT1 M6 D2\nG0 X50 Z5\nG1 X40 F100\nM30\n", "sinumerik", ["T0102"]),
    ("G18 G90\nT1 M6 D1\nG0 X50 Z5\nG1 X40 F100\nD2\nZ-10\nD0\nX60\nM30\n", "sinumerik",
     ["T0101", "T0102", "T0100"]),
    ("G18 G90 G0 X50 Z5\nT0102\nG1 X40 F0.2\nT0105\nZ-10\nT0303\nX60\nM30\n", "iso-t", ["T0102", "T0105", "T0303"]),
    ("G18 G90\nT1 D2 M6\nG0 X50 Z5\nG1 X40 F100\nG41 D1\nZ-10\nG40\nM30\n", "fagor", ["T0102", "T0101"]),
])
def test_the_register_goes_into_the_t_word_and_the_path_is_kept(src, dialect, want):
    conv = nctrans.transpile(src, read=dialect, write="iso-t")
    assert conv.ok, conv.diagnostics
    assert t_words(conv.text) == want, conv.text
    assert nctrans.equiv(src, conv.text, read_a=dialect, read_b="iso-t")


def test_a_t_word_for_the_tool_in_place_changes_only_the_offset():
    # the turret does not index for T0105 after T0102 (same tool 1): one tool change, tool 1
    recs = list(nctrans.toolpath("G18 G90 G0 X50 Z5\nT0102\nG1 X40 F0.2\nT0105\nZ-10\nM30\n", "iso-t"))
    assert [r.tool for r in recs if r.kind == "tool_change"] == [1]


def test_a_fagor_d_with_no_tool_is_not_written_without_its_offset():
    # G41 D1 with no T before it: which tool is in the turret is not in the program, so no T word
    # can carry register 1; the block is refused at its line (the structural writer), never a
    # G41 without a register as before
    src = "G18 G90\nG0 X50 Z5\nG41 D1\nG1 X40 F100\nZ-10\nG40\nM30\n"
    conv = nctrans.transpile(src, read="fagor", write="iso-t")
    said = [d for d in conv.diagnostics if d.line == 3 and "no tool known" in d.message]
    assert said, conv.diagnostics
    assert conv.text is None or "G41" not in conv.text or t_words(conv.text)
    # nor lowered whole with some tool's radius: the radius of D1 of a tool the program never
    # chose is not known (NC123), so the whole-program lowering is refused too and says why
    assert conv.text is None
    assert [d for d in conv.diagnostics if d.line == 3 and "NC123" not in d.rule
            and "tool the machine holds" in d.message], conv.diagnostics


def test_an_iso_mill_length_and_radius_register_that_differ_are_refused_at_the_line():
    src = "G17 G90 G0 X0 Y0 Z5\nT1 M6\nG43 H1 Z5\nG41 D11 G1 X10 F100\nG40 G1 X0\nM30\n"
    conv = nctrans.transpile(src, read="iso-m", write="iso-t")
    assert [d for d in conv.diagnostics if d.line == 4 and "one register for both" in d.message]
