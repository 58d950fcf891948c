"""nctrans.ir.walk: the one tree walk, jump targets and constants (hand-computed expectations)."""
from __future__ import annotations

from nctrans.dialects import base
from nctrans.ir import nodes as n
from nctrans.ir import walk

S = n.Span("t", 1)


def blk(*body, number=None, label=None):
    return n.Block(S, list(body), number, label)


def num(v):
    return n.Num(float(v))


def test_walk_visits_structures_before_their_bodies_in_source_order():
    inner = blk(number="3")
    loop = n.While(S, num(1), [inner])
    iff = n.If(S, num(1), [blk(number="2"), loop], [blk(number="4")])
    nodes = [blk(number="1"), iff, blk(number="5")]
    assert [getattr(x, "number", type(x).__name__) for x in walk.walk(nodes)] == \
        ["1", "If", "2", "While", "3", "4", "5"]
    assert [b.number for b in walk.blocks(nodes)] == ["1", "2", "3", "4", "5"]


def test_jump_targets_cover_goto_case_and_return_to_a_block_number():
    case = n.Case(S, num(1), [(num(1), "A"), (num(2), "B")], "C")
    nodes = [blk(n.Goto("L1")), n.Loop(S, [blk(n.Goto("20", "backward"))]), case, blk(n.Return("70"))]
    assert walk.jump_targets(nodes) == {"L1", "20", "A", "B", "C", "70"}
    assert walk.return_targets(nodes) == {"70"}
    sub = n.Subprogram("O9", S, [blk(n.Goto("9"))])
    prog = n.Program("t", "x", [blk(n.Goto("1"))], {"O9": sub})
    assert walk.program_jump_targets(prog) == {"1", "9"}
    assert [name for name, _ in walk.units(prog)] == [None, "O9"]


def test_constants_fold_arithmetic_and_literals_stay_literal():
    e = n.Binary("*", n.Unary("-", num(2)), n.Binary("+", num(1.5), num(0.5)))    # -2 * (1.5 + 0.5)
    assert walk.constant(e) == -4.0
    assert walk.constant(n.Binary("/", num(1), num(0))) is None
    assert walk.constant(n.Binary("+", num(1), n.Var("num", 1))) is None
    assert walk.literal(n.Unary("-", num(5))) == -5.0 and walk.literal(e) is None


def test_iso_emitter_treats_the_block_a_subprogram_returns_to_as_a_jump_target():
    """M99 P30 in the subprogram lands on N30 of the main program: the emitter's known position
    must be dropped there as at any jump target (it was only a target of the subprogram before)."""
    from nctrans.dialects.iso_m.emitter import IsoEmitter
    iso = base.get("iso-m")
    text = "O1\nG90 G0 X5 Y5\nM98 P9\nN30 G0 X5 Y5\nM30\nO9\nG0 X7 Y7\nM99 P30\n"
    em = IsoEmitter(iso.parse(text, "t.nc").program)
    em._plan()
    assert "30" in em.targets[None]
