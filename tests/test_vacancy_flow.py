"""An ISO macro file written as a PROC checks on entry only the arguments it uses bare at a point
its own vacancy tests have not shown them passed on every path (nctrans.lower.vacancy_flow).
Hand cases per construct, and a hypothesis property against an independent oracle: a bare use is
reported exactly when it is reachable with the argument left out (guards then always jump)."""
from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from nctrans.dialects.base import get
from nctrans.lower import macro_procs
from nctrans.lower.vacancy_flow import shows_passed


def _checked(text: str) -> set[int]:
    program = get("iso-m").parse(text, "O9001.nc").program
    found, why = macro_procs.standalone(program)
    assert found is not None, why
    return found.bare


def test_guard_before_the_use():
    assert _checked("O9001\nIF[#24EQ#0]GOTO9\nG1 X#24 F100.\nN9 M99\n") == set()


def test_a_path_around_the_guard_needs_the_check():
    # GOTO5 on #1 jumps past the vacancy test of #24 straight to its bare use
    assert _checked("O9001\nIF[#1EQ1]GOTO5\nIF[#24EQ#0]GOTO9\nN5 G1 X#24 F100.\nN9 M99\n") == {24}


def test_use_before_the_guard_in_a_loop_back():
    assert _checked("O9001\nN1 G1 X#24 F100.\nIF[#24EQ#0]GOTO9\nGOTO1\nN9 M99\n") == {24}


def test_comparison_with_a_constant_guards_only_where_zero_goes_the_other_way():
    # vacant reads 0: 0 < 0.1 jumps to N9, so falling through shows #24 passed ...
    assert _checked("O9001\nIF[#24LT0.1]GOTO9\nG1 X#24 F100.\nN9 M99\n") == set()
    # ... 0 > 0.1 is false, so a vacant #24 falls through as well
    assert _checked("O9001\nIF[#24GT0.1]GOTO9\nG1 X#24 F100.\nN9 M99\n") == {24}


def test_or_guard_and_structured_if_and_while():
    assert _checked("O9001\nIF[[#24EQ#0]OR[#26LT1.]]GOTO9\nG1 X#24 Z#26 F100.\nN9 M99\n") == set()
    assert _checked("O9001\nIF[[#24EQ#0]AND[#26LT1.]]GOTO9\nG1 X#24 Z#26 F100.\nN9 M99\n") == {24, 26}
    assert _checked("O9001\nIF[#24EQ#0]THEN #3000=1(NO X)\nG1 X#24 F100.\nM99\n") == set()
    assert _checked("O9001\nIF[#24EQ#0]THEN #1=1\nG1 X#24 F100.\nM99\n") == {24}
    assert _checked("O9001\nWHILE[#25NE#0]DO1\nG1 Y#25 F100.\n#25=#25-1\nEND1\nM99\n") == set()
    assert _checked("O9001\nWHILE[#1GT0]DO1\nG1 Y#25 F100.\nEND1\nM99\n") == {25}


def test_computed_jump_keeps_every_check():
    # #1 itself is used bare (the jump's number); #24 stays checked although it is tested first
    assert _checked("O9001\nIF[#24EQ#0]GOTO9\nGOTO#1\nG1 X#24 F100.\nN9 M99\n") == {1, 24}


def test_shows_passed_by_hand():
    from nctrans.ir import nodes as ir
    k, vac = ir.Var("num", 6), ir.Var("num", 0)
    eq = ir.Binary("==", k, vac)
    assert shows_passed(eq, False, {6}) == {6} and shows_passed(eq, True, {6}) == set()
    lt = ir.Binary("<", ir.Num(0.1), k)            # 0.1 < #6: false for vacant (0)
    assert shows_passed(lt, True, {6}) == {6} and shows_passed(lt, False, {6}) == set()
    assert shows_passed(ir.Unary("not", eq), True, {6}) == {6}
    assert shows_passed(ir.Binary("==", k, ir.Num(5.0)), True, {6}) == {6}


# ------------------------------------------------------------------ property against an oracle
# A macro of numbered lines N1..Nn, each one of: the guard `IF[#24EQ#0]GOTO t`, a jump on another
# argument `IF[#1EQ1]GOTO t`, `GOTO t`, a bare use `G1 X#24`, or a plain move; M99 at the end.
LINE = st.one_of(
    st.tuples(st.just("guard"), st.integers(1, 9)),
    st.tuples(st.just("either"), st.integers(1, 9)),
    st.tuples(st.just("goto"), st.integers(1, 9)),
    st.tuples(st.just("use"), st.just(0)),
    st.tuples(st.just("plain"), st.just(0)),
)


def _text(lines) -> str:
    out = ["O9001"]
    for i, (kind, t) in enumerate(lines, start=1):
        t = min(t, len(lines) + 1)
        out.append(f"N{i} " + {"guard": f"IF[#24EQ#0]GOTO{t}", "either": f"IF[#1EQ1]GOTO{t}",
                                "goto": f"GOTO{t}", "use": "G1 X#24 F100.", "plain": "G1 Y1. F100."}[kind])
    out.append(f"N{len(lines) + 1} M99")
    return "\n".join(out) + "\n"


def _reachable_use_when_vacant(lines) -> bool:
    """Breadth-first over the lines with #24 left out: a guard then always jumps."""
    n = len(lines)
    seen, todo = set(), [1]
    while todo:
        i = todo.pop()
        if i in seen or i > n:
            continue
        seen.add(i)
        kind, t = lines[i - 1]
        t = min(t, n + 1)
        if kind == "use":
            return True
        if kind in ("guard", "goto"):
            todo.append(t)
        elif kind == "either":
            todo += [t, i + 1]
        else:
            todo.append(i + 1)
    return False


@settings(max_examples=150, deadline=None)
@given(st.lists(LINE, min_size=1, max_size=8))
def test_check_exactly_where_a_vacant_argument_reaches_a_bare_use(lines):
    if not any(kind == "use" for kind, _ in lines):
        return
    assert (24 in _checked(_text(lines))) == _reachable_use_when_vacant(lines)
