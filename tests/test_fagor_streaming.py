"""Streamed Fagor parse + run (pipeline.load(..., stream=True)) against the whole-program parse.

Fagor CAM programs (plain ISO-style blocks, Fagor comments) stream like ISO and Sinumerik ones and
take the same fast lane: runs of plain lines go to the native kernel as PlainRuns, lowered by
stream.plain_line when Python runs them. Every way through must be invisible: the same JSON
lines, byte for byte, the same diagnostics and the same converted text as the whole parse, with
the kernel on and off. The programs are the conformance programs (corpus/fagor), the ISO milling
corpus written as Fagor (nctrans convert) and generated ones.
"""
from __future__ import annotations

import io
import tracemalloc
from functools import lru_cache
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from nctrans import limits, pipeline, plainrun, source, toolpath_io
from nctrans.api import transpile
from nctrans.dialects.base import StreamedBody
from nctrans.dialects.fagor.frontend import parse
from nctrans.dialects.fagor.stream import plain_line, streamable

from conftest import CORPUS, examples

NATIVE = plainrun.native
ISO_MILL = CORPUS / "iso-mill"
# the corpus programs of up to ~5000 lines (the 22k-line one is the bench's)
PROGRAMS = sorted(p for p in ISO_MILL.iterdir() if p.is_file() and p.stat().st_size < 150_000) \
    if ISO_MILL.is_dir() else []
CONFORMANCE = sorted((Path(__file__).resolve().parents[1] / "corpus" / "fagor").glob("*.nc"))
CAM = ISO_MILL / "brianhooper-fusion-1001.nc"


@lru_cache(maxsize=None)
def as_fagor(path) -> str:
    result = transpile(path, read="iso-m", write="fagor")
    if result.text is None:
        pytest.skip(f"{path.name} does not convert to Fagor")
    return result.text


def run(text: str, *, stream: bool, kernel: bool = True, lint: bool = False):
    """(JSON lines, diagnostics, whether the body was streamed, JSON chunks from the kernel)."""
    saved = plainrun.native
    plainrun.native = NATIVE if kernel else None
    try:
        src = source.decode(text.encode(), "t.nc")
        ld = pipeline.load_source(src, "t.nc", "fagor", stream=stream)
        streamed = isinstance(ld.program.body, StreamedBody) if ld.program is not None else False
        m = pipeline.load_machine(None, "fagor")
        buf = io.StringIO()
        chunks = 0
        if lint:
            pipeline.lint(ld, m)
        else:
            items = list(pipeline.toolpath_of(ld, m, fast_sink="jsonl"))
            chunks = sum(1 for r in items if isinstance(r, plainrun.JsonChunk))
            toolpath_io.write_jsonl(items, buf)
        diags = [(d.rule, d.severity, d.line, d.column, d.message) for d in ld.diagnostics]
        return buf.getvalue(), diags, streamed, chunks
    finally:
        plainrun.native = saved


def same_every_way(text: str, lint: bool = False) -> tuple:
    """Assert the whole parse, streamed with the kernel and streamed without it agree."""
    full = run(text, stream=False, lint=lint)
    fast = run(text, stream=True, lint=lint)
    slow = run(text, stream=True, kernel=False, lint=lint)
    assert not full[2]
    assert fast[1] == full[1] and slow[1] == full[1]
    assert fast[0] == full[0] and slow[0] == full[0]
    return full, fast, slow


@pytest.mark.parametrize("path", CONFORMANCE, ids=lambda p: p.name)
def test_conformance_programs_stream_or_not_to_the_same_toolpath(path):
    text = path.read_text()
    same_every_way(text)
    same_every_way(text, lint=True)


@pytest.mark.skipif(not PROGRAMS, reason="shared corpus not found")
@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_corpus_program_as_fagor_streams_to_the_same_toolpath(path, monkeypatch):
    # An ISO main program ending in M99 becomes an endless loop here; the three runs are
    # compared up to the budget equiv gives endless programs (limits.MAX_ENDLESS_STEPS), not
    # MAX_STEPS: 2 M steps took 30 s a run and repeat the same pass. Others end far below it.
    monkeypatch.setenv("NCTRANS_MAX_STEPS", str(limits.MAX_ENDLESS_STEPS))
    text = as_fagor(path)
    _full, fast, _slow = same_every_way(text)
    assert fast[2] == streamable(text)[0]


def test_cam_program_streams_through_the_kernel():
    if not CAM.exists():
        pytest.skip("shared corpus not found")
    text = as_fagor(CAM)
    assert streamable(text) == (True, text.split("\n", 1)[0][1:])
    full, fast, slow = same_every_way(text)
    assert fast[2] and slow[2]
    if NATIVE is not None:
        assert fast[3] > 0                 # the kernel wrote records itself
    assert full[0].count("\n") > 1000


def test_lint_report_streamed_matches_full_parse():
    """What `nctrans lint` reports: NC112 after M30 comes from the IR analyses for a whole program
    and from watching the stream go by for a streamed one, in the same words."""
    from nctrans import linting
    text = "%PART\nG0 X0 Y0 ; start\nG1 X10 F100\nX20\nM30\nG1 X99\nX98\n"
    reports = []
    for stream in (False, True):
        ld = pipeline.load_source(source.decode(text.encode(), "t.nc"), "t.nc", "fagor", stream=stream)
        assert (ld.streamed is not None) == stream
        assert ld.program.name == "PART"
        reports.append([(d.rule, d.line, d.message) for d in linting.lint_loaded(ld)])
    assert reports[0] == reports[1]
    assert reports[0] == [("NC112", 6, "never runs: 2 block(s) after the program end at line 5, "
                                       "and no jump reaches them")]


@pytest.mark.parametrize("text", [
    "$IF P1==1\nG0 X1\n$ENDIF\n", "$GOTO N20\nG0 X1\nN20 G0 X2\n", "#MSG [\"hi\"]\nG0 X1\n", "G0 X1\nM30\n%L SUB\nG0 X2\nM17\n",
    "LL SUB\n", "L \"C:\\\\sub.nc\"\n", "P1=5\nG1 X1 F100\n", "P100=5\n", "N10: G1 X1 F100\n", "[LBL] G1 X1\n",
    "G180 A1\n", "G0 X1\nM17\n", "G0 X1\nM29\n", "G198 X100\n", "G04 1\n", "G1 X[1+2] F100\n", "G159=2\n",
    "G0 X1 (#RPT)\n", "#COMMENT BEGIN\nX\n#COMMENT END\n", "G1 X1 F100\nMG5\n", "V.P.A=1\n", "G0 X1 0\n",
    "G0 X1\n#RPT [N10, N20, 2]\n", "G0 X=5\n",
])
def test_programs_that_need_the_whole_ir_are_not_streamed(text):
    assert streamable(text)[0] is False
    assert not run(text, stream=True)[2]
    same_every_way(text)


@pytest.mark.parametrize("text", [
    "%O1001\n; CAM\nN10 G94 G17 G40 G90 G80 D0\nT7 M6\nS1000 M3\nG54\nG0 X1 Y2\nZ0.5 D7\nG1 Z-1 F40\nX2 Y3\nX3\nM30\n",
    "G71\nG0 X0 Y0 (comment with IF and = and [)\nG2 X10 Y0 I5 J0 F100\nG3 X0 Y0 I-5 J0\nX1 Y1\n",
    "G0 X1\nX2\nG81 Z-5 R1\nX3\nX4\nG80\nX5\nX6\n", "G63 G1 Z-5 F100 S-500\nZ0\nZ-1\nM5\nG0 X1\nX2\n",
    "G0 X0\nG91\nX1\nX1\nG90 G1 X0 F100\nG4 K1\nM3.S2\nX2 Y2\n", "%\nG0 X1\n%\n", "G0 X1\n\n\nX2\n  \nX3\n",
])
def test_cam_programs_are_streamed(text):
    assert streamable(text)[0] is True
    assert run(text, stream=True)[2]
    same_every_way(text)
    same_every_way(text, lint=True)


WORD = st.sampled_from(["G0", "G1", "G2", "G3", "G00", "G01", "G17", "G18", "G90", "G91", "G70", "G71", "M3",
                        "M5", "M8", "M9", "T1 M6", "D1", "D0", "G54", "G55", "S1200", "S-300", "F150.", "F0",
                        "; note", "(note)", "G4 K1", "M0", "G5", "G7", "N7", "N0010", "G0.0", "N1.5", "G81 Z-1",
                        "G80", "G63", "G41", "G40", "G6", "G8", "R5", "Q45", "NR2", "G1X1", "X 1", "M30"])
AXIS = st.tuples(st.sampled_from(["X", "Y", "Z", "I", "J", "K", "A", "U", "x"]),
                 st.integers(-5000, 5000), st.sampled_from(["", ".", " ", " 0"])).map(
                     lambda t: f"{t[0]}{t[1] / 100}{t[2]}")
BLOCK = st.lists(st.one_of(WORD, AXIS), min_size=0, max_size=5).map(" ".join)


@settings(max_examples=80, deadline=None)
@given(st.lists(BLOCK, min_size=1, max_size=40), st.booleans())
def test_generated_straight_programs_stream_to_the_same_toolpath(blocks, end):
    text = "\n".join(["G0 X0 Y0 Z0 A0 U0"] + blocks + (["M30", "G1 X5"] if end else [])) + "\n"
    same_every_way(text)


PLAIN_WORD = st.tuples(st.sampled_from("NGXYZIJKFABCUVW"),
                       st.sampled_from(["", "+", "-"]),
                       st.sampled_from(["0", "1", "2", "3", "01", "10", "1.5", ".5", "4.", "123456789012345678",
                                        "0.0001"])).map("".join)


@pytest.mark.long_property
@settings(max_examples=examples(500, 150), deadline=None)
@given(st.lists(PLAIN_WORD, min_size=1, max_size=6), st.sampled_from([" ", "  ", ""]))
def test_scan_takes_only_lines_plain_line_lowers_as_the_front_end_does(words, sep):
    """A line the kernel's strict scan takes is lowered by plain_line exactly as the full front end
    lowers it (the Block a PlainRun expands to when Python runs it)."""
    if NATIVE is None:
        pytest.skip("nctrans._plainrun not built")
    line = sep.join(words)
    text = line + "\n"
    blocks = NATIVE.scan(text, 0, "\n", plainrun.motion_code("arc_cw"), True, False, True)[2]
    if not blocks:
        return
    number, body, _mode = plain_line(line.replace(" ", ""), None, None, False)
    # the whole parse in arc mode (the state the scan was asked about)
    full = parse("G2\n" + text, "t.nc")
    assert not full.diagnostics, line
    (_mode_block, block) = full.program.body
    assert (number, body) == (block.number, block.body), line


def test_plain_motion_codes_of_the_table_are_the_kernels():
    """The kernel reads G0..G3 as rapid, linear, arc_cw, arc_ccw: so must the Fagor table."""
    for g, motion in enumerate(plainrun.MOTIONS):
        assert plain_line(f"G{g}X1", None, None, False)[2] == motion
        assert plain_line(f"G0{g}X1", None, None, False)[2] == motion


@pytest.mark.parametrize("dialect", ["fagor", "sinumerik"])
def test_a_blank_inside_a_number_is_no_plain_word(dialect):
    """`X1 0` is a syntax error in Fagor and Sinumerik (their words are separated, blanks are not
    ignored as in ISO): the kernel's strict scan must not read it as X10. It did for Sinumerik,
    which streamed a move to X10 where the whole parse reported NC002 and did not move."""
    if NATIVE is None:
        pytest.skip("nctrans._plainrun not built")
    for line in ("G1 X1 0 Y2 F100", "X1 .5", "X- 1", "G1 X1 Y2 5"):
        assert NATIVE.scan(line + "\n", 0, "\n", 1, True, False, True)[2] == 0, line
    assert NATIVE.scan("G1 X1 Y2 F100 \n", 0, "\n", 1, True, False, True)[2] == 1
    text = "G0 X0 Y0 Z0\nG1 X1 0 Y2 F100\nX5 Y1\nX6\nX7\n"
    ld = pipeline.load_source(source.decode(text.encode(), "t"), "t", dialect, stream=True)
    records = list(pipeline.toolpath_of(ld, pipeline.load_machine(None, dialect)))
    assert [r.line for r in records if r.kind in ("rapid", "linear")] == [1, 3, 4, 5]
    assert [d.rule for d in ld.diagnostics] == ["NC002"]
    assert ld.diagnostics[0].line == 2


def peak_mib(text: str) -> float:
    """Peak above the source text (which the caller holds) while loading and running it."""
    src = source.decode(text.encode(), "big.nc")
    tracemalloc.start()
    try:
        ld = pipeline.load_source(src, "big.nc", "fagor", stream=True)
        assert isinstance(ld.program.body, StreamedBody)
        for _ in pipeline.toolpath_of(ld, pipeline.load_machine(None, "fagor")):
            pass
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()


def test_streamed_memory_does_not_grow_with_program_length():
    def program(n):
        lines = [f"N{i * 5} G1 X{i % 97 * 0.37:.4f} Y{i % 89 * 0.41:.4f} Z-{i % 7 * 0.1:.3f} F500."
                 + (" ; pass" if i % 50 == 0 else "") for i in range(n)]
        return "%BIG\nG90 G71 G54\nG0 X0 Y0 Z5.\n" + "\n".join(lines) + "\nM30\n"
    small, large = program(2_000), program(20_000)
    peak_mib(small)                     # warm-up: one-time caches are not the program's
    p_small, p_large = peak_mib(small), peak_mib(large)
    # the whole parse holds ~1 KiB per block (20 MiB here); streamed, 10x the program is flat
    assert p_large < p_small + 1.0, (p_small, p_large)


@pytest.mark.parametrize("target", ["fagor", "iso-m", "sinumerik"])
def test_streamed_conversion_writes_what_the_whole_program_converts_to(target):
    """convert from Fagor streams: the same text as converting the whole parsed program, kernel
    on or off."""
    if not CAM.exists():
        pytest.skip("shared corpus not found")
    text = as_fagor(CAM)
    saved = plainrun.native
    try:
        plainrun.native = None
        whole = transpile(text, read="fagor", write=target).text
        assert whole and whole.count("\n") > 1000
        for kernel in (True, False):
            plainrun.native = NATIVE if kernel else None
            buf = io.StringIO()
            resets = []
            buf.reset = lambda: resets.append(1)        # called when the whole program is converted instead
            result = transpile(text, read="fagor", write=target, out=buf)
            assert result.text == "" and buf.getvalue() == whole and not resets
    finally:
        plainrun.native = saved


def test_a_cam_program_runs_without_loading_the_grammar(tmp_path):
    """Plain CAM blocks, `;` and `( )` comments, tool and spindle words need no parser: lark (~25 ms
    of start-up with its tables) is never imported for them; a block that needs it loads it."""
    import json
    import subprocess
    import sys
    prog = tmp_path / "cam.nc"
    prog.write_text("%CAM\n; CAM\nG71 G17 G90\nT1 M6 (tool)\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\n"
                    "X10 Y0\nG2 X20 Y0 I5 J0\nM30\n")
    code = ("import sys, nctrans.cli as c; c.main(['toolpath', sys.argv[1], '--from', 'fagor', '--format', "
            "'jsonl']); print('lark' in sys.modules, file=sys.stderr)")
    proc = subprocess.run([sys.executable, "-c", code, str(prog)], capture_output=True, text=True)
    assert proc.stderr.strip().splitlines()[-1] == "False", proc.stderr
    kinds = [json.loads(line)["kind"] for line in proc.stdout.splitlines()]
    assert kinds == ["tool_change", "spindle", "rapid", "linear", "linear", "arc", "stop"]
    arc = json.loads(proc.stdout.splitlines()[5])
    assert arc["end"] == {"X": 20.0, "Y": 0.0, "Z": -1.0} and arc["center"] == {"X": 15.0, "Y": 0.0, "Z": -1.0}
    prog.write_text("P100=2\nG1 X[P100*5] F100\nM30\n")
    proc = subprocess.run([sys.executable, "-c", code, str(prog)], capture_output=True, text=True)
    assert proc.stderr.strip().splitlines()[-1] == "True", proc.stderr
    assert json.loads(proc.stdout.splitlines()[0])["end"]["X"] == 10.0
