"""A cycle call records and says each thing once: CYCLE84 turning the spindle back to cw after
G332's return and again for SDAC (same direction, same speed) is one spindle record; an omitted
value filled from the state (NC128) is not said beside a refusal of the same call (NC206/NC224/
NC225), which moved nothing."""
from __future__ import annotations

import nctrans

START = "G17 G90 G71\nT1 D1 M6\nS500 M3\nG0 X0 Y0 Z10\n"


def _run(call):
    text = START + call + "\nM30\n"
    return list(nctrans.toolpath(text, "sinumerik")), nctrans.lint(text, "sinumerik")


def test_cycle84_without_speed_change_records_cw_once():
    # CYCLE84(RTP 10, RFP 0, SDIS 2, DP -15, , DTB 0.5, SDAC 3 (cw), , PIT 1.25, POSS 0, SST 500):
    # S500 M3 in force, so the tap turns cw at 500 down, ccw at 500 up, then cw at 500 (G332's
    # return and SDAC 3 at the same speed: one record)
    recs, _ = _run("CYCLE84(10, 0, 2, -15, , 0.5, 3, , 1.25, 0, 500)")
    spindle = [(r.line, r.spindle_dir, r.spindle) for r in recs if r.kind == "spindle"]
    assert spindle == [(3, "cw", 500.0), (5, "ccw", 500.0), (5, "cw", 500.0)]
    kinds = [r.kind for r in recs if r.line == 5]
    assert kinds == ["rapid", "linear", "dwell", "spindle", "linear", "spindle", "rapid"]


def test_cycle84_with_its_own_speed_still_records_each_change():
    # SST 800, SST1 0 (retract at SST): cw 800 down, ccw 800 up, then back to the speed before
    # the call (500) cw: three spindle records at line 5, none repeated
    recs, _ = _run("CYCLE84(10, 0, 2, -15, , 0.5, 3, , 1.25, 0, 800)")
    spindle = [(r.spindle_dir, r.spindle) for r in recs if r.kind == "spindle" and r.line == 5]
    assert spindle == [("cw", 800.0), ("ccw", 800.0), ("cw", 500.0)]


def test_nc128_not_beside_a_refusal():
    # no DP and no DPR: NC206, nothing moves; SST omitted would be NC128
    recs, diags = _run("CYCLE84(10, 0, 2, , , 0.5, 3, , 1.25, 0)")
    assert not [r for r in recs if r.line == 5]
    assert [d.rule for d in diags if d.line == 5] == ["NC206"]


def test_nc128_still_said_where_the_call_runs():
    _, diags = _run("CYCLE84(10, 0, 2, -15, , 0.5, 3, , 1.25, 0)")
    assert [d.rule for d in diags if d.line == 5] == ["NC128"]
