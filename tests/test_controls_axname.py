"""AXNAME / AXSTRING (seed L2217-2238): a string turned into an axis identifier and back, so cycle
code that addresses its axes indirectly (`AX[AXNAME("X")]=...`) runs. Expected values by hand."""
from __future__ import annotations

from nctrans import pipeline
from nctrans.source import from_text


def run(text: str):
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = list(pipeline.toolpath_of(ld, None))
    return recs, ld.diagnostics


def moves(recs):
    return [(r.kind, r.end["X"], r.end["Y"], r.end["Z"]) for r in recs if r.kind in ("rapid", "linear")]


def test_axname_addresses_axes_indirectly():
    text = ('DEF AXIS _A\nDEF STRING[8] NAM\nG0 X0 Y0 Z10\n_A=AXNAME("y")\n'
            'AX[AXNAME("X")]=12 AX[_A]=7\n'             # X 12, Y 7 (lower case "y" is the axis Y)
            'NAM=AXSTRING(_A)\nIF NAM<>"Y" GOTOF BAD\n'
            'G1 AX[AXNAME("Z")]=-3 F100\nM30\nBAD:\nG0 X99\nM30\n')
    recs, diags = run(text)
    assert moves(recs) == [("rapid", 0.0, 0.0, 10.0), ("rapid", 12.0, 7.0, 10.0), ("linear", 12.0, 7.0, -3.0)]
    assert [d for d in diags if d.severity in ("error", "warning")] == []


def test_axname_in_a_cycle_proc_with_the_axis_name_as_a_string_parameter():
    # a PROC that drills along the axis it is given by name: Z from 5 down to -4, back to 5
    text = ('G0 X1 Y2 Z5\nDRL("Z", -4)\nM30\n'
            'PROC DRL(STRING[4] _AXN, REAL _DP)\nDEF AXIS _AX\n_AX=AXNAME(_AXN)\n'
            'G1 F50 AX[_AX]=_DP\nG0 AX[_AX]=5\nRET\n')
    recs, diags = run(text)
    assert moves(recs)[-2:] == [("linear", 1.0, 2.0, -4.0), ("rapid", 1.0, 2.0, 5.0)]
    assert [d for d in diags if d.severity in ("error", "warning")] == []


def test_axname_of_no_axis_is_the_controls_alarm():
    recs, diags = run('DEF AXIS _A\n_A=AXNAME("Q7")\nG0 AX[AXNAME("")]=1\nM30\n')
    assert [(d.rule, d.line) for d in diags if d.severity == "error"] == [("NC104", 2), ("NC104", 3)]
    assert moves(recs) == []
