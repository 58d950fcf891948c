"""Spindle-synchronised moves (issue 8): G33 threads and tapping keep their lead through the
interpreter and through --flatten (never a plain G1). Feeds are lead x S, worked out by hand."""
from __future__ import annotations

import pytest

from nctrans import api, pipeline
from nctrans.source import from_text


def run(text: str, dialect: str):
    ld = pipeline.load_source(from_text(text, "t.nc"), "t.nc", dialect)
    recs = list(pipeline.toolpath_of(ld, None))
    return recs, ld.diagnostics


def feeds(recs):
    return [(round(r.end["X"], 6), round(r.end["Z"], 6), r.feed, r.pitch)
            for r in recs if r.kind == "linear"]


@pytest.mark.parametrize("dialect,thread", [("sinumerik", "G33 Z-10 K1.5"),   # K = lead
                                            ("iso-m", "G33 Z-10 F1.5")])       # F = lead (ISO 4.5)
def test_g33_feeds_lead_times_speed_and_carries_the_lead(dialect, thread):
    recs, diags = run(f"G0 X0 Y0 Z5 S500 M3\n{thread}\nM30\n", dialect)
    assert feeds(recs) == [(0.0, -10.0, 750.0, 1.5)]         # 1.5 mm/rev x 500 rev/min
    assert not [d for d in diags if d.severity in ("error", "warning")]


def test_g33_lead_of_the_axis_that_travels_furthest():
    # X travels 5, Z 2: the X lead I2 applies: 2 x 400 = 800 mm/min
    recs, _ = run("G0 X0 Y0 Z0 S400 M3\nG33 X5 Z-2 I2 K1\nM30\n", "sinumerik")
    assert feeds(recs) == [(5.0, -2.0, 800.0, 2.0)]


def test_g33_does_not_change_the_programmed_feed_on_sinumerik():
    recs, _ = run("G0 X0 Y0 Z5 S500 M3\nG1 F100 Z3\nG33 Z-10 K1.5\nG1 X5\nM30\n", "sinumerik")
    assert [f[2] for f in feeds(recs)] == [100.0, 750.0, 100.0]


def test_g33_without_a_lead_is_an_error_and_moves_nothing():
    recs, diags = run("G0 X0 Y0 Z5 S500 M3\nG33 Z-10\nM30\n", "sinumerik")
    assert feeds(recs) == []
    assert [(d.rule, d.line) for d in diags if d.severity == "error"] == [("NC206", 2)]


TAP = "G17 G90 G0 X10 Y10 Z20 S500 M3\nCYCLE84(10, 0, 2, -10, , , 3, , 1.5)\nM30\n"


@pytest.mark.parametrize("target,dialect,down,up", [
    ("sinumerik", "sinumerik", "G33 Z-10 K1.5", "Z2 K1.5"),
    # flattened ISO for a Fanuc (the default): G33 with the lead as F (seed 4.5); CYCLE84's tap
    # reverses without stopping, which no G84 does: it stays G33 moves
    ("iso-m", "iso-m", "G33 Z-10. F1.5", "Z2. F1.5"),
])
def test_flattened_tapping_stays_spindle_synchronised(target, dialect, down, up):
    # CYCLE84 (PIT 1.5, S500): G0 to RFP+SDIS = 2, tap to -10, spindle reversed, tap back to 2,
    # spindle forward, G0 to RTP = 10; flattened as G33 with the lead, never as plain G1 feeds
    conv = api.transpile(TAP, "sinumerik", target, flatten=True)
    lines = conv.text.splitlines()
    i = next(k for k, ln in enumerate(lines) if ln.startswith("G33"))
    assert lines[i] == down and lines[i + 1] == "M4" and lines[i + 2] == up and lines[i + 3] == "M3"
    assert not any(ln.startswith(("G1 ", "G01 ")) for ln in lines)
    assert any(d.rule == "NC401" and "spindle-synchronised" in d.message for d in conv.diagnostics)
    # the flattened program runs to the same records, leads included
    src, _ = run(TAP, "sinumerik")
    out, _ = run(conv.text, dialect)
    assert feeds(out) == feeds(src) == [(10.0, -10.0, 750.0, 1.5), (10.0, 2.0, 750.0, 1.5)]


def test_flattened_iso_g84_keeps_its_lead():
    # G94 F750 S500: lead 750/500 = 1.5 (spec 5 "under G94 the lead is F/S"). For a Fanuc (the
    # default) the tap is its rigid tapping cycle again, from R = where the tap begins (Z2);
    # for LinuxCNC G33 moves with the lead as K (G84 stops the spindle, G33.1 does not)
    text = "G21 G17 G90 G94 G0 X0 Y0 Z20 S500 M3\nG99 G84 X5 Y5 Z-8 R2 F750\nG80\nG1 X0 F200\nM30\n"
    src, _ = run(text, "iso-m")
    fanuc = api.transpile(text, "iso-m", "iso-m", flatten=True)
    lines = fanuc.text.splitlines()
    i = lines.index("S500 M29")
    assert lines[i + 1:i + 3] == ["F750. G99 G84 R2. X5. Y5. Z-8.", "G80"]
    assert not any(ln.startswith("G33") for ln in lines)
    assert [d.line for d in fanuc.lowered if "G84/G74" in d.message] == [2]
    assert any("F200." in ln for ln in lines)
    out, _ = run(fanuc.text, "iso-m")
    assert feeds(out) == feeds(src)
    assert api.equiv(text, fanuc.text, read_a="iso-m", read_b="iso-m")
    linuxcnc = api.transpile(text, "iso-m", "iso-m", flatten=True, profile="linuxcnc")
    assert "G33 Z-8. K1.5" in linuxcnc.text.splitlines() and "M29" not in linuxcnc.text
    assert [d.line for d in linuxcnc.lowered if "as K for LinuxCNC" in d.message] == [2]
    out, _ = run(linuxcnc.text, "iso-m")
    assert feeds(out) == feeds(src)


def test_flattened_cycle84_for_linuxcnc_is_one_g33_1():
    # CYCLE84 taps in, reverses, taps out, turns forward: LinuxCNC's G33.1 does exactly that
    conv = api.transpile(TAP, "sinumerik", "iso-m", flatten=True, profile="linuxcnc")
    lines = conv.text.splitlines()
    assert "G33.1 Z-10. K1.5" in lines and "M4" not in lines and not any("G33 " in ln for ln in lines)
    assert api.equiv(TAP, conv.text, read_a="sinumerik", read_b="iso-m")
    src, _ = run(TAP, "sinumerik")
    out, _ = run(conv.text, "iso-m")
    assert feeds(out) == feeds(src)


def test_a_profile_neither_side_knows_is_a_usage_error():
    with pytest.raises(Exception, match="nor of iso-m's: haas, linuxcnc"):
        api.transpile(TAP, "sinumerik", "iso-m", flatten=True, profile="heidenhain")


def test_converting_sinumerik_g33_to_iso_writes_the_lead_as_f_and_restores_the_feed():
    conv = api.transpile("G0 X0 Y0 Z5 S500 M3\nG1 F100 Z3\nG33 Z-10 K1.5\nG1 X5\nM30\n",
                         "sinumerik", "iso-m")
    lines = conv.text.splitlines()
    # not flattened: ISO's own G33 (seed 4.5), lead as F, the feed written again after it
    assert "G33 Z-10. F1.5" in lines and "G1 F100. X5." in lines
    assert not [d for d in conv.lowered if "as K" in d.message]


def test_m29_rigid_tap_mode_has_no_motion_effect_and_the_tap_keeps_its_lead():
    # Fusion 360 / Haas rigid tapping: M29 S500 then G84 F750 -> lead 750/500 = 1.5
    text = "G21 G17 G90 G94 G0 X0 Y0 Z20 S500 M3\nM29 S500\nG99 G84 X5 Y5 Z-8 R2 F750\nG80\nM30\n"
    recs, diags = run(text, "iso-m")
    assert not [d for d in diags if d.severity in ("error", "warning")]
    assert feeds(recs) == [(5.0, -8.0, 750.0, 1.5), (5.0, 2.0, 750.0, 1.5)]
