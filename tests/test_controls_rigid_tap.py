"""Sinumerik G331/G332 rigid tapping (issue 8): spindle-synchronised feed lead x S, records that
carry the pitch, the spindle reversed for the retraction. Expected values by hand."""
from __future__ import annotations

import pytest

import nctrans
from nctrans import api


def events(text: str, dialect: str = "sinumerik") -> list[tuple]:
    out = []
    for r in nctrans.toolpath(text, dialect):
        if r.kind in ("rapid", "linear"):
            out.append((r.kind, round(r.end["Z"], 6), None if r.kind == "rapid" else round(r.feed, 6),
                        r.pitch))
        elif r.kind == "spindle":
            out.append(("spindle", r.spindle_dir))
    return out


def diags(text: str) -> list[tuple]:
    return [(d.rule, d.line, d.severity) for d in api.lint(text, "sinumerik")]


def test_right_hand_tap_and_retract():
    # K1.5 at S500: 750 mm/min both ways; G332 reverses the spindle and, retracted, it turns as
    # before the G331 again (cw); the M3 after it changes nothing and records nothing
    text = "G17 G90 G0 X10 Y20 Z5\nS500 M3\nG331 Z-20 K1.5\nG332 Z5 K1.5\nM3\nG0 Z50\nM30\n"
    assert events(text) == [("rapid", 5.0, None, None), ("spindle", "cw"),
                            ("linear", -20.0, 750.0, 1.5), ("spindle", "ccw"),
                            ("linear", 5.0, 750.0, 1.5), ("spindle", "cw"),
                            ("rapid", 50.0, None, None)]
    assert diags(text) == []


def test_left_hand_tap_from_the_sign_of_the_lead():
    # K-1 at S200 under M3: G331 turns the spindle counterclockwise, 200 mm/min, G332 clockwise
    text = "G0 X0 Y0 Z2\nS200 M3\nG331 Z-10 K-1\nG332 Z2 K-1\nM30\n"
    assert events(text) == [("rapid", 2.0, None, None), ("spindle", "cw"), ("spindle", "ccw"),
                            ("linear", -10.0, 200.0, 1.0), ("spindle", "cw"),
                            ("linear", 2.0, 200.0, 1.0)]


def test_lead_in_inch_under_g700():
    # K0.05 inch = 1.27 mm per revolution at S400: 508 mm/min; Z-1 inch = -25.4
    text = "G700 G0 X0 Y0 Z0.1\nS400 M3\nG331 Z-1 K0.05\nM30\n"
    assert events(text)[2:] == [("linear", -25.4, 508.0, 1.27)]


def test_tapping_ignores_f_and_restores_it_after():
    # F100 stays the feed of the G1 after the tapping (not 750)
    text = "G0 X0 Y0 Z5\nS500 M3\nG1 Z4 F100\nG331 Z-20 K1.5\nG332 Z5 K1.5\nG1 Z6\nM30\n"
    ev = events(text)
    assert ev[2] == ("linear", 4.0, 100.0, None) and ev[-1] == ("linear", 6.0, 100.0, None)


def test_modal_g331_taps_again_with_its_lead():
    text = "G0 X0 Y0 Z5\nS100 M3\nG331 Z-5 K2\nZ-8 K2\nZ-9\nM30\n"
    ev = events(text)
    assert ev[2:] == [("linear", -5.0, 200.0, 2.0), ("linear", -8.0, 200.0, 2.0), ("linear", -9.0, 200.0, 2.0)]
    assert diags(text) == []


def test_no_spindle_speed_is_an_error_and_no_move():
    text = "G0 X0 Y0 Z5\nG331 Z-5 K1\nM30\n"
    assert events(text) == [("rapid", 5.0, None, None)]
    assert ("NC206", 2, "error") in diags(text)


def test_g331_is_in_g_group_1_index_11():
    from nctrans.interp.interpreter import interpret
    from nctrans.dialects import base
    res = base.get("sinumerik").parse("S100 M3\nG331 Z-1 K1\nR1=$P_GG[1]\nG0 X=R1\nM30\n", "t.mpf")
    recs = [r for r in interpret(res.program, diagnostics=[]) if r.kind == "rapid"]
    assert recs[-1].end["X"] == 11.0


TAP_PROGRAM = "G17 G90 G0 X10 Y20 Z5\nS500 M3\nG331 Z-20 K1.5\nG332 Z5 K1.5\nG0 Z50\nM30\n"


def test_conversion_to_iso_writes_synchronised_moves():
    """ISO has no G331: the stretch is lowered to G33 moves with their lead and the spindle
    reversal (M4/M3) between them; the toolpath stays the same, spindle events included."""
    out = api.transpile(TAP_PROGRAM, "sinumerik", "iso-m")
    assert out.text is not None, [d.message for d in out.diagnostics]
    assert api.equiv(TAP_PROGRAM, out.text, read_a="sinumerik", read_b="iso-m").equivalent
    assert events(out.text, "iso-m") == events(TAP_PROGRAM)
    words = out.text.split()
    assert "G33" in words and "M4" in words


def test_conversion_to_fagor_writes_g63():
    """Fagor's rigid tapping is G63 (seed L8556-8780: lead = F / S, direction the sign of S, ended
    by M3/M4): K1.5 at S500 is F750; after M4 the retraction is G63 again with S-500. Never plain
    feeds (tests/test_controls_g63.py has the reader's side)."""
    out = api.transpile(TAP_PROGRAM, "sinumerik", "fagor")
    lines = [ln.split(";")[0].split() for ln in out.text.splitlines()]
    taps = [ln for ln in lines if "G63" in ln]
    assert [[w for w in ln if w[0] in "ZFS"] for ln in taps] == [["Z-20", "F750", "S500"], ["Z5", "F750", "S-500"]]
    assert not any("G01" in ln for ln in lines)
    assert api.equiv(TAP_PROGRAM, out.text, read_a="sinumerik", read_b="fagor")


def test_sinumerik_output_keeps_g331_g332():
    text = "G0 X0 Y0 Z5\nS500 M3\nG331 Z-20 K1.5\nZ-22 K1.5\nG332 Z5 K1.5\nM30\n"
    out = api.transpile(text, "sinumerik", "sinumerik").text
    assert "G331" in out and "G332" in out
    assert events(out) == events(text)


def test_modal_stretch_is_lowered_whole_for_iso():
    """Axis words after G331/G332 still tap: the whole stretch up to G1/G0 is lowered, so no
    later block runs as a plain G33 in the wrong mode (hand-counted: 4 taps down, 2 up; the
    spindle reversed for each G332 block and back to M3 after it)."""
    text = ("G0 X0 Y0 Z5\nS500 M3\nG331 Z-20 K1.5\nZ-22 K1.5\nG1 X1 F100\nG331 Z-24 K1.5\n"
            "Z-25 K1.5\nG332 Z5 K1.5\nZ6 K1.5\nG0 Z10\nM30\n")
    want = [("rapid", 5.0, None, None), ("spindle", "cw"), ("linear", -20.0, 750.0, 1.5), ("linear", -22.0, 750.0, 1.5),
            ("linear", -22.0, 100.0, None), ("linear", -24.0, 750.0, 1.5),
            ("linear", -25.0, 750.0, 1.5), ("spindle", "ccw"), ("linear", 5.0, 750.0, 1.5), ("spindle", "cw"),
            ("spindle", "ccw"), ("linear", 6.0, 750.0, 1.5), ("spindle", "cw"), ("rapid", 10.0, None, None)]
    assert events(text) == want
    out = api.transpile(text, "sinumerik", "iso-m")
    assert events(out.text, "iso-m") == want
    assert api.equiv(text, out.text, read_a="sinumerik", read_b="iso-m").equivalent


# ---------------------------------------------------------------- G33 between F-lead and K-lead

def test_iso_g33_lead_becomes_k_in_sinumerik():
    """ISO G33 Z.. F1.5 reads its lead from F; Sinumerik from K only (an F alone: no lead, NC206).
    Hand values at S500: 1.5 x 500 = 750 mm/min; the second G33 takes the F in force ($P_F);
    under G20 F0.05 inch = 1.27 mm lead, 635 mm/min."""
    iso = ("G21 G17 G90 G0 X0 Y0 Z5\nS500 M3\nG33 Z-20 F1.5\nG0 Z5\nG33 Z-10\nG0 Z5\n"
           "G20\nG33 Z-0.5 F0.05\nM30\n")
    want = [("linear", -20.0, 750.0, 1.5), ("linear", -10.0, 750.0, 1.5),
            ("linear", -12.7, 635.0, 1.27)]
    assert [e for e in events(iso, "iso-m") if e[0] == "linear"] == want
    out = api.transpile(iso, "iso-m", "sinumerik")
    assert "K=1.5" in out.text and "K=$P_F" in out.text
    assert [e for e in events(out.text) if e[0] == "linear"] == want
    assert not [d for d in api.lint(out.text, "sinumerik") if d.severity == "error"]


def test_iso_taper_thread_with_f_lead_is_never_written_without_its_lead():
    """Along two axes the lead's axis is not known statically: the block is lowered (its lead
    written from the analysed pitch) or refused at its line, never written without a lead."""
    text = "G0 X0 Z5\nS100 M3\nG33 X2 Z-10 F1\nM30\n"
    out = api.transpile(text, "iso-m", "sinumerik")
    assert any(d.rule in ("NC402", "NC401") and d.line == 3 for d in out.diagnostics)
    assert out.text is None or api.equiv(text, out.text, read_a="iso-m", read_b="sinumerik").equivalent


def test_p_f_reads_the_feed_in_its_own_unit():
    """$P_F gives F as programmed: under G70 F stays mm/min (100), under G700 inch/min (4)."""
    text = "G70 G1 X0 F100\nR1=$P_F\nG700 F4\nR2=$P_F\nG71 G0 X=R1 Y=R2\nM30\n"
    rapid = [r for r in nctrans.toolpath(text, "sinumerik") if r.kind == "rapid"][-1]
    assert (rapid.end["X"], rapid.end["Y"]) == (100.0, 4.0)


# ---------------------------------------------------------------- modal lead, spindle after G332

def test_modal_lead_taps_without_k_and_with_none_refuses():
    # the lead is modal: Z-9 after K2 taps with 2 (200 mm/min at S100); G332 without K retracts
    # with it too; a G331 with no lead ever programmed is NC206 and does not move
    text = "G0 X0 Y0 Z5\nS100 M3\nG331 Z-5 K2\nZ-9\nG332 Z5\nM30\n"
    ev = [e for e in events(text) if e[0] == "linear"]
    assert ev == [("linear", -5.0, 200.0, 2.0), ("linear", -9.0, 200.0, 2.0), ("linear", 5.0, 200.0, 2.0)]
    assert diags(text) == []
    none = "G0 X0 Y0 Z5\nS100 M3\nG331 Z-5\nM30\n"
    assert [e for e in events(none) if e[0] == "linear"] == []
    assert ("NC206", 3, "error") in diags(none)


def test_spindle_returns_after_g332_to_its_state_before_g331():
    # right-hand tap under M3: G332 reverses (ccw), and once it has retracted the spindle turns
    # clockwise again, recorded at the G332 line (4); standing before (M5) it stands again
    text = "G0 X0 Y0 Z5\nS500 M3\nG331 Z-20 K1.5\nG332 Z5 K1.5\nG0 Z50\nM30\n"
    recs = [(r.line, r.kind, r.spindle_dir) for r in nctrans.toolpath(text, "sinumerik") if r.kind == "spindle"]
    assert recs == [(2, "spindle", "cw"), (4, "spindle", "ccw"), (4, "spindle", "cw")]
    spos = "G0 X0 Y0 Z5\nS600 M5\nG331 Z-25 K2\nG332 Z5 K2\nG0 Z50\nM30\n"
    assert [e for e in events(spos) if e[0] == "spindle"] == [("spindle", "off"), ("spindle", "cw"),
                                                               ("spindle", "ccw"), ("spindle", "off")]
    # M5 between the two: the retraction reverses, then the spindle stands as M5 left it
    m5 = "G0 X0 Y0 Z5\nS500 M3\nG331 Z-10 K1\nM5\nG332 Z5 K1\nM30\n"
    assert [e for e in events(m5) if e[0] == "spindle"] == [("spindle", "cw"), ("spindle", "off"),
                                                             ("spindle", "ccw"), ("spindle", "off")]
    for t in (text, spos):
        out = api.transpile(t, "sinumerik", "iso-m")
        assert out.text is not None and api.equiv(t, out.text, read_a="sinumerik", read_b="iso-m").equivalent
