"""Drilling cycles as the controls run them (issue 8): Sinumerik CYCLE81 goes straight to RFP+SDIS,
CYCLE83 pecks from FDEP/DAM in both modes, Fanuc positions a G98 hole after G99 holes at R.
Every expected point is computed by hand in the comments."""
from __future__ import annotations

import pytest

from nctrans import pipeline
from nctrans.interp.cycles import cycle_table, deep_hole_depths
from nctrans.source import from_text


def run(text: str, dialect: str):
    ld = pipeline.load_source(from_text(text, "t.nc"), "t.nc", dialect)
    recs = list(pipeline.toolpath_of(ld))
    return recs, ld.diagnostics


def path(recs, line=None):
    """(kind, X, Y, Z) of the moves (of one source line)."""
    return [(r.kind, round(r.end["X"], 6), round(r.end["Y"], 6), round(r.end["Z"], 6))
            for r in recs if r.kind in ("rapid", "linear", "arc") and (line is None or r.line == line)]


SETUP = "G17 G90 G0 X0 Y0 Z50 F100 S1000 M3\n"


def test_cycle81_goes_straight_to_rfp_plus_sdis():
    # RTP=10 RFP=0 SDIS=2 DP=-5 from Z50: G0 Z2, G1 Z-5, G0 Z10 (never to RTP first)
    recs, diags = run(SETUP + "CYCLE81(10, 0, 2, -5)\nM30\n", "sinumerik")
    assert path(recs, 2) == [("rapid", 0, 0, 2), ("linear", 0, 0, -5), ("rapid", 0, 0, 10)]
    assert not [d for d in diags if d.severity == "error"]


def test_cycle81_with_dpr_and_mcall_at_several_positions():
    # DPR=7 from RFP=1: bottom 1-7=-6; approach 1+2=3; each position: plane move at the current
    # height, then G0 Z3, G1 Z-6, G0 Z10
    text = SETUP + "MCALL CYCLE81(10, 1, 2, , 7)\nX10\nY10\nMCALL\nX0\nM30\n"
    recs, _ = run(text, "sinumerik")
    assert path(recs, 3) == [("rapid", 10, 0, 50), ("rapid", 10, 0, 3), ("linear", 10, 0, -6),
                             ("rapid", 10, 0, 10)]
    assert path(recs, 4) == [("rapid", 10, 10, 10), ("rapid", 10, 10, 3), ("linear", 10, 10, -6),
                             ("rapid", 10, 10, 10)]
    assert path(recs, 6) == [("rapid", 0, 10, 10)]           # MCALL off: a plain move


def test_holes1_positions_at_the_current_height():
    # HOLES1(SPCA=0, SPCO=0, STA1=0, FDIS=10, DBH=5, NUM=2): holes at X10 and X15
    text = SETUP + "MCALL CYCLE81(10, 0, 2, -5)\nHOLES1(0, 0, 0, 10, 5, 2)\nMCALL\nM30\n"
    recs, _ = run(text, "sinumerik")
    assert path(recs, 3) == [
        ("rapid", 10, 0, 50), ("rapid", 10, 0, 2), ("linear", 10, 0, -5), ("rapid", 10, 0, 10),
        ("rapid", 15, 0, 10), ("rapid", 15, 0, 2), ("linear", 15, 0, -5), ("rapid", 15, 0, 10)]


def test_cycle83_swarf_removal_vari_1():
    # RTP=20 RFP=0 SDIS=2 DP=-30 FDEP=-10 DAM=4 VARI=1. Strokes 10, 6 (10-4), then 4 (6-4=2 is
    # not above DAM) until the bottom: depths -10 -16 -20 -24 -28 -30. Anticipation 0.6 mm (total
    # depth 30 <= 30). Between infeeds: G0 Z2, G0 Z(last + 0.6).
    recs, _ = run(SETUP + "CYCLE83(20, 0, 2, -30, , -10, , 4, , , , 1)\nM30\n", "sinumerik")
    want = [("rapid", 0, 0, 2), ("linear", 0, 0, -10)]
    for last, depth in ((-10, -16), (-16, -20), (-20, -24), (-24, -28), (-28, -30)):
        want += [("rapid", 0, 0, 2), ("rapid", 0, 0, last + 0.6), ("linear", 0, 0, depth)]
    want.append(("rapid", 0, 0, 20))
    assert path(recs, 2) == want


def test_cycle83_chip_breaking_vari_0_with_first_feed_factor_and_dwell():
    # VARI=0: G1 back 1 mm (no _VRT) between infeeds; FRF=0.5: first infeed at F50; DTB=1 s after
    # every infeed. DP=-12 FDEP=-5 DAM=2: strokes 5, 3 (5-2), 2 (3-2=1 is not above 2), then the
    # last 2: depths -5 -8 -10 -12.
    text = SETUP + "CYCLE83(10, 0, 1, -12, , -5, , 2, 1, , 0.5, 0)\nM30\n"
    recs, _ = run(text, "sinumerik")
    assert path(recs, 2) == [("rapid", 0, 0, 1), ("linear", 0, 0, -5), ("linear", 0, 0, -4),
                             ("linear", 0, 0, -8), ("linear", 0, 0, -7), ("linear", 0, 0, -10),
                             ("linear", 0, 0, -9), ("linear", 0, 0, -12), ("rapid", 0, 0, 10)]
    feeds = [r.feed for r in recs if r.line == 2 and r.kind == "linear"]
    assert feeds == [50.0] + [100.0] * 6
    assert [r.dwell_s for r in recs if r.line == 2 and r.kind == "dwell"] == [1.0] * 4


def test_deep_hole_depths_upwards_and_without_first_depth():
    # drilling upwards (RTP below RFP): the same strokes mirrored
    assert deep_hole_depths(0.0, 10.0, 4.0, 1.0, -1.0) == [4.0, 7.0, 9.0, 10.0]
    # no FDEP: strokes of DAM
    assert deep_hole_depths(0.0, -7.0, None, 3.0, 1.0) == [-3.0, -6.0, -7.0]


def test_fanuc_g98_after_g99_holes_positions_at_r():
    # G99 hole at (1,2) ends at R=2; the G98 hole at X3 is positioned at R (not lifted to Zi=10
    # first), drilled, then returns to Zi=10; the next G98 hole starts from 10.
    text = "G17 G90 G0 X0 Y0 Z10\nG99 G81 X1 Y2 Z-5 R2 F100\nG98 X3\nX5\nG80\nM30\n"
    recs, _ = run(text, "iso-m")
    assert path(recs, 3) == [("rapid", 3, 2, 2), ("linear", 3, 2, -5), ("rapid", 3, 2, 10)]
    assert path(recs, 4) == [("rapid", 5, 2, 10), ("rapid", 5, 2, 2), ("linear", 5, 2, -5),
                             ("rapid", 5, 2, 10)]


@pytest.mark.parametrize("dialect,mode", [("iso-m", "current"), ("sinumerik", "current"),
                                          ("a-linuxcnc-profile", "clear_level")])
def test_positioning_is_data(dialect, mode):
    assert cycle_table().position_at(dialect) == mode


def test_cycle84_taps_synchronised_with_reversal():
    # MPIT=8 -> M8 coarse pitch 1.25 mm; S500: feed 1.25*500 = 625 mm/min. G0 Z2, tap to -15,
    # dwell 0.5, spindle reversed (ccw), tap back to Z2, the G332 returns it to cw (as before the
    # call), SDAC=3 -> cw, which it already is (one record), G0 Z10.
    text = "G17 G90 G0 X0 Y0 Z50 F100 S500 M3\nCYCLE84(10, 0, 2, -15, , 0.5, 3, 8)\nM30\n"
    recs, _ = run(text, "sinumerik")
    mine = [r for r in recs if r.line == 2]
    assert [(r.kind, r.end["Z"] if r.end else r.spindle_dir or r.dwell_s) for r in mine] == [
        ("rapid", 2.0), ("linear", -15.0), ("dwell", 0.5), ("spindle", "ccw"), ("linear", 2.0),
        ("spindle", "cw"), ("rapid", 10.0)]
    taps = [r for r in mine if r.kind == "linear"]
    assert [(r.feed, r.pitch) for r in taps] == [(625.0, 1.25), (625.0, 1.25)]
    assert all(r.pitch is None for r in recs if r.kind == "rapid")


def test_cycle84_left_hand_from_negative_pit():
    # PIT=-1.5: left hand, lead 1.5, feed 1.5*400 = 600; reversal at the bottom is cw, back to ccw
    # (M4, as before the call) after the retraction, then SDAC 5: off
    text = "G17 G90 G0 X0 Y0 Z50 S400 M4\nCYCLE84(10, 0, 2, -15, , , 5, , -1.5)\nM30\n"
    recs, _ = run(text, "sinumerik")
    mine = [r for r in recs if r.line == 2]
    assert [r.spindle_dir for r in mine if r.kind == "spindle"] == ["cw", "ccw", "off"]
    assert {(r.feed, r.pitch) for r in mine if r.kind == "linear"} == {(600.0, 1.5)}


def test_iso_g84_records_the_lead_f_over_s():
    # G94 F625 S500: lead 625/500 = 1.25 mm on both tapping strokes
    text = "G17 G90 G0 X0 Y0 Z10 S500 M3\nG98 G84 X1 Y1 Z-5 R2 F625\nG80\nM30\n"
    recs, _ = run(text, "iso-m")
    assert [r.pitch for r in recs if r.kind == "linear"] == [1.25, 1.25]


def test_tapping_cycle_without_pitch_is_an_error():
    recs, diags = run("G0 Z50 S500 M3\nCYCLE84(10, 0, 2, -15, , , 3, , , , 500)\nM30\n", "sinumerik")
    assert [d.rule for d in diags if d.line == 2] == ["NC206"]
    assert not [r for r in recs if r.line == 2 and r.kind == "linear"]
