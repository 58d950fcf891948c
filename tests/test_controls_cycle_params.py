"""Parameters of Sinumerik's standard drilling and boring cycles as the cycles read them (issue 8,
the re-check of every modelled cycle's parameter mapping; general knowledge of the Siemens cycles
manual [GK], the seeds do not document these cycles). Every expected point is computed by hand in
the comments.

- A cycle is a subprogram, and a subprogram sees an omitted argument as 0 (seed L4722): it cannot
  tell DPR 0 from DPR not programmed, so DPR 0 (and FDPR 0) leaves the depth to DP (FDEP).
- CYCLE83 _DTD: the dwell at the final depth (> 0 seconds, < 0 spindle revolutions, 0 as DTB).
- CYCLE85 feeds out at RFF; CYCLE86 lifts off by RPA/RPO/RPAP after the oriented stop and turns
  the spindle back on in SDIR; CYCLE87/CYCLE88 retract with G0 after NC start.
"""
from __future__ import annotations

import pytest

import nctrans
from nctrans import pipeline
from nctrans.source import from_text

SETUP = "G17 G90 G0 X0 Y0 Z50 F80 S600 M3\n"


def run(call: str):
    text = SETUP + call + "\nM30\n"
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld) if r.line == 2]
    return recs, ld.diagnostics


def steps(recs):
    out = []
    for r in recs:
        if r.kind in ("rapid", "linear"):
            out.append((r.kind, round(r.end["X"], 6), round(r.end["Y"], 6), round(r.end["Z"], 6)))
        elif r.kind == "dwell":
            out.append(("dwell", round(r.dwell_s, 6)))
        elif r.kind == "spindle":
            out.append(("spindle", r.spindle_dir))
        else:
            out.append((r.kind,))
    return out


def test_dpr_zero_is_not_programmed():
    # RTP 10, RFP 0, SDIS 2, DP -20, DPR 0: the depth is DP's: G0 Z2, G1 Z-20, G0 Z10 (before: a
    # hole 0 deep, G1 to Z0)
    recs, _ = run("CYCLE81(10, 0, 2, -20, 0)")
    assert steps(recs) == [("rapid", 0, 0, 2), ("linear", 0, 0, -20), ("rapid", 0, 0, 10)]
    # a DPR that is not 0 still wins over DP: 0 - 5 = -5
    recs, _ = run("CYCLE81(10, 0, 2, -20, 5)")
    assert steps(recs)[1] == ("linear", 0, 0, -5)


def test_fdpr_zero_leaves_the_first_depth_to_fdep_and_dtd_dwells_at_the_bottom():
    # CYCLE83 chip breaking (VARI 0), DP -30, FDEP -10, FDPR 0, DAM 5, DTB 0, _DTD 2: strokes 10,
    # then 10 - 5 = 5 (not more than DAM: DAM from then on): depths -10, -15, -20, -25, -30, each
    # backed off 1 mm (_VRT 0: 1 mm) with G1 before the next; a dwell of 2 s at -30 only
    recs, diags = run("CYCLE83(10, 0, 2, -30, 0, -10, 0, 5, 0, 0, 1, 0, 0, 0, 0, 2)")
    assert not [d for d in diags if d.severity != "info"]
    want = [("rapid", 0, 0, 2)]
    for z in (-10, -15, -20, -25):
        want += [("linear", 0, 0, z), ("linear", 0, 0, z + 1)]
    want += [("linear", 0, 0, -30), ("dwell", 2.0), ("rapid", 0, 0, 10)]
    assert steps(recs) == want


def test_dtd_in_revolutions():
    # _DTD -3: three spindle revolutions at S600 = 3 * 60 / 600 = 0.3 s at the final depth; DTB
    # 0.5 at the depths before it. Swarf removal (VARI 1): FDEP -10, DAM 10: depths -10, -20
    recs, _ = run("CYCLE83(10, 0, 2, -20, , -10, , 10, 0.5, 0, 1, 1, 0, 0, 0, -3)")
    dwells = [s for s in steps(recs) if s[0] == "dwell"]
    assert dwells == [("dwell", 0.5), ("dwell", 0.3)]


def test_cycle85_feeds_out_at_rff():
    # FFR 100 in, RFF 500 out: G0 Z2, G1 Z-20 F100, G1 Z2 F500, G0 Z10
    recs, _ = run("CYCLE85(10, 0, 2, -20, , 0, 100, 500)")
    assert [(s, r.feed) for s, r in zip(steps(recs), recs) if r.kind == "linear"] == [
        (("linear", 0, 0, -20), 100.0), (("linear", 0, 0, 2), 500.0)]
    assert steps(recs)[-1] == ("rapid", 0, 0, 10)


def test_cycle86_lifts_off_by_rpa_rpo_rpap_and_restarts_in_sdir():
    # SDIR 4, RPA -1, RPO 0.5, RPAP 0.2, POSS 90: the hole is bored in M4 (SDIR; the program runs
    # M3), G1 to -20, oriented stop, G0 by (-1, 0.5, 0.2) to (-1, 0.5, -19.8), G0 up to RTP 10,
    # back over the hole (0, 0, 10), spindle M4
    recs, _ = run("CYCLE86(10, 0, 2, -20, , 0, 4, -1, 0.5, 0.2, 90)")
    assert steps(recs) == [("spindle", "ccw"), ("rapid", 0, 0, 2), ("linear", 0, 0, -20), ("dwell", 0.0),
                           ("spindle", "orient"),
                           ("rapid", -1, 0.5, -19.8), ("rapid", -1, 0.5, 10), ("rapid", 0, 0, 10),
                           ("spindle", "ccw")]


@pytest.mark.parametrize("call, dwell", [("CYCLE87(10, 0, 2, -20, , 3)", []),
                                         ("CYCLE88(10, 0, 2, -20, , 1.5, 3)", [("dwell", 1.5)])])
def test_cycle87_88_retract_with_g0_after_nc_start(call, dwell):
    recs, _ = run(call)
    got = steps(recs)
    assert got[:2] == [("rapid", 0, 0, 2), ("linear", 0, 0, -20)]
    assert got[2:2 + len(dwell)] == dwell
    assert got[2 + len(dwell):5 + len(dwell)] == [("spindle", "off"), ("stop",), ("rapid", 0, 0, 10)]


@pytest.mark.parametrize("call", [
    "CYCLE81(10, 0, 2, -20, 0)", "CYCLE83(10, 0, 2, -30, 0, -10, 0, 5, 0, 0, 1, 0, 0, 0, 0, 2)",
    "CYCLE85(10, 0, 2, -20, , 0, 100, 500)", "CYCLE86(10, 0, 2, -20, , 0, 4, -1, 0.5, 0.2, 90)",
    "CYCLE87(10, 0, 2, -20, , 3)", "CYCLE88(10, 0, 2, -20, , 1.5, 3)"])
def test_converted_to_iso_the_same_toolpath(call):
    text = SETUP + call + "\nM30\n"
    conv = nctrans.transpile(text, read="sinumerik", write="iso-m")
    assert conv.ok, conv.diagnostics
    assert nctrans.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m")


def test_cycle97_thread_size_up_to_m60():
    # MPIT 56 (no PIT): the ISO 261 coarse pitch of M56 is 5.5 mm [GK]; CYCLE97 takes MPIT 3..60.
    # External (VARI 1), DM1 = DM2 = 56, TDEP 3, FAL 0, one cut (NRC 1), no idle pass
    text = ("G18 G90 G54 T1 D1\nS200 M3\nG0 X70 Z10\n"
            "CYCLE97(, 56, 0, -20, 56, 56, 4, 2, 3, 0, 0, 0, 1, 0, 1, 1)\nG0 X80\nM30\n")
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    cuts = [r for r in pipeline.toolpath_of(ld) if r.line == 4 and r.kind == "linear"]
    assert cuts and {r.pitch for r in cuts} == {5.5}


def test_cycle84_taps_at_sst_and_retracts_at_sst1():
    # SST 400 / SST1 200 under S600 M3 [GK, Siemens cycles manual: tap (G331) at SST, retract
    # (G332) at SST1, then the speed active before the call again with SDAC's direction]:
    # G0 Z2 (RFP 0 + SDIS 2); S400 M3; tap to DP -18 at lead 1.5 x 400 = 600 mm/min; dwell 0.3;
    # S200 reversed (M4); back to Z2 at 1.5 x 200 = 300 mm/min; S600 M3 (SDAC 3); G0 Z10 (RTP)
    recs, diags = run("CYCLE84(10, 0, 2, -18, , 0.3, 3, , 1.5, 0, 400, 200)")
    got = [(r.kind, r.end["Z"], r.feed, r.pitch, r.spindle) if r.kind in ("rapid", "linear") else
           (r.kind, r.spindle_dir, r.spindle) if r.kind == "spindle" else (r.kind, r.dwell_s) for r in recs]
    assert got == [("rapid", 2, None, None, 600), ("spindle", "cw", 400), ("linear", -18, 600, 1.5, 400),
                   ("dwell", 0.3), ("spindle", "ccw", 200), ("linear", 2, 300, 1.5, 200),
                   ("spindle", "cw", 600), ("rapid", 10, None, None, 600)]
    assert not diags
    # SST1 0: retract at SST; SST 600 = the speed in force: no change before the tap
    # (600 x 1.5 = 900 mm/min both ways)
    recs, diags = run("CYCLE84(10, 0, 2, -18, , 0, 3, , 1.5, 0, 600, 0)")
    assert [(r.feed, r.spindle) for r in recs if r.kind == "linear"] == [(900, 600), (900, 600)]
    # reversed for G332, back to the state before the call (G332); SDAC 3 is that state again:
    # no second record
    assert [(r.spindle_dir, r.spindle) for r in recs if r.kind == "spindle"] == [
        ("ccw", 600), ("cw", 600)]
    assert not diags
    # SST omitted: the tap runs at the speed in force, said at the line (NC128)
    recs, diags = run("CYCLE84(10, 0, 2, -18, , 0, 3, , 1.5)")
    assert [r.feed for r in recs if r.kind == "linear"] == [900, 900]
    assert [d.rule for d in diags] == ["NC128"]


def test_cycle84_speeds_convert_with_equal_toolpaths():
    text = SETUP + "CYCLE84(10, 0, 2, -18, , 0.3, 3, , 1.5, 0, 400, 200)\nG1 X20\nM30\n"
    for target in ("iso-m", "fagor", "sinumerik"):
        conv = nctrans.transpile(text, read="sinumerik", write=target)
        assert nctrans.equiv(text, conv.text, read_a="sinumerik", read_b=target), target
