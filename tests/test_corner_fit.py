"""Sinumerik roundings the control inserts in ways an ISO `,R` cannot say (issue #8), by hand:
- a G1 that moves nothing between the rounding's block and the next move is a block without motion
  in the plane (up to three may stand between, MD 20200 [GK]): the rounding goes to the next block
  that moves, and written to ISO (whose control alarms unless the very next block is a contour
  move that can carry it) the corner is lowered to the arc it inserts;
- a rounding too large for its blocks is shrunk by Siemens [GK] (nctrans: to the largest that
  fits, NC229), and an ISO control alarms at it: the conversion writes the shrunk size.
"""
from __future__ import annotations

import subprocess
import sys

import pytest

import nctrans
from nctrans import pipeline
from nctrans.source import from_text

HEAD = "G17 G90 G0 X0 Y0 Z0 F1000\n"


def run(text):
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind in ("linear", "arc")]
    return recs, sorted((d.line, d.rule) for d in ld.diagnostics if d.severity != "info")


def test_a_rounding_goes_past_a_g1_that_moves_nothing():
    # X line to (10, 0), Y line up: RND=2 at the 90 degree corner runs from (8, 0) to (10, 2)
    # about (8, 2), counter-clockwise; the G1 X10 between moves nothing: its block keeps its record
    # (a move of no length, line 3) where the tool stands then, after the arc, at (10, 2)
    recs, said = run(HEAD + "G1 X10 RND=2\nG1 X10\nY10\nM30\n")
    assert said == []
    assert [(r.line, r.kind, r.end["X"], r.end["Y"]) for r in recs] == [
        (2, "linear", 8.0, 0.0), (2, "arc", 10.0, 2.0), (3, "linear", 10.0, 2.0), (4, "linear", 10.0, 10.0)]
    assert recs[2].start == recs[2].end
    arc = recs[1]
    assert (arc.center["X"], arc.center["Y"], arc.direction) == (8.0, 2.0, "ccw")


def test_more_than_three_blocks_that_move_nothing_leave_the_corner_sharp():
    recs, said = run(HEAD + "G1 X10 RND=2\nX10\nX10\nX10\nX10\nY10\nM30\n")
    assert said == [(2, "NC217")]
    assert [(r.end["X"], r.end["Y"]) for r in recs][0] == (10.0, 0.0)
    assert not [r for r in recs if r.kind == "arc"]
    # three are allowed
    recs, said = run(HEAD + "G1 X10 RND=2\nX10\nM1\nX10\nY10\nM30\n")
    assert said == [] and [r for r in recs if r.kind == "arc"]


@pytest.mark.parametrize("target", ["iso-m", "iso-t"])
def test_across_a_block_that_moves_nothing_it_converts_as_the_arc(target):
    text = HEAD + "G1 X10 RND=2\nG1 X10\nY10\nM30\n"
    conv = nctrans.transpile(text, read="sinumerik", write=target)
    assert conv.ok and ",R" not in conv.text, conv.text
    assert nctrans.equiv(text, conv.text, read_a="sinumerik", read_b=target)


def test_a_fitting_rounding_keeps_its_iso_word():
    text = HEAD + "G1 X10 RND=2\nY10\nX0 RND=3\nY0\nM30\n"
    conv = nctrans.transpile(text, read="sinumerik", write="iso-m")
    assert conv.ok and ",R2." in conv.text and ",R3." in conv.text, conv.text
    assert nctrans.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m")


@pytest.mark.parametrize("target", ["iso-m", "iso-t"])
def test_a_rounding_too_large_is_written_at_the_size_the_control_shrinks_it_to(tmp_path, target):
    # lines of 10 and 5 mm at 90 degrees: a rounding of 20 needs 20 mm on each; Siemens shrinks it
    # [GK], nctrans to the largest that fits: 5 (NC229). An ISO control alarms at ,R20, so the
    # conversion writes ,R5 (exit 0: NC229 is a warning) and drives the same toolpath
    src = tmp_path / "p.mpf"
    text = HEAD + "G1 X10 RND=20\nY5\nM30\n"
    src.write_text(text)
    out = subprocess.run([sys.executable, "-m", "nctrans", "convert", str(src), "--to", target,
                          "-o", str(tmp_path / "o.nc")], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "p.mpf:2:1: info[NC401]" in out.stderr and "too large" in out.stderr
    written = (tmp_path / "o.nc").read_text()
    assert ",R5." in written and ",R20" not in written, written
    assert nctrans.equiv(text, written, read_a="sinumerik", read_b=target)


def test_a_shrunk_rounding_at_an_acute_corner_converts_equivalently():
    # (0, 0) -> (10, 0) -> (0, 10): the lines turn by 135 degrees; a rounding r needs
    # r / tan(22.5) on each, so the first line (10 mm) takes at most 10 tan(22.5) = 4.1421356:
    # 4.142 at the control's 0.001 mm. Then a rounding that fits (RND=1 at the next corner).
    text = HEAD + "G1 X10 RND=20\nX0 Y10 RND=1\nY20\nM30\n"
    conv = nctrans.transpile(text, read="sinumerik", write="iso-m")
    assert conv.ok and ",R4.142" in conv.text and ",R1." in conv.text, conv.text
    assert nctrans.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m")


# --------------------------------------------------------------------------- property: the shrink
# Two lines (0, 0) -> (L1, 0) -> that + L2 (cos t, sin t), turning by |t|. Worked out here on the
# lines alone: a rounding r touches each line r tan(|t| / 2) from the corner, a chamfer with legs
# L (CHR) is 2 L cos(|t| / 2) long (CHF); each fits while its legs are at most min(L1, L2). So the
# largest rounding is min / tan(|t| / 2), the largest CHR min, the largest CHF 2 min cos(|t| / 2).

from hypothesis import example, given, settings, strategies as st  # noqa: E402


@settings(max_examples=60, deadline=None)
@given(st.floats(0.5, 30), st.floats(0.5, 30),
       st.one_of(st.floats(10, 170), st.floats(-170, -10)), st.floats(0.1, 50),
       st.sampled_from(["RND", "CHR", "CHF"]))
@example(11.32421875, 11.320581602569785, 11.320581602569785, 11.320581602569785, "CHR")  # at the limit
def test_an_element_too_large_shrinks_to_the_largest_that_fits(l1, l2, turn, value, word):
    import math
    import re
    t = math.radians(turn)
    p2 = (l1 + l2 * math.cos(t), l2 * math.sin(t))
    text = HEAD + f"G1 X{l1:.6f} {word}={value:.6f}\nX{p2[0]:.6f} Y{p2[1]:.6f}\nM30\n"
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind in ("linear", "arc")]
    l1r, l2r = round(l1, 6), math.dist((round(l1, 6), 0), (round(p2[0], 6), round(p2[1], 6)))
    shortest, half = min(l1r, l2r), math.radians(abs(turn)) / 2
    largest = {"RND": shortest / math.tan(half), "CHR": shortest, "CHF": 2 * shortest * math.cos(half)}[word]
    said = [d for d in ld.diagnostics if d.rule == "NC229"]
    value = round(value, 6)
    # at the limit either reading is right: the fit takes a point within 1e-7 of a line's length
    # past its end as on it (corners.py), beside the 6 decimals the program is written with
    margin = 1e-6 + 2e-7 * max(l1r, l2r)
    if value <= largest - margin:
        assert not said
        return
    if value < largest + margin:
        return
    (d,) = said
    size = float(re.search(r"inserts it at (\S+) ", d.message).group(1))
    assert largest - 0.001 - 1e-6 <= size <= largest + 1e-5       # (the fit allows 1e-7 of a line)
    element = [r for r in recs if r.kind == "arc" or (r.kind == "linear" and r.line == 2)][-1]
    # the element starts on the first line and ends on the second
    assert -1e-6 <= element.start["X"] <= l1r + 1e-6 and abs(element.start["Y"]) < 1e-6
    ex, ey = element.end["X"] - round(l1, 6), element.end["Y"]
    assert abs(ex * math.sin(t) - ey * math.cos(t)) < 1e-5 and -1e-6 <= ex * math.cos(t) + ey * math.sin(t) <= l2r + 1e-6
    if word != "CHF":                               # ISO has ,R and ,C (legs); a CHF is written as its line
        conv = nctrans.transpile(text, read="sinumerik", write="iso-m")
        assert conv.ok, conv.diagnostics
        assert nctrans.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m")
