"""The native kernel under every unit system, and the block-length limit inside plain runs.

Sinumerik G70 reads lengths in inch and feeds in mm/min (G700: both in inch; G71/G710: mm), so the
kernel is handed a feed scale apart from the length scale. Streamed with the kernel, streamed
without it and the full parse must write the same JSON lines and diagnostics on programs that
switch between all four, and the kernel must actually carry the plain lines under G70 (it did not:
such programs ran through Python, 0.42 s instead of 0.15 s on the 22k-line bench program).

NCTRANS_MAX_BLOCK_CHARS: a line longer than it is NC010 at its line, kernel on or off (a plain
line of up to 256 characters used to run inside a kernel run without the check).
"""
from __future__ import annotations

import io
import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from nctrans import pipeline, plainrun, source, toolpath_io

NATIVE = plainrun.native


@pytest.fixture(autouse=True)
def _need_native():
    if NATIVE is None:
        import os
        if os.environ.get("CI"):
            pytest.fail("nctrans._plainrun was not built: the install must compile it in CI", pytrace=False)
        pytest.skip("nctrans._plainrun not built (no C compiler?)")


def run(text: str, dialect: str, *, stream: bool = True, kernel: bool = True) -> tuple:
    """(JSON lines, diagnostics, JSON chunks the kernel wrote) of one toolpath run."""
    name = "t.mpf" if dialect == "sinumerik" else "t.nc"
    saved = plainrun.native
    plainrun.native = NATIVE if kernel else None
    try:
        ld = pipeline.load_source(source.decode(text.encode(), name), name, dialect, stream=stream)
        items = list(pipeline.toolpath_of(ld, pipeline.load_machine(None, dialect), fast_sink="jsonl"))
        buf = io.StringIO()
        toolpath_io.write_jsonl(items, buf)
        chunks = sum(1 for r in items if isinstance(r, plainrun.JsonChunk))
        diags = [(d.rule, d.severity, d.line, d.column, d.message) for d in ld.diagnostics]
        return buf.getvalue(), diags, chunks
    finally:
        plainrun.native = saved


def same_with_and_without_kernel(text: str, dialect: str = "sinumerik") -> tuple:
    """Assert the kernel run, the Python run and the full parse agree; return the kernel run."""
    fast = run(text, dialect)
    slow = run(text, dialect, kernel=False)
    full = run(text, dialect, stream=False)
    assert fast[1] == slow[1] == full[1]
    assert fast[0] == slow[0] == full[0]
    return fast


def records(jsonl: str) -> list[dict]:
    return [json.loads(line) for line in jsonl.splitlines()]


@pytest.mark.parametrize("units, length, feed", [
    ("G70", 25.4, 100.0),        # inch lengths, feed in mm/min
    ("G700", 25.4, 2540.0),      # inch lengths and feed
    ("G71", 1.0, 100.0),
    ("G710", 1.0, 100.0),
])
def test_plain_run_under_each_unit_system(units, length, feed):
    text = f"G90 G17 {units}\nG0 X0 Y0 Z0\nG1 X1 F100\nX2 Y1\nX3\nG2 X5 Y1 I1 J0\nG1 Y2\nY3\nM30\n"
    out, diags, chunks = same_with_and_without_kernel(text)
    assert chunks > 0                                # the kernel wrote these moves
    moves = [r for r in records(out) if r["kind"] in ("linear", "arc")]
    # hand-computed: X1 is 1 x length, every feed move at F100 read in the feed unit
    assert moves[0]["end"]["X"] == pytest.approx(1 * length)
    assert moves[2]["end"]["X"] == pytest.approx(3 * length)
    assert moves[-1]["end"]["Y"] == pytest.approx(3 * length)
    assert [m["feed"] for m in moves] == pytest.approx([feed] * len(moves))
    assert not [d for d in diags if d[1] == "error"]


def test_units_switch_between_runs_keeps_the_feed_unit():
    """G70 -> G700 -> G71 with plain runs between: a feed read under G70 stays 100 mm/min when
    G700 comes (the switch does not rescale a feed already read), then F10 under G700 is 254."""
    text = ("G90 G70\nG0 X0 Y0\nG1 X1 F100\nX2\nX3\nG700\nX4\nX5\nF10 X6\nX7\nG71\nX8\nX9\nM30\n")
    out, _diags, chunks = same_with_and_without_kernel(text)
    assert chunks > 0
    moves = [r for r in records(out) if r["kind"] == "linear"]
    assert [round(m["end"]["X"], 4) for m in moves] == [25.4, 50.8, 76.2, 101.6, 127.0, 152.4, 177.8,
                                                       8.0, 9.0]
    assert [m["feed"] for m in moves][:3] == [100.0, 100.0, 100.0]
    assert moves[5]["feed"] == pytest.approx(254.0) and moves[6]["feed"] == pytest.approx(254.0)


UNITS = st.sampled_from(["G70", "G700", "G71", "G710", "G91", "G90", "F40", "F7.5", "G0", "G1"])
AXIS_WORD = st.tuples(st.sampled_from("XYZ"), st.integers(-3000, 3000)).map(lambda t: f"{t[0]}{t[1] / 1000}")
PLAIN = st.tuples(st.sampled_from(["", "G1 ", "G0 ", "F12.5 ", "F300 "]),
                  st.lists(AXIS_WORD, min_size=1, max_size=3, unique_by=lambda w: w[0])).map(
                      lambda t: t[0] + " ".join(t[1]))


@settings(max_examples=60, deadline=None)
@given(st.lists(st.one_of(UNITS, PLAIN, PLAIN, PLAIN), min_size=2, max_size=30),
       st.sampled_from(["G70", "G700", "G71", "G710"]))
def test_generated_unit_switching_programs_same_with_and_without_kernel(lines, units):
    same_with_and_without_kernel(f"G90 {units}\nG0 X0 Y0 Z0\nF100\n" + "\n".join(lines) + "\nM30\n")


@pytest.mark.parametrize("dialect, text, long_line", [
    ("sinumerik", "G71 G90\nG0 X0 Y0\nG1 X1 F100\nX2 Y2\nX3.1234567 Y3.1234567 Z-1.1234567\nX4\nX5\nM30\n", 5),
    ("iso-m", "%\nO1\nG21G90\nG0X0Y0\nG1X1F100\nX2Y2\nX3.1234567Y3.1234567Z-1.1234567\nX4\nX5\nM30\n%\n", 7),
    # a blank line longer than the limit inside a run
    ("iso-m", "%\nO1\nG21G90\nG0X0Y0\nG1X1F100\nX2Y2\n" + " " * 40 + "\nX4\nX5\nM30\n%\n", 7),
    ("sinumerik", "G71 G90\nG0 X0 Y0\nG1 X1 F100\nX2 Y2\n" + " " * 40 + "\nX4\nX5\nM30\n", 5),
])
def test_block_longer_than_the_limit_is_nc010_with_and_without_kernel(monkeypatch, dialect, text, long_line):
    monkeypatch.setenv("NCTRANS_MAX_BLOCK_CHARS", "30")
    out, diags, _chunks = same_with_and_without_kernel(text, dialect)
    assert [(d[0], d[2], d[3]) for d in diags if d[0] == "NC010"] == [("NC010", long_line, 1)]
    # the long block is not analysed: no move ends on its line
    assert all(r["line"] != long_line for r in records(out))
