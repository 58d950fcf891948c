"""Sinumerik CYCLE72, contour milling along a contour subprogram (issue 8,
nctrans/interp/contour_milling.py): hand-computed paths, refusals, a property over random
rectangles, conversion to ISO. Expected values are worked out by hand from the module docstring
(facts [GK] of the Siemens milling cycles manual, choices [NC])."""
from __future__ import annotations

import math

import pytest
from hypothesis import given, settings, strategies as st

from nctrans import api, pipeline
from nctrans.interp.contour_milling import plan72
from nctrans.interp.milling_cycles import MillingError
from nctrans.machine import Machine, Tool
from nctrans.source import from_text

CONTOUR = "ANF: G1 X10 Y10\nX50\nY30\nENDE: X10\n"
MACHINE = Machine(name="t", tools=[Tool(number=1, radius=3.0, length=0.0)])   # the cycle path, not the tool length (tests of D length: test_system_data_writes)


def _text(call: str, contour: str = CONTOUR) -> str:
    return f"G17 G90 G54 T1 D1 M6\nS2000 M3 F500\nG0 X0 Y0 Z20\n{call}\nG0 Z50\nM30\n{contour}"


def _run(call: str, contour: str = CONTOUR, machine=MACHINE):
    ld = pipeline.load_source(from_text(_text(call, contour), "t.mpf"), "t.mpf", "sinumerik")
    out = []
    for r in pipeline.toolpath_of(ld, machine):
        if r.kind in ("rapid", "linear", "arc") and r.line == 4:
            e = tuple(round(r.end[a], 6) for a in "XYZ")
            out.append((r.kind, e, r.feed if r.kind != "rapid" else None)
                       + ((tuple(round(r.center[a], 6) for a in "XY"), r.direction) if r.kind == "arc" else ()))
    return out, ld.diagnostics


def test_left_of_the_contour_quarter_circles_two_cuts_by_hand():
    # tool radius 3 left of (10,10) (50,10) (50,30) (10,30): y 13, the concave corner (47,13), x 47,
    # y 27, to x 10. Quarter circle LP1 5 in: centre (10,18), from (5,18); out: centre (10,22) to
    # (5,22). MID 3: cuts at Z-3 and Z-6; VARI 111: rough, G1 FF3 between cuts, back to RFP+SDIS.
    got, diags = _run('CYCLE72("ANF:ENDE", 10, 0, 2, -6, 3, 0, 0, 300, 100, 111, 41, 2, 5, 400, 2, 5)')
    assert not [d for d in diags if d.severity != "info"]

    def cut(z):
        return [("linear", (5, 18, z), 100), ("arc", (10, 13, z), 300, (10, 18), "ccw"),
                ("linear", (47, 13, z), 300), ("linear", (47, 27, z), 300), ("linear", (10, 27, z), 300),
                ("arc", (5, 22, z), 300, (10, 22), "ccw"), ("rapid", (5, 22, 2), None)]
    # the cycle ends at RTP 10 (module docstring: "at the end G0 to RTP"; it used to stop at 2)
    want = [("rapid", (5, 18, 20), None), ("rapid", (5, 18, 2), None)] + cut(-3) + \
        [("linear", (5, 18, 2), 400)] + cut(-6) + [("rapid", (5, 22, 10), None)]
    assert got == want


@pytest.mark.parametrize("vari, last", [(301, -5.5), (201, -3.5), (101, 2)])
def test_the_cycle_ends_at_rtp_whatever_the_retraction_between_passes(vari, last):
    # RL 40, AS 1 LP 4 out to (6,30); one cut at -6 + FALD 0.5 = -5.5; the retraction after the pass:
    # hundreds 3 none (-5.5), 2 by SDIS 2 (-3.5), 1 to RFP+SDIS (2); then G0 to RTP 10
    got, diags = _run(f'CYCLE72("ANF:ENDE", 10, 0, 2, -6, 0, 0, 0.5, 300, 100, {vari}, 40, 1, 4, , 1, 4)')
    assert not [d for d in diags if d.severity != "info"]
    tail = [("rapid", (6, 30, last), None)] if last != -5.5 else []
    assert got[-len(tail) - 2:] == [("linear", (6, 30, -5.5), 300)] + tail + [("rapid", (6, 30, 10), None)]


def test_on_the_contour_straight_approach_and_retract_to_rtp_by_hand():
    # RL 40: the centre on the contour; AS 1 straight tangential LP 4: in from (6,10), out to (6,30);
    # one cut (MID 0) to DP-6 less FALD 0.5 (roughing); VARI 1: G0 between, RTP at the end.
    got, _ = _run('CYCLE72("ANF:ENDE", 10, 0, 2, -6, 0, 0, 0.5, 300, 100, 1, 40, 1, 4, , 1, 4)')
    assert got == [("rapid", (6, 10, 20), None), ("rapid", (6, 10, 2), None),
                   ("linear", (6, 10, -5.5), 100), ("linear", (10, 10, -5.5), 300),
                   ("linear", (50, 10, -5.5), 300), ("linear", (50, 30, -5.5), 300),
                   ("linear", (10, 30, -5.5), 300), ("linear", (6, 30, -5.5), 300),
                   ("rapid", (6, 30, 10), None)]


@pytest.mark.parametrize("call, rule", [
    ('CYCLE72("ANF:ENDE", 10, 0, 2, -6, 3, 0, 0, 300, 100, 1, 41, 11, 5, , 1, 5)', "NC224"),
    ('CYCLE72("ANF:ENDE", 10, 0, 2, -6, 3, 0, 0, 300, 100, 1, 40, 2, 5, , 1, 5)', "NC224"),
    ('CYCLE72("ANF:ENDE", 10, 0, 2, -6, 3, 0.5, 0, 300, 100, 1, 40, 1, 5, , 1, 5)', "NC224"),
    ('CYCLE72("ANF:ENDE", 10, 0, 2, -6, 3, 0, 0, 300, 100, 5, 41, 1, 5, , 1, 5)', "NC225"),
    ('CYCLE72("ANF:ENDE", 10, 0, 2, -6, 3, 0, 0, 300, 100, 1, 43, 1, 5, , 1, 5)', "NC225"),
    ('CYCLE72("NOPE", 10, 0, 2, -6, 3, 0, 0, 300, 100, 1, 41, 1, 5, , 1, 5)', "NC225"),
])
def test_what_is_not_modelled_or_alarms_moves_nothing(call, rule):
    got, diags = _run(call)
    assert got == [] and [d.rule for d in diags if d.line == 4 and d.severity != "info"] == [rule]


def test_without_a_tool_radius_it_moves_nothing():
    got, diags = _run('CYCLE72("ANF:ENDE", 10, 0, 2, -6, 3, 0, 0, 300, 100, 1, 41, 1, 5, , 1, 5)', machine=None)
    assert got == [] and [d.rule for d in diags if d.line == 4] == ["NC224"]


def _distance_to_rect(q, x0, y0, x1, y1) -> float:
    """Distance from q to the boundary of the rectangle, negative inside."""
    dx, dy = max(x0 - q[0], 0, q[0] - x1), max(y0 - q[1], 0, q[1] - y1)
    if dx or dy:
        return math.hypot(dx, dy)
    return -min(q[0] - x0, x1 - q[0], q[1] - y0, y1 - q[1])


@settings(max_examples=60, deadline=None)
@given(st.floats(10, 60), st.floats(10, 60), st.floats(0.5, 5), st.floats(0, 1),
       st.sampled_from([1, 2, 3]), st.floats(1, 8), st.floats(0.5, 4))
def test_outside_a_rectangle_the_tool_keeps_radius_and_allowance(w, h, radius, fal, how, lp, mid):
    # a closed rectangle run counterclockwise, milled on its right (outside): every cutting point
    # stays at least radius + FAL from the part and the contour pass runs exactly at that distance
    pts = [(0, 0), (w, 0), (w, h), (0, h), (0, 0)]
    moves = [("linear", q, None, None) for q in pts[1:]]
    p = dict(RTP=10, RFP=0, SDIS=2, DP=-5, MID=mid, FAL=fal, FFP1=300, FFD=100, VARI=1, RL=42,
             AS1=how, LP1=lp, AS2=how, LP2=lp)
    steps = plan72(pts[0], moves, p, radius, (-20.0, -20.0, 20.0), 500)
    at = (-20.0, -20.0, 20.0)
    on_contour = 0
    for s in steps:
        if s[0] == "feed":
            continue
        if s[1][2] < 0:                                       # below the top: cutting
            d = _distance_to_rect(s[1], 0, 0, w, h)
            assert d >= radius + fal - 1e-6, (s, d)
            on_contour += abs(d - radius - fal) < 1e-6
        at = s[1]
    cuts = math.ceil(5 / mid - 1e-9)
    assert on_contour >= 4 * cuts and at[2] == 10                 # ends at RTP (VARI hundreds 0)
    assert min(s[1][2] for s in steps if s[0] != "feed") == pytest.approx(-5)


def test_converted_to_iso_is_lowered_and_equivalent():
    text = _text('CYCLE72("ANF:ENDE", 10, 0, 2, -6, 3, 0, 0, 300, 100, 111, 41, 2, 5, 400, 2, 5)')
    conv = api.transpile(text, "sinumerik", "iso-m", machine=MACHINE)
    assert conv.text is not None and "CYCLE72" not in conv.text
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m", machine=MACHINE)
    again = api.transpile(text, "sinumerik", "sinumerik", machine=MACHINE)
    assert "CYCLE72(" in again.text
    assert api.equiv(text, again.text, read_a="sinumerik", read_b="sinumerik", machine=MACHINE)


def test_any_values_plan_or_refuse():
    moves = [("linear", q, None, None) for q in ((10, 0), (10, 10))]
    for bad in (dict(DP=float("nan")), dict(VARI=7), dict(AS1=2, LP1=0), dict(RL=41, FAL=1e9)):
        with pytest.raises(MillingError):
            plan72((0, 0), moves, dict(dict(RTP=10, RFP=0, DP=-5, VARI=1, RL=41), **bad), 2.0, (0, 0, 20), 100)
