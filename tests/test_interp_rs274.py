"""Small ISO programs through the iso-m front end and the interpreter, compared move by move with
LinuxCNC's rs274 (the reference). The full corpus comparison lives in the harness tests; these
pin the interpreter's own semantics: arcs, planes, units, offsets, G92, G52, G53, G28, tool length."""
from __future__ import annotations

import math

import pytest

import rs274 as harness
from nctrans.interp import interpret
from nctrans.machine import Machine, Tool

TOOLS = [(1, 30.0, 2.0), (2, 55.5, 4.0)]

PROGRAMS = {
    "arcs_planes": """G21 G90 G17
G0 X0 Y0 Z5
G1 F200 Z0
G2 X10 Y0 I5 J0
G3 X0 Y0 R5
G2 X0 Y0 I5 J0 P3
G3 X10 Y0 Z-3 I5 J0 P2
G2 X20 Y0 R-5
G18 G2 Z7 X20 K5 I0
G19 G3 Y10 Z7 J5 K0
G17 G91 G2 X10 Y10 I10 J0
G90 G0 Z20
M2
""",
    "inch_units": """G20 G90 G17
G0 X1 Y1 Z0.5
G1 F20 X2
G2 X3 Y2 R1
G3 X2 Y3 I-1 J0
G91 G1 X-1 Y-1
M2
""",
    "offsets_tool_home": """G21 G90 G17
G10 L2 P1 X100 Y50 Z-20
G10 L2 P2 X-10 Y5 Z0
G54 G0 X10 Y10 Z5
T1 M6
G43 H1 G0 Z5
G1 F100 X20 Y20 Z-1
G55 G0 X0 Y0
T2 M6
G43 H2 Z10
G53 G0 Z0
G91 G28 Z0
G90 G28 X0 Y0
G49 G0 X1 Y1 Z1
M2
""",
    "g92_g52": """G21 G90 G17
G0 X10 Y10 Z0
G92 X0 Y0
G0 X5 Y5
G91 G0 X1
G90 G92.1
G0 X5 Y5
G52 X20 Y30
G0 X1 Y1
G2 X3 Y1 I1 J0 F100
G52 X0 Y0
G0 X0 Y0
M2
""",
}


def parse(text: str, file: str):
    from nctrans.dialects import base
    try:
        d = base.get("iso-m")
    except (ImportError, AttributeError):     # front end not registered yet
        d = None
    if d is not None:
        return d.parse(text, file)
    fe = pytest.importorskip("nctrans.dialects.iso_m.frontend")
    return fe.parse_program(text, file)


@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_matches_rs274(name, rs274, rs274_cache):
    text = PROGRAMS[name]
    src = rs274_cache / f"interp_{name}.ngc"
    src.write_text(text)
    table = harness.write_tool_table(rs274_cache / "interp_tools.tbl", TOOLS)
    ref = harness.run_rs274(src, table, rs274_cache / f"interp_{name}.out")
    assert ref.completed, ref.message
    res = parse(text, str(src))
    program = getattr(res, "program", res)
    machine = Machine(tools=[Tool(number=t, length=l, radius=r) for t, l, r in TOOLS])
    diags: list = []
    recs = [r for r in interpret(program, machine, diagnostics=diags)
            if r.kind in ("rapid", "linear", "arc")]
    assert not [d for d in diags if d.severity == "error"], diags
    got = [harness.Motion.of(r) for r in recs]
    problem = harness.compare(ref.moves, got, name)
    assert problem is None, problem


def test_arc_turns_and_full_circle_match_rs274_rotation(rs274, rs274_cache):
    """ARC_FEED rotation -3 (G2 ... P3 with start == end) is a full circle plus 2 extra turns."""
    text = "G21 G90 G17\nG1 F100 X0 Y0\nG2 X0 Y0 I5 J0 P3\nM2\n"
    program = getattr(parse(text, "t.ngc"), "program", None)
    if program is None:
        pytest.skip("front end result has no program")
    (arc,) = [r for r in interpret(program, diagnostics=[]) if r.kind == "arc"]
    assert arc.turns == 2 and arc.start == arc.end and math.isclose(arc.center["X"], 5.0)
