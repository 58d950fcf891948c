"""The emitter base (nctrans.dialects.emit): the table-driven expression printer, codes spelled
from the target's rules table, and the one NotExpressible -> NC402 path."""
from __future__ import annotations

import pytest

from nctrans.dialects import base
from nctrans.dialects.emit import ExpressionSyntax, NotExpressible, Spelling, format_number
from nctrans.ir import nodes as n


def _emit(text: str, source: str, target: str):
    program = base.get(source).parse(text, "t").program
    return base.get(target).emit(program)


def _codes(result) -> list[str]:
    return [d.rule for d in result.diagnostics]


# ----------------------------------------------------------------- expressions from a table

class _Toy(Spelling):
    """A made-up dialect whose syntax comes only from the table below."""
    def var_text(self, v):
        return str(v.key)

    @property
    def syntax(self):
        return _TOY


_TOY = ExpressionSyntax({
    "brackets": ["<", ">"], "separator": ";", "atom": 9, "negative_number": 7,
    "binary": {"+": {"text": " plus ", "prec": 4}, "*": {"text": " times ", "prec": 5},
               "==": {"text": " is ", "prec": 3, "operands": "atoms"},
               "and": {"text": " & ", "prec": 2, "operands": "always"}},
    "unary": {"-": {"text": "neg ", "prec": 7, "operands": 7}},
    "functions": {"sqrt": "ROOT"}})


def _v(name):
    return n.Var("name", name)


@pytest.mark.parametrize("expr, text", [
    (n.Binary("*", n.Binary("+", _v("a"), _v("b")), _v("c")), "<a plus b> times c"),
    (n.Binary("+", _v("a"), n.Binary("*", _v("b"), _v("c"))), "a plus b times c"),
    # left-associative: a+(b+c) keeps its brackets, (a+b)+c needs none
    (n.Binary("+", _v("a"), n.Binary("+", _v("b"), _v("c"))), "a plus <b plus c>"),
    (n.Binary("+", n.Binary("+", _v("a"), _v("b")), _v("c")), "a plus b plus c"),
    # "atoms": every operand that is not a number, variable or call is bracketed
    (n.Binary("==", n.Binary("+", _v("a"), n.Num(1.0)), n.Num(-2.0)), "<a plus 1> is <-2>"),
    (n.Binary("==", n.Func("sqrt", [_v("a")]), _v("b")), "ROOT<a> is b"),
    # "always": even atoms
    (n.Binary("and", _v("a"), _v("b")), "<a> & <b>"),
    (n.Unary("-", n.Binary("*", _v("a"), _v("b"))), "neg <a times b>"),
    (n.Func("sqrt", [n.Binary("+", _v("a"), _v("b"))]), "ROOT<a plus b>"),
])
def test_printer_reads_operators_precedence_and_brackets_from_the_table(expr, text):
    assert _Toy().expr(expr) == text


def test_what_the_table_does_not_list_is_not_expressible():
    with pytest.raises(NotExpressible, match="operator '-'"):
        _Toy().expr(n.Binary("-", _v("a"), _v("b")))
    with pytest.raises(NotExpressible, match="function SIN"):
        _Toy().expr(n.Func("sin", [_v("a")]))


@pytest.mark.parametrize("value, point, text", [
    (1.0, False, "1"), (1.0, True, "1."), (-0.0, False, "-0"), (0.1, False, "0.1"),
    (123456789.123, False, "123456789.123"), (1e-7, False, "0.0000001"), (2.5e20, False, "250000000000000000000")])
def test_numbers_are_the_exact_shortest_decimal_without_exponent(value, point, text):
    assert format_number(value, point) == text


def test_a_number_that_is_not_finite_is_not_expressible():
    with pytest.raises(NotExpressible):
        format_number(float("nan"))


# ----------------------------------------------------------------- codes from the target's table

def test_iso_turning_cancels_a_g92_shift_with_its_own_code():
    # on an ISO lathe (system A) G92 is a threading cycle; the shift cancel is G50.3 (rules/iso-t.toml)
    r = _emit("G92 X10 Z5\nG92.1\nM30\n", "iso-m", "iso-t")
    lines = r.text.splitlines()
    assert "G50 X20. Z5." in lines        # G50 sets the position on a lathe, X in diameter
    assert "G50.3" in lines and not any("G92" in line for line in lines)


def test_iso_turning_never_writes_the_mill_scale_cancel():
    # a mill's G50 (scaling off) is the lathe's position setting: writing it would set X0 Z0 here
    r = _emit("G0 X1 Z1\nG50\nM30\n", "iso-m", "iso-t")
    assert not any(line.split()[:1] == ["G50"] for line in r.text.splitlines())
    assert "NC402" not in _codes(r)
    assert any(d.rule == "NC401" and "scaling" in d.message for d in r.diagnostics)


def test_iso_turning_refuses_a_rotation():
    # G68 on an ISO lathe is the double-turret mirror, not a rotation: the rotation is refused
    r = _emit("N10 ROT RPL=30\nN20 G1 X10 F100\nN30 ROT\nN40 M30\n", "sinumerik", "iso-t")
    assert "NC402" in _codes(r)
    assert not any(w in ("G68", "G69") for line in r.text.splitlines() for w in line.split())


def test_whole_frame_cancel_on_a_lathe_keeps_only_the_shift_cancel():
    r = _emit("N10 TRANS X5\nN20 G1 X10 F100\nN30 LABEL1:\nN40 TRANS\nN50 M30\n", "sinumerik", "iso-t")
    cancel = next(line for line in r.text.splitlines() if line.startswith("N40"))
    assert cancel == "N40 G52 X0. Y0. Z0."


def test_iso_milling_whole_frame_cancel_still_cancels_every_component():
    r = _emit("N10 TRANS X5\nN20 G1 X10 F100\nN30 LABEL1:\nN40 TRANS\nN50 M30\n", "sinumerik", "iso-m")
    lines = r.text.splitlines()
    at = next(i for i, line in enumerate(lines) if line.startswith("N40"))
    # one cancel a line: the ISO front end keeps one frame code per block (G69 G50 lost the G69)
    assert lines[at:at + 4] == ["N40 G52 X0. Y0. Z0.", "G69", "G50", "G50.1 X0. Y0. Z0."]
