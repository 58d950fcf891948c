"""Sinumerik AP=IC(..): a polar angle relative to the last polar angle (issue #8; Siemens
Fundamentals, polar coordinates [GK]; the seed lists AP/RP only). Points by hand."""
from __future__ import annotations

import math

import pytest

import nctrans
from nctrans import pipeline
from nctrans.source import from_text

PROGRAM = ("G17 G90 G0 X0 Y0 Z5\nG111 X10 Y10\nG1 AP=30 RP=10 F100\nAP=IC(30)\nAP=IC(-90) RP=5\n"
           "AP=AC(180)\nM30\n")


def xy(deg: float, r: float, pole=(10.0, 10.0)):
    return (round(pole[0] + r * math.cos(math.radians(deg)), 6), round(pole[1] + r * math.sin(math.radians(deg)), 6))


def test_incremental_polar_angle_adds_to_the_last_one():
    ld = pipeline.load_source(from_text(PROGRAM, "p.mpf"), "p.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind == "linear"]
    assert not [d for d in ld.diagnostics if d.severity in ("error", "warning")], ld.diagnostics
    # pole (10, 10): AP=30 RP=10; +30 -> 60 (RP 10); -90 -> -30 with RP 5; AP=AC(180) RP 5
    got = [(round(r.end["X"], 6), round(r.end["Y"], 6)) for r in recs]
    assert got == [xy(30, 10), xy(60, 10), xy(-30, 5), xy(180, 5)]
    assert got[1] == (15.0, 18.660254) and got[3] == (5.0, 10.0)


@pytest.mark.parametrize("target", ["sinumerik", "iso-m", "fagor"])
def test_incremental_polar_angle_converts_to_the_same_path(target):
    conv = nctrans.transpile(PROGRAM, read="sinumerik", write=target)
    assert conv.ok, conv.diagnostics
    assert nctrans.equiv(PROGRAM, conv.text, read_a="sinumerik", read_b=target)
