"""Sinumerik roundings the control inserts in ways an ISO `,R` cannot say (issue #8), by hand:
- a G1 that moves nothing between the rounding's block and the next move is a block without motion
  in the plane (up to three may stand between, MD 20200 [GK]): the rounding goes to the next block
  that moves, and written to ISO (whose control alarms unless the very next block is a contour
  move that can carry it) the corner is lowered to the arc it inserts;
- a rounding too large for its blocks is shrunk by Siemens, which nctrans does not model, and an
  ISO control alarms at it: the conversion refuses it at its line (exit 1), never `,R20` and 0.
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
    # about (8, 2), counter-clockwise; the G1 X10 between moves nothing
    recs, said = run(HEAD + "G1 X10 RND=2\nG1 X10\nY10\nM30\n")
    assert said == []
    assert [(r.kind, r.end["X"], r.end["Y"]) for r in recs] == [
        ("linear", 8.0, 0.0), ("arc", 10.0, 2.0), ("linear", 10.0, 10.0)]
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
def test_a_rounding_too_large_is_refused_at_its_line(tmp_path, target):
    # lines of 10 and 5 mm at 90 degrees: a rounding of 20 needs 20 mm on each; Siemens shrinks it
    src = tmp_path / "p.mpf"
    src.write_text(HEAD + "G1 X10 RND=20\nY5\nM30\n")
    out = subprocess.run([sys.executable, "-m", "nctrans", "convert", str(src), "--to", target,
                          "-o", str(tmp_path / "o.nc")], capture_output=True, text=True, timeout=120)
    assert out.returncode == 1, out.stderr
    assert "p.mpf:2:1: error[NC402]" in out.stderr and "shrinks" in out.stderr
    assert not (tmp_path / "o.nc").exists()
