"""Spindle positioning (issue 8, nctrans/interp/spindle_position.py): Sinumerik SPOS/SPOSA and M19
stop the spindle at an angle; the toolpath says where (a probe then feeds with it: no NC209), and ISO gets
M19 where M19 means the same (an absolute 0: SD 43240 M19_SPOS, 0 by default), a refusal at the line
otherwise. Expected angles worked out by hand in the comments."""
from __future__ import annotations

import math

import pytest

from nctrans import api, pipeline
from nctrans.source import from_text

HEAD = "T1 M6\nS1000 M3\nG0 X10 Y10 Z5\n"


def run(text: str, dialect: str = "sinumerik"):
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", dialect)
    recs = list(pipeline.toolpath_of(ld, None))
    return recs, ld.diagnostics


def spindle_events(recs):
    return [(r.line, r.spindle_dir, r.spindle_angle) for r in recs if r.kind == "spindle"]


def test_spos_positions_and_stops_the_spindle():
    text = HEAD + ("SPOS=90\n"              # line 4: 90
                   "SPOSA=IC(-120)\n"       # 5: 90 - 120 = -30 -> 330
                   "SPOS=ACP(450)\n"        # 6: 450 -> 90
                   "SPOS[1]=DC(-90)\n"      # 7: 270
                   "G1 Z0 F100\n"           # 8: a probe's feed move: not NC209
                   "M3 S500\nM30\n")
    recs, diags = run(text)
    assert spindle_events(recs)[1:] == [(4, "orient", 90.0), (5, "orient", 330.0), (6, "orient", 90.0),
                                        (7, "orient", 270.0), (9, "cw", None)]
    assert [(d.rule, d.line) for d in diags if d.severity != "info"] == []


def test_incremental_from_a_turning_spindle_is_said_unknown():
    recs, diags = run(HEAD + "SPOS=IC(45)\nM19\nSPOS=IC(45)\nM30\n")
    # line 4: the spindle was turning: stops, angle unknown (NC220); M19 at 0 (SD 43240 default);
    # then 0 + 45
    events = spindle_events(recs)[1:]
    assert math.isnan(events[0][2]) and events[1:] == [(5, "orient", None), (6, "orient", 45.0)]
    assert [(d.rule, d.line) for d in diags if d.severity != "info"] == [("NC220", 4)]
    conv = api.transpile(HEAD + "SPOS=IC(45)\nM30\n", "sinumerik", "sinumerik", flatten=True)
    assert conv.text is None and [(d.rule, d.line) for d in conv.diagnostics if d.severity == "error"] == [
        ("NC402", 4)]


def test_other_spindles_stay_said_not_modelled():
    recs, diags = run(HEAD + "SPOS[2]=0\nM30\n")
    assert spindle_events(recs)[1:] == []
    assert [(d.rule, d.line) for d in diags if d.severity != "info"] == [("NC220", 4)]


def test_spos_0_converts_to_m19_and_stays_equivalent():
    text = HEAD + "SPOS=0\nG0 Z20\nSPOSA=AC(360)\nM3\nG0 X0\nM30\n"
    conv = api.transpile(text, "sinumerik", "iso-m")
    assert conv.text is not None
    assert [line for line in conv.text.splitlines() if "M19" in line] == ["M19", "M19"]
    assert {d.line for d in conv.lowered if "M19" in d.message} == {4, 6}
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m")


@pytest.mark.parametrize("flatten", [False, True])
def test_spos_to_an_angle_is_refused_for_iso_at_its_line(flatten):
    conv = api.transpile(HEAD + "G0 Z20\nSPOS=90\nM30\n", "sinumerik", "iso-m", flatten=flatten)
    assert conv.text is None
    assert [(d.rule, d.line) for d in conv.diagnostics if d.severity == "error"] == [("NC402", 5)]
    assert "M19" in [d for d in conv.diagnostics if d.severity == "error"][0].message


def test_flattened_sinumerik_keeps_the_angle():
    text = HEAD + "SPOS=90\nSPOS=IC(90)\nM3\nM30\n"
    conv = api.transpile(text, "sinumerik", "sinumerik", flatten=True)
    assert conv.text is not None and "SPOS=90" in conv.text and "SPOS=180" in conv.text
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="sinumerik")


def test_equiv_tells_the_angles_apart():
    a, b = HEAD + "SPOS=90\nM30\n", HEAD + "SPOS=0\nM30\n"
    assert not api.equiv(a, b, read_a="sinumerik", read_b="sinumerik")
    assert api.equiv(b, HEAD + "M19\nM30\n", read_a="sinumerik", read_b="sinumerik")


def test_iso_m19_stops_the_spindle_and_converts():
    text = "T1 M6\nS1000 M3\nG0 X10 Y10 Z5\nM19\nG1 Z0 F100\nM30\n"
    recs, diags = run(text, "iso-m")
    assert spindle_events(recs)[1:] == [(4, "orient", None)]
    assert [(d.rule, d.line) for d in diags if d.severity != "info"] == []
    conv = api.transpile(text, "iso-m", "sinumerik")
    assert conv.text is not None and "M19" in conv.text
    assert api.equiv(text, conv.text, read_a="iso-m", read_b="sinumerik")


def test_an_unknown_angle_never_reaches_the_json_record_as_null(tmp_path):
    # the toolpath JSON of the IC-from-turning case: the event is there, its angle key is left out
    import json
    from nctrans.toolpath_io import to_json_line
    recs, _ = run(HEAD + "SPOS=IC(45)\nSPOS=IC(45)\nM30\n")
    lines = [json.loads(to_json_line(r)) for r in recs if r.kind == "spindle"]
    orients = [d for d in lines if d.get("spindle_dir") == "orient"]
    assert len(orients) == 2
    assert all(None not in d.values() for d in lines)
    assert "spindle_angle" not in orients[0] and "spindle_angle" not in orients[1]   # still unknown + 45
