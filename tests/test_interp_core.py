"""Interpreter behaviour on hand-built IR: motion, units, arcs, frames, offsets, control flow, calls."""
from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given, settings, strategies as hs

from interp_helpers import B, av, mode, move, moves, num, run
from nctrans.dialects import base
from nctrans.interp import interpret
from nctrans.interp.resolver import Resolver, candidate_names
from nctrans.ir import nodes as n
from nctrans.machine import Machine, Tool


def approx(d, **exp):
    return all(math.isclose(d[k], v, abs_tol=1e-9) for k, v in exp.items())


def test_rapid_linear_and_feed():
    b = B()
    b(move("rapid", X=10, Y=20, Z=5))
    b(n.Feed(num(300)), move("linear", X=15))
    recs, diags = run(b.program())
    assert not diags
    r, l = recs
    assert r.kind == "rapid" and r.start == {"X": 0, "Y": 0, "Z": 0}
    assert r.end == {"X": 10, "Y": 20, "Z": 5} and r.feed is None
    assert l.kind == "linear" and l.start == r.end and l.end["X"] == 15 and l.feed == 300
    assert [x.seq for x in recs] == [1, 2] and [x.line for x in recs] == [1, 2]


def test_inch_units_scale_lengths_feed_not_rotary():
    b = B()
    b(mode("units", "inch"), n.Feed(num(10)), move("linear", X=1, Y=2, A=90))
    b(move("arc_ccw", X=0, Y=3, center=dict(I=-1, J=0)))
    (rec, arc), diags = run(b.program())
    assert not diags and approx(arc.center, X=0, Y=50.8)
    assert approx(rec.end, X=25.4, Y=50.8, A=90.0)
    assert rec.start["A"] == 0.0           # a new axis appears in start and end
    assert math.isclose(rec.feed, 254.0)


def test_incremental_and_per_word_override():
    b = B()
    b(move("rapid", X=10, Y=10))
    b(mode("distance", "incremental"), move(X=5, Y=av(3, "abs")))
    b(move(X=5))
    recs, _ = run(b.program())
    assert approx(recs[1].end, X=15, Y=3) and approx(recs[2].end, X=20, Y=3)


def test_missing_feed_reported_once():
    b = B()
    b(move("linear", X=1))(move(X=2))
    recs, diags = run(b.program())
    assert len(recs) == 2 and [d.rule for d in diags] == ["NC202"]


# ------------------------------------------------------------------ arcs

def test_arc_ijk_centre_incremental():
    b = B()
    b(n.Feed(num(100)), move("linear", X=0, Y=0))
    b(move("arc_cw", X=10, Y=0, center=dict(I=5, J=0)))
    recs, diags = run(b.program())
    arc = recs[-1]
    assert not diags
    assert arc.kind == "arc" and arc.direction == "cw" and arc.plane == "XY" and arc.turns == 0
    assert approx(arc.center, X=5, Y=0, Z=0)


@pytest.mark.parametrize("r,cy", [(5.0, 0.0), (7.0, -math.sqrt(24)), (-7.0, math.sqrt(24))])
def test_arc_radius_short_and_long(r, cy):
    b = B()
    b(n.Feed(num(100)), move("arc_cw", X=10, Y=0, radius=r))
    (arc,), diags = run(b.program())
    assert not diags
    # cw short arc from (0,0) to (10,0): centre below the chord; long arc: above
    assert approx(arc.center, X=5.0, Y=cy)


def test_arc_radius_too_small_and_full_circle_by_radius():
    b = B()
    b(n.Feed(num(100)), move("arc_ccw", X=10, Y=0, radius=4))
    b(move("arc_ccw", X=10, Y=0, radius=4))
    recs, diags = run(b.program())
    assert recs == [] and [d.rule for d in diags] == ["NC203", "NC203"]


def test_arc_radius_mismatch_uses_linuxcnc_tolerance():
    # rs274 accepts I5.01 (difference 0.02 mm) and rejects I5.02 (0.04 mm) on a 10 mm chord
    for i, ok in ((5.01, True), (5.02, False)):
        b = B()
        b(n.Feed(num(100)), move("arc_cw", X=10, Y=0, center=dict(I=i, J=0)))
        recs, diags = run(b.program())
        assert (len(recs) == 1) == ok and (not diags) == ok


def test_full_circle_helix_and_turns():
    b = B()
    b(n.Feed(num(100)), move("arc_ccw", center=dict(I=5, J=0)))
    b(move("arc_cw", X=10, Z=-3, center=dict(I=5), turns=1))
    (c, h), diags = run(b.program())
    assert not diags
    assert c.start == c.end and c.turns == 0 and c.direction == "ccw"
    assert h.turns == 1 and approx(h.end, X=10, Y=0, Z=-3) and approx(h.center, X=5, Y=0, Z=-3)


def test_arc_planes_zx_and_yz():
    b = B()
    b(n.Feed(num(100)), mode("plane", "ZX"), move("arc_cw", Z=10, X=0, center=dict(K=5, I=0)))
    b(mode("plane", "YZ"), move("arc_ccw", Y=10, Z=10, center=dict(J=5)))
    (a, c), diags = run(b.program())
    assert not diags
    assert a.plane == "ZX" and approx(a.center, Z=5, X=0)
    assert c.plane == "YZ" and approx(c.center, Y=5, Z=10)


def test_arc_absolute_centre_mode():
    b = B()
    b(n.Feed(num(100)), move("linear", X=10))
    b(mode("arc_distance", "absolute"), move("arc_ccw", X=0, Y=10, center=dict(I=0, J=0)))
    recs, diags = run(b.program())
    assert not diags and approx(recs[-1].center, X=0, Y=0)


# ------------------------------------------------------------------ offsets and frames

def machine():
    return Machine(offsets={"G54": {"X": 100, "Y": 50, "Z": -20}, "G55": {"X": 1}},
                   tools=[Tool(number=1, length=30.0, radius=2.0)])


def test_work_offsets_and_tool_length():
    b = B()
    b(move("rapid", X=10, Y=10, Z=5))
    b(n.ToolSelect(num(1)), n.ToolChange())
    b(mode("tool_length", "plus"), n.OffsetSelect("length", num(1)), move(Z=5))
    b(mode("work_offset", "G55"), mode("tool_length", "off"), move(X=0))
    recs, _ = run(b.program(), machine())
    m = moves(recs)
    assert approx(m[0].end, X=110, Y=60, Z=-15)
    tc = [r for r in recs if r.kind == "tool_change"]
    assert tc[0].tool == 1 and m[1].tool == 1
    assert approx(m[1].end, Z=15)                    # 5 - 20 + 30
    assert approx(m[2].end, X=1, Y=60, Z=15)         # G55 changes X only; machine does not jump
    assert m[2].start == m[1].end


def test_g92_set_position_and_reset():
    # rs274: at (0,0) G92 X5 Y5 gives offset -5, so G0 X0 Y0 goes to machine (-5, -5)
    b = B()
    b(n.SetPosition({"X": av(5), "Y": av(5)}))
    b(move("rapid", X=0, Y=0))
    b(n.ResetSetPosition(), move(X=0))
    recs, _ = run(b.program())
    assert approx(recs[0].end, X=-5, Y=-5) and approx(recs[1].end, X=0, Y=-5)


def test_local_shift_rotation_scale_mirror():
    b = B()
    b(n.FrameOp("trans", {"X": num(10)}, local=True), move("rapid", X=1, Y=0))
    b(n.FrameOp("rot", center={"X": av(0), "Y": av(0)}, angle=num(90)), move(X=1, Y=0))
    b(n.FrameOp("rot", clear=True), n.FrameOp("scale", {"X": num(2), "Y": num(2)},
                                               center={"X": av(0), "Y": av(0)}), move(X=1, Y=1))
    b(n.FrameOp("scale", clear=True), n.FrameOp("mirror", {"X": num(1)}, center={"X": av(0)}), move(X=1, Y=1))
    b(n.Feed(num(10)), move("arc_cw", X=1, Y=-1, radius=1))
    recs, diags = run(b.program())
    assert not diags
    e = [r.end for r in recs]
    assert approx(e[0], X=11, Y=0)
    assert approx(e[1], X=10, Y=1)                   # rotated 90° about program zero, then +10
    assert approx(e[2], X=12, Y=2)
    assert approx(e[3], X=9, Y=1)
    assert recs[4].direction == "ccw"                 # one mirrored axis swaps cw/ccw


def test_rotation_keeps_incremental_moves_in_rotated_system():
    b = B()
    b(n.FrameOp("rot", center={"X": av(0), "Y": av(0)}, angle=num(90)))
    b(mode("distance", "incremental"), move("rapid", X=1))(move(X=1))
    recs, _ = run(b.program())
    assert approx(recs[-1].end, X=0, Y=2)


def test_machine_coordinates_move_ignores_offsets():
    b = B()
    b(n.ToolSelect(num(1)), n.ToolChange(), mode("tool_length", "plus"),
      n.OffsetSelect("length", num(1)))
    b(move("rapid", Z=0, machine=True))(move(X=0))
    recs, _ = run(b.program(), machine())
    m = moves(recs)
    assert approx(m[0].end, X=0, Z=0)                 # G53 Z0: machine zero of the controlled point
    assert approx(m[1].end, X=100, Z=0)


def test_home_return_g28():
    # as rs274: G91 G28 Z0 -> intermediate = current, then Z to machine 0; only named axes move
    b = B()
    b(move("rapid", X=10, Y=10, Z=5))
    b(mode("distance", "incremental"), n.HomeReturn(1, {"Z": av(0)}))
    b(mode("distance", "absolute"), n.HomeReturn(1, {"X": av(0), "Y": av(0)}))
    recs, _ = run(b.program(), machine())
    e = [r.end for r in recs]
    assert approx(e[1], X=110, Y=60, Z=-15) and approx(e[2], X=110, Y=60, Z=0)
    assert approx(e[3], X=100, Y=50, Z=0) and approx(e[4], X=0, Y=0, Z=0)


# ------------------------------------------------------------------ variables and control flow

def V(k):
    return n.Var("num", k)


def test_vacant_word_is_dropped_and_counts_as_zero_in_arithmetic():
    b = B()
    b(move("rapid", X=10, Y=n.AxisValue(V(1))))
    b(n.Assign(V(2), n.Binary("*", V(1), num(5))), move(Y=n.AxisValue(V(2))))
    b(n.Assign(V(3), V(1)), move(Y=n.AxisValue(n.Binary("+", V(3), num(7)))))
    recs, diags = run(b.program())
    assert not diags
    assert [r.end["Y"] for r in recs] == [0.0, 0.0, 7.0]
    assert [r.end["X"] for r in recs] == [10.0] * 3


def test_vacant_comparisons():
    b = B()
    b.node(n.If(b.span(), n.Binary("==", V(1), V(0)), [n.Block(b.span(), [move("rapid", X=1)[1]])]))
    b.node(n.If(b.span(), n.Binary("==", V(1), num(0)), [n.Block(b.span(), [move("rapid", X=2)[1]])]))
    recs, _ = run(b.program())
    assert [r.end["X"] for r in recs] == [1.0]


def test_while_loop_and_counter():
    b = B()
    b(n.Assign(V(1), num(0)))
    body = [n.Block(n.Span("t.nc", 3), [n.Assign(V(1), n.Binary("+", V(1), num(1))),
                                        n.Motion({"X": n.AxisValue(V(1))})])]
    b.node(n.While(b.span(), n.Binary("<", V(1), num(3)), body))
    recs, _ = run(b.program())
    assert [r.end["X"] for r in recs] == [1.0, 2.0, 3.0]
    assert all(r.line == 3 for r in recs)


def test_for_loop_repeat_until_and_case():
    b = B()
    var = n.Var("R", 1)
    b.node(n.ForLoop(b.span(), var, num(1), num(5), [n.Block(b.span(), [n.Motion({"X": n.AxisValue(var)})])],
                     step=num(2)))
    b.node(n.RepeatUntil(b.span(), [n.Block(b.span(), [n.Assign(n.Var("R", 2), n.Binary("+", n.Var("R", 2), num(1))),
                                                      n.Motion({"Y": n.AxisValue(n.Var("R", 2))})])],
                         n.Binary(">=", n.Var("R", 2), num(2))))
    b.node(n.Case(b.span(), num(2), [(num(1), "ONE"), (num(2), "TWO")], default=None))
    b(move(Z=1), label="ONE")
    b(move(Z=2), label="TWO")
    recs, diags = run(b.program())
    assert not diags
    assert [r.end["X"] for r in recs[:3]] == [1.0, 3.0, 5.0]
    assert [r.end["Y"] for r in recs[3:5]] == [1.0, 2.0]
    assert [r.end["Z"] for r in recs[5:]] == [2.0]


def test_goto_numbers_compare_numerically_and_directions():
    b = B()
    b(n.Goto("100", "forward"))
    b(move("rapid", X=1))
    b(move("rapid", X=2), number="0100")
    b(n.Assign(V(1), n.Binary("+", V(1), num(1))))
    b(n.Goto("N100", "backward", cond=n.Binary("<", V(1), num(2))))
    recs, diags = run(b.program())
    assert not diags and [r.end["X"] for r in recs] == [2.0, 2.0]


def test_undefined_label_stops_with_nc102():
    b = B()
    b(n.Goto("999"))(move("rapid", X=1))
    recs, diags = run(b.program())
    assert recs == [] and [d.rule for d in diags] == ["NC102"] and diags[0].line == 1


def test_endless_loop_truncated_by_step_budget():
    b = B()
    b.node(n.Loop(b.span(), [n.Block(n.Span("t.nc", 7), [n.Motion({"X": av(1)})])]))
    recs, diags = run(b.program(), max_steps=1000)
    assert len(recs) <= 1000 and diags[-1].rule == "NC205" and "line" in diags[-1].message


def test_restart_in_main_program_runs_one_pass():
    b = B()
    b(move("rapid", X=1))(n.ProgramEnd("restart"))
    recs, diags = run(b.program())
    assert [r.kind for r in recs] == ["rapid", "stop"] and diags[0].rule == "NC205"


@pytest.mark.parametrize("expr", [n.Binary("/", num(1), num(0)), n.Func("sqrt", [num(-1)]),
                                  n.Binary("mod", num(1), num(0)), n.Func("ln", [num(0)])])
def test_arithmetic_errors_are_nc106(expr):
    b = B()
    b(n.Assign(V(1), expr))(move("rapid", X=1))
    recs, diags = run(b.program())
    assert len(recs) == 1 and [d.rule for d in diags] == ["NC106"] and diags[0].line == 1


def test_undefined_name_variable_nc101_and_declared_names():
    b = B()
    b(move("rapid", X=n.AxisValue(n.Var("name", "NOPE"))))
    b(n.VarDecl("LEN", "REAL", init=[num(4)]), n.VarDecl("ARR", "REAL", dims=[3]))
    b(n.Assign(n.Var("name", "ARR", [num(2)]), num(8)))
    b(move(X=n.AxisValue(n.Binary("+", n.Var("name", "LEN"), n.Var("name", "ARR", [num(2)])))))
    b(move(X=n.AxisValue(n.Var("name", "ARR", [num(3)]))))
    recs, diags = run(b.program())
    assert [d.rule for d in diags] == ["NC101", "NC105"]
    assert recs[-1].end["X"] == 12.0


def test_unknown_system_value_is_info_and_word_dropped():
    b = B()
    b(move("rapid", X=n.AxisValue(n.Var("system", "$AA_MW"))))
    recs, diags = run(b.program())
    assert [d.rule for d in diags] == ["NC107"] and recs == []


def test_functions_in_degrees():
    b = B()
    b(move("rapid", X=n.AxisValue(n.Func("sin", [num(30)])), Y=n.AxisValue(n.Func("atan2", [num(1), num(1)]))))
    b(move(X=n.AxisValue(n.Func("fup", [num(-1.2)])), Y=n.AxisValue(n.Func("round", [num(-2.5)]))))
    recs, _ = run(b.program())
    assert approx(recs[0].end, X=0.5, Y=45.0) and approx(recs[1].end, X=-2.0, Y=-3.0)


# ------------------------------------------------------------------ subprograms

def sub(name, *blocks, params=None):
    return n.Subprogram(name, n.Span("t.nc", 90), list(blocks), params=params or [])


def blk(line, *stmts):
    return n.Block(n.Span("t.nc", line), list(stmts))


def test_subprogram_call_with_repeat_and_line_numbers():
    s = sub("O1000", blk(91, n.Motion({"X": av(1)}, ), n.ModeChange("distance", "incremental")),
            blk(92, n.Return()))
    b = B()
    b(mode("distance", "incremental"), n.SubCall("1000", repeat=num(3), kind="m98"))
    b(move(Y=1))
    recs, diags = run(b.program(subs={"O1000": s}))
    assert not diags
    assert [r.end["X"] for r in recs] == [1.0, 2.0, 3.0, 3.0]
    assert [r.line for r in recs] == [91, 91, 91, 2]


def test_macro_call_binds_named_arguments_to_locals():
    s = sub("O9010", blk(91, n.Motion({"X": n.AxisValue(V(1)), "Y": n.AxisValue(V(2))})),
            blk(92, n.Return()))
    b = B()
    b(n.Assign(V(1), num(77)))
    b(n.SubCall("O9010", named_args={"A": num(5)}, kind="g65", bindings={"A": V(1)}))
    b(move("rapid", Z=n.AxisValue(V(1))))
    recs, diags = run(b.program(subs={"O9010": s}))
    assert not diags
    assert approx(recs[0].end, X=5, Y=0) and recs[1].end["Z"] == 77.0   # caller's #1 restored


def test_positional_params_and_return_to_label():
    s = sub("PART", blk(91, n.Motion({"X": n.AxisValue(n.Var("name", "W"))})),
            blk(92, n.Return("20")), params=[n.Param("W")])
    b = B()
    b(n.SubCall("part", args=[num(4)]))
    b(move("rapid", Y=1))
    b(move("rapid", Y=2), number="20")
    recs, diags = run(b.program(subs={"PART": s}))
    assert not diags and [r.end["Y"] for r in recs] == [0.0, 2.0] and recs[0].end["X"] == 4.0


def test_unresolved_call_nc103_and_runaway_recursion():
    b = B()
    b(n.SubCall("O4242"))(move("rapid", X=1))
    recs, diags = run(b.program())
    # the call is kept as an opaque event where it stands, then the move
    assert [r.kind for r in recs] == ["call", "rapid"] and recs[0].call == "O4242"
    assert diags[0].rule == "NC103"
    s = sub("O1", blk(91, n.SubCall("O1")))
    b = B()
    b(n.SubCall("O1"))
    recs, diags = run(b.program(subs={"O1": s}))
    assert any(d.rule == "NC105" for d in diags)


def test_modal_call_after_each_move():
    s = sub("O9", blk(91, n.Motion({"Z": av(-1)})), blk(92, n.Motion({"Z": av(0)})), blk(93, n.Return()))
    b = B()
    b(n.SubCall("O9", modal="after_move", kind="g66"))
    b(move("rapid", X=1))(move(X=2))(n.ModalCallOff())(move(X=3))
    recs, _ = run(b.program(subs={"O9": s}))
    assert [(r.line, r.end["X"], r.end["Z"]) for r in recs] == [
        (2, 1, 0), (91, 1, -1), (92, 1, 0), (3, 2, 0), (91, 2, -1), (92, 2, 0), (5, 3, 0)]


def test_resolver_finds_files_beside_the_caller(tmp_path):
    (tmp_path / "O1234.nc").write_text("x")
    parsed = []

    def parse(path):
        parsed.append(path)
        return n.Program(str(path), "test", [n.Block(n.Span(str(path), 1), [n.Motion({"X": av(9)})])])
    iso = base.get("iso-m")
    res = Resolver([tmp_path], parse, iso.subprogram_files)   # the caller t.nc is elsewhere: the search path finds it
    b = B()
    b(n.SubCall("1234"))(n.SubCall("O1234"))
    recs, diags = run(b.program(), resolver=res)
    assert not diags and len(recs) == 2 and recs[0].file.endswith("O1234.nc")
    assert len(parsed) == 1
    assert candidate_names("../etc/passwd") == [] and iso.subprogram_files("../etc/passwd") == []
    assert "L10.SPF" in base.get("sinumerik").subprogram_files("L10")
    assert "SUB1.SPF" in base.get("sinumerik").subprogram_files("%_N_SUB1_SPF")


# ------------------------------------------------------------------ events and streaming

def test_events_spindle_coolant_dwell_stop():
    b = B()
    b(n.SpindleSpeed(num(1000)), mode("spindle", "cw"), mode("coolant", "flood"))
    b(n.Dwell(num(0.5)))(n.Stop(optional=True))(n.ProgramEnd())
    recs, _ = run(b.program())
    d = [r.to_dict() for r in recs]
    assert d[0]["kind"] == "spindle" and d[0]["spindle_dir"] == "cw" and d[0]["spindle"] == 1000
    assert d[1]["coolant"] == "flood" and d[2]["dwell_s"] == 0.5
    assert d[3]["stop_kind"] == "optional" and d[4]["stop_kind"] == "end"


def test_streaming_first_record_of_huge_program_is_immediate():
    class Endless(list):
        pass
    b = B()
    b.node(n.Loop(b.span(), [n.Block(n.Span("t.nc", 2), [n.Motion({"X": av(1)})]),
                             n.Block(n.Span("t.nc", 3), [n.Motion({"X": av(2)})])]))
    diags = []
    it = interpret(b.program(), diagnostics=diags)
    first = list(itertools.islice(it, 5))
    assert [r.end["X"] for r in first] == [1, 2, 1, 2, 1] and not diags


def test_flatten_hook_gets_work_coordinates():
    seen = []
    b = B()
    b(move("rapid", X=1, Y=2))
    diags = []
    list(interpret(b.program(), machine(), diagnostics=diags,
                   flatten_hook=lambda rec, work, center: seen.append((rec.end, work))))
    (mend, work), = seen
    assert approx(mend, X=101, Y=52) and approx(work, X=1, Y=2)


@settings(max_examples=60, deadline=None)
@given(hs.lists(hs.tuples(hs.sampled_from(["rapid", "linear"]), hs.floats(-100, 100), hs.floats(-100, 100),
                          hs.booleans()), min_size=1, max_size=12))
def test_property_records_chain_and_incremental_equals_absolute(steps):
    """Each record starts where the last ended; G91 moves reach the same points as the G90 ones."""
    ba, bi = B(), B()
    ba(n.Feed(num(100)), move("rapid", X=0, Y=0))
    bi(n.Feed(num(100)), move("rapid", X=0, Y=0), mode("distance", "incremental"))
    px = py = 0.0
    for kind, x, y, _ in steps:
        ba(move(kind, X=x, Y=y))
        bi(move(kind, X=x - px, Y=y - py))
        px, py = x, y
    ra, _ = run(ba.program(), machine())
    ri, _ = run(bi.program(), machine())
    for a, b_ in zip(ra, ri):
        assert math.isclose(a.end["X"], b_.end["X"], abs_tol=1e-6)
        assert math.isclose(a.end["Y"], b_.end["Y"], abs_tol=1e-6)
    for prev, cur in zip(ra, ra[1:]):
        assert prev.end == cur.start


def test_cutter_comp_routes_moves_through_the_compensator():
    pytest.importorskip("nctrans.interp.cutter_comp")
    m = Machine(tools=[Tool(number=1, radius=1.0)])
    b = B()
    b(n.Feed(num(100)), move("linear", X=0, Y=-5))
    b(mode("cutter_comp", "left"), n.OffsetSelect("radius", num(1)), move(X=0, Y=0))
    b(move(X=10, Y=0))(move(X=10, Y=10))
    b(mode("cutter_comp", "off"), move(X=20, Y=20))
    b(mode("coolant", "off"))
    recs, diags = run(b.program(), m)
    assert not diags
    ms = moves(recs)
    for prev, cur in zip(ms, ms[1:]):
        assert all(math.isclose(prev.end[a], cur.start[a], abs_tol=1e-9) for a in "XY")
    # left of the path going +X is +Y: the compensated edge runs at Y = 1
    assert any(r.kind == "linear" and math.isclose(r.end["Y"], 1.0) for r in ms)
    assert ms[-1].end == {"X": 20.0, "Y": 20.0, "Z": 0.0}
    assert recs[-1].kind == "coolant"


def test_three_point_tangent_and_aperture_arcs():
    b = B()
    b(n.Feed(num(100)), move("linear", X=10, Y=0))
    m = n.Motion({"X": av(-10), "Y": av(0)}, via={"X": av(0), "Y": av(10)})
    b(n.ModeChange("motion", "arc_3point"), m)                   # ccw half circle over the top
    b(n.ModeChange("motion", "arc_tangent"), n.Motion({"X": av(-20), "Y": av(10)}))
    b(n.ModeChange("motion", "arc_cw"), n.Motion({"X": av(0), "Y": av(10)}, aperture=num(180)))
    b(n.ModeChange("motion", "arc_ccw"), n.Motion({}, center={"I": av(0), "J": av(-10)},
                                                  aperture=num(90)))
    recs, diags = run(b.program())
    assert not diags
    c3, ct, ap, apc = recs[1:]
    assert c3.direction == "ccw" and approx(c3.center, X=0, Y=0)
    # leaving (-10,0) downwards (tangent of the ccw circle there is -Y): the centre lies on the
    # x axis to the left; through (-20,10) it is (-20,0) and the turn is cw
    assert ct.direction == "cw" and approx(ct.center, X=-20, Y=0)
    assert approx(ap.center, X=-10, Y=10) and ap.direction == "cw"
    assert approx(apc.end, X=-10, Y=0) and approx(apc.center, X=0, Y=0)   # ccw 90° from the top


def test_frame_replacement_rules():
    """Sinumerik-style TRANS (no centre, not local) replaces the whole programmable frame;
    ISO G52 (local) and pivoted ops (G68) replace only their own component."""
    b = B()
    b(n.FrameOp("trans", {"X": num(10)}, local=True))
    b(n.FrameOp("rot", center={"X": av(0), "Y": av(0)}, angle=num(90)), move("rapid", X=1, Y=0))
    b(n.FrameOp("trans", {"X": num(5)}, local=True), move(X=1, Y=0))       # rotation kept
    b(n.FrameOp("trans", {"Y": num(7)}), move(X=1, Y=0))                    # everything replaced
    b(n.FrameOp("rot", angle=num(90), additive=True), move(X=1, Y=0))       # AROT about zero
    b(n.FrameOp("mirror", {"X": num(1), "Y": num(1)}, center={"X": av(0), "Y": av(0)}))
    b(n.FrameOp("mirror", {"X": num(1)}, clear=True), n.FrameOp("rot", clear=True), move(X=1, Y=1))
    recs, diags = run(b.program())
    assert not diags
    e = [r.end for r in recs]
    assert approx(e[0], X=10, Y=1) and approx(e[1], X=5, Y=1)
    assert approx(e[2], X=1, Y=7) and approx(e[3], X=0, Y=8)
    # G69 clears the G68 component only; the additive rotation stays: (1,1) -> (-1,1),
    # mirrored in Y only -> (-1,-1), shifted -> (-1,6)
    assert approx(e[4], X=-1, Y=6)


def test_diagnostics_in_a_loop_are_reported_once():
    b = B()
    b(n.Assign(V(1), num(0)))
    body = [n.Block(n.Span("t.nc", 3), [n.Assign(V(1), n.Binary("+", V(1), num(1))),
                                        n.Assign(V(2), n.Binary("/", num(1), num(0))),
                                        n.SubCall("O777")])]
    b.node(n.While(b.span(), n.Binary("<", V(1), num(50)), body))
    recs, diags = run(b.program())
    assert sorted(d.rule for d in diags) == ["NC103", "NC106"]


def test_modal_cycle_call_and_hole_pattern():
    pytest.importorskip("nctrans.interp.cycles")
    b = B()
    b(move("rapid", X=0, Y=0, Z=20), n.Feed(num(100)))
    b(n.CycleCall("drill", {"retract_plane": num(10), "r_plane": num(0), "safety": num(2),
                            "bottom": num(-5)}, modal=True, name="CYCLE81"))
    b(n.CycleCall("holes_circle", {"cpa": num(50), "cpo": num(50), "rad": num(20), "sta1": num(0),
                                   "inda": num(90), "num": num(4)}, name="HOLES2"))
    b(n.ModalCallOff(), move("rapid", X=0))
    recs, diags = run(b.program())
    assert not diags
    bottoms = [(round(r.end["X"], 6), round(r.end["Y"], 6)) for r in recs if r.kind == "linear"]
    assert bottoms == [(70, 50), (50, 70), (30, 50), (50, 30)]
    assert all(r.end["Z"] == -5 for r in recs if r.kind == "linear")
    assert recs[-1].end["X"] == 0 and recs[-1].line == 4
