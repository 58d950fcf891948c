"""NC138: a work position of X read under DIAMON ($AA_IW[X], $P_EP[X]). nctrans gives the radius;
the seeds do not say whether the control gives the diameter (seed L28087: "actual value in the
WCS"), so the read is said at its line [GK, not confirmed]. Values by hand."""
from __future__ import annotations

import nctrans
from nctrans import api

PROGRAM = "G18 G90 DIAMON\nG0 X40 Z5\nR1=$AA_IW[X]\nG0 X=R1+10\nDIAMOF\nR2=$P_EP[X]\nG0 X=R2+1\nM30\n"


def test_read_under_diamon_is_the_radius_and_said_at_its_line_only():
    ends = [r.end["X"] for r in nctrans.toolpath(PROGRAM, "sinumerik") if r.kind == "rapid"]
    # X40 (diameter) = radius 20; R1 = 20 (the radius), X=R1+10 = 30 diameter = radius 15; under
    # DIAMOF $P_EP[X] is 15, X=R2+1 = radius 16 (no diagnostic: a radius on every control)
    assert ends == [20.0, 15.0, 16.0]
    diags = [(d.line, d.severity) for d in api.lint(PROGRAM, "sinumerik") if d.rule == "NC138"]
    assert diags == [(3, "warning")]


def test_z_and_a_mill_without_diamon_are_not_said():
    text = "G18 G90 DIAMON\nG0 X40 Z5\nR1=$AA_IW[Z]\nM30\n"
    assert not [d for d in api.lint(text, "sinumerik") if d.rule == "NC138"]
    text = "G17 G90\nG0 X40 Y5\nR1=$AA_IW[X]\nG0 X=R1+1\nM30\n"
    assert not [d for d in api.lint(text, "sinumerik") if d.rule == "NC138"]


def test_g50_converted_to_sinumerik_reads_p_ep_under_diamof():
    # ISO-T G50 X100. (a diameter) becomes ATRANS X=$P_EP[X]-(100.)/2 between DIAMOF and DIAMON,
    # so the radius is read whatever the control does under DIAMON: no NC138, same toolpath
    src = "G50 X100. Z50.\nG0 X60. Z20.\nM30\n"
    out = api.transpile(src, "iso-t", "sinumerik").text
    lines = out.splitlines()
    i = lines.index("ATRANS X=$P_EP[X]-(100.)/2 Z=$P_EP[Z]-(50.)")
    assert lines[i - 1] == "DIAMOF" and lines[i + 1] == "DIAMON"
    assert not [d for d in api.lint(out, "sinumerik") if d.rule == "NC138"]
    assert api.equiv(src, out, read_a="iso-t", read_b="sinumerik")
