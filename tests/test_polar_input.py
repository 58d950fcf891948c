"""ISO G15/G16 polar coordinate input (ISO seed L3707-3747, nctrans/interp/polar_input.py): the
plane's first axis word is the radius, the second the angle. Every expected point is by hand."""
from __future__ import annotations

import math

import pytest
from hypothesis import given, settings, strategies as hs

import nctrans
from nctrans import pipeline
from nctrans.source import from_text

TARGETS = ("sinumerik", "fagor", "iso-t", "iso-m")


def run(text: str, dialect: str = "iso-m"):
    ld = pipeline.load_source(from_text(text, "t.nc"), "t.nc", dialect)
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear", "arc")]
    return recs, [(d.line, d.rule) for d in ld.diagnostics if d.severity in ("warning", "error")]


def ends(recs, axes=("X", "Y")):
    return [(r.line,) + tuple(round(r.end[a], 3) for a in axes) for r in recs]


SEED = "G17 G90 X0 Y0\nG16 X100. Y45.\nG91 X100 Y0\nG90 Y90.\nG15\nM30\n"


def test_the_seed_example():
    # seed L3736-3744: N10 radius 100 at 45 deg about the zero: 100 * cos 45 = 70.711 (both axes);
    # N15 G91: pole = current position (70.711, 70.711), radius 100 at 0 deg -> (170.711, 70.711);
    # N20 G90 with no X: pole = zero, radius = sqrt(170.711^2 + 70.711^2) = sqrt(29142.3 + 5000.0)
    # = 184.776, at 90 deg -> (0, 184.776)
    recs, said = run(SEED)
    assert said == []
    assert ends(recs) == [(1, 0.0, 0.0), (2, 70.711, 70.711), (3, 170.711, 70.711), (4, 0.0, 184.776)]


@pytest.mark.parametrize("target", TARGETS)
def test_the_seed_example_converts_equivalent(target):
    conv = nctrans.transpile(SEED, read="iso-m", write=target)
    assert conv.ok, conv.diagnostics
    assert nctrans.equiv(SEED, conv.text, read_a="iso-m", read_b=target), conv.text
    if target != "iso-m":       # written as the Cartesian points, never X100 Y45 read as a point
        assert "Y45" not in conv.text and "70.710678" in conv.text, conv.text


def test_a_word_left_out_keeps_its_polar_value_and_other_axes_stay_cartesian():
    # G90 X10 Y30 -> (10 cos 30, 10 sin 30) = (8.660, 5.000); X20 alone keeps the angle 30:
    # (17.321, 10.000); Y90 Z-5 keeps the radius 20: (0, 20) and Z goes to -5 (not polar)
    text = "G17 G90 G0 X0 Y0 Z0\nG16\nG1 X10 Y30 F100\nX20\nY90 Z-5\nG15\nX5 Y5\nM30\n"
    recs, said = run(text)
    assert said == []
    assert ends(recs, "XYZ") == [(1, 0.0, 0.0, 0.0), (3, 8.66, 5.0, 0.0), (4, 17.321, 10.0, 0.0),
                                 (5, 0.0, 20.0, -5.0), (7, 5.0, 5.0, -5.0)]


def test_inch_scales_the_radius_not_the_angle():
    # G20: radius 1 in = 25.4 mm at 90 deg -> (0, 25.4); read as a length the angle would be 2286
    recs, said = run("G20 G17 G90 G0 X0 Y0\nG16 X1. Y90.\nG15\nM30\n")
    assert said == [] and ends(recs)[-1] == (2, 0.0, 25.4)


def test_other_planes():
    # G18: Z is the radius, X the angle: 10 at 90 deg from Z toward X -> Z 0, X 10;
    # G19: Y is the radius, Z the angle: 10 at 30 deg -> Y 8.660, Z 5
    recs, said = run("G90 G0 X0 Y0 Z0\nG18 G16 Z10. X90.\nG15\nG19 G16 Y10. Z30.\nG15\nM30\n")
    assert said == []
    assert ends(recs, "XYZ")[1:] == [(2, 10.0, 0.0, 0.0), (4, 10.0, 8.66, 5.0)]


def test_incremental_pole_is_the_current_position():
    # from (10, 0): G91 X5 Y90 -> pole (10, 0), radius 5 at 90 deg -> (10, 5); then G91 X5 Y180
    # -> pole (10, 5) -> (5, 5)
    recs, said = run("G17 G90 G0 X10 Y0\nG16\nG91 X5 Y90\nX5 Y180\nG90 G15\nM30\n")
    assert said == [] and ends(recs)[1:] == [(3, 10.0, 5.0), (4, 5.0, 5.0)]


def test_incremental_angle_alone_turns_about_the_zero():
    # the bolt circle: no radius word, so the pole is the workpiece zero (seed N20's comment) and
    # the radius the current distance, 10; G91 Y30 adds 30 deg to the angle 0 programmed last (the
    # current point's too): (10 cos 30, 10 sin 30) = (8.660, 5); again: 60 deg (5, 8.660)
    recs, said = run("G17 G90 G0 X0 Y0\nG16 X10. Y0.\nG91 Y30.\nY30.\nG90 G15\nM30\n")
    assert said == []
    assert ends(recs)[1:] == [(2, 10.0, 0.0), (3, 8.66, 5.0), (4, 5.0, 8.66)]


@pytest.mark.parametrize("text, line", [
    # G91 radius, no angle: no angle about the new pole
    ("G17 G90 G0 X0 Y0\nG16 X10. Y0.\nG91 X5.\nG90 G15\nM30\n", 3),
    # after a move about the current point (10, 0) -> (10, 5): its angle about the zero (26.57 deg)
    # is not the 90 deg programmed last: which one G91 Y30 adds to, the seed does not say
    ("G17 G90 G0 X0 Y0\nG16 X10. Y0.\nG91 X5. Y90.\nY30.\nG90 G15\nM30\n", 4),
    # the first polar block: no angle programmed yet
    ("G17 G90 G0 X10 Y0\nG16\nG91 Y30.\nG90 G15\nM30\n", 3),
    # a Cartesian move since the last polar angle: X keeps (10, 0)'s angle 0 or the point (0, 10)'s?
    ("G17 G90 G0 X0 Y0\nG16 X10. Y0.\nG15\nX0 Y10.\nG16\nX5.\nG15\nM30\n", 6),
])
def test_a_kept_or_added_angle_the_seed_leaves_open_is_refused(text, line):
    recs, said = run(text)
    assert said == [(line, "NC117")]
    assert line not in [r.line for r in recs]


@pytest.mark.parametrize("block", [
    "G2 X10. Y90. R10.",                # a circle with polar words
    "G81 X10. Y90. Z-5. R2. F100 K3",   # a repeated cycle position (one K=1 position is modelled)
    "G92 X0 Y0",                        # a dimension word that is no motion
    "G53 X0 Y0",
])
def test_what_the_seed_leaves_open_is_refused_at_its_line(block):
    text = f"G17 G90 G0 X0 Y0 Z5\nG16 X10. Y0.\n{block}\nG15\nG80\nM30\n"
    recs, said = run(text)
    assert (3, "NC117") in said
    # the refused block moves nothing: the last point is still (10, 0) from line 2
    assert ends(recs)[-1] == (2, 10.0, 0.0)
    # converted: the stretch from G16 (line 2) is refused there, saying why (NC402 with the NC117
    # text), or refused in place (the Sinumerik output alarms at line 2)
    for target in ("sinumerik", "fagor", "iso-t"):
        conv = nctrans.transpile(text, read="iso-m", write=target)
        located = [d for d in conv.diagnostics if d.line == 2 and d.rule in ("NC402", "NC412")]
        assert located, (target, conv.diagnostics)
        if conv.text is None:
            assert any("polar coordinate input" in d.message for d in located)
        else:
            assert 'SETAL(65002, "NOT CONVERTED: SOURCE LINE 2")' in conv.text


@settings(max_examples=12, deadline=None)
@given(hs.lists(hs.tuples(hs.booleans(), hs.integers(1, 60), hs.integers(-360, 360)), min_size=1, max_size=4))
def test_polar_stretches_convert_equivalent(steps):
    lines = ["G17 G90 G0 X0 Y0 Z5", "G16"]
    for inc, r, a in steps:
        lines.append(f"{'G91' if inc else 'G90'} G1 X{r}. Y{a}. F200")
    text = "\n".join(lines + ["G90 G15", "G0 X0 Y0", "M30", ""])
    recs, said = run(text)
    assert said == []
    # every polar end point lies at its radius from its pole (the zero, or the previous point)
    prev = (0.0, 0.0)
    for (inc, r, _), rec in zip(steps, recs[1:]):
        pole = prev if inc else (0.0, 0.0)
        assert math.isclose(math.hypot(rec.end["X"] - pole[0], rec.end["Y"] - pole[1]), r, abs_tol=1e-6)
        prev = (rec.end["X"], rec.end["Y"])
    for target in ("sinumerik", "fagor"):
        conv = nctrans.transpile(text, read="iso-m", write=target)
        assert conv.ok and nctrans.equiv(text, conv.text, read_a="iso-m", read_b=target), conv.text
