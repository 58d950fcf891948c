"""The conversion policy: structural first, plain motion when the target cannot express a construct,
refusal only when even plain motion cannot carry it; --strict refuses every lowering."""
from pathlib import Path

from nctrans import equivalence as equiv
from nctrans.convert import CONSTRUCT_NOTE, convert
from nctrans.dialects.base import get
from nctrans.interp import interpret
from nctrans.lower.flatten import flatten

SIN = """DEF REAL DEPTH=2
N10 G17 G90 G71
N20 T1 M6
N30 G0 X0 Y0 Z5
LOOP_START:
N40 G1 Z=-DEPTH F200
N50 X=AC(20) Y=IC(5)
N60 DEPTH=DEPTH+2
N70 IF DEPTH<=6 GOTOB LOOP_START
N80 G0 Z5
M30
"""


def _records(program):
    return list(interpret(program, None, diagnostics=[]))


def _convert(text, src, dst, **kw):
    program = get(src).parse(text, "p." + src).program
    res = convert(program, get(dst),
                  flatten_with=lambda diags: flatten(program, None, diagnostics=diags), **kw)
    return program, res


def test_construct_the_target_lacks_is_lowered_alone_with_a_located_info():
    # X=AC(20) has no ISO word: its label loop (lines 5-9) becomes plain motion, the rest stays
    program, res = _convert(SIN, "sinumerik", "iso-m")
    assert res.text is not None and not res.flattened
    infos = [d for d in res.diagnostics if d.rule == "NC401" and CONSTRUCT_NOTE in d.message]
    assert [(d.line, d.severity) for d in infos] == [(7, "info")]
    assert "lines 5-9" in infos[0].message
    lines = res.text.splitlines()
    assert "#100=2" in lines and "N20 T1 M6" in lines and "N80 G0 Z5." in lines   # kept as written
    assert "GOTO" not in res.text                    # the loop itself was run out
    out = get("iso-m").parse(res.text, "p.nc").program
    assert equiv.compare(_records(program), _records(out)) is None


def test_strict_refuses_the_lowering():
    _, res = _convert(SIN, "sinumerik", "iso-m", strict_mode=True)
    assert res.text is None
    assert any(d.severity == "error" and d.rule in ("NC401", "NC402") for d in res.diagnostics)


def test_expressible_program_stays_structured():
    iso = "G21 G90\n#1=0\nWHILE [#1 LT 3] DO1\nG1 X[#1*10] F100\n#1=#1+1\nEND1\nM30\n"
    program, res = _convert(iso, "iso-m", "sinumerik")
    assert res.text is not None and not res.flattened
    assert "WHILE" in res.text.upper()
    out = get("sinumerik").parse(res.text, "p.mpf").program
    assert equiv.compare(_records(program), _records(out)) is None
