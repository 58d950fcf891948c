"""Structural conversion of a compact parse (issue 15): `convert` without --flatten of a structured
program whose plain stretches are held as PlainRuns (Dialect.parse_compact), the emitters writing
them a few blocks at a time, must give the bytes and diagnostics of the whole parse, on every
target: on generated programs (hypothesis), on corpus programs the compact parse takes, and where
a construct's lowering reaches into a run (more in test_compact_lowering.py)."""
from __future__ import annotations

import re
from contextlib import contextmanager
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import CORPUS, TextSink
from nctrans import api, pipeline, plainrun
from nctrans.dialects.base import CompactBody
from nctrans.source import from_text

pytestmark = pytest.mark.skipif(plainrun.native is None, reason="runs of plain lines need the native kernel")

TARGETS = ("iso-m", "sinumerik", "fagor", "iso-t")



def _same_both_ways(text: str, name: str, source: str, targets=TARGETS) -> None:
    """Written as it goes (an output sink), parsed compact and parsed whole (the dialect's
    parse_compact switched off): the same text and diagnostics."""
    dialect = pipeline.get_dialect(source)
    for target in targets:
        results = []
        for compact in (True, False):
            sink = TextSink()
            with _parse_compact(dialect, compact):
                done = api.transpile(text, source, target, file=name, out=sink)
            results.append(("".join(sink.parts) if done.text is not None else None,
                            [d.format_text() for d in done.diagnostics]))
        assert results[0] == results[1], target


@contextmanager
def _parse_compact(dialect, on: bool):
    """The dialect parses compact (as it does) or never (its whole parse)."""
    if on:
        yield
        return
    cls = type(dialect)
    had = "parse_compact" in cls.__dict__
    saved = cls.__dict__.get("parse_compact")
    cls.parse_compact = lambda self, text, file="<stdin>", jumps=False: None
    try:
        yield
    finally:
        if had:
            cls.parse_compact = saved
        else:
            del cls.parse_compact


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
# CAM stretches: its lowering is widened over the offset's whole run, runs included (lowered
# without the whole parse: nctrans.lower.compact_constructs, tests/test_compact_lowering.py)
OFFSET_AROUND_RUNS = ("%\nO1001\nG21 G90 G17 G40 G80\nT1 M6\nS8000 M3\nG0 X0 Y0 Z5.\nG52 X10. Y5.\n"
                      + cam(0, 50) + "G99 G73 X1. Y1. Z-5. R1. Q0.5 F100.\nX2.\nG80\n" + cam(50, 50)
                      + "G52 X0 Y0\nM98 P2000\n" + cam(100, 50) + "M30\nO2000\nG0 Z10.\nM99\n%\n")


def test_a_structured_program_converts_as_parsed_whole():
    assert _compact(STRUCTURED, "s.nc", "iso-m")
    _same_both_ways(STRUCTURED, "s.nc", "iso-m")
    _same_runs(STRUCTURED, "s.nc", "iso-m")


# a G65 macro in the same file, called around long plain stretches: it becomes a PROC with named
# parameters (macro_procs) whichever way the program was parsed
MACRO_IN_FILE = ("O1000\nG21 G90 G17 G54\nT1 M6\nS1000 M3\n" + cam(0, 300) + "G65 P3000 A1. B2.\n"
                 + cam(300, 300) + "G65 P3000 A3. B4.\nM30\nO3000\nG1 X#1 Y#2 F100\nM99\n")


def test_a_macro_called_between_runs_becomes_a_proc_as_parsed_whole():
    assert _compact(MACRO_IN_FILE, "m.nc", "iso-m")
    _same_both_ways(MACRO_IN_FILE, "m.nc", "iso-m", targets=("sinumerik",))
    out = api.transpile(MACRO_IN_FILE, "iso-m", "sinumerik", file="m.nc").text
    assert "PROC L3000(REAL ARG_A, REAL ARG_B" in out and "L3000(1., 2.)" in out


def test_a_lowering_over_runs_converts_as_parsed_whole():
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
    sink = TextSink()
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
    _same_runs(text, "g.nc", "iso-m")


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


# What makes a straight CAM program structured (as bench --peaks does): a subprogram call, a G28, a
# WHILE loop of peck drilling, in the middle of its body; the subprogram after its end.
_MIDDLE = "M98 P2000 L2\nG28 G91 Z0\nG90\n#1=0\nWHILE[#1LT2]DO1\nG0 X[#1*10] Y0 Z5.\n" \
          "G99 G73 X1. Y1. Z-5. R1. Q0.5 F100.\nG80\n#1=#1+1\nEND1\n"
_END = re.compile(r"^\s*(%|O\d+.*|.*\bM0*(2|30)\b.*)\s*$", re.IGNORECASE)


def _made_structured(text: str) -> str:
    body = [line for line in text.splitlines() if not _END.match(line)]
    mid = len(body) // 2
    return "%\n" + "\n".join(body[:mid]) + "\n" + _MIDDLE + "\n".join(body[mid:]) \
        + "\nM30\nO2000\nG91 G1 X1. F100.\nY1.\nG90\nM99\n%\n"


def _cam_corpus() -> list[Path]:
    """Straight CAM programs of the ISO corpus (they stream), 5-40 KB, that are held compact when
    made structured: three, spread over the sources."""
    found = []
    for p in sorted((CORPUS / "iso-mill").glob("*")) if (CORPUS / "iso-mill").is_dir() else ():
        if not 5_000 <= p.stat().st_size <= 40_000:
            continue
        text = p.read_text(encoding="utf-8", errors="replace")
        if pipeline.get_dialect("iso-m").parse_stream(text, p.name) is not None \
                and _compact(_made_structured(text), p.name, "iso-m"):
            found.append(p)
    return found[::max(1, len(found) // 3)][:3]


@pytest.mark.parametrize("path", _cam_corpus(), ids=lambda p: p.name)
def test_corpus_cam_programs_made_structured_convert_as_parsed_whole(path):
    text = _made_structured(path.read_text(encoding="utf-8", errors="replace"))
    assert _compact(text, path.name, "iso-m")
    _same_both_ways(text, path.name, "iso-m")


# --------------------------------------------------------------------------- Sinumerik sources

def sinumerik_cam(first: int, count: int) -> str:
    return "".join(f"G1 X{i % 97}.125 Y{i % 89}.25 Z-{i % 7}.5\n" for i in range(first, first + count))


# a Sinumerik CAM program with structure between long plain stretches: a WHILE loop around a drilling
# cycle, a FOR loop calling a subprogram of the same file, an IF, R parameters
SINUMERIK_STRUCTURED = (
    "%_N_PART_MPF\nDEF INT COUNT\nG0 G54 G64\nG71 G90 G17 G40 G94\nT1 D1 M6\nS8000 M3\nG0 X0 Y0 Z5\n"
    "G1 Z-1 F500\n" + sinumerik_cam(0, 300) + "R1=0\nWHILE R1<3\nG0 X=R1*10 Y0 Z5\n"
    "CYCLE83(5,0,1,-5,,-2,,1,0.5,0,1,0)\nR1=R1+1\nENDWHILE\nFOR COUNT=1 TO 2\nL2000\nENDFOR\n"
    "IF R1>2\nG0 Z20\nENDIF\nG1 F400\n" + sinumerik_cam(300, 300) + "G2 X10 Y0 I5 J0\nX20 Y0 I5 J0\n"
    + sinumerik_cam(600, 20) + "M30\n%_N_L2000_SPF\nG91 G1 X1 F100\nY1\nG90\nM17\n")


def _same_runs(text: str, name: str, source: str) -> None:
    """Run parsed compact and parsed whole: the same records, jsonl and diagnostics; and lint."""
    src = from_text(text, name)
    whole = pipeline.load_source(src, name, source)
    compact = pipeline.load_source(src, name, source, compact=True)
    assert type(compact.program.body) is CompactBody
    a, b = list(pipeline.toolpath_of(whole)), list(pipeline.toolpath_of(compact))
    assert [r.to_dict() for r in a] == [r.to_dict() for r in b]
    assert [d.format_text() for d in whole.diagnostics] == [d.format_text() for d in compact.diagnostics]
    dialect = pipeline.get_dialect(source)
    found = []
    for on in (True, False):
        with _parse_compact(dialect, on):
            found.append([d.format_text() for d in api.lint(text, source, file=name)])
    assert found[0] == found[1]


def test_a_structured_sinumerik_program_is_held_compact():
    program = pipeline.get_dialect("sinumerik").parse_compact(SINUMERIK_STRUCTURED, "p.mpf").program
    runs = [x for x in program.body.items if type(x) is plainrun.PlainRun]
    # `G0 X0 Y0 Z5` (line 7), `G1 Z-1 F500` and 300 CAM lines (to line 308); after ENDIF (line 320)
    # `G1 F400`, 300 more, the two arcs (the second by centre words alone, after G2) and 20 more
    assert [(r.line, r.blocks) for r in runs] == [(7, 302), (321, 323)]
    assert "L2000" in program.subprograms


@pytest.mark.parametrize("text", [
    "N10 G0 X1\nG1 X2 F100\nX3\nX4\nGOTOB N10\nM30\n",                 # a jump back into the main body
    "MARK: G0 X1\nG1 X2 F100\nX3\nX4\nREPEAT MARK P=2\nM30\n",          # a repetition of a section of it
    "PROC PART\nG0 X1\nG1 X2 F100\nX3\nX4\nM17\n",                     # a PROC file
])
def test_sinumerik_programs_that_jump_into_the_main_body_are_parsed_whole(text):
    assert pipeline.get_dialect("sinumerik").parse_compact(text, "j.mpf") is None


def test_a_structured_sinumerik_program_runs_and_converts_as_parsed_whole():
    _same_runs(SINUMERIK_STRUCTURED, "p.mpf", "sinumerik")
    _same_both_ways(SINUMERIK_STRUCTURED, "p.mpf", "sinumerik")


_SIN_MOVE = _MOVE             # the same words read the same in both dialects
_SIN_ARC = st.builds(lambda d, x, i: f"G{d} X{x} Y0 I{i} J0", st.sampled_from([2, 3]), st.integers(1, 20),
                     st.integers(1, 10))
_SIN_PLAIN = st.lists(st.one_of(_SIN_MOVE, _SIN_MOVE, _SIN_ARC), min_size=2, max_size=12)
_SIN_STRUCTURES = st.sampled_from([
    "L2000",
    "R1=0\nWHILE R1<2\nG0 X=R1*5 Y0 Z5\nR1=R1+1\nENDWHILE",
    "FOR COUNT=1 TO 2\nG91 G1 X1\nG90\nENDFOR",
    "IF R2<1\nR2=2\nENDIF",
    "MCALL CYCLE81(5,0,1,-3)\nX4 Y4\nMCALL",
    "CYCLE83(5,0,1,-5,,-2,,1,0.5,0,1,0)",
    "TRANS X5 Y5",
    "TRANS",
    "G91 G0 X1\nG90",
    "; a comment",
    "N5000 M1",
    "G17 G18\nG17",
])


@st.composite
def sinumerik_programs(draw) -> str:
    parts = ["%_N_GEN_MPF", "DEF INT COUNT", "G71 G90 G17 G40 F500", "T1 D1 M6", "S6000 M3"]
    for _ in range(draw(st.integers(1, 5))):
        lines = draw(_SIN_PLAIN)
        if draw(st.booleans()):
            lines = [f"N{10 * (k + 1)} {line}" for k, line in enumerate(lines)]
        parts.extend(lines)
        parts.append(draw(_SIN_STRUCTURES))
    parts.extend(draw(_SIN_PLAIN))
    parts += ["M30", "%_N_L2000_SPF", "G91 G1 X1 F100", "G90", "M17"]
    return "\n".join(parts) + "\n"


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(sinumerik_programs())
def test_generated_sinumerik_programs_run_and_convert_as_parsed_whole(text):
    if not _compact(text, "g.mpf", "sinumerik"):
        return
    _same_runs(text, "g.mpf", "sinumerik")
    _same_both_ways(text, "g.mpf", "sinumerik")
