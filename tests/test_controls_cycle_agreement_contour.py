"""Sinumerik CYCLE95 (stock removal) and CYCLE72 (contour milling): the built-in models
(nctrans/interp/stock_removal.py, contour_milling.py) against cycle code run by nctrans (issue 8,
"Done when"), move for move, over hand-picked and generated parameter sets and contours.

The PROCs (tests/data/cycle-procs/CYCLE95.SPF, CYCLE72.SPF and their helpers) read the contour as
the real cycles do, through the contour tables of seed 14.2/14.3 (CONTPRON in both directions for
CYCLE95, CONTDCON for CYCLE72; nctrans/interp/contour_tables.py), and follow the models'
documented [GK] facts and [NC] choices: they check the arithmetic and the interpreter, not those
choices; the offset paths (CYCLE72 RL 41/42, CYCLE95 FAL) by a helper of their own (CYC72OFS:
convex corners rounded, concave ones cut at the intersection, lines and arcs). Not covered:
contours given as labels of the calling program ("ANF:END"), what the models refuse (undercuts,
DT/DAM, a spatial approach)."""
from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from nctrans import pipeline

import cycle_agreement
from cycle_agreement import num, procs


def records_with(contour: str, plane: tuple[str, str], machine=None):
    """A records function for cycle_agreement: the program beside its contour subprogram KONT,
    run with `machine` (None: the dialect's default machine)."""
    def records(where: Path, text: str):
        (where / "KONT.SPF").write_text(contour)
        path = where / "MAIN.MPF"
        path.write_text(text)
        ld = pipeline.load(str(path), "sinumerik")
        recs = list(pipeline.toolpath_of(ld, machine))
        bad = [d.format_text() for d in ld.diagnostics if d.severity in ("error", "warning")]
        out, at = [], None
        for r in recs:
            if r.kind in ("rapid", "linear", "arc"):
                end = tuple(r.end.get(a, 0.0) for a in ("X", "Y", "Z"))
                if r.kind != "arc" and at is not None and max(abs(p - q) for p, q in zip(end, at)) < 1e-7:
                    continue
                at = end
                arc = (tuple(r.center.get(a, 0.0) for a in plane), r.direction) if r.kind == "arc" else None
                out.append((r.kind, end, r.feed if r.kind != "rapid" else None, arc))
        return out, bad
    return records


# ------------------------------------------------------------------------------------ CYCLE95

PROCS95 = ("CYCLE95", "CYC95ON", "CYC95MV", "CYC72OFS", "CYC72TG", "CYC72X")
TURN = "G18 G90 {units} {diam} T1 D0\nS800 M3 G95 F0.3\nG0 X{x} Z{z}\n"
AFTER = "G0 X{x} Z30\nM30\n"
MODES95 = [("", False), ("", True), ("G70", False), ("G700", True)]


def turn_program(call: str, units: str, diamon: bool, x: float = 60, z: float = 10) -> str:
    scale = 2 if diamon else 1
    return (TURN.format(units=units, diam="DIAMON" if diamon else "", x=x * scale, z=z) + call + "\n"
            + AFTER.format(x=70 * scale))


def contour95(points: list, diamon: bool, arcs: dict | None = None) -> str:
    """The contour subprogram: G1 to each (x radius, z); arcs {index: "G2 .. CR=r"} replace a
    line by an arc (its words given as radius, doubled here under DIAMON)."""
    lines = []
    for i, (x, z) in enumerate(points):
        xs = x * (2 if diamon else 1)
        if arcs and i in arcs:
            g, cr = arcs[i]
            lines.append(f"{g} X{xs:g} Z{z:g} CR={cr:g}")
        else:
            lines.append(f"G1 X{xs:g} Z{z:g}")
    return "\n".join(lines) + "\nRET\n"


CONTOURS95 = {
    # outside longitudinal, written from the deep end: shoulder, taper, shoulder
    "steps": ([(10, 2), (10, -10), (15, -15), (20, -15), (20, -25), (24, -25)], None),
    # the same written from the top down (the model and the PROC turn it round)
    "steps-reversed": ([(24, -25), (20, -25), (20, -15), (15, -15), (10, -10), (10, 2)], None),
    # a quarter circle into the shoulder (RND-free: an arc block), then a chamfer-like taper
    "arc": ([(8, 2), (8, -6), (14, -12), (18, -12), (20, -14)], {2: ("G3", 6)}),
    "arc-cw": ([(8, 2), (8, -6), (14, -12), (20, -12)], {2: ("G2", 6)}),
}
CALLS95 = {
    "complete": 'CYCLE95("KONT", 2, 0.25, 0.5, 0, 0.3, 0.1, 0.1, 9, , , 1)',
    "rough": 'CYCLE95("KONT", 1.5, 0.2, 0.4, 0, 0.25, 0.1, 0.12, 1, , , 0.5)',
    "finish": 'CYCLE95("KONT", 2, 0, 0, 0, 0.3, 0.1, 0.08, 5)',
    "complete-default-vrt": 'CYCLE95("KONT", 3, 0, 0.3, 0, 0.3, 0.1, 0.1, 9)',
    "rough-fal": 'CYCLE95("KONT", 2, 0.1, 0.2, 0.4, 0.3, 0.1, 0.1, 1, , , 1)',
}


@pytest.mark.parametrize("units, diamon", MODES95)
@pytest.mark.parametrize("contour", sorted(CONTOURS95))
@pytest.mark.parametrize("call", sorted(CALLS95))
def test_cycle95_model_agrees_with_cycle_code(tmp_path, call, contour, units, diamon):
    pts, arcs = CONTOURS95[contour]
    want = cycle_agreement.agree(tmp_path, turn_program(CALLS95[call], units, diamon),
                                 procs(*PROCS95),
                                 records_with(contour95(pts, diamon, arcs), ("X", "Z")))
    assert sum(m[0] == "linear" for m in want) >= 3


FORMS95 = {
    # VARI form (VARI-1) % 4 -> contour points (x radius, z) written from the deep end
    0: [(10, 2), (10, -10), (15, -15), (20, -15), (20, -25), (24, -25)],      # longitudinal outside
    2: [(24, 2), (24, -10), (18, -14), (14, -14), (14, -25), (10, -25)],      # longitudinal inside
    1: [(30, -8), (20, -8), (16, -4), (10, -4), (10, 0), (4, 0)],             # face outside
    3: [(30, -8), (20, -8), (16, -4), (10, -4), (10, 0), (4, 0)],             # face inside (the model: as outside [NC])
}


@pytest.mark.parametrize("units, diamon", MODES95)
@pytest.mark.parametrize("form", sorted(FORMS95))
@pytest.mark.parametrize("what", [0, 1, 2])
def test_cycle95_forms_agree(tmp_path, form, what, units, diamon):
    vari = 4 * what + form + 1
    call = f'CYCLE95("KONT", 1.75, 0.2, 0.3, 0.25, 0.3, 0.1, 0.1, {vari}, , , 0.5)'
    want = cycle_agreement.agree(tmp_path, turn_program(call, units, diamon, x=70, z=12),
                                 procs(*PROCS95),
                                 records_with(contour95(list(reversed(FORMS95[form])) if what == 1 else FORMS95[form],
                                                        diamon), ("X", "Z")))
    assert sum(m[0] == "linear" for m in want) >= 3


@st.composite
def cycle95_programs(draw):
    """A monotonic contour of the VARI's form (steps across, along, tapers), written either way
    round, the allowances, MID, _VRT, VARI, DIAMON and the units."""
    vari = draw(st.integers(1, 12))
    form = (vari - 1) % 4
    steps = draw(st.lists(st.tuples(st.sampled_from(["d", "p", "taper"]), st.sampled_from([1, 2.5, 4, 7])),
                          min_size=1, max_size=5))
    d, p = 0.0, 2.0
    rel = [(d, p)]
    for kind, v in steps:
        d, p = (d + v, p) if kind == "d" else (d, p - v) if kind == "p" else (d + v / 2, p - v)
        rel.append((d, p))
    if form == 0:
        pts = [(5 + a, b) for a, b in rel]
    elif form == 2:
        pts = [(40 - a, b) for a, b in rel]
    else:
        pts = [(30 + b, -20 + a) for a, b in rel]              # face: Z rises from the deep end
    if draw(st.booleans()):
        pts.reverse()
    units, diamon = draw(st.sampled_from(MODES95))
    args = [draw(st.sampled_from([0.7, 1.5, 3])), draw(st.sampled_from([None, 0, 0.2])),
            draw(st.sampled_from([None, 0, 0.4])), draw(st.sampled_from([0, 0.2])), 0.3, 0.1, 0.12, vari,
            None, None,
            draw(st.sampled_from([None, 0, 0.5, 2]))]
    while args and args[-1] is None:
        args.pop()
    call = 'CYCLE95("KONT", ' + ", ".join(num(a) for a in args) + ")"
    return turn_program(call, units, diamon, x=80, z=15), contour95(pts, diamon)


@settings(max_examples=20, deadline=None, suppress_health_check=list(HealthCheck))
@given(cycle95_programs())
def test_cycle95_agrees_over_parameter_sets(tmp_path_factory, program):
    text, contour = program
    cycle_agreement.agree(tmp_path_factory.mktemp("t"), text, procs(*PROCS95),
                          records_with(contour, ("X", "Z")))


# ------------------------------------------------------------------------------------ CYCLE72

MILL = "G17 G90 G54 {units} T1 D1 M6\nS2000 M3 F500\nG0 X0 Y0 Z20\n"
PROCS72 = ("CYCLE72", "CYC72MV", "CYC72TG", "CYC72LD", "CYC72OFS", "CYC72X", "CYCLEVEL", "CYCAPPR")


def mill_records(contour: str):
    """Records of a milling program with tool 1 (radius 3) in the machine model."""
    from nctrans.machine import Machine, Tool
    machine = Machine(name="t", tools=[Tool(number=1, radius=3.0, length=0.0)])
    return records_with(contour, ("X", "Y"), machine)


CONTOURS72 = {
    # an open rectangle (left of it: one concave corner per turn; right: convex, rounded)
    "rectangle": "G1 X10 Y10\nX50\nY30\nX10\nRET\n",
    # a line into a tangent arc and out of it along a line: no corner at either end
    "tangent-arc": "G1 X10 Y10\nX30\nG3 X40 Y20 CR=10\nG1 Y40\nRET\n",
    # an arc between two corners (line -> arc and arc -> line corners, concave on one side)
    "arc-corners": "G1 X0 Y10\nX20\nG2 X40 Y10 CR=10\nG1 X40 Y-10\nRET\n",
    # two arcs meeting at a right turn (up, then right): convex on the left, concave on the right
    "arc-arc": "G1 X0 Y0\nG3 X20 Y0 CR=10\nG3 X30 Y10 CR=10\nRET\n",
}
CALLS72 = {
    "left-quarter": 'CYCLE72("KONT", 10, 0, 2, -6, 3, 0, 0, 300, 100, 111, 41, 2, 5, 400, 2, 5)',
    "right-semi-finish": 'CYCLE72("KONT", 10, 0, 2, -4, 2.5, 0.5, 0.3, 250, 80, 2, 42, 3, 4, , 3, 4)',
    "right-line-rough": 'CYCLE72("KONT", 10, 0, 2, -5, 2, 0.5, 0.5, 300, 100, 201, 42, 1, 6, , 1, 3)',
    "left-line-none": 'CYCLE72("KONT", 5, 1, 1, -3, 0, 0, 0, 300, , 301, 41, 1, 4, , 2, 4)',
    "on-contour": 'CYCLE72("KONT", 10, 0, 2, -6, 4, 0, 0.5, 300, 100, 11, 40, 1, 4, 350, 1, 4)',
}


@pytest.mark.parametrize("units", ["", "G70"])
@pytest.mark.parametrize("contour", sorted(CONTOURS72))
@pytest.mark.parametrize("call", sorted(CALLS72))
def test_cycle72_model_agrees_with_cycle_code(tmp_path, call, contour, units):
    text = MILL.format(units=units) + CALLS72[call] + "\nG0 Z50\nM30\n"
    want = cycle_agreement.agree(tmp_path, text, procs(*PROCS72), mill_records(CONTOURS72[contour]))
    assert sum(m[0] in ("linear", "arc") for m in want) >= 4


@st.composite
def cycle72_programs(draw):
    """A contour of lines turning by 45 or 90 degrees either way (sides of 10 mm or more, so the
    offset of at most 3 + 1 mm never swallows a side), and a CYCLE72 call over its parameters."""
    heading, x, y = draw(st.sampled_from([0, 90, 180, 270])), 0.0, 0.0
    lines = ["G1 X0 Y0"]
    for k in range(draw(st.integers(2, 5))):
        if k:
            heading += draw(st.sampled_from([-90, -45, 45, 90]))
        length = draw(st.sampled_from([10, 15, 25]))
        x += length * round(math.cos(math.radians(heading)), 12)
        y += length * round(math.sin(math.radians(heading)), 12)
        lines.append(f"X{x:.6f} Y{y:.6f}")
    rl = draw(st.sampled_from([40, 41, 42]))
    vari = draw(st.sampled_from([1, 2])) + 10 * draw(st.integers(0, 1)) + 100 * draw(st.integers(0, 3))
    as1 = 1 if rl == 40 else draw(st.sampled_from([1, 2, 3]))
    as2 = 1 if rl == 40 else draw(st.sampled_from([1, 2, 3]))
    fal = 0 if rl == 40 else draw(st.sampled_from([None, 0, 0.5, 1]))
    args = [10, 0, 2, draw(st.sampled_from([-2, -5, -8])), draw(st.sampled_from([None, 0, 2, 3.5])), fal,
            draw(st.sampled_from([None, 0, 0.3])), 300, draw(st.sampled_from([None, 100])), vari, rl, as1,
            draw(st.sampled_from([2, 4, 6])), draw(st.sampled_from([None, 400])), as2, draw(st.sampled_from([2, 5]))]
    call = 'CYCLE72("KONT", ' + ", ".join(num(a) for a in args) + ")"
    units = draw(st.sampled_from(["", "G70"]))
    return MILL.format(units=units) + call + "\nG0 Z50\nM30\n", "\n".join(lines) + "\nRET\n"


@settings(max_examples=20, deadline=None, suppress_health_check=list(HealthCheck))
@given(cycle72_programs())
def test_cycle72_agrees_over_parameter_sets(tmp_path_factory, program):
    text, contour = program
    cycle_agreement.agree(tmp_path_factory.mktemp("t"), text, procs(*PROCS72), mill_records(contour))
