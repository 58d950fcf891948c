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
    assert "#100=2" in lines and "N20 T1 M6 G43 H1" in lines and "N80 G0 Z5." in lines   # kept as written
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


def test_a_lowered_construct_holds_at_most_the_documented_number_of_blocks(monkeypatch):
    """The label loop (3 passes, 2 moves each) is more than 4 blocks of plain motion: with the
    held limit at 4 it is refused at the construct's line, naming the limit, and the whole program
    is not lowered instead (it would be larger still)."""
    from nctrans.convert import HELD_LIMIT_NOTE
    monkeypatch.setenv("NCTRANS_MAX_LOWERED_BLOCKS", "4")
    _, res = _convert(SIN, "sinumerik", "iso-m")
    assert res.text is None and not res.flattened
    refused = [d for d in res.diagnostics if d.rule == "NC402" and d.severity == "error"]
    assert [d.line for d in refused] == [7]
    assert HELD_LIMIT_NOTE in refused[0].message and "past 4 blocks" in refused[0].message
    monkeypatch.setenv("NCTRANS_MAX_LOWERED_BLOCKS", "40")
    _, res = _convert(SIN, "sinumerik", "iso-m")
    assert res.text is not None


def test_the_whole_program_held_in_memory_is_bounded_too():
    program = get("iso-m").parse("G21 G90\nG1 X1 F100\nX2\nX3\nX4\nX5\nM30\n", "p.nc").program
    diags: list = []
    flat = flatten(program, None, diagnostics=diags, max_blocks=3)
    assert len(flat.body) == 4
    assert [(d.rule, d.severity, d.line) for d in diags if d.rule == "NC402"] == [("NC402", "error", 4)]


class _Sink:
    def __init__(self):
        self.parts: list = []

    def write(self, text):
        self.parts.append(text)

    def reset(self):
        self.parts = []


def test_the_whole_program_fallback_streams_past_the_held_limit(monkeypatch):
    """The label loop sets R1, which outlives the program, so it cannot be lowered alone: the
    whole program becomes plain motion (100 moves). Held in memory that is over a limit of 50
    blocks (refused, saying so at the construct); written to an output as it runs it is not, and
    the text is the one the default limit gives."""
    from nctrans import api
    from nctrans.convert import HELD_LIMIT_NOTE
    text = "G17 G90 G71\nR1=0\nLBL:\nG1 X=AC(R1) Y=IC(1) F100\nR1=R1+1\nIF R1<100 GOTOB LBL\nM30\n"
    held = api.transpile(text, "sinumerik", "iso-m")
    assert held.text is not None and held.text.count("\nX") == 99
    monkeypatch.setenv("NCTRANS_MAX_LOWERED_BLOCKS", "50")
    refused = api.transpile(text, "sinumerik", "iso-m")
    errors = [d for d in refused.diagnostics if d.severity == "error"]
    assert refused.text is None and [d.line for d in errors] == [4]
    assert HELD_LIMIT_NOTE in errors[0].message and "past 50 blocks" in errors[0].message
    sink = _Sink()
    streamed = api.transpile(text, "sinumerik", "iso-m", out=sink)
    assert streamed.text == "" and "".join(sink.parts) == held.text
    assert [d.format_text() for d in streamed.diagnostics] == [d.format_text() for d in held.diagnostics]


# three X=AC words in one IF: the segment (lines 7-9) is lowered once, so one NC401 names it
SEVERAL_IN_ONE = """G71 G90 G17 G40 F500
T1 D1 M6
S6000 M3
G0 X0 Y0 Z5
R1=0
IF R1<2
G1 X=AC(20) Y1
G1 X=AC(3) Y2
G1 X=AC(4) Y2
ENDIF
G0 X0
M30
"""


def test_a_segment_lowered_alone_is_named_once():
    program, res = _convert(SEVERAL_IN_ONE, "sinumerik", "iso-m")
    assert res.text is not None and not res.flattened
    infos = [d for d in res.diagnostics if d.rule == "NC401" and CONSTRUCT_NOTE in d.message]
    # was one note per refused line (7, 8, 9), each saying "lines 7-9 were lowered" (the blocks
    # inside the IF: the IF line itself is not a block)
    assert [d.line for d in infos] == [7]
    assert "nor what lines 8, 9 hold" in infos[0].message and "lines 7-9 were" in infos[0].message
    out = get("iso-m").parse(res.text, "p.nc").program
    assert equiv.compare(_records(program), _records(out)) is None
