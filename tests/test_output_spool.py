"""An emitter's output lines spilled to a temporary file (nctrans.spilled.OutputLines): a program
that jumps back into its body is written as one structure the writer may still take back, so its
lines were held until the end (a 30 MB ISO M99 restart written as a Sinumerik LOOP peaked at
196 MiB, now 69; bench `--peaks`). Spilled or held, the text is the same, byte for byte."""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from nctrans import api, spilled
from conftest import TextSink

# operations on a list of output lines, as the emitters use them
ops = st.lists(st.one_of(
    st.tuples(st.just("append"), st.text(alphabet="GX1.ä;", max_size=6)),
    st.tuples(st.just("extend"), st.lists(st.text(alphabet="GY2 ", max_size=4), max_size=7)),
    st.tuples(st.just("cut"), st.integers(min_value=0, max_value=40)),
    st.tuples(st.just("insert"), st.integers(min_value=0, max_value=3)),
), max_size=60)


@pytest.fixture
def small_spill(monkeypatch):
    monkeypatch.setattr(spilled, "SPILL_LINES", 4)
    monkeypatch.setattr(spilled, "HEAD_LINES", 3)
    monkeypatch.setattr(spilled, "PIECE", 5)          # pieces end inside characters too


@given(ops)
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_spilled_lines_behave_as_the_list(small_spill, program):
    lines, ref = spilled.OutputLines(), []
    for op, arg in program:
        if op == "append":
            lines.append(arg)
            ref.append(arg)
        elif op == "extend":
            lines.extend(arg)
            ref.extend(arg)
        elif op == "cut":               # a refused structure taken back: del lines[start:]
            del lines[arg:]
            del ref[arg:]
        elif arg <= min(len(ref), 3):   # a name table inserted after the first lines
            lines[arg:arg] = ["(TABLE)", "(A=#1)"]
            ref[arg:arg] = ["(TABLE)", "(A=#1)"]
        assert len(lines) == len(ref)
    assert list(lines) == ref
    text = lines.text()
    assert "".join(spilled.pieces(text)) == str(text) == "\n".join(ref) + "\n"


def _same_spilled_or_held(text: str, source: str, target: str, monkeypatch) -> str:
    outs = []
    for spill_at in (10 ** 9, 7):
        monkeypatch.setattr(spilled, "SPILL_LINES", spill_at)
        monkeypatch.setattr(spilled, "HEAD_LINES", 2)
        sink = TextSink()
        conv = api.transpile(text, source, target, file="p", out=sink)
        assert conv.text == "", conv.diagnostics
        outs.append(("".join(sink.parts), [d.format_text() for d in conv.diagnostics]))
    assert outs[0] == outs[1]
    return outs[0][0]


def cam(first: int, count: int, numbered: bool = False) -> str:
    return "".join(f"{f'N{10 * i} ' if numbered else ''}G1 X{i % 97}.125 Y{i % 89}.25 Z-{i % 7}.5\n"
                   for i in range(first, first + count))


def test_an_iso_restart_written_as_a_loop_is_the_same_spilled(monkeypatch):
    text = "%\nO1000\nG21 G90 G17 G40 G80 F500.\nT1 M6\nS6000 M3\n" + cam(0, 60) + "M99\n%\n"
    out = _same_spilled_or_held(text, "iso-m", "sinumerik", monkeypatch)
    assert "LOOP" in out and out.count("\n") > 60


def test_a_sinumerik_label_loop_written_to_iso_is_the_same_spilled(monkeypatch):
    text = ("%_N_LOOP_MPF\nDEF INT CNT\nG71 G90 G17 G40 F500\nT1 D1 M6\nS6000 M3\nG0 X0 Y0 Z5\nCNT=0\n"
            "TOP:\n" + cam(0, 40) + "CNT=CNT+1\nIF CNT<2 GOTOB TOP\n" + cam(40, 40) + "M30\n")
    for target in ("iso-m", "fagor", "iso-t"):
        out = _same_spilled_or_held(text, "sinumerik", target, monkeypatch)
        assert out.count("\n") > 80


def test_an_iso_goto_loop_with_a_refused_structure_is_the_same_spilled(monkeypatch):
    # a WHILE Sinumerik cannot write (G73 in it: lowered) inside a jump loop
    text = ("%\nO1000\nG21 G90 G17 G40 G80 F500.\nT1 M6\nS6000 M3\n#100=0\n" + cam(0, 20, numbered=True)
            + "#1=0\nWHILE[#1LT2]DO1\nG0 X[#1*10] Y0 Z5.\nG99 G73 X1. Y1. Z-5. R1. Q0.5 F100.\nG80\n"
            "#1=#1+1\nEND1\n#100=#100+1\nIF[#100LT2]GOTO100\n" + cam(20, 20) + "M30\n%\n")
    for target in ("sinumerik", "fagor"):
        _same_spilled_or_held(text, "iso-m", target, monkeypatch)
