"""A lowering note repeated at every line that needs it is said once per program, at its first
line, with the count of the later lines (the NC401 of iso-m -> Fagor was two notes at every tool
change: 6000 for a 3000-change program, capped by NC009 at 1000 listed)."""
from __future__ import annotations

import nctrans


def _changes(count: int) -> str:
    lines = ["O1000", "G21 G90 G17"]
    for i in range(count):
        lines += [f"T{i % 5 + 1} M6", f"G0 X{i % 50} Y0 Z5"]
    return "\n".join(lines + ["M30"]) + "\n"


def test_3000_tool_changes_to_fagor_give_two_notes():
    conv = nctrans.transpile(_changes(3000), read="iso-m", write="fagor")
    assert conv.text is not None
    notes = [d for d in conv.diagnostics if d.rule == "NC401"]
    # two distinct lowerings: the M06 at line 3 (first change), the D0 at line 4 (its G0 line);
    # 3000 changes each, so 2999 more lines each
    assert [(d.line, d.message.endswith("(and 2999 more lines)")) for d in notes] == [(3, True), (4, True)]
    assert "M06 on Fagor activates offset D1" in notes[0].message
    assert "D0 written" in notes[1].message
    assert not [d for d in conv.diagnostics if d.rule == "NC009"]


def test_a_single_change_has_no_count():
    conv = nctrans.transpile(_changes(1), read="iso-m", write="fagor")
    notes = [d for d in conv.diagnostics if d.rule == "NC401"]
    assert [d.line for d in notes] == [3, 4] and not [d for d in notes if "more line" in d.message]


def test_two_changes_count_one_more_line():
    conv = nctrans.transpile(_changes(2), read="iso-m", write="fagor")
    notes = [d for d in conv.diagnostics if d.rule == "NC401"]
    assert [d.message.endswith("(and 1 more line)") for d in notes] == [True, True]
