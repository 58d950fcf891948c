"""Sinumerik polar words and poles (nctrans/interp/polar_words.py): the stored polar angle and
radius (seed L13315-13317; [GK] Siemens Fundamentals), RP=IC(..) and a pole given with IC(..)
refused at their line (NC118). Every expected point is by hand."""
from __future__ import annotations

import pytest

import nctrans
from nctrans import pipeline
from nctrans.source import from_text


def run(text: str, dialect: str = "sinumerik"):
    ld = pipeline.load_source(from_text(text, "p.mpf"), "p.mpf", dialect)
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear", "arc")]
    return ([(r.line, round(r.end["X"], 6), round(r.end["Y"], 6)) for r in recs],
            [(d.line, d.rule) for d in ld.diagnostics if d.severity in ("warning", "error")])


STORED = "G17 G90 G0 X0 Y0 Z5\nG111 X0 Y0\nG1 AP=0 RP=10 F100\nG1 X20\nG1 AP=90\nAP=IC(90)\nM30\n"


def test_a_left_out_radius_is_the_one_programmed_not_the_distance_of_the_tool():
    # AP=0 RP=10 -> (10, 0); X20 (Cartesian) -> (20, 0), the stored radius stays 10; AP=90 ->
    # (0, 10), not (0, 20); AP=IC(90) adds to the programmed 90: 180 -> (-10, 0)
    got, said = run(STORED)
    assert said == []
    assert got[-4:] == [(3, 10.0, 0.0), (4, 20.0, 0.0), (5, 0.0, 10.0), (6, -10.0, 0.0)]


@pytest.mark.parametrize("target", ["iso-m", "fagor", "iso-t", "sinumerik"])
def test_stored_polar_words_convert_equivalent(target):
    conv = nctrans.transpile(STORED, read="sinumerik", write=target)
    assert conv.ok, conv.diagnostics
    assert nctrans.equiv(STORED, conv.text, read_a="sinumerik", read_b=target), conv.text


def test_a_left_out_word_after_a_new_pole_is_refused():
    # the radius must be written again after G111 ([GK]); the tool at (10, 0) is 10 from the new
    # pole (0, 0) but the control does not read it from there: line 3 moves nothing (NC118);
    # line 4 gives both words: radius 5 at 90 deg about (0, 0) -> (0, 5)
    got, said = run("G17 G90 G0 X10 Y0\nG111 X0 Y0\nG1 AP=90 F100\nG1 AP=90 RP=5\nM30\n")
    assert (3, "NC118") in said
    assert got == [(1, 10.0, 0.0), (4, 0.0, 5.0)]


def test_a_plane_change_sets_the_polar_words_to_zero():
    # seed L13317: after G18 the stored radius is 0: G17 AP=0 RP=10 -> (10, 0); back from G18 to
    # G17 a block with AP=90 only goes to radius 0 about the pole (0, 0): (0, 0)
    got, said = run("G17 G90 G0 X0 Y0\nG111 X0 Y0\nG0 AP=0 RP=10\nG18\nG17\nG0 AP=90\nM30\n")
    assert said == [] and got[-2:] == [(3, 10.0, 0.0), (6, 0.0, 0.0)]


def test_incremental_radius_is_refused_at_its_line():
    # RP=IC(5): the polar radius is an absolute value; line 4 moves nothing, line 5 goes on with
    # the stored radius 10 at 180 deg about (10, 10) -> (0, 10)
    text = "G17 G90 G0 X0 Y0\nG111 X10 Y10\nG1 AP=0 RP=10 F100\nG1 RP=IC(5)\nG1 AP=180\nM30\n"
    got, said = run(text)
    assert said == [(4, "NC118")]
    assert got[-2:] == [(3, 20.0, 10.0), (5, 0.0, 10.0)]
    conv = nctrans.transpile(text, read="sinumerik", write="iso-m")
    assert conv.text is None and any(d.rule == "NC402" and d.line == 4 for d in conv.diagnostics)


def test_a_pole_given_with_ic_is_refused_and_so_are_moves_about_it():
    # G112 AP=IC(90) RP=10: no reference for the angle; line 4 moves nothing, line 5 sets a pole
    # again (G111 X5 Y5) and line 6 is radius 5 at 0 deg about it: (10, 5)
    text = "G17 G90 G0 X0 Y0\nG111 X0 Y0\nG112 AP=IC(90) RP=10\nG0 AP=0 RP=1\nG111 X5 Y5\nG0 AP=0 RP=5\nM30\n"
    got, said = run(text)
    assert said == [(3, "NC118"), (4, "NC118")]
    assert got[-1] == (6, 10.0, 5.0) and [g[0] for g in got] == [1, 6]


def test_a_pole_in_polar_words_about_the_zero():
    # G111 AP=90 RP=10: the pole is 10 at 90 deg about the zero, (0, 10); AP=0 RP=5 -> (5, 10);
    # G112 AP=180 RP=5 moves the pole 5 along -X from (0, 10): (-5, 10); AP=270 RP=2 -> (-5, 8)
    got, said = run("G17 G90 G0 X0 Y0\nG111 AP=90 RP=10\nG0 AP=0 RP=5\nG112 AP=180 RP=5\n"
                    "G0 AP=270 RP=2\nM30\n")
    assert said == [] and got[-2:] == [(3, 5.0, 10.0), (5, -5.0, 8.0)]


FAGOR = "%PROGRAM\nG17 G90 G00 X0 Y0 Z5\nG01 R10 Q0 F100\nG91 R5\nQ90\nG90 X20 Y0\nQ180\nM30\n"


def test_fagor_incremental_polar_words_add_to_the_current_point():
    # 8065 manual L3222-3232: under G91 R and Q are increments. R10 Q0 -> (10, 0); G91 R5 -> radius
    # 15 at 0 deg (15, 0); Q90 -> radius 15 at 90 deg (0, 15); G90 X20 Y0 (Cartesian) -> (20, 0);
    # Q180 alone: the current point's radius, 20 (Fagor reads the point, not a stored value) -> (-20, 0)
    got, said = run(FAGOR, "fagor")
    assert said == []
    assert got[-5:] == [(3, 10.0, 0.0), (4, 15.0, 0.0), (5, 0.0, 15.0), (6, 20.0, 0.0), (7, -20.0, 0.0)]


def test_fagor_pole_goes_back_to_the_zero_at_a_plane_change():
    # L3244-3247: G30 I10 J10, R5 Q0 -> (15, 10); after G18 and back to G17 the polar origin is the
    # work zero: R5 Q0 -> (5, 0)
    got, said = run("%PROGRAM\nG17 G90 G00 X0 Y0\nG30 I10 J10\nG01 R5 Q0 F100\nG18\nG17\nR5 Q0\nM30\n", "fagor")
    assert said == [] and got[-2:] == [(4, 15.0, 10.0), (7, 5.0, 0.0)]


# a plane change after the pole: Fagor's polar origin goes back to the zero, Sinumerik keeps G111's
FAGOR_PLANE = "%PROGRAM\nG17 G90 G00 X0 Y0\nG30 I10 J10\nG01 R5 Q0 F100\nG18\nG17\nR5 Q0\nR5 Q90\nM30\n"
SIN_PLANE = "G17 G90 G0 X0 Y0\nG111 X10 Y10\nG1 AP=0 RP=5 F100\nG18\nG17\nAP=0 RP=5\nAP=90 RP=5\nM30\n"


@pytest.mark.parametrize("source, text, target", [
    ("fagor", FAGOR, "sinumerik"), ("fagor", FAGOR, "iso-m"), ("sinumerik", STORED, "fagor"),
    ("fagor", FAGOR_PLANE, "sinumerik"), ("sinumerik", SIN_PLANE, "fagor")])
def test_polar_words_between_controls_that_read_them_differently(source, text, target):
    # Sinumerik keeps the programmed radius, Fagor reads the point's, Fagor's G91 R/Q are
    # increments, and Fagor's pole goes back to the zero at a plane change (FAGOR_PLANE: line 7 is
    # (5, 0) on Fagor, (15, 10) about a kept pole; SIN_PLANE: (15, 10) and (10, 15) on Sinumerik):
    # written where both controls read the same point, lowered (NC401) elsewhere
    conv = nctrans.transpile(text, read=source, write=target)
    assert conv.ok, conv.diagnostics
    assert nctrans.equiv(text, conv.text, read_a=source, read_b=target), conv.text
