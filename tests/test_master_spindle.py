"""Sinumerik spindle words with a spindle number, and SETMS (issue 8; interp/spindle_position.py).

nctrans models one spindle, the master. `S2=500` used to set the master's speed (a spindle record
at 500 rev/min for a spindle that never changed); now every word of a spindle that is not the
master is NC220 at its line, and SETMS(n) moves the master role (said at its line, since the
state kept is the previous master's until it is set again)."""
from __future__ import annotations

import pytest

from nctrans import pipeline, plainrun
from nctrans.source import from_text


def _run(text: str, kernel: bool = True):
    saved = plainrun.native
    if not kernel:
        plainrun.native = None
    try:
        ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
        recs = [r for r in pipeline.toolpath_of(ld, pipeline.load_machine(None, "sinumerik"))
                if r.kind == "spindle"]
    finally:
        plainrun.native = saved
    events = [(r.line, r.spindle, r.spindle_dir, r.spindle_angle) for r in recs]
    said = [(d.rule, d.line) for d in ld.diagnostics if d.severity != "info"]
    return events, said


def test_a_numbered_speed_of_another_spindle_is_not_the_masters():
    text = "G0 X0 Y0 Z10\nM3 S1000\nS2=500\nG1 X10 F100\nS1=800\nM30\n"
    events, said = _run(text)
    # line 3 (spindle 2) leaves the master at 1000; line 5 (S1=, the master) sets 800
    assert events == [(2, 1000.0, "cw", None), (5, 800.0, "cw", None)]
    assert said == [("NC220", 3)]


def test_setms_moves_the_master_role():
    text = ("G0 X0 Y0 Z10\nM3 S1000\nSETMS(2)\nSPOS[1]=90\nS2=600\nSPOS=30\nSETMS\n"
            "SPOS[1]=10\nM30\n")
    events, said = _run(text)
    # SETMS(2) (line 3): said; SPOS[1] (line 4) is spindle 1, no longer the master: said, nothing
    # recorded; S2=600 (line 5) is the master's speed now; SPOS=30 (line 6) positions the master;
    # SETMS (line 7) gives the role back to spindle 1 (said); SPOS[1]=10 (line 8) is the master's.
    assert events == [(2, 1000.0, "cw", None), (5, 600.0, "cw", None), (6, 600.0, "orient", 30.0),
                      (8, 600.0, "orient", 10.0)]
    assert said == [("NC220", 3), ("NC220", 4), ("NC220", 7)]


def test_a_computed_master_number_leaves_numbered_words_unmodelled():
    text = "R1=2\nM3 S1000\nSETMS(R1)\nS1=300\nS=400\nM30\n"
    events, said = _run(text)
    assert events == [(2, 1000.0, "cw", None), (5, 400.0, "cw", None)]
    assert said == [("NC220", 3), ("NC220", 4)]


@pytest.mark.parametrize("text", [
    "G0 X0 Y0 Z10\nM3 S1000\nG1 X1 F100\nX2\nS2=500\nX3\nY1\nSETMS(2)\nX4\nS2=700\nX5\nM30\n",
])
def test_same_with_and_without_the_native_kernel(text):
    assert _run(text, kernel=True) == _run(text, kernel=False)
