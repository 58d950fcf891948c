"""ISO canned cycle positions under G16 (nctrans/interp/polar_input.py, rules iso-m
`polar_cycle_positions`): on a Fanuc [GK] the plane words of a G81..G89 block are radius and angle
about the G16 pole, as in a motion block: the bolt hole circle of the Fanuc manual. Where the rules
say the control alarms (the seed's Sinumerik ISO mode without _ZSFI[3] = 1, seed L2427, L6385) the
block is NC117 at its line. Every expected point is computed by hand."""
from __future__ import annotations

import math

from hypothesis import given, settings, strategies as hs

import nctrans
from nctrans import pipeline
from nctrans.interp import polar_input
from nctrans.source import from_text


def run(text: str):
    ld = pipeline.load_source(from_text(text, "t.nc"), "t.nc", "iso-m")
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear")]
    return recs, [(d.line, d.rule) for d in ld.diagnostics if d.severity in ("warning", "error")]


def bottoms(recs):
    return [(r.line, round(r.end["X"], 3), round(r.end["Y"], 3), round(r.end["Z"], 3))
            for r in recs if r.kind == "linear"]


ABSOLUTE = ("G17 G21 G90 G54 G0 X0 Y0 Z50\nS1000 M3\nG16\nG99 G81 X100. Y30. Z-20. R-5. F200.\n"
            "Y150.\nG98 Y270.\nG15 G80\nG0 X0 Y0\nM30\n")
INCREMENTAL = ("G17 G21 G90 G54 G0 X0 Y0 Z0\nS1000 M3\nG16\nG81 X100. Y30. Z-20. R-5. F200.\n"
               "G91 Y120.\nY120.\nG90 G15 G80\nG0 X0 Y0\nM30\n")


def test_bolt_hole_circle_absolute():
    # radius 100 about the zero at 30, 150, 270 degrees: (100 cos 30, 100 sin 30) = (86.603, 50),
    # (-86.603, 50), (0, -100); Y150 alone keeps the radius: sqrt(86.603^2 + 50^2) = 100.
    # G99: back to R -5 between holes; G98 on the last: back to the initial level Z50
    recs, said = run(ABSOLUTE)
    assert said == []
    assert bottoms(recs) == [(4, 86.603, 50.0, -20.0), (5, -86.603, 50.0, -20.0), (6, 0.0, -100.0, -20.0)]
    assert [r.end["Z"] for r in recs if r.line == 6][-1] == 50.0
    # the tool moves to each hole at R (G99), not through the part
    assert [(r.line, round(r.end["Z"], 3)) for r in recs if r.kind == "rapid" and r.line in (5, 6)][0] == (5, -5.0)


def test_bolt_hole_circle_incremental_angle():
    # G91 Y120: the angle adds to the one last programmed (30 -> 150 -> 270), the radius stays 100;
    # under G91 R and Z are incremental too (ISO cycles): R = initial 0 - 5 = -5, Z = R - 20 = -25
    recs, said = run(INCREMENTAL)
    assert said == []
    assert bottoms(recs) == [(4, 86.603, 50.0, -20.0), (5, -86.603, 50.0, -25.0), (6, 0.0, -100.0, -25.0)]


def test_where_the_control_alarms_the_block_is_refused(monkeypatch):
    real = polar_input.option
    monkeypatch.setattr(polar_input, "option",
                        lambda d, k, default=None: "alarm" if k == "polar_cycle_positions" else real(d, k, default))
    recs, said = run(ABSOLUTE)
    assert (4, "NC117") in said
    assert not [r for r in recs if r.line == 4]


def test_bolt_hole_circle_converts_equivalent():
    for text in (ABSOLUTE, INCREMENTAL):
        for target in ("sinumerik", "fagor", "iso-m"):
            conv = nctrans.transpile(text, read="iso-m", write=target)
            assert conv.text is not None, (target, conv.diagnostics)
            assert nctrans.equiv(text, conv.text, read_a="iso-m", read_b=target), target


@settings(max_examples=25, deadline=None)
@given(hs.integers(5, 200), hs.integers(-360, 360), hs.lists(hs.integers(-180, 180), min_size=1, max_size=5))
def test_each_hole_lies_on_the_circle_at_its_angle(radius, start, steps):
    # the first hole at (radius, start), then G91 steps of the angle: hole k at start + sum of steps
    lines = ["G17 G21 G90 G0 X0 Y0 Z10", "G16", f"G99 G81 X{radius}. Y{start}. Z-3. R2. F100"]
    lines += [f"G91 Y{a}." for a in steps]
    recs, said = run("\n".join(lines + ["G90 G15 G80", "M30", ""]))
    assert said == []
    holes = bottoms(recs)
    assert len(holes) == 1 + len(steps)
    angle = start
    for k, (_, x, y, _) in enumerate(holes):
        if k:
            angle += steps[k - 1]
        assert math.isclose(x, radius * math.cos(math.radians(angle)), abs_tol=2e-3)
        assert math.isclose(y, radius * math.sin(math.radians(angle)), abs_tol=2e-3)
