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


def test_a_numbered_spos_of_the_master_positions_it():
    text = ("G0 X0 Y0 Z10\nM3 S1000\nSPOS[1]=90\nSETMS(2)\nSPOS[2]=45\nSPOS[2]=IC(10)\nSPOS[3]=5\n"
            "SPOSA[2]=DC(0)\nM30\n")
    events, said = _run(text)
    # SPOS[1] (line 3) under the configured master is SPOS=90; SETMS(2) (line 4) said; SPOS[2]=45
    # (line 5) is the master's now, as SPOS=45 (it was NC220 before); IC(10) from 45 is 55 (line 6);
    # SPOS[3] (line 7) is not the master: said, nothing recorded; SPOSA[2]=DC(0) (line 8): 0
    assert events == [(2, 1000.0, "cw", None), (3, 1000.0, "orient", 90.0), (5, 1000.0, "orient", 45.0),
                      (6, 1000.0, "orient", 55.0), (8, 1000.0, "orient", 0.0)]
    assert said == [("NC220", 4), ("NC220", 7)]


def test_a_numbered_spos_of_the_master_converts_from_the_run():
    # SPOS[2]=0 after SETMS(2): the text alone does not say spindle 2 is the master, so no writer
    # spells it as its own master positioning; the run does, and the ISO program (one spindle) gets
    # the M19 of the lowered block
    from nctrans import api
    text = "G0 X0 Y0 Z10\nM3 S1000\nSETMS(2)\nSPOS[2]=0\nG1 X10 F100\nM30\n"
    conv = api.transpile(text, "sinumerik", "iso-m")
    assert conv.text is not None and "M19" in conv.text.splitlines()
    assert [d for d in conv.diagnostics if d.line == 4 and d.rule == "NC401"]


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


@pytest.mark.parametrize("kernel", [True, False])
def test_a_numbered_spindle_function_is_spindle_ns_not_the_masters(kernel):
    # M1=3 is spindle 1 clockwise: the master's only while spindle 1 is the master. After SETMS(2)
    # it was read as the master's M3 (a cw record for the master that never started)
    text = ("G0 X0 Y0 Z10\nS1000 M1=3\nSETMS(2)\nS600 M1=5\nG1 X10 F100\nSETMS\nM1=4\nM30\n")
    events, said = _run(text, kernel)
    # line 4: S600 is the master's speed (spindle 2, direction kept as spindle 1's: SETMS said);
    # its M1=5 stops spindle 1, not the master; line 7: M1=4 after SETMS is the master's again
    assert events == [(2, 1000.0, "cw", None), (4, 600.0, "cw", None), (7, 600.0, "ccw", None)]
    assert ("NC220", 4) in said and ("NC220", 2) not in said and ("NC220", 7) not in said


def test_a_numbered_spindle_function_keeps_its_number_when_written_back():
    from nctrans import api
    text = "SETMS(2)\nS500 M1=3\nG1 X10 F100\nM1=5\nM30\n"
    out = api.transpile(text, read="sinumerik", write="sinumerik").text
    # written as plain M3/M5 it would start and stop spindle 2, the master after SETMS(2)
    assert [ln for ln in out.splitlines() if "M1=" in ln or ln.strip() in ("M3", "M5")] == \
        ["S500 M1=3", "M1=5"]
