"""Runs of plain lines are read once: the kernel finds where a run ends as it runs it.

The front end only asks scan() whether a run starts (its first two lines); the kernel then holds
each line to scan()'s checks while it runs it, and the front end goes on where the kernel stopped.
Whoever needs the end first (a consumer that is not the kernel, a block the kernel hands back, the
front end asked for more before the run ran) finds it with scan(). Every way must give the bytes
and diagnostics of the run without the kernel: here at the edges of that hand-over (kernel calls
of a few blocks ending on blank lines inside a run, runs ending in blank lines, no final newline,
a block the kernel hands back mid-run, a consumer that expands runs in Python).
"""
from __future__ import annotations

import io
import os
from unittest import mock

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from nctrans import pipeline, plainrun, source, toolpath_io
from nctrans.interp import native as native_lane

from conftest import CORPUS, examples

NATIVE = plainrun.native


@pytest.fixture(autouse=True)
def _need_native():
    if NATIVE is None:
        if os.environ.get("CI"):
            pytest.fail("nctrans._plainrun was not built: the install must compile it in CI", pytrace=False)
        pytest.skip("nctrans._plainrun not built (no C compiler?)")


def run(text: str, dialect: str, *, kernel: bool = True, sink="jsonl", native=None) -> tuple:
    """(JSON lines, diagnostics) of the streamed toolpath; sink None: records as objects,
    "discard": none (lint). `native`: the kernel module to use (a wrapper of it)."""
    name = "t.mpf" if dialect == "sinumerik" else "t.nc"
    saved = plainrun.native
    plainrun.native = (native or NATIVE) if kernel else None
    try:
        ld = pipeline.load_source(source.decode(text.encode(), name), name, dialect, stream=True)
        items = pipeline.toolpath_of(ld, pipeline.load_machine(None, dialect), fast_sink=sink if kernel else None)
        buf = io.StringIO()
        toolpath_io.write_jsonl(items, buf)
        return buf.getvalue(), [(d.rule, d.severity, d.line, d.column, d.message) for d in ld.diagnostics]
    finally:
        plainrun.native = saved


def count_scanned() -> tuple:
    """(a wrapper of the kernel, the list of blocks each of its scan() calls read)."""
    read: list = []

    class Counting:
        def __getattr__(self, name):
            return getattr(NATIVE, name)

        def scan(self, *args):
            result = NATIVE.scan(*args)
            read.append(result[2])
            return result

    return Counting(), read


def test_a_cam_program_is_read_once():
    """The 22k-line Fusion program: 22,000 plain lines run by the kernel, and scan() reads at most
    the two lines that start each run (it read every plain line before the kernel ran them)."""
    path = CORPUS / "iso-mill" / "mheaton-fusion-adaptive-1001.nc"
    text = source.decode(path.read_bytes(), path.name).text
    counting, scanned = count_scanned()
    out, _diags = run(text, "iso-m", native=counting)
    assert out.count("\n") > 20_000
    assert scanned and max(scanned) <= 2
    assert sum(scanned) < 1_000


def test_a_consumer_without_the_kernel_still_finds_the_run_ends():
    """Records as objects (backplot, equiv): no kernel, so the runs' ends come from scan()."""
    text = "G0 X0 Y0\nG1 X1 F100\nX2\n\nX3\n; note\nX4\nX5\nX6\nM30\n"
    counting, scanned = count_scanned()
    objects, diags = run(text, "sinumerik", sink=None, native=counting)
    assert sum(scanned) > 4                  # the runs' ends: scan() read their lines
    assert (objects, diags) == run(text, "sinumerik", kernel=False)


LINE = st.one_of(
    st.tuples(st.sampled_from(["", "G1 ", "G0 ", "G2 ", "F50 "]),
              st.lists(st.tuples(st.sampled_from("XYZ"), st.integers(-99, 99)), min_size=1, max_size=3,
                       unique_by=lambda w: w[0])).map(lambda t: t[0] + " ".join(f"{a}{v / 10}" for a, v in t[1])),
    st.sampled_from(["", "", " ", "  \r", "; comment", "M5", "M3 S1000", "G91", "G90", "I1 J0", "R1=2",
                     "G1 X1 F0", "G17", "G2 X1 Y1 CR=5", "N10 X1", "X" + "1" * 40]),
)


@pytest.mark.long_property
@settings(max_examples=examples(120, 60), deadline=None)
@given(st.lists(LINE, min_size=1, max_size=40), st.integers(1, 4), st.booleans(),
       st.sampled_from(["sinumerik", "iso-m"]))
def test_kernel_calls_of_few_blocks_give_the_same_toolpath(lines, kernel_blocks, final_newline, dialect):
    """The kernel stops every `kernel_blocks` blocks (on a blank line inside a run, right before a
    run's end, ...) and hands blocks back (arcs without centre, missing feed, M5 stops it); runs end
    in blank lines, long lines (NC010) and the end of the text with or without a final newline."""
    body = "\n".join(line.replace(" ", "") if dialect == "iso-m" else line for line in lines)
    head = "G0X0Y0Z0\nG1F100\n" if dialect == "iso-m" else "G0 X0 Y0 Z0\nG1 F100\n"
    text = head + body + ("\n" if final_newline else "")
    saved = native_lane.KERNEL_BLOCKS
    native_lane.KERNEL_BLOCKS = kernel_blocks
    try:
        with mock.patch.dict(os.environ, {"NCTRANS_MAX_BLOCK_CHARS": "30"}):
            assert run(text, dialect) == run(text, dialect, kernel=False)
            assert run(text, dialect, sink="discard")[1] == run(text, dialect, kernel=False)[1]
    finally:
        native_lane.KERNEL_BLOCKS = saved
