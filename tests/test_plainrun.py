"""The native plain-run kernel against the Python path it specialises (nctrans/plainrun.py).

The kernel must be invisible: the same JSON lines, byte for byte, and the same diagnostics as the
pure-Python front end and interpreter (plainrun.native switched off), on every corpus program and
on generated programs built to hit its edges (inch, incremental, offsets, arc modes, missing
feed, tiny and huge numbers, unknown axes, odd G spellings, CRLF, blank lines). Without the
compiled extension these tests skip, except in CI, where the build must have produced it.
"""
from __future__ import annotations

import io
import math
import os
import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from nctrans import pipeline, plainrun, source, toolpath_io
from nctrans.dialects.iso_m.fastpath import PLAIN, WORD
from nctrans.dialects.iso_m.frontend import Lowering

from conftest import CORPUS, examples

GEOMETRY = Path(__file__).parent / "data" / "rs274-geometry-machine.toml"
NATIVE = plainrun.native


@pytest.fixture(autouse=True)
def _need_native():
    if NATIVE is None:
        if os.environ.get("CI"):
            pytest.fail("nctrans._plainrun was not built: the install must compile it in CI", pytrace=False)
        pytest.skip("nctrans._plainrun not built (no C compiler?)")


def run(text: str, kernel: bool, machine=None, name: str = "t.nc", lint: bool = False):
    """(JSON lines, diagnostics, JSON chunks seen) of the streamed toolpath, with or without kernel."""
    saved = plainrun.native
    plainrun.native = NATIVE if kernel else None
    try:
        src = source.decode(text.encode("latin-1", errors="replace"), name)
        ld = pipeline.load_source(src, name, "iso-m", stream=True)
        m = pipeline.load_machine(machine, "iso-m")
        buf = io.StringIO()
        chunks = 0
        if lint:
            pipeline.lint(ld, m)
        else:
            items = list(pipeline.toolpath_of(ld, m, fast_sink="jsonl" if kernel else None))
            chunks = sum(1 for r in items if isinstance(r, plainrun.JsonChunk))
            toolpath_io.write_jsonl(items, buf)
        diags = [(d.rule, d.severity, d.line, d.column, d.message) for d in ld.diagnostics]
        return buf.getvalue(), diags, chunks
    finally:
        plainrun.native = saved


def iso_corpus():
    return sorted(p for p in (CORPUS / "iso-mill").iterdir() if p.is_file())


@pytest.mark.parametrize("machine", [None, str(GEOMETRY)], ids=["zero-tools", "geometry"])
@pytest.mark.parametrize("path", iso_corpus(), ids=lambda p: p.name)
def test_corpus_program_same_with_and_without_kernel(path, machine):
    text = source.decode(path.read_bytes(), path.name).text
    slow, slow_diags, _ = run(text, kernel=False, machine=machine, name=path.name)
    fast, fast_diags, _ = run(text, kernel=True, machine=machine, name=path.name)
    assert fast_diags == slow_diags
    assert fast == slow


def test_kernel_carries_a_cam_program():
    """Not vacuous: on the big adaptive-clearing program nearly every record comes from the kernel."""
    path = CORPUS / "iso-mill" / "mheaton-fusion-adaptive-1001.nc"
    text = source.decode(path.read_bytes(), path.name).text
    out, _, chunks = run(text, kernel=True, name=path.name)
    assert chunks >= 1
    records = out.count("\n")
    src = source.decode(path.read_bytes(), path.name)
    ld = pipeline.load_source(src, path.name, "iso-m", stream=True)
    objects = [r for r in pipeline.toolpath_of(ld, None, fast_sink="jsonl")
               if not isinstance(r, plainrun.JsonChunk)]
    assert records > 20_000 and len(objects) < records / 100
    assert sum(o.kind == "arc" for o in objects) < 10 < out.count('"kind":"arc"')   # arcs too


@pytest.mark.parametrize("text", [
    "%\nO1\nG1F250.\nX1.\nX2.\nG1F100.\nX3.\nX4.\nM30\n%\n",       # F in a block without motion
    "%\nO1\nG20G91G1F10.\nX1.Y1.\nX.5\nG90X0Y0\nZ-.1\nM30\n%\n",       # inch, incremental
    "%\nO1\nG0X1.\nG2X2.Y1.R1.F50.\nX3.Y2.\nG1X4.\nX5.\nM30\n%\n",    # arc mode hands back
    "%\nO1\nG1X1.\nX2.\nF100.X3.\nM30\n%\n",                          # no feed yet: NC202
    "%\nO1\nG0X1.\nX0.00001\nX0.0000001\nX1000000000.5\nX2.\nM30\n%\n",  # spellings only repr() has
    "%\nO1\nG0X0Y0\nG2X2.Y0I1.J0F100.\nX0Y0I-1.J0\nG3X1.Y1.I0J1.\nG1X5.\nM30\n%\n",   # arcs by centre
    "%\nO1\nG20G0X0Y0\nG3X2.Y0I1.J0F10.\nI-1.J0\nG2X1.Y1.I0.J1.001\nM30\n%\n",   # inch, full circle, off circle
    "%\nO1\nG18G0X0Z0\nG2X2.Z0I1.K0F100.\nG19G3Y1.Z1.J0K1.\nM30\n%\n",         # other planes
    "%\nO1\nG0X0Y0\nG2X2.Y0R1.F100.\nX0Y0I-1.J0\nM30\n%\n",                  # radius format: Python
    "%\nO1\nG90.1G0X0Y0\nG2X2.Y0I1.J0F100.\nX0Y0I0J0\nG91.1\nG3X2.Y0I1.J0\nX0Y0I-1.J0\nM30\n%\n",
])
def test_edge_programs_same_with_and_without_kernel(text):
    assert run(text, kernel=True)[:2] == run(text, kernel=False)[:2]


def test_kernel_memory_does_not_grow_with_program_length():
    """The kernel writes a bounded chunk per call: the streamed jsonl run stays flat."""
    import tracemalloc

    def program(n):
        lines = [f"N{i * 5}G1X{i % 97 * 0.37:.4f}Y{i % 89 * 0.41:.4f}Z-{i % 7 * 0.1:.3f}F500."
                 for i in range(n)]
        return "%\nO1\nG90G21G54\nG0X0Y0Z5.\n" + "\n".join(lines) + "\nM30\n%\n"

    class Null:
        def write(self, s):
            return len(s)

    def peak(text):
        src = source.decode(text.encode(), "big.nc")
        tracemalloc.start()
        try:
            ld = pipeline.load_source(src, "big.nc", "iso-m", stream=True)
            n = toolpath_io.write_jsonl(pipeline.toolpath_of(ld, None, fast_sink="jsonl"), Null())
            return n, tracemalloc.get_traced_memory()[1] / 2**20
        finally:
            tracemalloc.stop()
    peak(program(2_000))
    (n_small, small), (n_large, large) = peak(program(10_000)), peak(program(100_000))
    assert n_large == 100_002 and large < small + 1.0, (small, large)     # G0, 100k G1, M30


def test_lint_same_with_and_without_kernel():
    text = "%\nO1\nG21G90G54\nG0X0Y0Z5.\nG1X1.Z-1.\nX2.\nG1F100.X3.\nF-5.X4.\nM30\n%\n"
    assert run(text, kernel=True, lint=True)[1] == run(text, kernel=False, lint=True)[1]
    assert any(d[0] == "NC202" for d in run(text, kernel=True, lint=True)[1])   # G1 without feed


# ------------------------------------------------------------------ generated programs

NUMBER = st.one_of(
    st.integers(-99999, 99999).map(lambda i: f"{i / 1000:.3f}"),
    st.integers(-999, 999).map(str),                                   # no decimal point
    st.integers(0, 255).map(lambda j: f"{j / 128:.7f}"),               # ties at the 7th decimal
    st.sampled_from(["0.00001", "-0.00004", "0.0000004", ".5", "5.", "-.25", "+1.5", "0", "-0.",
                     "123456789.", "1000000000.5", "9" * 30]),
)
AXIS_WORD = st.tuples(st.sampled_from("XYZ" * 6 + "ABUW"), NUMBER).map("".join)
G_WORD = st.sampled_from(["G0", "G1", "G1", "G00", "G01", "G1.0", "G+1", "G-0", "G.0", "G-1", "G2",
                          "G3", "G1.5", "G001", "G90", "G91"])
ODD = st.sampled_from(["F0", "F-5.", "S1000", "I1.", "R2.", "N5", "G1", "X1.", "M8"])
# mostly CAM-shaped lines ([N] [G] axes [F]) so the kernel runs; now and then a word it must refuse
PLAIN_LINE = st.tuples(
    st.sampled_from(["", "", "N10", "N0020"]),
    st.one_of(st.just(""), st.just(""), G_WORD),
    st.lists(AXIS_WORD, min_size=0, max_size=3).map("".join),
    st.sampled_from(["", "", "", "F300.", "F.5", "F1200"]),
    st.one_of(*[st.just("")] * 8, ODD),
).map(lambda t: [w for w in t if w])
SPACED = st.tuples(PLAIN_LINE, st.booleans()).map(lambda t: (" " if t[1] else "").join(t[0]))
HEADER = st.lists(st.sampled_from(["G20", "G21", "G90", "G91", "G54", "G55", "G43H1", "G43H3", "G49",
                                   "G17", "G18", "M3S1200", "T2M6", "G94", "G95", "G93", "G0Z5.",
                                   "G1F100.", "G2X1.Y1.R1.F50.", "G52X10.Y-5.", "G92X0Y0"]),
                  min_size=0, max_size=4)


@pytest.mark.long_property
@settings(max_examples=examples(150, 60), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(HEADER.map("".join), st.lists(st.one_of(*[SPACED] * 6, HEADER.map("".join), st.just("")),
                                     min_size=1, max_size=30),
       st.sampled_from(["\n", "\r\n"]), st.booleans())
def test_generated_program_same_with_and_without_kernel(header, lines, newline, geometry):
    text = newline.join(["%", "O1", header, "G1F250."] + lines + ["M30", "%"]) + newline
    machine = str(GEOMETRY) if geometry else None
    slow = run(text, kernel=False, machine=machine)
    fast = run(text, kernel=True, machine=machine)
    assert fast[1] == slow[1]
    assert fast[0] == slow[0]


COORD = st.one_of(st.integers(-99999, 99999).map(lambda i: f"{i / 1000:.4f}"), NUMBER)
CAM_LINE = st.tuples(
    st.sampled_from(["", "N10 ", "N0020"]),
    st.sampled_from(["", "", "", "G1", "G0", "G01 ", "G00", "G2", "G3", "G02", "G1.0"]),
    st.lists(st.sampled_from("XYZ"), min_size=1, max_size=3, unique=True),
    st.lists(COORD, min_size=3, max_size=3),
    st.sampled_from(["", "", "", "", "F300.", "F1200", " F.5"]),
    st.sampled_from(["", "", "", "I1.J0", "I-0.5J0.5", "J2.", "I1.5K3.", "I0J0"]),
).map(lambda t: t[0] + t[1] + "".join(f"{a}{v}" for a, v in zip(t[2], t[3])) + t[5] + t[4])


@pytest.mark.long_property
@settings(max_examples=examples(100, 40), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(HEADER.map("".join), st.lists(st.one_of(*[CAM_LINE] * 12, HEADER.map("".join)), min_size=5,
                                     max_size=60), st.booleans())
def test_generated_cam_program_same_with_and_without_kernel(header, lines, geometry):
    """CAM-shaped programs, where the kernel carries most blocks and hands some back."""
    text = "\n".join(["%", "O1", header, "G1F250."] + lines + ["M30", "%"]) + "\n"
    machine = str(GEOMETRY) if geometry else None
    slow = run(text, kernel=False, machine=machine)
    fast = run(text, kernel=True, machine=machine)
    assert fast[1] == slow[1]
    assert fast[0] == slow[0]


# ------------------------------------------------------------------ the scan

@pytest.mark.long_property
@settings(max_examples=examples(600, 200), deadline=None)
@given(SPACED, st.sampled_from(["", "\r"]), st.sampled_from([None, "rapid", "linear", "arc_cw", "arc_ccw"]),
       st.sampled_from([None, "drill"]), st.booleans())
def test_scan_accepts_only_what_the_python_fast_path_lowers(line, cr, motion, cycle, arc_abs):
    """A line the kernel takes is one the Python plain path takes in the same static state, and
    it leaves the same motion mode."""
    text = line + cr + "\n"
    _end, _lines, blocks, mode = NATIVE.scan(text, 0, "\n", plainrun.motion_code(motion), cycle is None,
                                             arc_abs)
    code = (line + cr).replace(" ", "")
    code = code[:-1] if code.endswith("\r") else code
    python = None
    if code and code[0] != "O" and PLAIN.fullmatch(code):
        python = Lowering("t.nc", []).plain_block(WORD.findall(code), motion, cycle, arc_abs)
    if blocks:
        assert python is not None, line
        assert mode == (-1 if python[2] is None else plainrun.MOTIONS.index(python[2]))
    elif python is not None:
        # the kernel may be more careful than Python, never less: only over-long lines
        assert len(code) >= 255, line


def test_scan_spans_blank_lines_inside_a_run_only():
    text = "\nG1X1.\n\nX2.\n\n(comment)\nX3.\n"
    assert NATIVE.scan(text, 0, "\n", 0, True, False)[2] == 0     # never starts on a blank line
    end, lines, blocks, motion = NATIVE.scan(text, 1, "\n", 0, True, False)
    assert (lines, blocks, motion) == (3, 2, 1)
    assert text[end:].startswith("\n(comment)")              # the trailing blank line is not taken


@pytest.mark.long_property
@settings(max_examples=examples(3000, 500), deadline=None)
@given(st.one_of(st.floats(-2e9, 2e9, allow_nan=False), st.floats(-1e-3, 1e-3),
                 st.integers(-10**9, 10**9).map(lambda i: i / 128),
                 st.integers(-10**12, 10**12).map(lambda i: (i + 0.5) / 1e6),
                 st.sampled_from([0.0, -0.0, 1e-4, -1e-4, 4.9e-7, 5e-7, 99999.9999995, 1e9, 0.0078125])))
def test_kernel_spells_numbers_as_the_jsonl_writer(v):
    """Every spelling the kernel writes is _spell's; where it declines, the block goes to Python."""
    got = NATIVE.spell(v)
    if got is not None:
        assert got == toolpath_io._spell(v)


DIGITS = st.text("0123456789", min_size=0, max_size=24)
WORD_NUMBER = st.one_of(
    st.tuples(st.sampled_from(["", "-", "+"]), DIGITS, st.sampled_from(["", "."]), DIGITS)
    .map(lambda t: t[0] + t[1] + (t[2] + t[3] if t[2] else "")),
    NUMBER, COORD,
    st.sampled_from(["9007199254740993", "9007199254740992.5", "0.1", "-0.", "+.0",
                     "0." + "0" * 22 + "1", "1" + "0" * 30, "123456789012345678.9", ".0000000000000000000001"]),
).filter(re.compile(r"[-+]?(\d+\.?\d*|\.\d+)").fullmatch)      # a word's number (number_len)


@pytest.mark.long_property
@settings(max_examples=examples(3000, 500), deadline=None)
@given(WORD_NUMBER)
def test_kernel_reads_numbers_as_float_does(text):
    """The kernel's exact fast path (integer digits / 10^k) and its fallback give float()'s double,
    bit for bit (the sign of zero included)."""
    got, want = NATIVE.number(text), float(text)
    assert got == want and math.copysign(1.0, got) == math.copysign(1.0, want), (text, got, want)


@pytest.mark.parametrize("budget", [1, 7, 50, 4100, 4400])
def test_straight_blocks_do_not_spend_the_step_budget_with_or_without_kernel(budget):
    from nctrans.interp import interpret
    text = "%\nO1\nG0X0Y0Z5.\nG1F100.\n" + "\n".join(f"X{i}.Y{i % 7}." for i in range(4500)) + "\nM30\n%\n"

    def go(kernel):
        saved = plainrun.native
        plainrun.native = NATIVE if kernel else None
        try:
            ld = pipeline.load_source(source.decode(text.encode(), "t.nc"), "t.nc", "iso-m", stream=True)
            diags: list = []
            buf = io.StringIO()
            toolpath_io.write_jsonl(interpret(ld.program, None, diagnostics=diags, max_steps=budget,
                                              fast_sink="jsonl" if kernel else None), buf)
            return buf.getvalue(), [(d.rule, d.line, d.message) for d in diags]
        finally:
            plainrun.native = saved
    fast, slow = go(True), go(False)
    assert fast == slow
    # the budget counts repeated execution only: all 4500 moves (+ the rapid, the stop) come out
    assert not any(d[0] == "NC205" for d in fast[1])
    assert fast[0].count("\n") == 4502


@pytest.mark.skipif(NATIVE is None, reason="the native kernel is not built")
@pytest.mark.parametrize("change", [{"pos": -1000}, {"pos": 10**6}, {"end": 10**6}, {"motion": 7},
                                    {"motion": -1}, {"lineno": -5}, {"max_blocks": -1},
                                    {"scale": 0.0}, {"scale": float("nan")}, {"plane": "QQ"},
                                    {"feed_scale": -1.0}, {"feed_scale": float("inf")}])
def test_kernel_validates_its_arguments_at_the_boundary(change):
    """run() and scan() refuse out-of-range arguments with ValueError instead of reading outside
    the text or the kernel's tables (pos=-1000 was a use after free under ASan, motion=7 an
    out-of-bounds index)."""
    text = "G1X1.Y2.F100.\nX3.Y4.\n"
    args = dict(pos=0, end=len(text), lineno=1, motion=1, max_blocks=10, scale=1.0, plane="XY", feed_scale=1.0)
    args.update(change)
    with pytest.raises(ValueError):
        NATIVE.run(text, args["pos"], args["end"], "\n", args["lineno"], "XYZ", [0.0, 0.0, 0.0], None,
                   [0.0, 0.0, 0.0], args["scale"], False, args["motion"], 100.0, ',"feed_mode":"per_min"',
                   "", 0, '"t.nc"', args["max_blocks"], True, args["plane"], False, 1e-6, args["feed_scale"])
    if set(change) <= {"pos", "motion"}:
        with pytest.raises(ValueError):
            NATIVE.scan(text, args["pos"], "\n", args["motion"], True, False)
