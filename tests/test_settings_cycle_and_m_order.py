"""Two conversion differences found converting an NX-style Sinumerik program:
- CYCLE832 (high-speed settings; no path of its own, passed over by the toolpath) was written to ISO
  as `G65 P9134` and to Fagor as `L CYCLE832`, calls of programs no such control has: now the NC413
  comment of a function with no motion effect;
- `M9 M5` in one Sinumerik block recorded coolant before spindle while the ISO and Fagor readings
  (RS274/NGC order) record the spindle first: equiv called the converted program different."""
from __future__ import annotations

from nctrans import api

TEXT = ("G17 G90 G54 G0 X0 Y0 Z50\nT1 D1 M6\nCYCLE832(0.01,1,1)\nS5000 M3 M8\nG1 Z-2 F500\n"
        "CYCLE832()\nG0 Z50\nM9 M5\nM30\n")


def test_settings_cycle_becomes_a_comment_with_nc413():
    for target, comment in (("iso-m", "("), ("fagor", ";")):
        conv = api.transpile(TEXT, "sinumerik", target)
        assert conv.text
        lines = [ln for ln in conv.text.splitlines() if "CYCLE832" in ln]
        assert len(lines) == 2 and all(ln.lstrip().startswith(comment) for ln in lines), lines
        assert "G65" not in conv.text and "L CYCLE832" not in conv.text
        assert [d.line for d in conv.diagnostics if d.rule == "NC413"] == [3, 6]
        assert api.equiv(TEXT, conv.text, read_a="sinumerik", read_b=target)


def test_spindle_before_coolant_in_one_block_as_iso_reads_it():
    kinds = [r.kind for r in api.toolpath(TEXT, "sinumerik") if r.line == 8]
    assert kinds == ["spindle", "coolant"]
    iso = "G17 G90 G54 G0 X0 Y0 Z50\nS5000 M3 M8\nM9 M5\nM30\n"
    assert [r.kind for r in api.toolpath(iso, "iso-m") if r.line == 3] == ["spindle", "coolant"]
