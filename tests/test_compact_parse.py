"""The compact whole parse (Dialect.parse_compact, issue 15): a structured ISO program (loops,
subprogram calls, macro variables) whose plain stretches are held as PlainRuns, spans of the text
read again when they run, so that --flatten and equiv of a 30 MB macro program stay small. What
runs it must give what the whole parse gives: the toolpath and the flattened conversion are
compared with the whole parse's on generated programs and on every corpus program it takes."""
from __future__ import annotations

import io
from pathlib import Path

import pytest

from conftest import CORPUS, TextSink
from nctrans import api, pipeline, plainrun, toolpath_io
from nctrans.dialects.base import CompactBody
from nctrans.dialects.iso_m.frontend import parse_compact
from nctrans.source import from_text

pytestmark = pytest.mark.skipif(plainrun.native is None, reason="runs of plain lines need the native kernel")


def cam(first: int, count: int) -> str:
    return "".join(f"G1 X{i % 97}.125 Y{i % 89}.25 Z-{i % 7}.5\n" for i in range(first, first + count))


# a CAM body around a subprogram called twice, a G28, a WHILE loop of peck drilling (G73, which
# Sinumerik and Fagor lack) and more CAM body; the subprogram follows M30
STRUCTURED = ("%\nO1000\nG21 G90 G17 G40 G49 G80\nT1 M6\nS8000 M3\nG0 X0 Y0 Z5.\nG43 H1 Z50.\nG1 Z-1. F500.\n"
              + cam(0, 400) + "M98 P2000 L2\nG28 G91 Z0\nG90\n#1=0\nWHILE[#1LT3]DO1\nG0 X[#1*10] Y0 Z5.\n"
              "G99 G73 X1. Y1. Z-5. R1. Q0.5 F100.\nG80\n#1=#1+1\nEND1\nG0 Z50.\nG1 F500.\n" + cam(400, 400)
              + "M30\nO2000\nG91 G1 X1. F100.\nY1.\nG90\nM99\n%\n")




def test_plain_stretches_are_held_as_runs():
    program = parse_compact(STRUCTURED, "s.nc").program
    assert type(program.body) is CompactBody
    runs = [x for x in program.body.items if type(x) is plainrun.PlainRun]
    # line 8 `G1 Z-1. F500.` and the 400 CAM lines; after END1 (line 418) `G0 Z50.`, `G1 F500.` and
    # 400 more; the 11 other blocks and the WHILE are held as parsed, M30 ends the main body
    assert [(r.line, r.blocks) for r in runs] == [(8, 401), (419, 402)]
    assert len(program.body.items) == 13 and "O2000" in program.subprograms


@pytest.mark.parametrize("text", [
    "G0 X1\nN10 G1 X2 F100\nX3\nX4\nGOTO 10\nM30\n",                 # a jump back into the main body
    "G0 X1\nG1 X2 F100\nX3\nX4\nM99\n",                              # M99 ends the main: it restarts
    "G0 X1\nN20 G1 X2 F100\nX3\nX4\nM98 P5\nM30\nO5\nG0 X1\nM99 P20\n",  # returns to N20 of the main
])
def test_programs_that_jump_into_the_main_body_are_parsed_whole(text):
    assert parse_compact(text, "j.nc") is None


def _compare(text: str, name: str) -> None:
    """The compact parse runs as the whole parse does (records, diagnostics), and --flatten
    written as it runs (compact) gives the text and diagnostics of --flatten held whole."""
    src = from_text(text, name)
    whole = pipeline.load_source(src, name, "iso-m")
    compact = pipeline.load_source(src, name, "iso-m", compact=True)
    assert type(compact.program.body) is CompactBody
    assert [d.format_text() for d in compact.diagnostics] == [d.format_text() for d in whole.diagnostics]
    a, b = list(pipeline.toolpath_of(whole)), list(pipeline.toolpath_of(compact))
    assert [r.to_dict() for r in a] == [r.to_dict() for r in b]
    assert [d.format_text() for d in whole.diagnostics] == [d.format_text() for d in compact.diagnostics]
    # `nctrans toolpath` (jsonl): the runs go through the native kernel
    texts = []
    for ld in (pipeline.load_source(src, name, "iso-m"), pipeline.load_source(src, name, "iso-m", compact=True)):
        buf = io.StringIO()
        toolpath_io.write_jsonl(pipeline.toolpath_of(ld, fast_sink="jsonl"), buf)
        texts.append((buf.getvalue(), [d.format_text() for d in ld.diagnostics]))
    assert texts[0] == texts[1]
    for target in ("iso-m", "sinumerik", "fagor"):
        held = api.transpile(text, "iso-m", target, flatten=True, file=name)
        sink = TextSink()
        streamed = api.transpile(text, "iso-m", target, flatten=True, file=name, out=sink)
        assert (streamed.text is None) == (held.text is None)
        if held.text is not None:
            assert "".join(sink.parts) == held.text
        assert [d.format_text() for d in streamed.diagnostics] == [d.format_text() for d in held.diagnostics]


def test_a_structured_program_runs_and_flattens_as_parsed_whole():
    _compare(STRUCTURED, "s.nc")


def _compact_corpus() -> list[Path]:
    out = []
    for d in ("iso-mill", "linuxcnc"):
        for p in sorted((CORPUS / d).glob("*")) if (CORPUS / d).is_dir() else ():
            text = p.read_text(encoding="utf-8", errors="replace")
            if pipeline.get_dialect("iso-m").parse_stream(text, p.name) is None \
                    and parse_compact(text, p.name) is not None:
                out.append(p)
    return out


@pytest.mark.parametrize("path", _compact_corpus(), ids=lambda p: p.name)
def test_corpus_programs_parsed_compact_run_as_parsed_whole(path):
    _compare(path.read_text(encoding="utf-8", errors="replace"), path.name)
