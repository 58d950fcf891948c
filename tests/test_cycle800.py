"""Sinumerik CYCLE800 (swivel plane) [GK]: front end lowering, frame semantics with hand-computed
machine positions, retract records, emitter round trip / iso-m fallback, the conformance program."""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from nctrans import equivalence as equiv
from nctrans.dialects.base import get
from nctrans.dialects.sinumerik.frontend import parse
from nctrans.interp import interpret
from nctrans.interp.cycles import swivel_axis_order, swivel_plan
from nctrans.ir import nodes as n
from nctrans.lower.flatten import flatten
from nctrans.machine import default_mill

REPO = Path(__file__).resolve().parents[1]
SWIVEL = REPO / "corpus" / "sinumerik" / "swivel.mpf"
HEAD = "G17 G90 G54 G0 X0 Y0 Z50\nT1 D1 M6\nS1000 M3\n"


def run(text: str, machine=None):
    res = parse(HEAD + text.strip() + "\n", "t.mpf")
    diags: list = list(res.diagnostics)
    recs = list(interpret(res.program, machine, diagnostics=diags))
    return recs, diags


def moves(recs, line=None):
    return [(r.kind, tuple(round(r.end[a], 4) for a in ("X", "Y", "Z"))) for r in recs
            if r.kind in ("rapid", "linear", "arc") and (line is None or r.line == line)]


def serious(diags):
    return [d.format_text() for d in diags if d.severity != "info"]


def test_front_end_lowers_to_a_swivel_cycle_node():
    prog = parse('CYCLE800(1,"TABLE",0,57,1,2,3,4,5,6,7,8,9,1,0)\n', "t.mpf").program
    calls = [s for b in prog.body for s in getattr(b, "body", []) if isinstance(s, n.CycleCall)]
    assert len(calls) == 1
    c = calls[0]
    assert (c.kind, c.name) == ("swivel_plane", "CYCLE800")
    assert c.params["swivel_record"] == n.Str("TABLE")
    assert {k: c.params[k].value for k in ("swivel_retract", "swivel_mode", "ref_x", "ref_z",
                                          "angle_1", "angle_3", "shift_x", "shift_z")} == \
        {"swivel_retract": 1, "swivel_mode": 57, "ref_x": 1, "ref_z": 3, "angle_1": 4,
         "angle_3": 6, "shift_x": 7, "shift_z": 9}


def test_mode_decoding():
    assert swivel_axis_order(57) == ["X", "Y", "Z"]
    assert swivel_axis_order(27) == ["Z", "Y", "X"]
    assert swivel_axis_order(0b100110) == ["Y", "X", "Y"]
    assert swivel_plan({"swivel_mode": 57 + 64}).mode == "projection"
    assert swivel_plan({"swivel_mode": 192}).mode == "direct"
    p = swivel_plan({"swivel_record": "T", "swivel_mode": 27, "angle_1": 90, "angle_3": 10})
    assert p.rotations == [("Z", 90.0), ("X", 10.0)] and not p.deselect
    assert swivel_plan({"swivel_record": "0"}).deselect
    assert not swivel_plan({"swivel_record": "0", "angle_2": 5}).deselect


def test_rotate_90_about_z():
    recs, diags = run('CYCLE800(0,"TABLE",0,57,0,0,0,0,0,90,0,0,0,1,0)\nG1 X10 Y0 F100')
    assert moves(recs)[-1] == ("linear", (0.0, 10.0, 50.0))
    # the rotary axes the control positions are not modelled: a warning at the call, nothing else
    assert [(d.rule, d.severity, d.line) for d in diags if d.severity != "info"] == [
        ("NC107", "warning", 4)]
    assert "swivel data record 'TABLE'" in diags[-1].message and "not modelled" in diags[-1].message
    # no rotary axis is moved
    assert all(set(r.end) <= {"X", "Y", "Z"} for r in recs if r.end)


def test_reference_point_and_zero_point_after_rotation():
    # TRANS X10 Y5 : AROT Z90 : ATRANS X2 -> program (x, y) at machine (10 - y, 5 + 2 + x)
    recs, _ = run('CYCLE800(0,"TABLE",0,57,10,5,0,0,0,90,2,0,0,1,0)\nG1 X0 Y0 F100\nG1 X5 Y3')
    assert [m[1] for m in moves(recs)[-2:]] == [(10.0, 7.0, 50.0), (7.0, 12.0, 50.0)]


def test_rotation_about_x_then_z_order():
    # _MODE 57: first X (_A=90), then Z (_C=90); AROT X90 : AROT Z90 -> p' = Rx(Rz(p))
    recs, _ = run('CYCLE800(0,"T",0,57,0,0,0,90,0,90,0,0,0,1,0)\nG1 X10 Y0 Z0 F100')
    # Rz90 (10,0,0) = (0,10,0); Rx90 (0,10,0) = (0,0,10)
    assert moves(recs)[-1][1] == (0.0, 0.0, 10.0)


def test_new_plane_replaces_and_additive_composes():
    recs, _ = run('TRANS X100\nCYCLE800(0,"T",0,57,0,0,0,0,0,90,0,0,0,1,0)\nG1 X10 Y0 F100')
    assert moves(recs)[-1][1] == (0.0, 10.0, 50.0)           # TRANS X100 is gone
    recs, _ = run('TRANS X100\nCYCLE800(0,"T",1,57,0,0,0,0,0,90,0,0,0,1,0)\nG1 X10 Y0 F100')
    assert moves(recs)[-1][1] == (100.0, 10.0, 50.0)         # composed on TRANS X100
    recs, _ = run('CYCLE800(0,"T",0,57,0,0,0,0,0,90,0,0,0,1,0)\n'
                  'CYCLE800(0,"T",1,57,0,0,0,0,0,90,0,0,0,1,0)\nG1 X10 Y0 F100')
    assert moves(recs)[-1][1] == (-10.0, 0.0, 50.0)          # 90 + 90
    c30 = 10 * math.cos(math.radians(30))
    recs, _ = run('CYCLE800(0,"T",0,57,0,0,0,0,0,90,0,0,0,1,0)\n'
                  'CYCLE800(0,"T",1,57,0,0,0,30,0,0,0,0,0,1,0)\nG1 X0 Y10 Z0 F100')
    assert moves(recs)[-1][1] == (round(-c30, 4), 0.0, 5.0)


def test_deselect_clears_the_rotation():
    for deselect in ('CYCLE800()', 'CYCLE800(0,"0",0,57,0,0,0,0,0,0,0,0,0,1,0)',
                     'CYCLE800(0,"",1,57,0,0,0,0,0,0,0,0,0,1,0)'):
        recs, diags = run('CYCLE800(0,"T",0,57,5,0,0,0,0,90,0,0,0,1,0)\n' + deselect + '\nG1 X10 Y0 F100')
        assert moves(recs)[-1][1] == (10.0, 0.0, 50.0), deselect
        # the swivel at line 4 warns (rotary axes not modelled); the deselect at line 5 does not
        assert [d.line for d in diags if d.severity != "info"] == [4], deselect


def test_retract_records():
    recs, _ = run('G0 X3 Y4 Z20\nCYCLE800(1,"T",0,57,0,0,0,0,0,0,0,0,0,1,0)')
    assert moves(recs, line=5) == [("rapid", (3.0, 4.0, 1000.0))]
    recs, _ = run('G0 X3 Y4 Z20\nCYCLE800(2,"T",0,57,0,0,0,0,0,0,0,0,0,1,0)')
    assert moves(recs, line=5) == [("rapid", (3.0, 4.0, 1000.0)), ("rapid", (1000.0, 1000.0, 1000.0))]
    recs, _ = run('G0 X3 Y4 Z20\nCYCLE800(5,"T",0,57,0,0,0,0,0,0,0,0,0,1,15)')
    assert moves(recs, line=5) == [("rapid", (3.0, 4.0, 35.0))]
    # the machine model's max travel, under a work offset (machine coordinates)
    m = default_mill().copy()
    m.axes["Z"].max = 400.0
    recs, _ = run('G0 X3 Y4 Z20\nCYCLE800(4,"T",0,57,0,0,0,0,0,90,0,0,0,1,0)\nG0 X0 Y0', m)
    assert moves(recs, line=5) == [("rapid", (3.0, 4.0, 400.0))]
    assert moves(recs, line=6) == [("rapid", (0.0, 0.0, 400.0))]
    recs, diags = run('CYCLE800(3,"T",0,57,0,0,0,0,0,0,0,0,0,1,0)')
    assert [d.rule for d in diags if d.severity == "error"] == ["NC105"]


def test_unsupported_mode_keeps_the_frame():
    recs, diags = run('TRANS X1\nCYCLE800(0,"T",0,121,0,0,0,0,0,90,0,0,0,1,0)\nG1 X10 Y0 F100')
    assert moves(recs)[-1][1] == (11.0, 0.0, 50.0)
    assert any(d.rule == "NC107" and "'projection'" in d.message for d in diags)
    assert not [d for d in diags if d.rule == "NC103"]


def test_sinumerik_round_trip_and_iso_fallback():
    text = SWIVEL.read_text()
    src = parse(text, "swivel.mpf").program
    out = get("sinumerik").emit(src)
    assert out.text is not None and "CYCLE800(1,\"TABLE\",0,57,0,0,0,0,0,90,0,0,0,1,0)" in out.text
    back = parse(out.text, "back.mpf").program
    a = list(interpret(src, diagnostics=[]))
    b = list(interpret(back, diagnostics=[]))
    assert equiv.compare(a, b) is None
    iso = get("iso-m").emit(src)
    assert any(d.rule == "NC402" and d.severity == "error" and "CYCLE800" in d.message for d in iso.diagnostics)


def test_conformance_program_lints_clean_and_flattens_equivalently():
    res = parse(SWIVEL.read_text(), str(SWIVEL))
    diags = list(res.diagnostics)
    recs = list(interpret(res.program, default_mill(), diagnostics=diags))
    bad = [d.format_text() for d in diags if d.rule[:3] in ("NC0", "NC1")
           and not (d.rule == "NC107" and "swivel data record" in d.message)]
    assert not bad, bad
    assert sum(1 for d in diags if d.rule == "NC107") == 4
    fdiags: list = []
    flat = flatten(res.program, default_mill(), diagnostics=fdiags)
    got = list(interpret(flat, default_mill(), diagnostics=[]))
    assert equiv.compare(recs, got) is None
    # the flattened program has no cycle call left: the path carries the rotated coordinates
    iso = get("iso-m").emit(flat)
    assert iso.text is not None and "CYCLE800" not in iso.text
    back = get("iso-m").parse(iso.text, "swivel.nc").program
    assert equiv.compare(recs, list(interpret(back, default_mill(), diagnostics=[]))) is None
