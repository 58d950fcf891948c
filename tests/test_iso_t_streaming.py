"""Streamed ISO turning (`iso-t`): a lathe program that runs straight through (no G70-G73 contour
cycle, no control flow) is parsed lazily, with the same toolpath and diagnostics as the full parse
and memory that does not grow with the program."""
from __future__ import annotations

import tracemalloc

import pytest
from hypothesis import given, settings, strategies as st

from nctrans import pipeline, source
from nctrans.dialects.base import StreamedBody
from nctrans.dialects.iso_t.frontend import parse_stream

from conftest import CORPUS

LATHE = sorted(p for p in (CORPUS / "iso-turn").iterdir() if p.is_file()) if (CORPUS / "iso-turn").is_dir() else []


def run(ld: pipeline.Loaded):
    records = [r.to_dict() for r in pipeline.toolpath_of(ld, pipeline.load_machine(None, "iso-t"))]
    return records, [repr(d) for d in ld.diagnostics]


def both(text: str, name: str = "t.nc"):
    src = source.decode(text.encode(), name)
    streamed = pipeline.load_source(src, name, "iso-t", stream=True)
    return run(pipeline.load_source(src, name, "iso-t")), run(streamed), streamed


@pytest.mark.skipif(not LATHE, reason="shared corpus not found")
@pytest.mark.parametrize("path", LATHE, ids=lambda p: p.name)
def test_corpus_lathe_toolpath_and_lint_match_full_parse(path):
    assert run(pipeline.load(str(path), "iso-t", stream=True)) == run(pipeline.load(str(path), "iso-t"))
    lint = [[repr(d) for d in pipeline.lint(pipeline.load(str(path), "iso-t", stream=stream))]
            for stream in (False, True)]
    assert lint[0] == lint[1]


def test_contour_cycles_and_control_flow_need_the_whole_body():
    assert parse_stream("G18 G99\nT0101\nG0 X20. Z2.\nG1 U-2. W-5. F0.2\nM30\n", "a.nc") is not None
    for text in ("G71 U1. R0.5\nG71 P10 Q20 U0.2 W0.1 F0.3\nN10 G0 X10.\nN20 G1 Z-10.\nM30\n",
                 "G70 P10 Q20\nM30\n", "G 7 3 P1 Q2\nM30\n", "M98 P1000\nM30\n", "N10 G0 X1.\nGOTO 10\n"):
        assert parse_stream(text, "a.nc") is None, text


def test_streamed_lathe_program_starts_in_diameter_mode():
    # X is a diameter: X20. puts the tool 10 mm off the axis, U-2. moves it 1 mm in, streamed or not
    full, streamed, ld = both("G18 G99\nT0101\nG0 X20. Z2.\nG1 U-2. W-5. F0.2\nM30\n")
    assert isinstance(ld.program.body, StreamedBody)
    assert streamed == full
    ends = [(r["end"]["X"], r["end"]["Z"]) for r in streamed[0] if r["kind"] in ("rapid", "linear")]
    assert ends[-2:] == [(10.0, 2.0), (9.0, -3.0)]


WORD = st.sampled_from(["G0", "G1", "G2", "G3", "G18", "G90", "G91", "G96 S150", "G97 S800", "G50 S2000",
                        "G98", "G99", "M3", "M4", "M5", "M8", "T0101", "T0202", "G28 U0. W0.", "G4 P500",
                        "G41", "G42", "G40", "G90 X20. Z-5. F0.2", "G92 X20. Z-5. F1.5", "F0.25", "G20", "G21"])
AXIS = st.tuples(st.sampled_from("XZUWRIK"), st.integers(-5000, 5000)).map(lambda t: f"{t[0]}{t[1] / 100}")
BLOCK = st.lists(st.one_of(WORD, AXIS), min_size=0, max_size=4).map(" ".join)


@settings(max_examples=60, deadline=None)
@given(st.lists(BLOCK, min_size=1, max_size=30), st.booleans())
def test_generated_straight_lathe_programs_match_full_parse(blocks, end):
    text = "\n".join(["%", "O100", "G18 T0101"] + blocks + (["M30", "G1 X5."] if end else []) + ["%"]) + "\n"
    full, streamed, _ = both(text)
    assert streamed == full


def peak_mib(text: str) -> float:
    """Peak above the source text (which the caller holds) while loading and running it."""
    src = source.decode(text.encode(), "big.nc")
    tracemalloc.start()
    try:
        ld = pipeline.load_source(src, "big.nc", "iso-t", stream=True)
        assert isinstance(ld.program.body, StreamedBody)
        for _ in pipeline.toolpath_of(ld, pipeline.load_machine(None, "iso-t")):
            pass
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()


def test_streamed_lathe_memory_does_not_grow_with_program_length():
    def program(n):
        lines = [f"N{i * 5} G1 X{20 + i % 97 * 0.37:.4f} Z-{i % 89 * 0.41:.4f} F0.2" for i in range(n)]
        return "%\nO1\nG18 G99 T0101\nG97 S800 M3\nG0 X30. Z2.\n" + "\n".join(lines) + "\nM30\n%\n"
    small, large = program(2_000), program(20_000)
    peak_mib(small)                     # warm-up: one-time caches are not the program's
    p_small, p_large = peak_mib(small), peak_mib(large)
    # the full parse holds ~1 KiB per block (20 MiB here); streamed, 10x the program is flat
    assert p_large < p_small + 1.0, (p_small, p_large)
