"""Streamed iso-m parse + run (pipeline.load(..., stream=True)) against the full parse: the same
toolpath and the same diagnostics in the same order on every iso-mill corpus program, control flow
sent to the full parse, and memory that does not grow with program length."""
from __future__ import annotations

import tracemalloc
from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

from nctrans import pipeline, source
from nctrans.machine import Machine
from nctrans.dialects.base import StreamedBody
from nctrans.dialects.iso_m.frontend import parse_program, parse_stream
from conftest import CORPUS

ISO_MILL = CORPUS / "iso-mill"
PROGRAMS = sorted(ISO_MILL.iterdir()) if ISO_MILL.is_dir() else []


def run(ld: pipeline.Loaded):
    records = [r.to_dict() for r in pipeline.toolpath_of(ld, pipeline.load_machine(None, ld.dialect))]
    return records, [d.to_dict() if hasattr(d, "to_dict") else repr(d) for d in ld.diagnostics]


def both(text: str, name: str = "t.nc"):
    src = source.decode(text.encode(), name)
    full = run(pipeline.load_source(src, name, "iso-m"))
    streamed = pipeline.load_source(src, name, "iso-m", stream=True)
    return full, run(streamed), streamed


@pytest.mark.skipif(not PROGRAMS, reason="shared corpus not found")
@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_corpus_toolpath_and_diagnostics_match_full_parse(path):
    full_ld = pipeline.load(str(path), "iso-m")
    lint_full = [repr(d) for d in pipeline.lint(full_ld)]
    tp_full = run(pipeline.load(str(path), "iso-m"))
    tp_stream = run(pipeline.load(str(path), "iso-m", stream=True))
    lint_stream = [repr(d) for d in pipeline.lint(pipeline.load(str(path), "iso-m", stream=True))]
    assert tp_stream == tp_full
    assert lint_stream == lint_full


def test_cam_program_is_streamed_and_macro_program_is_not():
    assert parse_stream("%\nO1\nG0X1Y2\nG1X3F100.(IF A GOTO B #1)\nM30\n%\n", "a.nc") is not None
    for text in ("#1=2\nG0X#1\nM30\n", "N10G0X1\nGOTO10\n", "WHILE[1LT2]DO1\nG0X1\nEND1\nM30\n",
                 "M98P1000\nM30\nO1000\nG0X1\nM99\n", "G65P9000A1.\nM30\n", "G0X1\nM99\n",
                 "G0 X1\nm 9 9\n", "G0X[1+2]\nM30\n"):
        assert parse_stream(text, "a.nc") is None, text


def test_text_after_program_end_and_later_subprogram_give_the_same_diagnostics():
    text = ("%\nO1\nG0X0Y0\nG1X10F100.\nG1X(open\nM30\nO2000\nG1X1Q5.\nG999\nM99\n"
            "G1 X1 X2\n%\nafter the end\n")
    full, streamed, ld = both(text)
    assert ld.streamed is None          # completed by the run
    assert streamed == full
    assert any("NC003" in repr(d) for d in full[1])


def test_streamed_program_starts_from_the_power_on_work_offset():
    # G54 is the power-on work offset of iso-m; with the machine's G54 at X100 Y-50 the move to
    # X1 Y1 ends at machine X101 Y-49, streamed or not (the streamed run once started from none).
    machine = Machine(name="vmc", offsets={"G54": {"X": 100.0, "Y": -50.0, "Z": 0.0}})
    src = source.decode(b"G1 X1 Y1 F100\nX2\n", "t.nc")
    ends = []
    for stream in (False, True):
        ld = pipeline.load_source(src, "t.nc", "iso-m", stream=stream)
        assert (ld.streamed is not None) == stream
        ends.append([r.end for r in pipeline.toolpath_of(ld, machine)])
    assert ends[0] == ends[1] == [{"X": 101.0, "Y": -49.0, "Z": 0.0}, {"X": 102.0, "Y": -49.0, "Z": 0.0}]


def test_empty_program_reports_nc004_streamed_too():
    full, streamed, _ = both("%\n\n%\n")
    assert streamed == full and any("NC004" in repr(d) for d in full[1])


WORD = st.sampled_from(["G0", "G1", "G2", "G3", "G17", "G18", "G90", "G91", "G20", "G21", "M3",
                        "M5", "M8", "M9", "T1M6", "G43H1", "G81R1.Z-2.", "G80", "G4P500", "M0",
                        "G28", "G54", "G55", "S1200", "F150."])
AXIS = st.tuples(st.sampled_from("XYZIJR"), st.integers(-5000, 5000)).map(lambda t: f"{t[0]}{t[1] / 100}")
BLOCK = st.lists(st.one_of(WORD, AXIS), min_size=0, max_size=5).map("".join)


@settings(max_examples=60, deadline=None)
@given(st.lists(BLOCK, min_size=1, max_size=40), st.booleans())
def test_generated_straight_programs_match_full_parse(blocks, end):
    text = "\n".join(["%", "O100"] + blocks + (["M30", "G1X5"] if end else []) + ["%"]) + "\n"
    full, streamed, _ = both(text)
    assert streamed == full


def peak_mib(text: str) -> float:
    """Peak above the source text (which the caller holds) while loading and running it."""
    src = source.decode(text.encode(), "big.nc")
    tracemalloc.start()
    try:
        ld = pipeline.load_source(src, "big.nc", "iso-m", stream=True)
        assert isinstance(ld.program.body, StreamedBody)
        for _ in pipeline.toolpath_of(ld, pipeline.load_machine(None, "iso-m")):
            pass
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()


def test_streamed_memory_does_not_grow_with_program_length():
    def program(n):
        lines = [f"N{i * 5}G1X{i % 97 * 0.37:.4f}Y{i % 89 * 0.41:.4f}Z-{i % 7 * 0.1:.3f}F500."
                 for i in range(n)]
        return "%\nO1\nG90G21G54\nG0X0Y0Z5.\n" + "\n".join(lines) + "\nM30\n%\n"
    small, large = program(2_000), program(20_000)
    peak_mib(small)                     # warm-up: one-time caches are not the program's
    p_small, p_large = peak_mib(small), peak_mib(large)
    # the full parse holds ~1 KiB per block (20 MiB here); streamed, 10x the program is flat
    assert p_large < p_small + 1.0, (p_small, p_large)
    assert parse_program(small, "x").program.body       # the full parse still holds the body


@pytest.mark.skipif(not PROGRAMS, reason="shared corpus not found")
def test_control_flow_check_same_with_and_without_the_kernel_scan():
    """The kernel's scan only steps over plain lines: whether a program streams does not depend on it."""
    from nctrans import plainrun
    from nctrans.dialects.iso_m.frontend import _control_flow_at
    texts = [source.decode(p.read_bytes(), p.name).text for p in PROGRAMS if p.is_file()]
    texts += ["G1X1F100\nX2\n(GOTO 5)\nX3\n", "G1X1F100\nX2\nX3 (open\nGOTO5\n", "G0X1\nG1X2F1;IF\n",
              "G0X1\nX2\n#1=5\n", "G0 X1\nX2 Y3\nWHILE[1]DO1\n"]
    saved = plainrun.native
    try:
        with_kernel = [_control_flow_at(t, True) is None for t in texts]
        plainrun.native = None
        without = [_control_flow_at(t, True) is None for t in texts]
    finally:
        plainrun.native = saved
    assert with_kernel == without
    assert with_kernel[-5:] == [True, False, True, False, False]


# Lines that a control-flow mark may hide in (or look like one): plain CAM words, the marks in
# several spellings and cases, comments holding them, characters whose upper case is a mark's
# ("ı" -> "I"), spaces inside words, CR line ends.
_CAM_WORDS = st.sampled_from(["N10 ", "G1", "G01 ", "G2", "G3", "X1.5", "Y-2", "Z.5", "I1.", "J-0.5", "F300.",
                              " ", "W2.", "g1", "x3"])
_MARKED = st.sampled_from(["GOTO5", "goto 5", "IF[#1GT0]", "ıF", "WHILE[1]DO1", "END 1", "DO2", "#1=5",
                           "G65P1", "G 6 6", "G0066", "M98P5", "M 9 9", "M17", "[", "(GOTO 5)", ";IF",
                           "(G65", "M30", "M3", "G64", "END", "DOX", "E1", "D1", "(WHILE)X1"])
_LINE = st.lists(st.one_of(*[_CAM_WORDS] * 6, _MARKED), max_size=5).map("".join)


@settings(max_examples=300, deadline=None)
@given(st.lists(_LINE, max_size=30), st.sampled_from(["\n", "\r\n"]), st.booleans())
def test_control_flow_found_at_the_same_place_with_and_without_the_kernel(lines, newline, semicolon):
    """The kernel only passes over lines that hold no mark: the first mark (its offset, or none)
    is the one the pattern finds searching the whole text."""
    from nctrans import plainrun
    from nctrans.dialects.iso_m.frontend import _control_flow_at
    text = newline.join(lines)
    saved = plainrun.native
    try:
        with_kernel = _control_flow_at(text, semicolon)
        plainrun.native = None
        without = _control_flow_at(text, semicolon)
    finally:
        plainrun.native = saved
    assert with_kernel == without
