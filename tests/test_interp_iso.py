"""The interpreter on real ISO (Fanuc macro B) text through the iso-m front end."""
from __future__ import annotations

import itertools
import math

import pytest

from nctrans.dialects import base
from nctrans.interp import interpret
from nctrans.interp.resolver import Resolver
from nctrans.machine import Machine, Tool


def parse(text: str, file: str = "t.nc"):
    from nctrans.dialects import base
    try:
        d = base.get("iso-m")
    except (ImportError, AttributeError):     # front end not registered yet
        d = None
    if d is not None:
        return d.parse(text, file).program
    fe = pytest.importorskip("nctrans.dialects.iso_m.frontend")
    return fe.parse_program(text, file).program


def run(text, machine=None, **kw):
    diags: list = []
    recs = list(interpret(parse(text, kw.pop("file", "t.nc")), machine, diagnostics=diags, **kw))
    return recs, diags


def ends(recs, axis="X"):
    return [round(r.end[axis], 6) for r in recs if r.kind in ("rapid", "linear", "arc")]


def test_while_if_goto_and_vacant_variables():
    recs, diags = run("""G21 G90 G17
#1=0
WHILE [#1 LT 3] DO1
G0 X#1 Y#2
#1=#1+1
END1
IF [#1 EQ 3] GOTO 100
G0 X99
N100 G0 X[#5*2+7]
IF [#5 EQ #0] GOTO 0200
G0 X98
N200 M30
""")
    assert not diags
    assert ends(recs) == [0.0, 1.0, 2.0, 7.0]
    assert ends(recs, "Y") == [0.0] * 4            # Y#2 with #2 vacant: no Y word at all


def test_arithmetic_errors_are_diagnostics():
    recs, diags = run("G21\n#1=1/0\nG0 X[SQRT[-1]]\nG0 X1\nM30\n")
    assert [d.rule for d in diags] == ["NC106", "NC106"] and [d.line for d in diags] == [2, 3]
    assert ends(recs) == [1.0]


def test_endless_program_is_truncated():
    recs, diags = run("N10 G91 G0 X1\nGOTO 10\n", max_steps=500)
    assert diags[-1].rule == "NC205" and len(recs) <= 500


def test_streaming_first_record_of_endless_program():
    diags: list = []
    it = interpret(parse("N1 G0 X1\nG0 X2\nGOTO 1\n"), diagnostics=diags)
    assert [r.end["X"] for r in itertools.islice(it, 4)] == [1, 2, 1, 2]


def test_units_incremental_and_arcs():
    recs, diags = run("""G20 G90 G17
G0 X1 Y0
G91 G1 X1 F10
G90 G3 X3 Y1 R1
G2 X3 Y1 I-1 J0
M30
""")
    assert not diags
    m = [r for r in recs if r.kind != "stop"]
    assert math.isclose(m[1].end["X"], 50.8) and math.isclose(m[1].feed, 254.0)
    assert m[2].direction == "ccw" and math.isclose(m[2].center["X"], 50.8)
    assert m[3].start == m[3].end and m[3].turns == 0 and math.isclose(m[3].center["X"], 50.8)


def test_g68_rotation_and_g51_scaling():
    recs, diags = run("""G21 G90 G17
G68 X0 Y0 R90
G0 X10 Y0
G69
G51 X0 Y0 P2000
G0 X1 Y1
G50
G0 X1 Y1
M30
""")
    assert not diags
    pts = [(round(r.end["X"], 6), round(r.end["Y"], 6)) for r in recs if r.kind == "rapid"]
    assert pts == [(0.0, 10.0), (2.0, 2.0), (1.0, 1.0)]


def test_work_offset_tool_length_from_machine():
    m = Machine(offsets={"G55": {"X": 100, "Z": -50}}, tools=[Tool(number=3, length=80.0)])
    recs, diags = run("G21 G90\nG55 G0 X0 Y0 Z10\nT3 M6\nG43 H3 Z10\nG49 G0 Z10\nM30\n", m)
    assert not diags
    z = ends(recs, "Z")
    assert ends(recs)[0] == 100.0 and z == [-40.0, 40.0, -40.0]


def test_subprogram_in_another_file(tmp_path):
    (tmp_path / "O9020.nc").write_text("O9020\nG91 G0 X1\nG90\nM99\n")
    main = tmp_path / "main.nc"
    main.write_text("G21 G90\nG0 X0\nM98 P9020 L3\nG0 Y5\nM30\n")
    from nctrans.dialects.iso_m.frontend import parse_program
    res = Resolver([], lambda p: parse_program(p.read_text(), str(p)).program,
                   base.get("iso-m").subprogram_files)
    recs, diags = run(main.read_text(), resolver=res, file=str(main))
    assert not diags
    assert ends(recs) == [0.0, 1.0, 2.0, 3.0, 3.0]
    assert [r.line for r in recs if r.kind == "rapid"] == [2, 2, 2, 2, 4]
    assert recs[1].file.endswith("O9020.nc")


def test_macro_call_and_modal_call_in_the_same_file():
    program = parse("""%
O0001
G21 G90 G0 X0 Y0 Z0
G65 P9010 A5 B6
G66 P9030 Z-2
G0 X10
G67
G0 X20
M30
O9010
G1 F100 X#1 Y#2
M99
O9030
G1 F50 Z#26
G0 Z0
M99
%
""")
    if not program.subprograms:
        pytest.skip("the iso-m front end does not split O-blocks into subprograms yet")
    diags: list = []
    recs = [r for r in interpret(program, diagnostics=diags) if r.kind != "stop"]
    assert not diags
    assert [(r.end["X"], r.end["Y"], r.end["Z"]) for r in recs] == [
        (0, 0, 0), (5, 6, 0), (10, 6, 0), (10, 6, -2), (10, 6, 0), (20, 6, 0)]
