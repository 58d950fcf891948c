"""The whole-program lowering (convert's last resort) says the same whether it is held or written
as it runs (`convert -o`, an output stream): the notes of the lowering passes that ran before it
(FOR loops written as WHILE for ISO) were dropped by the streamed one."""
from __future__ import annotations

import pytest

from conftest import TextSink
from nctrans import api

# The WHILE loop's cycle sets R1, which the program reads after it: the cycle cannot be lowered
# alone, so the whole program becomes plain motion; the FOR loop before it is what ISO lacks.
FOR_THEN_WHOLE = """DEF INT COUNT
G17 G90 G71
T1 D1
M6
S1000 M3
FOR COUNT=1 TO 3
G1 X=COUNT Y0 F100
ENDFOR
R1=0
WHILE R1<2
G0 X=R1*10 Y0 Z5
CYCLE83(5,0,1,-5,,-2,,1,0.5,0,1,0)
R1=R1+1
ENDWHILE
G0 X=R1
M30
"""


def _notes(conv) -> list[tuple]:
    return [(d.rule, d.severity, d.line, d.column, d.message) for d in conv.diagnostics]


@pytest.mark.parametrize("target", ["iso-m", "iso-t", "fagor"])
def test_streamed_whole_lowering_keeps_the_notes_of_the_held_one(target):
    held = api.transpile(FOR_THEN_WHOLE, "sinumerik", target)
    sink = TextSink()
    streamed = api.transpile(FOR_THEN_WHOLE, "sinumerik", target, out=sink)
    assert held.text is not None and streamed.text is not None
    assert "".join(sink.parts) == held.text
    assert _notes(streamed) == _notes(held)


def test_the_for_loop_note_is_at_the_for_line_when_streamed():
    streamed = api.transpile(FOR_THEN_WHOLE, "sinumerik", "iso-m", out=TextSink())
    notes = [d for d in streamed.diagnostics if "FOR loops written as WHILE loops" in d.message]
    assert [(d.rule, d.line) for d in notes] == [("NC401", 6)]
    assert any("lowered to plain motion" in d.message and d.line == 12 for d in streamed.diagnostics)
