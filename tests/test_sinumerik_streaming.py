"""Streamed Sinumerik parse + run (pipeline.load(..., stream=True)) against the full parse.

Sinumerik CAM programs stream like ISO ones and take the same fast lane: runs of plain lines go to
the native kernel as PlainRuns, lowered by frontend.plain_line when Python runs them. Every way
through must be invisible: the same JSON lines, byte for byte, and the same diagnostics as the full
parse, with the kernel on and off. The programs are the ISO milling corpus written as Sinumerik
(nctrans convert: `;` comments, G74 homing, G70/G71, lengths from D) and generated ones.
"""
from __future__ import annotations

import importlib
import io
import json
import tracemalloc
from functools import lru_cache

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from nctrans import limits, pipeline, plainrun, source, toolpath_io
from nctrans.api import transpile
from nctrans.dialects.base import StreamedBody
from nctrans.dialects.sinumerik.frontend import parse, plain_line, streamable
from nctrans.machine import Machine

from conftest import CORPUS, examples

NATIVE = plainrun.native
ISO_MILL = CORPUS / "iso-mill"
# the corpus programs of up to ~5000 lines (the 22k-line one is the bench's)
PROGRAMS = sorted(p for p in ISO_MILL.iterdir() if p.is_file() and p.stat().st_size < 150_000) \
    if ISO_MILL.is_dir() else []


@lru_cache(maxsize=None)
def as_sinumerik(path) -> str:
    result = transpile(path, read="iso-m", write="sinumerik")
    if result.text is None:
        pytest.skip(f"{path.name} does not convert to Sinumerik")
    return result.text


def run(text: str, *, stream: bool, kernel: bool = True, machine=None, lint: bool = False):
    """(JSON lines, diagnostics, whether the body was streamed, JSON chunks from the kernel)."""
    saved = plainrun.native
    plainrun.native = NATIVE if kernel else None
    try:
        src = source.decode(text.encode(), "t.mpf")
        ld = pipeline.load_source(src, "t.mpf", "sinumerik", stream=stream)
        streamed = isinstance(ld.program.body, StreamedBody) if ld.program is not None else False
        m = machine or pipeline.load_machine(None, "sinumerik")
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


def same_every_way(text: str, machine=None) -> tuple:
    """Assert full parse, streamed with the kernel and streamed without it agree; return them."""
    full = run(text, stream=False, machine=machine)
    fast = run(text, stream=True, machine=machine)
    slow = run(text, stream=True, kernel=False, machine=machine)
    assert not full[2]
    assert fast[1] == full[1] and slow[1] == full[1]
    assert fast[0] == full[0] and slow[0] == full[0]
    return full, fast, slow


@pytest.mark.skipif(not PROGRAMS, reason="shared corpus not found")
@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_corpus_program_as_sinumerik_streams_to_the_same_toolpath(path, monkeypatch):
    # An ISO main program ending in M99 becomes an endless loop here; the three runs are
    # compared up to the budget equiv gives endless programs (limits.MAX_ENDLESS_STEPS), not
    # MAX_STEPS: 2 M steps took 30 s a run and repeat the same pass. Others end far below it.
    monkeypatch.setenv("NCTRANS_MAX_STEPS", str(limits.MAX_ENDLESS_STEPS))
    same_every_way(as_sinumerik(path))


def test_cam_program_streams_through_the_kernel():
    path = ISO_MILL / "brianhooper-fusion-1001.nc"
    if not path.exists():
        pytest.skip("shared corpus not found")
    text = as_sinumerik(path)
    assert streamable(text)
    full, fast, slow = same_every_way(text)
    assert fast[2] and slow[2]
    if NATIVE is not None:
        assert fast[3] > 0                 # the kernel wrote records itself
    assert full[0].count("\n") > 1000


def test_lint_streamed_matches_full_parse():
    text = ("%_N_PART_MPF\n;$PATH=/_N_MPF_DIR\nG71 G17 G90\nT1 M6 ; tool\nD1\nS1000 M3\n"
            "G0 X0 Y0 Z5\nG1 Z-1 F100\nX10\nY10\nX0\nG2 X10 Y0 I5 J-5\nG1 G41 X5\nM30\nG1 X99\nX98\n")
    assert streamable(text)
    full = run(text, stream=False, lint=True)
    assert run(text, stream=True, lint=True)[1] == full[1]
    assert run(text, stream=True, kernel=False, lint=True)[1] == full[1]


def test_lint_report_streamed_matches_full_parse():
    """What `nctrans lint` reports (with the IR analyses; NC112 after M30 comes from them for a
    whole program and from watching the stream go by for a streamed one): the same words."""
    from nctrans import linting
    text = "G0 X0 Y0\nG1 X10 F100\nM30\nG1 X99\nX98\n"
    reports = []
    for stream in (False, True):
        ld = pipeline.load_source(source.decode(text.encode(), "t.mpf"), "t.mpf", "sinumerik", stream=stream)
        assert (ld.streamed is not None) == stream
        reports.append([(d.rule, d.line, d.message) for d in linting.lint_loaded(ld)])
    assert reports[0] == reports[1]
    assert reports[0] == [("NC112", 4, "never runs: 2 block(s) after the program end at line 3, "
                                       "and no jump reaches them")]


def test_streamed_program_starts_from_the_power_on_modes():
    # Sinumerik powers on in G1 and G53 (no work offset): the move to X1 Y1 is machine X1 Y1 even
    # with the machine's G54 at X100 Y-50; after G54, X3 is machine X103 and Y, not programmed,
    # stays where it is. Streamed and full alike.
    machine = Machine(name="vmc", offsets={"G54": {"X": 100.0, "Y": -50.0, "Z": 0.0}})
    text = "F100 X1 Y1\nX2\nG54 X3\nX4\n"
    full, _fast, _slow = same_every_way(text, machine)
    ends = [line.split('"end":')[1].split("}")[0] for line in full[0].splitlines()]
    assert ends == ['{"X":1.0,"Y":1.0,"Z":0.0', '{"X":2.0,"Y":1.0,"Z":0.0', '{"X":103.0,"Y":1.0,"Z":0.0',
                    '{"X":104.0,"Y":1.0,"Z":0.0']


@pytest.mark.parametrize("text", [
    "R1=5\nG1 X=R1 F100\n", "DEF REAL A\nG0 X1\n", "N10 G0 X1\nGOTOF N20\nN20 X2\n", "IF 1 GOTOF L1\nL1:\n",
    "WHILE R1<2\nR1=R1+1\nENDWHILE\n", "PROC P\nG0 X1\nM17\n", "G0 X1\nM17\n", "G0 X$AA_IW[X]\n",
    "CYCLE81(10, 0, 2, -5)\nX1\n", "MYSUB\n", "G0 X1\n%_N_SUB_SPF\nG0 X2\n", "DEFINE A AS X1\nA\n",
    "G291\nG0 X1\nG290\n", "L10\n", "TEST=1\n", "G0 X1\n%\n", "X=AC(R1)\n", "MCALL CYCLE81(1)\n",
    "G1 X1 F=R1\n", "WHENEVER $AA_IM[X]>5 DO M5\n", "LBL: G0 X1\n",
])
def test_programs_that_need_the_whole_ir_are_not_streamed(text):
    assert not streamable(text)
    assert not run(text, stream=True)[2]


@pytest.mark.parametrize("text", [
    "%_N_PART_MPF\n;$PATH=/_N_MPF_DIR\nG0 X1\nM30\n", "G74 Z1=0\nG0 X1 ; IF WHILE GOTO R1=2 $P\n",
    "T=\"MILL\" D1\nMSG(\"IF R1 $\")\nG0 X=IC(5) Y=AC(-2.5)\n", "G642 SOFT G0 X1\nM30\n",
])
def test_cam_programs_are_streamed(text):
    assert streamable(text)
    assert run(text, stream=True)[2]
    same_every_way(text)


WORD = st.sampled_from(["G0", "G1", "G2", "G3", "G17", "G18", "G90", "G91", "G70", "G71", "G700", "M3",
                        "M5", "M8", "M9", "T1 M6", "D1", "G54", "G55", "G500", "S1200", "F150.", "F0",
                        "G74 Z1=0", "; note", "G4 F1", "M0", "G64", "G60", "N7", "G01", "G0.0", "N1.5"])
AXIS = st.tuples(st.sampled_from(["X", "Y", "Z", "I", "J", "K", "A", "U", "x", "X="]),
                 st.integers(-5000, 5000), st.sampled_from(["", ".", " "])).map(
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
    full = parse(text, "t.mpf")
    assert not full.diagnostics, line
    (block,) = full.program.body
    assert (number, body) == (block.number, block.body), line


def test_plain_motion_codes_of_the_table_are_the_kernels():
    """The kernel reads G0..G3 as rapid, linear, arc_cw, arc_ccw: so must the Sinumerik table."""
    for g, motion in enumerate(plainrun.MOTIONS):
        assert plain_line(f"G{g}X1", None, None, False)[2] == motion


def peak_mib(text: str) -> float:
    """Peak above the source text (which the caller holds) while loading and running it."""
    src = source.decode(text.encode(), "big.mpf")
    tracemalloc.start()
    try:
        ld = pipeline.load_source(src, "big.mpf", "sinumerik", stream=True)
        assert isinstance(ld.program.body, StreamedBody)
        for _ in pipeline.toolpath_of(ld, pipeline.load_machine(None, "sinumerik")):
            pass
        return tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()


def test_streamed_memory_does_not_grow_with_program_length():
    def program(n):
        lines = [f"N{i * 5} G1 X{i % 97 * 0.37:.4f} Y{i % 89 * 0.41:.4f} Z-{i % 7 * 0.1:.3f} F500."
                 + (" ; pass" if i % 50 == 0 else "") for i in range(n)]
        return "%_N_BIG_MPF\nG90 G71 G54\nG0 X0 Y0 Z5.\n" + "\n".join(lines) + "\nM30\n"
    small, large = program(2_000), program(20_000)
    peak_mib(small)                     # warm-up: one-time caches are not the program's
    p_small, p_large = peak_mib(small), peak_mib(large)
    # the full parse holds ~1 KiB per block (20 MiB here); streamed, 10x the program is flat
    assert p_large < p_small + 1.0, (p_small, p_large)


# ------------------------------------------------------------------ plain words without the parser

PLAIN_BLOCK_WORD = st.one_of(
    st.tuples(st.sampled_from(["G", "M", "X", "Y", "Z", "I", "J", "K", "F", "S", "T", "D", "N", "H", "x", "L"]),
              st.sampled_from(["", " "]), st.sampled_from(["", "+", "-"]),
              st.sampled_from(["0", "1", "3", "01", "1.5", ".5", "4.", "17", "291", "1234567890123456"])),
    st.tuples(st.sampled_from(["X", "Z1", "CR", "AR", "TURN", "I1", "AP", "RP", "F", "R1", "XV", "S", "T", "ABC",
                               "x", "D"]),
              st.sampled_from(["=", " = "]), st.sampled_from(["", "-", "+"]),
              st.sampled_from(["0", "5", "5.5", ".5", "2.", "1EX3"]))).map("".join)


@pytest.mark.long_property
@settings(max_examples=examples(400, 120), deadline=None)
@given(st.lists(PLAIN_BLOCK_WORD, min_size=1, max_size=5), st.sampled_from([" ", "  "]))
def test_plain_words_read_without_the_parser_lower_as_the_parsers_trees(words, sep):
    """Blocks of plain words (`X10`, `Z1=0`, `CR=-5.5`) skip lark (frontend._plain_words): the
    Blocks and diagnostics are those of the parser's trees."""
    fe = importlib.import_module("nctrans.dialects.sinumerik.frontend")  # nctrans.dialects is a function
    text = sep.join(words) + "\n"
    light = parse(text, "t.mpf")
    saved = fe._plain_words
    fe._plain_words = lambda code: None
    try:
        parsed = parse(text, "t.mpf")
    finally:
        fe._plain_words = saved
    assert light.program.body == parsed.program.body, text
    assert [repr(d) for d in light.diagnostics] == [repr(d) for d in parsed.diagnostics], text


def test_a_cam_program_runs_without_loading_the_grammar(tmp_path):
    """Plain CAM blocks, `;` comments, G74 Z1=0 and CR= arcs need no parser: lark (~55 ms of
    start-up with its tables) is never imported for them."""
    import subprocess
    import sys
    prog = tmp_path / "cam.mpf"
    prog.write_text("; CAM\nG71 G17 G90\nG74 Z1=0\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\n"
                    "X10 Y0\nG2 X20 Y0 CR=5\nM30\n")
    code = ("import sys, nctrans.cli as c; c.main(['toolpath', sys.argv[1], '--format', 'jsonl']); "
            "print('lark' in sys.modules, file=sys.stderr)")
    proc = subprocess.run([sys.executable, "-c", code, str(prog)], capture_output=True, text=True)
    assert proc.stderr.strip().splitlines()[-1] == "False", proc.stderr
    kinds = [json.loads(line)["kind"] for line in proc.stdout.splitlines()]
    assert kinds == ["rapid", "rapid", "tool_change", "spindle", "rapid", "linear", "linear", "arc", "stop"]
    # G2 from X10 Y0 to X20 Y0 with CR=5: a half circle about X15 Y0
    arc = json.loads(proc.stdout.splitlines()[7])
    assert arc["end"] == {"X": 20.0, "Y": 0.0, "Z": -1.0} and arc["center"] == {"X": 15.0, "Y": 0.0, "Z": -1.0}


def test_streamed_conversion_writes_what_the_whole_program_converts_to():
    """convert Sinumerik -> Sinumerik streams (emit_stream takes the PlainRuns apart with
    plain_line): the same text as converting the whole parsed program, kernel on or off."""
    path = ISO_MILL / "brianhooper-fusion-1001.nc"
    if not path.exists():
        pytest.skip("shared corpus not found")
    text = as_sinumerik(path)
    whole = transpile(text, read="sinumerik", write="sinumerik").text
    assert whole and whole.count("\n") > 1000
    saved = plainrun.native
    try:
        for kernel in (True, False):
            plainrun.native = NATIVE if kernel else None
            buf = io.StringIO()
            resets = []
            buf.reset = lambda: resets.append(1)        # called when the whole program is converted instead
            result = transpile(text, read="sinumerik", write="sinumerik", out=buf)
            assert result.text == "" and buf.getvalue() == whole and not resets
    finally:
        plainrun.native = saved
