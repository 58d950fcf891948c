"""Omitted parameters of the Sinumerik cycle models: a cycle is a subprogram and sees an omitted
argument as 0 (seed L4722). RTP left out retracts to 0 (NC127); a feed or CYCLE86's SDIR left out
is taken from the program's state and said at the line (NC128)."""
from __future__ import annotations

from hypothesis import given, settings, strategies as hs

from nctrans import pipeline
from nctrans.interp.milling_cycles import levels_of
from nctrans.machine import Machine, Tool
from nctrans.source import from_text


def _run(body: str):
    text = f"G17 G90 G54 T1 D1 M6\nS1000 M3 F100\nG0 X10 Y10 Z50\n{body}\nM30\n"
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    machine = Machine(name="t", tools=[Tool(number=1, radius=3.0, length=0.0)])
    recs = [r for r in pipeline.toolpath_of(ld, machine) if r.kind in ("rapid", "linear", "arc")]
    return recs, ld.diagnostics


def _z(recs, line):
    return [(r.kind, r.end["X"], r.end["Z"]) for r in recs if r.line == line]


def test_omitted_rtp_retracts_to_zero():
    # RTP omitted = 0; RFP -5, SDIS 2: approach -5+2 = -3, DP -20; RTP 0 is above -3, so the
    # cycle ends at Z0 (was: Z50, the height it started from); G0 X20 then runs at Z0
    recs, diags = _run("CYCLE81(, -5, 2, -20)\nG0 X20")
    assert _z(recs, 4) == [("rapid", 10, -3), ("linear", 10, -20), ("rapid", 10, 0)]
    assert _z(recs, 5) == [("rapid", 20, 0)]
    assert [(d.rule, d.line) for d in diags] == [("NC127", 4)]
    # the same path as RTP 0 written out, which says nothing
    recs0, diags0 = _run("CYCLE81(0, -5, 2, -20)\nG0 X20")
    assert [(r.kind, r.end) for r in recs0] == [(r.kind, r.end) for r in recs]
    assert not diags0


def test_omitted_rtp_below_the_approach_level_ends_there():
    # RTP 0 below RFP+SDIS = 0+2: the model ends at the approach level Z2 (as an RTP 0 written
    # out does), never at the start height Z50
    recs, diags = _run("CYCLE82(, 0, 2, -10, , 1)")
    assert _z(recs, 4) == [("rapid", 10, 2), ("linear", 10, -10), ("rapid", 10, 2)]
    assert [d.rule for d in diags] == ["NC127"]


def test_omitted_rtp_under_mcall_is_said_once():
    recs, diags = _run("MCALL CYCLE81(, 0, 1, -5)\nX20\nX30\nMCALL")
    # X20 at Z50, then the hole: rapid to 0+1 = 1, feed to -5, back to 1 (RTP 0 below the
    # approach level); X30 at Z1, already at the approach level: feed to -5, back to 1
    assert [r.end["Z"] for r in recs if r.line in (5, 6)] == [50, 1, -5, 1, 1, -5, 1]
    assert [(d.rule, d.line) for d in diags] == [("NC127", 4)]


def test_milling_levels_take_an_omitted_rtp_as_zero():
    # RFP 0, SDIS 2, DP -5: approach 2; RTP 0 is below it, so the pocket retracts to 2
    lv = levels_of({"RFP": 0.0, "SDIS": 2.0, "DP": -5.0})
    assert (lv.rtp, lv.approach, lv.bottom, lv.retract) == (0.0, 2.0, -5.0, 2.0)
    recs, diags = _run("POCKET2(, 0, 2, -5, , 10, 0, 0, 100, 100, 5, 2, 0, 1)")
    assert recs[-1].end["Z"] == 2.0
    assert [d.rule for d in diags] == ["NC127"]


def test_feed_and_spindle_direction_from_state_are_said():
    # CYCLE85 FFR omitted: the analysis feeds in at the active F100, feeds out at RFF 200
    recs, diags = _run("CYCLE85(50, 0, 2, -20, , , , 200)")
    assert [(r.kind, r.end["Z"], r.feed) for r in recs if r.kind == "linear"] == [
        ("linear", -20, 100), ("linear", 2, 200)]
    assert [d.rule for d in diags] == ["NC128"]
    assert "FFR" in diags[0].message
    # given, nothing is said
    _, diags = _run("CYCLE85(50, 0, 2, -20, , , 80, 200)")
    assert not diags
    # CYCLE86 SDIR 0: the spindle turns on again in the direction in force
    _, diags = _run("CYCLE86(50, 0, 2, -20, , 0, , 1, 0, 0, 0)")
    assert [d.rule for d in diags] == ["NC128"] and "SDIR" in diags[0].message
    _, diags = _run("CYCLE86(50, 0, 2, -20, , 0, 3, 1, 0, 0, 0)")
    assert not diags
    # a milling cycle with FFD and FFP1 left out
    _, diags = _run("POCKET2(50, 0, 2, -5, , 10, 0, 0, , , 5, 2, 0, 1)")
    assert [d.rule for d in diags] == ["NC128"]
    assert "FFD" in diags[0].message and "FFP1" in diags[0].message


def test_cycle84_sdac_omitted_is_said():
    # SDAC 0: no direction after the cycle (3/4/5 are M3/M4/M5); the analysis turns the spindle
    # back to the direction in force (M3) and says so (NC128)
    recs, diags = _run("CYCLE84(50, 0, 2, -10, , 0, , , 1.5, 0, 1000)")
    assert [d.rule for d in diags] == ["NC128"] and "SDAC" in diags[0].message
    _, diags = _run("CYCLE84(50, 0, 2, -10, , 0, 3, , 1.5, 0, 1000)")
    assert not diags


@settings(max_examples=25, deadline=None)
@given(hs.sampled_from(["CYCLE81", "CYCLE82", "CYCLE83", "CYCLE85", "CYCLE89"]),
       hs.integers(-10, 10), hs.integers(0, 5), hs.integers(1, 30))
def test_an_omitted_rtp_is_rtp_zero(name, rfp, sdis, depth):
    # whatever the cycle and levels, leaving RTP out drives the toolpath of RTP 0 written out,
    # and only the omitted one says NC127 (feeds given so that nothing else is said)
    rest = {"CYCLE81": "", "CYCLE82": ", 0.5", "CYCLE83": ", , , 2, 0, 0, 1, 0",
            "CYCLE85": ", 0, 100, 200", "CYCLE89": ", 0.5"}[name]
    args = f"{rfp}, {sdis}, {rfp - depth}{rest}"
    recs, diags = _run(f"{name}(, {args})")
    recs0, diags0 = _run(f"{name}(0, {args})")
    assert [(r.kind, r.end) for r in recs] == [(r.kind, r.end) for r in recs0]
    assert [d.rule for d in diags] == ["NC127"] and not diags0
