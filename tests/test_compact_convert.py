"""Structural conversion of a compact parse (issue 15): `convert` without --flatten of a structured
program whose plain stretches are held as PlainRuns (Dialect.parse_compact), the emitters writing
them a few blocks at a time, must give the bytes and diagnostics of the whole parse, on every
target: on generated programs (hypothesis), on corpus programs the compact parse takes, and where
a construct's lowering reaches into a run (NeedsWholeParse: converted again parsed whole)."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import CORPUS
from nctrans import api, pipeline, plainrun
from nctrans.dialects.base import CompactBody
from nctrans.source import from_text

pytestmark = pytest.mark.skipif(plainrun.native is None, reason="runs of plain lines need the native kernel")

TARGETS = ("iso-m", "sinumerik", "fagor", "iso-t")


class Sink:
    def __init__(self):
        self.parts: list[str] = []

    def write(self, s: str) -> None:
        self.parts.append(s)

    def reset(self) -> None:
        self.parts = []


def _same_both_ways(text: str, name: str, source: str, targets=TARGETS) -> None:
    """Converted held whole (no output sink: parsed whole) and written as it goes (parsed compact):
    the same text and diagnostics."""
    for target in targets:
        held = api.transpile(text, source, target, file=name)
        sink = Sink()
        written = api.transpile(text, source, target, file=name, out=sink)
        assert (written.text is None) == (held.text is None), target
        if held.text is not None:
            assert "".join(sink.parts) == held.text, target
        assert [d.format_text() for d in written.diagnostics] == [d.format_text() for d in held.diagnostics], target


def _compact(text: str, name: str, source: str) -> bool:
    ld = pipeline.load_source(from_text(text, name), name, source, stream=True, compact=True)
    return ld.streamed is None and type(ld.program.body) is CompactBody


def cam(first: int, count: int, numbered: bool = False) -> str:
    return "".join(f"{f'N{10 * i} ' if numbered else ''}G1 X{i % 97}.125 Y{i % 89}.25 Z-{i % 7}.5\n"
                   for i in range(first, first + count))


# a CAM body around a subprogram called twice, a G28, a WHILE loop of peck drilling (G73, which
# Sinumerik and Fagor lack: lowered), a FOR-less counting loop and more CAM body
STRUCTURED = ("%\nO1000\nG21 G90 G17 G40 G49 G80\nT1 M6\nS8000 M3\nG0 X0 Y0 Z5.\nG43 H1 Z50.\nG1 Z-1. F500.\n"
              + cam(0, 300, numbered=True) + "M98 P2000 L2\nG28 G91 Z0\nG90\n#1=0\nWHILE[#1LT3]DO1\n"
              "G0 X[#1*10] Y0 Z5.\nG99 G73 X1. Y1. Z-5. R1. Q0.5 F100.\nG80\n#1=#1+1\nEND1\nG0 Z50.\n"
              "G1 F500.\n" + cam(300, 300) + "M30\nO2000\nG91 G1 X1. F100.\nY1.\nG90\nM99\n%\n")

# a peck drilling cycle (refused by Sinumerik and Fagor) inside a local offset (G52) that holds
# CAM stretches: its lowering is widened over the offset's whole run, runs included, so the
# program is converted again parsed whole
OFFSET_AROUND_RUNS = ("%\nO1001\nG21 G90 G17 G40 G80\nT1 M6\nS8000 M3\nG0 X0 Y0 Z5.\nG52 X10. Y5.\n"
                      + cam(0, 50) + "G99 G73 X1. Y1. Z-5. R1. Q0.5 F100.\nX2.\nG80\n" + cam(50, 50)
                      + "G52 X0 Y0\nM98 P2000\n" + cam(100, 50) + "M30\nO2000\nG0 Z10.\nM99\n%\n")


def test_a_structured_program_converts_as_parsed_whole():
    assert _compact(STRUCTURED, "s.nc", "iso-m")
    _same_both_ways(STRUCTURED, "s.nc", "iso-m")


def test_a_lowering_over_a_run_converts_the_program_parsed_whole():
    assert _compact(OFFSET_AROUND_RUNS, "o.nc", "iso-m")
    _same_both_ways(OFFSET_AROUND_RUNS, "o.nc", "iso-m")


def test_a_compact_conversion_holds_no_block_of_its_runs(monkeypatch):
    """The emitters take a run's blocks a few at a time: never the whole run at once."""
    taken: list[int] = []
    take = plainrun.PlainRun.take

    def counting_take(self, count):
        blocks, rest = take(self, count)
        taken.append(len(blocks))
        return blocks, rest
    monkeypatch.setattr(plainrun.PlainRun, "take", counting_take)
    text = STRUCTURED.replace(cam(300, 300), cam(300, 5000))
    sink = Sink()
    assert api.transpile(text, "iso-m", "iso-m", file="s.nc", out=sink).text == ""
    assert taken and max(taken) <= plainrun.RUN_CHUNK
    written = "".join(sink.parts)
    assert "WHILE[#1LT3]DO1" in written and "X61.125 Y48.25 Z-0.5" in written


# --------------------------------------------------------------------------- generated programs

_MOVE = st.builds(lambda g, x, y, z: f"G{g} X{x}.5 Y{y} Z-{z}.25", st.sampled_from([0, 1]),
                  st.integers(-50, 50), st.integers(-50, 50), st.integers(0, 9))
_ARC = st.builds(lambda d, x, i: f"G{d} X{x}. Y0 I{i}. J0", st.sampled_from([2, 3]), st.integers(1, 20),
                 st.integers(1, 10))
_PLAIN = st.lists(st.one_of(_MOVE, _MOVE, _ARC), min_size=2, max_size=12)
_STRUCTURES = st.sampled_from([
    "M98 P2000",
    "G28 G91 Z0\nG90",
    "#1=0\nWHILE[#1LT2]DO1\nG0 X[#1*5] Y0 Z5.\n#1=#1+1\nEND1",
    "IF[#5LT1]THEN#5=2",
    "G81 X1. Y1. Z-3. R1. F80.\nX4.\nG80",
    "G99 G73 X2. Y1. Z-5. R1. Q0.5 F100.\nG80",
    "G52 X5. Y5.",
    "G52 X0 Y0",
    "G91 G0 X1.\nG90",
    "(a comment)",
    "N5000 M1",
    "G17 G18\nG17",
])


@st.composite
def structured_programs(draw) -> str:
    parts = ["%", "O1000", "G21 G90 G17 G40 G80 F500.", "T1 M6", "S6000 M3"]
    number = 10
    for _ in range(draw(st.integers(1, 5))):
        lines = draw(_PLAIN)
        if draw(st.booleans()):
            lines = [f"N{number + 10 * k} {line}" for k, line in enumerate(lines)]
            number += 10 * len(lines)
        parts.extend(lines)
        parts.append(draw(_STRUCTURES))
    parts.extend(draw(_PLAIN))
    parts += ["M30", "O2000", "G91 G1 X1. F100.", "G90", "M99", "%"]
    return "\n".join(parts) + "\n"


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(structured_programs())
def test_generated_structured_programs_convert_as_parsed_whole(text):
    if not _compact(text, "g.nc", "iso-m"):
        return                  # nothing compact to compare (no run, or a jump into the main body)
    _same_both_ways(text, "g.nc", "iso-m")


# --------------------------------------------------------------------------- corpus

def _compact_corpus() -> list[tuple[Path, str]]:
    out = []
    for d, dialect in (("iso-mill", "iso-m"), ("linuxcnc", "iso-m"), ("sinumerik", "sinumerik")):
        for p in sorted((CORPUS / d).glob("*")) if (CORPUS / d).is_dir() else ():
            if p.stat().st_size > 150_000:
                continue
            text = p.read_text(encoding="utf-8", errors="replace")
            if _compact(text, p.name, dialect):
                out.append((p, dialect))
    return out


@pytest.mark.parametrize("path,dialect", _compact_corpus(), ids=lambda x: getattr(x, "name", x))
def test_corpus_programs_parsed_compact_convert_as_parsed_whole(path, dialect):
    _same_both_ways(path.read_text(encoding="utf-8", errors="replace"), path.name, dialect)
