"""Sinumerik turning cycles CYCLE97/CYCLE98 (threads), CYCLE94/CYCLE96 (undercuts) and CYCLE93
(grooving, sharp base corners): the built-in models (nctrans.interp.milling_cycles, .undercuts,
.grooving) against cycle code run by nctrans (issue 8, "Done when"), move for move, with each thread
cut's lead (pitch) and start angle (SF), arcs with their centre and direction, over hand-picked and
generated parameter sets. Written for DIAMOF (X a radius); the PROCs do not read
DIAMON ($P_GG of its group is not modelled).

The seeds do not document CYCLE97; tests/data/cycle-procs/CYCLE97.SPF is written in the Sinumerik
language from what rules/cycles.toml ([[milling]] CYCLE97, [milling_param], [metric_coarse_pitch])
and the model's docstring state ([GK] Siemens cycles manual, [NC] choices): G33 cuts with K, SF for
each start, the metric coarse pitch table as SET arrays, $AA_IW[X] for where the tool stands.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from nctrans import pipeline

import cycle_agreement
from cycle_agreement import assert_same, both_runs, close, procs

START = "G18 G90 T1 D1\nS500 M3\nG0 X{x} Z10\n"
# the same under DIAMON: X programmed as a diameter; each PROC turns DIAMOF for itself and SAVE
# restores DIAMON at its end (seed L4386), which the move after the call (X40: radius 20) shows
START_DIAMON = "G18 G90 DIAMON T1 D1\nS500 M3\nG0 X{x2} Z10\n"
AFTER = "G0 X40 Z30\n"


def start(x: float, diamon: bool, units: str = "") -> str:
    """The program's head; `units` G70 or G700 (inch lengths; the PROCs turn their own mm distances,
    the 1 mm clearances and the DIN and ISO tables, into inch, as the models read them in mm)."""
    text = START_DIAMON.format(x2=2 * x) if diamon else START.format(x=x)
    return text.replace("G18 G90", f"G18 G90 {units}") if units else text


MODES = [("", False), ("", True), ("G70", False), ("G700", True)]


def records(where: Path, text: str):
    path = where / "MAIN.MPF"
    path.write_text(text)
    ld = pipeline.load(str(path), "sinumerik")
    recs = list(pipeline.toolpath_of(ld))
    bad = [d.format_text() for d in ld.diagnostics if d.severity in ("error", "warning")]
    out, at = [], None
    for r in recs:
        if r.kind in ("rapid", "linear", "arc"):
            end = (r.end["X"], r.end["Z"])
            if r.kind != "arc" and at is not None and max(abs(p - q) for p, q in zip(end, at)) < 1e-7:
                continue
            at = end
            arc = ((r.center["X"], r.center["Z"]), r.direction) if r.kind == "arc" else None
            out.append((r.kind, end, r.feed, r.pitch, getattr(r, "thread_start", None) if r.pitch else None, arc))
    return out, bad


def agree(tmp_path: Path, text: str):
    return cycle_agreement.agree(tmp_path, text, procs("CYCLE97"), records)


CALLS = {
    "external": "CYCLE97(2, , 0, -20, 20, 20, 4, 2, 1.2, 0.2, 0, 0, 2, 1, 1, 1)",
    "internal-section-flank": "CYCLE97(2, , 0, -20, 20, 20, 4, 2, 1.2, 0.2, 30, 0, 4, 0, 4, 1)",
    "metric-taper": "CYCLE97(, 10, 0, -20, 20, 18, 0, 0, 0.9, 0, 0, 0, 1, 0, 1, 1)",
    "alternating-flanks-three-starts": "CYCLE97(1.5, , -5, -30, 24, 24, 3, 1, 0.9, 0.1, -29, 45, 3, 1, 3, 3, 0.5)",
    "towards-plus-z": "CYCLE97(1, , -30, -10, 16, 16, 2, 2, 0.6, 0, 0, 0, 2, 0, 2, 1)",
}


@pytest.mark.parametrize("units, diamon", MODES)
@pytest.mark.parametrize("name", sorted(CALLS))
def test_cycle97_model_agrees_with_cycle_code(tmp_path, name, units, diamon):
    want = agree(tmp_path, start(30, diamon, units) + CALLS[name] + "\n" + AFTER + "M30\n")
    # the move after the call, X40 Z30: a diameter under DIAMON (radius 20), in inch x 25.4
    inch = 25.4 if units else 1.0
    assert want[-1][1] == pytest.approx((20.0 * inch if diamon else 40.0 * inch, 30.0 * inch))
    assert sum(m[3] is not None for m in want) >= 1


@st.composite
def cycle97_calls(draw):
    """CYCLE97 parameter sets: lead or metric size, the thread's direction along Z, straight or
    tapered, run-in/out, depth and allowance, flank infeed (one or alternating), cuts and idle
    passes, the four VARI, starts and start angle, _VRT; the tool outside or inside the thread."""
    metric = draw(st.booleans())
    size = draw(st.sampled_from([6, 10, 16, 24, 36]))
    pit = None if metric else draw(st.sampled_from([0.75, 1, 1.5, 2, 3]))
    spl = draw(st.integers(-10, 0))
    fpl = spl + draw(st.sampled_from([-25, -12, 12]))
    dm1 = draw(st.sampled_from([12, 20, 30]))
    dm2 = draw(st.sampled_from([None, 0, dm1, dm1 - 2, dm1 + 1]))
    tdep = draw(st.sampled_from([0.5, 0.9, 1.6]))
    fal = draw(st.sampled_from([None, 0, 0.1]))
    args = [pit, size if metric else draw(st.sampled_from([None, 0])), spl, fpl, dm1, dm2,
            draw(st.sampled_from([None, 0, 2, 5])), draw(st.sampled_from([None, 0, 1.5])), tdep, fal,
            draw(st.sampled_from([None, 0, 30, -29])), draw(st.sampled_from([None, 0, 90, 300])),
            draw(st.integers(1, 5)), draw(st.sampled_from([None, 0, 1, 2])), draw(st.sampled_from([1, 2, 3, 4])),
            draw(st.sampled_from([None, 0, 1, 2, 4])), draw(st.sampled_from([None, 0, 0.5, 2]))]
    while args and args[-1] is None:
        args.pop()
    call = "CYCLE97(" + ", ".join("" if a is None else f"{a:g}" for a in args) + ")"
    return start(draw(st.sampled_from([2, 30])), draw(st.booleans())) + call + "\n" + AFTER + "M30\n"


@settings(max_examples=50, deadline=None, suppress_health_check=list(HealthCheck))
@given(cycle97_calls())
def test_cycle97_model_agrees_over_parameter_sets(tmp_path_factory, text):
    agree(tmp_path_factory.mktemp("t"), text)


# -------------------------------------------------------------------------------------------------
# CYCLE94 / CYCLE96 undercuts: one pass along the undercut's outline (nctrans.interp.undercuts);
# the PROCs hold the DIN 509 / DIN 76 / ISO 261 rows as SET arrays and take FORM as a STRING

def agree_undercut(tmp_path: Path, text: str, cycle: str):
    (want, bad_builtin), (got, bad_code) = both_runs(tmp_path, text, procs(cycle, "CYCUNDC"), records)
    # a G0 to the clearance point from the part's side of the surface undercut (an inside undercut
    # started outside the bore, an outside one inside the diameter) runs through the part: the
    # model says where (NC418); the PROC runs the same G0, which nctrans cannot tell from any G0 a
    # program writes. Here: CYCLE96 surfaces are all inside the start radius (DIATH <= 48, start
    # radius 40 or 60), so only its internal forms cross; CYCLE94's surface is SPD (a radius under
    # DIAMOF, a diameter under DIAMON)
    crossing = [b for b in bad_builtin if "[NC418]" in b]
    m = re.search(r"(CYCLE9[46])\(([\d.]+),[^)]*,\s*(\d+)\)", text)
    inside = int(m.group(3)) in (1, 2)
    diamon = "DIAMON" in text
    start = float(re.search(r"G0 X([\d.]+)", text).group(1)) / (2 if diamon else 1)
    if m.group(1) == "CYCLE96":
        crosses = inside
    else:
        surface = float(m.group(2)) / (2 if diamon else 1)
        crosses = start > surface if inside else start < surface
    assert bool(crossing) == crosses, (text, crossing)
    assert [b for b in bad_builtin if b not in crossing] == [] and bad_code == [], (bad_builtin, bad_code)
    assert len(got) == len(want) and all(close(g, w) for g, w in zip(got, want)), (got, want)
    return want


UNDERCUTS = {
    "94-E-outside": ('CYCLE94(20, 60, "E", 3)', "CYCLE94"),
    "94-F-outside-plus-z": ('CYCLE94(12, -10, "F", 4)', "CYCLE94"),
    "94-F-inside-large": ('CYCLE94(45, 30, "F", 2)', "CYCLE94"),
    "96-A": ('CYCLE96(20, -30, "A", 3)', "CYCLE96"),
    "96-B-plus-z": ('CYCLE96(12, 5, "B", 4)', "CYCLE96"),
    "96-C-inside": ('CYCLE96(30, -20, "C", 2)', "CYCLE96"),
    "96-D-inside-plus-z": ('CYCLE96(8, 0, "D", 1)', "CYCLE96"),
}


@pytest.mark.parametrize("units, diamon", MODES)
@pytest.mark.parametrize("name", sorted(UNDERCUTS))
def test_undercut_models_agree_with_cycle_code(tmp_path, name, units, diamon):
    call, cycle = UNDERCUTS[name]
    if units and cycle == "CYCLE96":
        pytest.skip("DIATH in inch names no metric thread exactly (M20 is 0.7874.. inch)")
    head = f"G18 G90 {units} DIAMON T1 D1\nS500 M3 F0.2 G95\nG0 X80 Z80\n" if diamon else \
        f"G18 G90 {units} T1 D1\nS500 M3 F0.2 G95\nG0 X40 Z80\n"
    want = agree_undercut(tmp_path, head + call + "\n" + AFTER + "M30\n", cycle)
    assert sum(m[0] == "linear" for m in want) >= 4 and sum(m[0] == "arc" for m in want) == 1


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.sampled_from(["CYCLE94", "CYCLE96"]), st.integers(1, 4), st.integers(-40, 40),
       st.sampled_from([1, 2.5, 6, 9, 16, 45, 80]), st.sampled_from([6, 8, 10, 16, 20, 24, 30, 36, 42, 48]),
       st.sampled_from("EFABCD"), st.booleans())
def test_undercut_models_agree_over_parameter_sets(tmp_path_factory, cycle, vari, spl, spd, diath, form, diamon):
    if cycle == "CYCLE94":
        call = f'CYCLE94({spd:g}, {spl}, "{"E" if form in "EAC" else "F"}", {vari})'
    else:              # forms A/B outside (VARI 3, 4), C/D inside (1, 2)
        call = f'CYCLE96({diath}, {spl}, "{("AB" if vari > 2 else "CD")[form in "FBD"]}", {vari})'
    head = f"G18 G90 {'DIAMON ' if diamon else ''}T1 D1\nS500 M3 F100\nG0 X{120 if diamon else 60} Z50\n"
    agree_undercut(tmp_path_factory.mktemp("u"), head + call + "\n" + AFTER + "M30\n", cycle)


# -------------------------------------------------------------------------------------------------
# CYCLE98 chained threads: CYCLE97's passes through up to three sections with their own leads

def agree_chain(tmp_path: Path, text: str):
    return cycle_agreement.agree(tmp_path, text, procs("CYCLE98"), records)


CHAINS = {
    "three-leads": "CYCLE98(0, 20, -10, 20, -20, 22, -30, 22, 3, 2, 1.2, 0.2, 0, 0, 2, 1, 1.5, 2, 2.5, 1, 1)",
    "internal-flanks-two-starts": ("CYCLE98(0, 30, -8, 29, -16, 29, -24, 30, 2, 0, 0.9, 0, -29, 30, 3, 0, 1, 1, 1,"
                                   " 4, 2, 0.5)"),
    "towards-plus-z": "CYCLE98(-30, 16, -20, 16, -10, 18, 0, 18, 0, 2, 0.6, 0.1, 30, 0, 2, 1, 1, 1.25, 1.5, 3, 1)",
}


@pytest.mark.parametrize("units, diamon", MODES)
@pytest.mark.parametrize("name", sorted(CHAINS))
def test_cycle98_model_agrees_with_cycle_code(tmp_path, name, units, diamon):
    want = agree_chain(tmp_path, start(30, diamon, units) + CHAINS[name] + "\n" + AFTER + "M30\n")
    assert sum(m[3] is not None for m in want) >= 3        # thread cuts carrying their lead


@settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.data())
def test_cycle98_model_agrees_over_parameter_sets(tmp_path_factory, data):
    draw = data.draw
    sp = draw(st.sampled_from([1, -1]))
    z = [draw(st.integers(-5, 5))]
    for _ in range(3):
        z.append(z[-1] - sp * draw(st.integers(4, 12)))
    d0 = draw(st.sampled_from([16, 24, 30]))
    dms = [d0 + draw(st.sampled_from([0, 0, 1, -1, 2])) for _ in range(4)]
    args = [z[0], dms[0], z[1], dms[1], z[2], dms[2], z[3], dms[3], draw(st.sampled_from([0, 2, 4])),
            draw(st.sampled_from([0, 1.5])), draw(st.sampled_from([0.6, 1.1])), draw(st.sampled_from([0, 0.1])),
            draw(st.sampled_from([0, 30, -29])), draw(st.sampled_from([0, 90])), draw(st.integers(1, 4)),
            draw(st.integers(0, 2))] + [draw(st.sampled_from([1, 1.5, 2])) for _ in range(3)] + \
        [draw(st.sampled_from([1, 2, 3, 4])), draw(st.sampled_from([0, 1, 3])), draw(st.sampled_from([0, 0.5]))]
    call = "CYCLE98(" + ", ".join(f"{a:g}" for a in args) + ")"
    agree_chain(tmp_path_factory.mktemp("c"), start(draw(st.sampled_from([2, 30])), draw(st.booleans())) + call
                + "\n" + AFTER + "M30\n")


# -------------------------------------------------------------------------------------------------
# CYCLE93 grooving in a straight contour, outer corners RCO rounded or chamfered by the PROC's own
# RND/CHF/CHR blocks (the interpreter's corner elements), base corners RCI 0: the tool's width comes
# from the machine model (a tool's `width`) for the built-in model, from R90 for the PROC (the
# control's cycle reads it from the two edges' offsets, which nctrans' machine model does not hold)

def agree_groove(tmp_path: Path, call: str, width: float, position: str = "G0 X40 Z20", diamon: bool = False,
                 units: str = ""):
    from nctrans.machine import Machine, Tool
    machine = Machine(name="t", tools=[Tool(number=1, width=width)])
    text = (f"R90={width:g}\nG18 G90 {units} {'DIAMON ' if diamon else ''}T1 D1\nS500 M3 F0.1 G95\n{position}\n"
            f"{call}\n" + AFTER + "M30\n")
    runs = []
    for how in ("builtin", "code"):
        d = tmp_path / how
        d.mkdir(exist_ok=True)
        if how == "code":
            for name, body in procs("CYCLE93", "CYCGRF", "CYCGRC", "CYCGRE").items():
                (d / name).write_text(body)
        path = d / "MAIN.MPF"
        path.write_text(text)
        ld = pipeline.load(str(path), "sinumerik")
        recs = list(pipeline.toolpath_of(ld, machine))
        # NC419 (the 1 mm default in inch, taken by the PROC too) is expected: see cycle_agreement
        bad = [x.format_text() for x in ld.diagnostics if x.severity in ("error", "warning")
               and x.rule != "NC419"]
        out, at = [], None
        for r in recs:
            if r.kind in ("rapid", "linear"):
                end = (r.end["X"], r.end["Z"])
                if at is not None and max(abs(p - q) for p, q in zip(end, at)) < 1e-7:
                    continue
                at = end
                out.append((r.kind, end, r.feed))
            elif r.kind in ("dwell", "arc"):
                out.append((r.kind, r.dwell_s, None))
        runs.append((out, bad))
    (want, bad_builtin), (got, bad_code) = runs
    assert bad_builtin == [] and bad_code == [], (bad_builtin, bad_code)
    assert_same(got, want, 1e-6, call)
    return want


GROOVES = {
    "outside-left": ("CYCLE93(20, -10, 8, 4, 0, 0, 0, 0, 0, 0, 0, 0.2, 0.3, 1.5, 0.5, 1)", 3),
    "face-right-flanks": ("CYCLE93(30, 0, 6, 3, 0, 10, 20, 0, 0, 0, 0, 0.1, 0.2, 1, 0, 6, 0.5)", 2.5),
    "inside-right-one-infeed": ("CYCLE93(10, -20, 10, 2, 0, 5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 7)", 4),
    "outside-rounded-and-chamfered": ("CYCLE93(20, -10, 8, 4, 0, 15, 0, 0.5, -0.4, 0, 0, 0.2, 0.3, 1.5, 0, 5)", 3),
    "face-chamfer-legs": ("CYCLE93(30, 0, 6, 3, 0, 0, 10, -0.3, 0.6, 0, 0, 0.1, 0.2, 1, 0, 12)", 2.5),
}


@pytest.mark.parametrize("units, diamon", MODES)
@pytest.mark.parametrize("name", sorted(GROOVES))
def test_cycle93_model_agrees_with_cycle_code(tmp_path, name, units, diamon):
    call, width = GROOVES[name]
    if diamon:                     # SPD is a diameter under DIAMON: the same groove
        head, spd, rest = call.partition("(")[0], call.split("(")[1].split(",")[0], call.split(",", 1)[1]
        call = f"{head}({2 * float(spd):g},{rest}"
    x = 5 if "inside" in name else 40
    want = agree_groove(tmp_path, call, width, f"G0 X{2 * x if diamon else x} Z20", diamon, units)
    assert sum(m[0] == "linear" for m in want) >= 4


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.data())
def test_cycle93_model_agrees_over_parameter_sets(tmp_path_factory, data):
    draw = data.draw
    vari = draw(st.integers(1, 8)) + draw(st.sampled_from([0, 10]))
    inside = vari % 10 in (3, 4, 7, 8)
    tw = draw(st.sampled_from([2, 3, 4]))
    widg = tw + draw(st.sampled_from([0.5, 1, 3, 7]))
    fal2 = draw(st.sampled_from([0, 0.1, 0.2]))
    if tw > widg - 2 * fal2 / math.cos(math.radians(20)):
        fal2 = 0
    diamon = draw(st.booleans())            # SPD a diameter under DIAMON: the same radius 15 or 25
    args = [draw(st.sampled_from([15, 25])) * (2 if diamon else 1), draw(st.integers(-20, 5)), widg,
            draw(st.sampled_from([1, 2.5, 4])), 0, draw(st.sampled_from([0, 0, 5, 20])),
            draw(st.sampled_from([0, 0, 10, 15])), draw(st.sampled_from([0, 0.3, -0.2])),
            draw(st.sampled_from([0, 0.5, -0.4])), 0, 0,
            draw(st.sampled_from([0, 0.1, 0.3])), fal2, draw(st.sampled_from([0, 0.7, 1.5, 5])),
            draw(st.sampled_from([0, 0.4])), vari, draw(st.sampled_from([0, 0.5, 2]))]
    call = "CYCLE93(" + ", ".join(f"{a:g}" for a in args) + ")"
    agree_groove(tmp_path_factory.mktemp("g"), call, tw, f"G0 X{(2 if inside else 50) * (2 if diamon else 1)} Z30",
                 diamon)


def test_save_restores_diamon_and_p_gg_29_reads_it(tmp_path):
    # found by the DIAMON runs: a PROC with SAVE that turns DIAMOF left the caller in DIAMOF (the
    # diameter state was not among what SAVE restores), so every X after a cycle's own code was
    # read as a radius, twice the intended size. Seed L4386: SAVE restores the modal G functions;
    # DIAMON/DIAMOF are G group 29 (L24279-24281), whose index $P_GG[29] reads 2 under DIAMON.
    # X40 (diameter) = radius 20; inside: R2 = 2, DIAMOF, X5 = radius 5; back: X22 = radius 11
    (tmp_path / "SUBD.SPF").write_text("PROC SUBD(REAL AA) SAVE\nR2=$P_GG[29]\nDIAMOF\nG0 X=AA\nRET\n")
    path = tmp_path / "MAIN.MPF"
    path.write_text("G18 G90 DIAMON G0 X40 Z0\nSUBD(5)\nG0 X=R2*10+2\nM30\n")
    ld = pipeline.load(str(path), "sinumerik")
    xs = [r.end["X"] for r in pipeline.toolpath_of(ld) if r.kind == "rapid"]
    assert [d for d in ld.diagnostics if d.severity != "info"] == [] and xs == [20.0, 5.0, 11.0]
