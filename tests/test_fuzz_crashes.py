"""Every input `make fuzz` (fuzz/fuzz_frontends.py) found crashing runs here from then on: decode,
parse, lint and convert must end with diagnostics, never an exception."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "fuzz"))
from fuzz_frontends import CRASHES, one_input  # noqa: E402

CASES = sorted(CRASHES.glob("*/crash-*"))


@pytest.mark.parametrize("path", CASES or [None], ids=lambda p: f"{p.parent.name}/{p.name}" if p else "none")
def test_kept_fuzz_crash_no_longer_crashes(path):
    if path is None:
        pytest.skip("no fuzz crash kept yet")
    one_input(path.parent.name, path.read_bytes())
