"""The DIN 76 thread undercut rows (rules/cycles.toml [undercut] din76, din76_internal) against a
public table: the HEIDENHAIN MANUALplus 620 user's manual 12/2017, 10.2 "Undercut parameters"
(manualshive.com, page 685; the same rows in the CNC PILOT 4290 manual 11.1.1). Expected values
typed from that table, not from the rules data: external I (d - dg), K (g2 of the normal form A),
R; internal I (dg - d), K (g2 of form C), R; W 30 degrees for both. The short forms B/D are not in
it ([GK])."""
from __future__ import annotations

import pytest

from nctrans.interp.undercuts import din76, din76_internal
from test_controls_undercuts import TAN30, _approx, _run

# pitch: (I, K, R) for the metric coarse pitches CYCLE96 reaches (M3..M48)
EXTERNAL = {0.5: (0.8, 1.75, 0.2), 0.7: (1.1, 2.45, 0.4), 0.8: (1.3, 2.8, 0.4), 1.0: (1.6, 3.5, 0.6),
            1.25: (2.0, 4.4, 0.6), 1.5: (2.3, 5.2, 0.8), 1.75: (2.6, 6.1, 1.0), 2.0: (3.0, 7.0, 1.0),
            2.5: (3.6, 8.7, 1.2), 3.0: (4.4, 10.5, 1.6), 3.5: (5.0, 12.0, 1.6), 4.0: (5.7, 14.0, 2.0),
            4.5: (6.4, 16.0, 2.0), 5.0: (7.0, 17.5, 2.5)}
INTERNAL = {0.5: (0.3, 2.7, 0.2), 0.7: (0.3, 3.8, 0.4), 0.8: (0.3, 4.2, 0.4), 1.0: (0.5, 5.2, 0.6),
            1.25: (0.5, 6.7, 0.6), 1.5: (0.5, 7.8, 0.8), 1.75: (0.5, 9.1, 1.0), 2.0: (0.5, 10.3, 1.0),
            2.5: (0.5, 13.0, 1.2), 3.0: (0.5, 15.2, 1.6), 3.5: (0.5, 17.7, 1.6), 4.0: (0.5, 20.0, 2.0),
            4.5: (0.5, 23.0, 2.0), 5.0: (0.5, 26.0, 2.5)}


@pytest.mark.parametrize("pitch", sorted(EXTERNAL))
def test_external_form_a_rows_match_the_published_table(pitch):
    i, k, r = EXTERNAL[pitch]
    cut = din76(pitch, "A")
    assert (cut.depth * 2, cut.width, cut.radius, cut.run_out) == pytest.approx((i, k, r, 30.0))


@pytest.mark.parametrize("pitch", sorted(INTERNAL))
def test_internal_form_c_rows_match_the_published_table(pitch):
    i, k, r = INTERNAL[pitch]
    d = 20.0
    cut, core = din76_internal(pitch, "C", d)
    # depth from the core hole (radius `core`) to dg / 2 = (d + I) / 2: the manual's (N + I - K) / 2
    assert (core + cut.depth) * 2 - d == pytest.approx(i)
    assert (cut.width, cut.radius, cut.run_out) == pytest.approx((k, r, 30.0))


def test_m42_form_a_rounds_the_face_with_radius_2_by_hand():
    # M42: coarse pitch 4.5; dg = 42 - 6.4 (t 3.2), g2 16, r 2 (the table; was 2.5). VARI 3, shoulder
    # at Z-40: start X22 Z-23 (1 out, 1 beyond g2); onto the thread X21 Z-24; run-out 3.2 / tan 30 =
    # 5.542563 to X17.8 Z-29.542563; base to Z-38 (r from the face); the radius to X19.8 Z-40; up the
    # face to X21, off to X22; G0 back.
    # (the tool starts at X40 Z5, inside the M42's radius 21: the approach crossing it is NC418)
    got, diags, _ = _run('CYCLE96(42, -40, "A", 3)')
    assert [d.rule for d in diags if d.severity != "info"] == ["NC418"]
    assert got == _approx([("rapid", 22, -23), ("linear", 21, -24), ("linear", 17.8, -24 - 3.2 / TAN30),
                           ("linear", 17.8, -38), ("arc", 19.8, -40), ("linear", 21, -40),
                           ("linear", 22, -40), ("rapid", 22, -23)])


def test_cycle96_in_inch_takes_the_metric_size_of_its_inch_diameter():
    # G700: DIATH 0.944882 inch = 24.0000 mm (M24, pitch 3) and SPL -1.181102 inch = -30 mm: the
    # same outline as the mm M24 form A (test_controls_undercuts), to 1e-5 mm (the inch rounding);
    # the 1 mm clearance stays 1 mm ([NC], as the model's other built-in distances)
    from nctrans import pipeline
    from nctrans.source import from_text
    from test_controls_undercuts import _lathe
    text = ("G18 G90 G700 DIAMON T1 D1\nS800 M3 G95 F0.004\nG0 X2 Z0.2\n"
            'CYCLE96(0.944882, -1.181102, "A", 3)\nG0 X3\nM30\n')
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    got = [(r.kind, r.end["X"], r.end["Z"]) for r in pipeline.toolpath_of(ld, _lathe())
           if r.line == 4 and r.kind in ("rapid", "linear", "arc")]
    want = [("rapid", 13, -18.5), ("linear", 12, -19.5), ("linear", 9.8, -19.5 - 2.2 / TAN30),
            ("linear", 9.8, -28.4), ("arc", 11.4, -30), ("linear", 12, -30), ("linear", 13, -30),
            ("rapid", 13, -18.5)]
    assert [k for k, *_ in got] == [k for k, *_ in want]
    for (_, x, z), (_, wx, wz) in zip(got, want):
        assert x == pytest.approx(wx, abs=1e-4) and z == pytest.approx(wz, abs=1e-4)
