"""Sinumerik G63, tapping with a compensating chuck (issue 8; nctrans/interp/rigid_tap.py): the
seed (L24397) writes it `G63 Z.. G1`, non-modal (group 2): the block is a plain feed at F (the
chuck takes up the spindle), the retraction a second G63 block after M4."""
from __future__ import annotations

from nctrans import api, pipeline
from nctrans.source import from_text

TAP = "G17 G90 G0 X10 Y20 Z5\nS500 M3 F750\nG63 Z-10 G1\nM4\nG63 Z5\nG0 X30\nM30\n"


def _run(text: str):
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = [(r.line, r.kind, r.end["Z"] if r.end else None, r.feed, r.spindle_dir)
            for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear", "spindle")]
    return recs, ld.diagnostics


def test_g63_taps_at_f_and_retracts_after_m4():
    recs, diags = _run(TAP)
    assert not [d for d in diags if d.severity in ("warning", "error")]
    assert recs == [(1, "rapid", 5.0, None, None), (2, "spindle", None, None, "cw"),
                    (3, "linear", -10.0, 750.0, None), (4, "spindle", None, None, "ccw"),
                    (5, "linear", 5.0, 750.0, None), (6, "rapid", 5.0, None, None)]


def test_g63_under_rapid_is_reported_and_moves_nothing():
    recs, diags = _run("G17 G90 G0 X10 Y20 Z5\nS500 M3 F750\nG63 Z-10\nG1 Z2\nM30\n")
    assert [r for r in recs if r[0] == 3] == []
    assert [(d.rule, d.line) for d in diags if d.severity == "error"] == [("NC226", 3)]
    assert (4, "linear", 2.0, 750.0, None) in recs          # the next motion code moves again


def test_g63_converted_is_its_feed_move_and_equivalent():
    for target in ("iso-m", "fagor"):
        conv = api.transpile(TAP, "sinumerik", target)
        assert conv.text is not None and "G63" not in conv.text, target
        assert any(d.rule == "NC401" and d.line == 3 for d in conv.diagnostics)
        assert api.equiv(TAP, conv.text, read_a="sinumerik", read_b=target)
    back = api.transpile(TAP, "sinumerik", "sinumerik")
    assert back.text.count("G63") == 2 and api.equiv(TAP, back.text, read_a="sinumerik", read_b="sinumerik")


# Fagor G63: interpolated (rigid) tapping (seed L8556-8780, spec 9.8): lead = F / S, the spindle
# turning by the sign of S whatever M3/M4 say, modal until M3/M4/M5/M19.
FAGOR_TAP = "G17 G90 G00 X0 Y0 Z5\nF750 S500 M3\nG63 Z-10 S500\nZ-12\nG63 Z5 S-500\nM3\nX10\nM30\n"


def _fagor(text: str):
    ld = pipeline.load_source(from_text(text, "t.pim"), "t.pim", "fagor")
    recs = [(r.line, r.kind, r.end["Z"] if r.end else None, r.feed, r.spindle_dir, r.pitch)
            for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear", "spindle")]
    return recs, ld.diagnostics


def test_fagor_g63_taps_with_lead_f_over_s_and_reverses_by_the_sign_of_s():
    recs, diags = _fagor(FAGOR_TAP)
    assert not [d for d in diags if d.severity in ("warning", "error")]
    moves = [r for r in recs if r[1] != "spindle"]
    # F750 / S500 = 1.5 mm a turn; Z-12 under modal G63 taps on; M3 ends G63: X10 is a rapid
    assert moves == [(1, "rapid", 5.0, None, None, None), (3, "linear", -10.0, 750.0, None, 1.5),
                     (4, "linear", -12.0, 750.0, None, 1.5), (5, "linear", 5.0, 750.0, None, 1.5),
                     (7, "rapid", 5.0, None, None, None)]
    turns = [(r[0], r[4]) for r in recs if r[1] == "spindle"]
    assert (5, "ccw") in turns and turns[-1] == (6, "cw")


def test_fagor_g63_per_revolution_and_without_feed():
    recs, _ = _fagor("G95 G00 Z5\nF1.25 S400 M3\nG63 Z-10 S400\nM30\n")
    assert (3, "linear", -10.0, 500.0, None, 1.25) in recs          # F is the lead under G95
    recs, diags = _fagor("G00 Z5\nS400 M3\nG63 Z-10 S400\nM30\n")
    assert not [r for r in recs if r[1] == "linear"]
    assert ("NC206", 3) in [(d.rule, d.line) for d in diags]


def test_fagor_g63_round_trips_and_converts_to_iso_and_sinumerik():
    again = api.transpile(FAGOR_TAP, "fagor", "fagor")
    assert "G63 Z5 S-500" in again.text and api.equiv(FAGOR_TAP, again.text, read_a="fagor", read_b="fagor")
    for target in ("iso-m", "sinumerik"):
        conv = api.transpile(FAGOR_TAP, "fagor", target)
        assert conv.text is not None and "G33" in conv.text, target
        assert api.equiv(FAGOR_TAP, conv.text, read_a="fagor", read_b=target)
