"""ISO programmable mirror, scaling and rotation (issue #8): G51.1/G50.1 are refused by the control
while G51 or G68 is on (ISO seed L1715-1718: program mirror, scaling, rotation in that order and
cancel in reverse), a G68 without X Y turns about the current position (seed L1453) and replaces no
other component, and Sinumerik frames that replace the whole frame are written to ISO with what may
be active cancelled first. Hand-computed points; conversions are checked with equiv."""
from __future__ import annotations

import subprocess
import sys

import pytest

import nctrans
from nctrans import pipeline
from nctrans.source import from_text


def run(text: str, dialect: str = "iso-m"):
    ld = pipeline.load_source(from_text(text, "t.nc"), "t.nc", dialect)
    recs = list(pipeline.toolpath_of(ld))
    return [(r.line, round(r.end["X"], 6), round(r.end["Y"], 6)) for r in recs if r.kind == "linear"], \
        sorted((d.line, d.rule) for d in ld.diagnostics if d.severity == "error")


HEAD = "G17 G90 G00 X0 Y0 Z5\n"


def test_mirror_under_rotation_or_scaling_is_an_error_at_its_line():
    _, errors = run(HEAD + "G68 X0 Y0 R30.\nG51.1 X0\nG01 X10. F100.\nG50.1 X0\nG69\nM30\n")
    assert errors == [(3, "NC215"), (5, "NC215")]
    _, errors = run(HEAD + "G51 X0 Y0 P2000\nG51.1 X0\nG01 X10. F100.\nG50\nG50.1 X0\nM30\n")
    assert errors == [(3, "NC215")]
    # in the seed's order: no error
    _, errors = run(HEAD + "G51.1 X0\nG51 X0 Y0 P2000\nG68 X0 Y0 R30.\nG01 X10. F100.\nG69\nG50\nG50.1 X0\nM30\n")
    assert errors == []


def test_lint_exits_1_at_the_mirror_line(tmp_path):
    p = tmp_path / "m.nc"
    p.write_text(HEAD + "G68 X0 Y0 R30.\nG51.1 X0\nG01 X10. F100.\nG69\nG50.1 X0\nM30\n")
    out = subprocess.run([sys.executable, "-m", "nctrans", "lint", str(p)], capture_output=True, text=True)
    assert out.returncode == 1 and "m.nc:3:1: error[NC215]" in out.stdout, out.stdout + out.stderr


def test_g68_without_a_centre_turns_about_the_current_position_and_keeps_the_mirror():
    # at (10, 0): G68 R90 about (10, 0): (10, 5) -> offset (0, 5) turned 90 -> (-5, 0) -> (5, 0).
    # Then G51.1 X0 and G51 P2 (about the work zero, seed L1625): (10, 5) scaled (20, 10), mirrored
    # (-20, 10); before, G51 without a centre dropped the mirror: (20, 10)
    moves, errors = run(HEAD + "G01 X10 Y0 F100\nG68 R90.\nG01 X10 Y5\nG69\nG51.1 X0\nG51 P2000\nG01 X10 Y5\n"
                        "G50\nG50.1 X0\nG01 X0 Y0\nM30\n")
    assert not errors
    assert moves == [(2, 10.0, 0.0), (4, 5.0, 0.0), (8, -20.0, 10.0), (11, 0.0, 0.0)]


SIN = {
    # ROT then MIRROR (which replaces the rotation): (10, 5) mirrored only: (-10, 5)
    "rot_then_mirror": "G17 G90 G0 X0 Y0 Z5\nROT RPL=30\nG1 X10 Y0 F100\nMIRROR X0\nG1 X10 Y5\nMIRROR\nG1 X0 Y0\nM30\n",
    # SCALE then MIRROR (which replaces the scale): (-10, 5)
    "scale_then_mirror": "G17 G90 G0 X0 Y0 Z5\nSCALE X2 Y2\nG1 X10 Y0 F100\nMIRROR X0\nG1 X10 Y5\nTRANS\nG1 X0 Y0\nM30\n",
    # ROT about the work zero after a move to (10, 0): (10, 5) -> (-5, 10)
    "rot_about_zero": "G17 G90 G0 X0 Y0 Z5\nG1 X10 Y0 F100\nROT RPL=90\nG1 X10 Y5\nROT\nG1 X0 Y0\nM30\n",
    # TRANS then ROT (which drops the shift): (10, 0) -> (0, 10)
    "trans_then_rot": "G17 G90 G0 X0 Y0 Z5\nTRANS X10\nG1 X0 Y0 F100\nROT RPL=90\nG1 X10 Y0\nROT\nG1 X0 Y0\nM30\n",
}


@pytest.mark.parametrize("name", sorted(SIN))
def test_replacing_sinumerik_frames_convert_to_iso_as_the_same_path_and_no_alarm(name):
    text = SIN[name]
    conv = nctrans.transpile(text, read="sinumerik", write="iso-m")
    assert conv.ok, conv.diagnostics
    assert nctrans.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m")
    ld = pipeline.load_source(from_text(conv.text, "o.nc"), "o.nc", "iso-m")
    list(pipeline.toolpath_of(ld))
    assert not [d for d in ld.diagnostics if d.rule == "NC215"], conv.text


def test_a_rotation_about_the_work_zero_is_written_with_its_centre():
    conv = nctrans.transpile(SIN["rot_about_zero"], read="sinumerik", write="iso-m")
    assert "G68 X0. Y0. R90." in conv.text
    moves, _ = run(conv.text)
    assert (round(moves[1][1], 6), round(moves[1][2], 6)) == (-5.0, 10.0)


ISO = {
    # G50.1 X0 cancels the mirror: (10, 5) stays (10, 5); written as MIRROR X0 it was mirrored
    "partial_mirror_cancel": HEAD + "G51.1 X0\nG1 X10 Y0 F100\nG50.1 X0\nG1 X10 Y5\nM30\n",
    "g68_current_point": HEAD + "G01 X10 Y0 F100\nG68 R90.\nG01 X10 Y5\nG69\nG01 X0 Y0\nM30\n",
    "g51_keeps_mirror": HEAD + "G51.1 X0\nG51 P2000\nG01 X10 Y5 F100\nG50\nG50.1 X0\nG01 X0 Y0\nM30\n",
}


@pytest.mark.parametrize("target", ["sinumerik", "fagor", "iso-m"])
@pytest.mark.parametrize("name", sorted(ISO))
def test_iso_mirror_rotation_and_scale_convert_to_the_same_path(name, target):
    text = ISO[name]
    conv = nctrans.transpile(text, read="iso-m", write=target)
    assert conv.ok, conv.diagnostics
    assert nctrans.equiv(text, conv.text, read_a="iso-m", read_b=target)
