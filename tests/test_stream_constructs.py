"""Per-construct lowering of a straight program, streamed (nctrans.lower.stream_constructs): the
same text and diagnostics as the whole-program lowering (convert) on generated programs and corpus
programs, for every target that lowers, without ever parsing the program whole, and memory that
does not grow with the program."""
from __future__ import annotations

import tracemalloc

import pytest
from hypothesis import given, settings, strategies as st

from conftest import TextSink
from nctrans import api
from tests.conftest import CORPUS


class NullSink:
    def write(self, text: str) -> None:
        pass

    def reset(self) -> None:
        pass


@pytest.fixture
def no_whole_parse(monkeypatch):
    """Fail if a conversion falls back to the whole-program path (parse whole, convert())."""
    import nctrans.convert

    def whole(*args, **kwargs):
        raise AssertionError("converted the whole program held in memory")
    monkeypatch.setattr(nctrans.convert, "convert", whole)


def streamed(text: str, source: str, target: str):
    sink = TextSink()
    conv = api.transpile(text, source, target, out=sink)
    return (None if conv.text is None else "".join(sink.parts)), [d.format_text() for d in conv.diagnostics]


def held(text: str, source: str, target: str):
    conv = api.transpile(text, source, target)
    return conv.text, [d.format_text() for d in conv.diagnostics]


def test_a_reference_return_is_lowered_alone_without_parsing_the_program_whole(no_whole_parse):
    text = "%\nO1\nG21 G90 G17\nG0 X0 Y0 Z5\nG28 G91 Z0.\nG90 G1 X10 F100\nG0 Z10\nM30\n%\n"
    out, diags = streamed(text, "iso-m", "fagor")
    assert out is not None
    lines = out.splitlines()
    # the G28 (machine Z0 under the default mill's zero G54 offset and no tool length) is plain
    # motion, then the source's incremental mode comes back, as the source has it until G90
    assert lines[lines.index("G00 X0 Y0 Z5") + 1:][:4] == [
        "G71 G90 ; nctrans: plain motion of a construct the target lacks", "G54 Z0 D0",
        "G91 ; nctrans: modes of the source restored", "G90 G01 X10 F100"]
    assert any("line 5 was lowered to plain motion here" in d for d in diags)


def test_a_cycle_is_lowered_with_every_block_it_runs_at(no_whole_parse):
    text = ("G21 G90 G17\nG0 X0 Y0 Z5\nG81 X5 Y5 Z-2 R1 F50\nX6\n(a hole)\nX7\nG80\nG0 Z10\nM30\n")
    out, diags = streamed(text, "iso-m", "fagor")
    assert out is not None and "G81" not in out
    # three holes: down to Z-2 and back to R1 at X5, X6, X7
    assert out.count("G01 Z-2") + out.count("G01 G94 Z-2") == 3
    assert any("lines 3-7 were lowered to plain motion here" in d for d in diags)


BLOCKS = st.sampled_from([
    "G0 X1 Y2", "G1 X3.5 Y-1 F200", "G1 Z-1 F100", "X4 Y4", "G0 Z5", "(comment)", "M3 S1000", "M5",
    "G4 P0.5", "G28 G91 Z0.", "G90", "G91", "G28 G91 X0. Y0.", "G81 X5 Y5 Z-2 R1 F50", "G83 X1 Y1 Z-3 R1 Q1 F40",
    "X6", "Y7", "G80", "G20", "G21", "#1=2", "G1 X#1 F100", "#101=3", "G17", "G18", "G19", "G43 H1",
    "G49", "G55", "G54", "G94", "G93", "F300", "G30 G91 Z0", "G92 X0 Y0", "G92.1", "M8", "M9",
])


@settings(max_examples=40, deadline=None)
@given(st.lists(BLOCKS, min_size=1, max_size=25), st.sampled_from(["fagor", "iso-t", "sinumerik"]))
def test_generated_straight_programs_lower_as_the_whole_program_does(blocks, target):
    text = "%\nO100\nG21 G90 G17 G54\n" + "\n".join(blocks) + "\nM30\n%\n"
    assert streamed(text, "iso-m", target) == held(text, "iso-m", target)


PROGRAMS = sorted(p for p in (CORPUS / "iso-mill").glob("*") if p.is_file()) if (CORPUS / "iso-mill").is_dir() else []
WITH_G28 = [p for p in PROGRAMS if "G28" in p.read_text(errors="replace")][:3]


@pytest.mark.skipif(not WITH_G28, reason="shared corpus not found")
@pytest.mark.parametrize("path", WITH_G28, ids=lambda p: p.name)
def test_corpus_programs_lower_as_the_whole_program_does(path):
    text = path.read_text(errors="replace")
    assert streamed(text, "iso-m", "fagor") == held(text, "iso-m", "fagor")


def _peak_mib(text: str) -> float:
    tracemalloc.start()
    try:
        conv = api.transpile(text, "iso-m", "fagor", out=NullSink())
        assert conv.text == ""
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()


def test_streamed_lowering_memory_does_not_grow_with_program_length(no_whole_parse):
    def program(count: int) -> str:
        lines = [f"N{i * 5}G1X{i % 97 * 0.37:.4f}Y{i % 89 * 0.41:.4f}Z-{i % 7 * 0.1:.3f}F500."
                 for i in range(count)]
        # a construct Fagor lacks at each end: the run goes through the whole program
        return "%\nO1\nG90G21G54\nG28G91Z0.\nG90\n" + "\n".join(lines) + "\nG28G91Z0.\nM30\n%\n"
    # past the blocks handed to the emitter at a time (convert.STREAM_CHUNK), and 3x that
    small, large = program(5_000), program(15_000)
    _peak_mib(program(100))             # warm-up: one-time caches are not the program's
    p_small, p_large = _peak_mib(small), _peak_mib(large)
    # held whole, the IR alone is ~1 KiB per block (10 MiB more here); streamed it is flat
    assert p_large < p_small + 1.5, (p_small, p_large)
