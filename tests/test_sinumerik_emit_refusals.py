"""The Sinumerik emitter on the emitter base: what it cannot write is an NC402 error at the line
of the statement, and the statement is left out. Before, an expression it could not write put a
placeholder into the text (`R100=R0` for an ISO system variable with no Sinumerik equivalent, an
unknown operator spelled as its IR name) and an unknown unary operator crashed it (KeyError)."""
from __future__ import annotations

import nctrans
from nctrans.dialects.base import get
from nctrans.ir import nodes as ir


def emit(body: list, dialect: str = "iso-m"):
    return get("sinumerik").emit(ir.Program("t.nc", dialect, body, {}, {}))


def block(line: int, *stmts) -> ir.Block:
    return ir.Block(ir.Span("t.nc", line), list(stmts))


def refusals(res) -> list:
    return [d for d in res.diagnostics if d.rule == "NC402" and d.severity == "error"]


def r(n: int) -> ir.Var:
    return ir.Var("R", n)


def test_system_variable_without_equivalent_is_refused_not_written_as_r0():
    ld = nctrans.parse("G90 G21 G54\nG54.1 P1\n#100=#4014\nG0 X#100\nM30\n", "iso-m")
    res = get("sinumerik").emit(ld)
    assert [d.line for d in refusals(res)] == [3]
    assert "#4014" in refusals(res)[0].message
    assert "R100=" not in res.text          # was "R100=R0": silently wrong
    assert "G0 X=R100" in res.text           # the other statements are written


def test_unknown_binary_operator_is_refused_at_its_line():
    res = emit([block(1, ir.Assign(r(1), ir.Num(1.0))),
                block(2, ir.Assign(r(2), ir.Binary("shl", r(1), ir.Num(2.0)))),
                block(3, ir.Assign(r(3), ir.Num(3.0)))])
    assert [d.line for d in refusals(res)] == [2]
    assert "shl" in refusals(res)[0].message
    assert res.text.split() == ["R1=1", "R3=3"]     # was "R2=R1shl2"


def test_unknown_unary_operator_is_refused_not_a_crash():
    res = emit([block(4, ir.Assign(r(1), ir.Unary("sqrt", ir.Num(2.0))))])   # was KeyError
    assert [d.line for d in refusals(res)] == [4]
    assert "R1=" not in res.text


def test_condition_that_cannot_be_written_refuses_the_whole_structure():
    cond = ir.Binary("==", ir.Var("num", 4014), ir.Num(1.0))
    body = [block(1, ir.Assign(r(1), ir.Num(1.0))),
            ir.If(ir.Span("t.nc", 2), cond, [block(3, ir.Assign(r(2), ir.Num(2.0)))]),
            block(4, ir.Assign(r(3), ir.Num(3.0)))]
    res = emit(body)
    assert [d.line for d in refusals(res)] == [2]
    assert res.text.split() == ["R1=1", "R3=3"]     # no IF line with a placeholder, no orphan ENDIF


def test_string_with_a_double_quote_is_refused():
    res = emit([block(5, ir.Message(ir.Str('say "hi"')))], dialect="fagor")
    assert [d.line for d in refusals(res)] == [5]
    assert "MSG" not in res.text                   # was MSG("say 'hi'") with the quotes changed


def test_conversion_lowers_the_refused_statement_instead():
    # through the conversion policy the refusal is lowered or refused, never written as R0
    conv = nctrans.transpile("G90 G21 G54\nG54.1 P1\n#100=#4014\nG0 X#100\nM30\n",
                             read="iso-m", write="sinumerik")
    assert "R0" not in (conv.text or "")
