"""Long differential runs of the native plain-run kernel against the Python path (`make fuzz`).

Windows of real corpus programs (any 5-200 consecutive lines, behind a random modal header) and
generated CAM-shaped programs: the streamed jsonl toolpath and its diagnostics must be the same
bytes with and without the kernel. tests/test_plainrun.py runs the same properties briefly.
"""
from __future__ import annotations

from hypothesis import given, strategies as st

from nctrans import source
from test_plainrun import CAM_LINE, GEOMETRY, HEADER, SPACED, _need_native, run  # noqa: F401 (fixture)

from conftest import CORPUS

PROGRAMS = [source.decode(p.read_bytes(), p.name).text.split("\n") for p in sorted((CORPUS / "iso-mill").glob("*"))
            if p.is_file()]


@given(st.sampled_from(range(len(PROGRAMS))), st.integers(0, 10**6), st.integers(5, 200),
       HEADER.map("".join), st.booleans())
def test_corpus_windows_same_with_and_without_kernel(index, start, length, header, geometry):
    """(Without the kernel: skipped, or failed in CI, by test_plainrun's _need_native.)"""
    lines = PROGRAMS[index]
    start %= max(1, len(lines) - 1)
    text = "\n".join(["%", "O1", header] + lines[start:start + length] + ["M30", "%"]) + "\n"
    machine = str(GEOMETRY) if geometry else None
    assert run(text, kernel=True, machine=machine)[:2] == run(text, kernel=False, machine=machine)[:2]


@given(HEADER.map("".join), st.lists(st.one_of(CAM_LINE, CAM_LINE, SPACED), min_size=1, max_size=80))
def test_generated_programs_same_with_and_without_kernel(header, lines):
    text = "\n".join(["%", "O1", header, "G1F300."] + lines + ["M30", "%"]) + "\n"
    assert run(text, kernel=True)[:2] == run(text, kernel=False)[:2]
