"""Shared fixtures: where the read-only shared tree is, and LinuxCNC's rs274 as the reference.

The corpus is read in place from ../shared (never copied into the project). rs274 is optional on a
developer machine (its tests skip) but required in CI: with CI set, a missing rs274 is a failure, so
the reference comparison cannot silently vanish from the pipeline.
"""
from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

TESTS = Path(__file__).resolve().parent
SHARED = Path(__file__).resolve().parents[1].parent / "shared"
CORPUS = SHARED / "corpus"
DATA = TESTS / "data"


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    return SHARED


@pytest.fixture(scope="session")
def corpus_dir() -> Path:
    if not CORPUS.is_dir():
        pytest.skip(f"shared corpus not found at {CORPUS}")
    return CORPUS


@pytest.fixture(scope="session")
def data_dir() -> Path:
    return DATA


@pytest.fixture(scope="session")
def rs274() -> Path:
    """Path of LinuxCNC's stand-alone rs274: skip without it, but fail when CI is set."""
    import rs274 as harness
    found = harness.RS274 if Path(harness.RS274).exists() else None
    if found is None:
        msg = f"LinuxCNC rs274 not found at {harness.RS274} (Debian package linuxcnc-uspace; or set RS274=path)"
        if os.environ.get("CI"):
            pytest.fail(msg + " and CI is set: the reference comparison must run in CI", pytrace=False)
        pytest.skip(msg)
    harness.RS274 = found
    return Path(found)


@pytest.fixture(scope="session")
def chromium():
    """A headless Chromium (tests/browser.py): skip without one, but fail when CI is set."""
    import browser
    if not browser.CHROMIUM:
        msg = "chromium not found (Debian package chromium; or set CHROMIUM=path)"
        if os.environ.get("CI"):
            pytest.fail(msg + " and CI is set: the backplot viewer must be tested in a real browser",
                        pytrace=False)
        pytest.skip(msg)
    b = browser.Browser()
    yield b
    b.close()


@pytest.fixture(scope="session")
def rs274_cache(tmp_path_factory) -> Path:
    """Per-session directory for rs274 outputs, so each program runs through rs274 once."""
    return tmp_path_factory.mktemp("rs274")


# Hypothesis profiles: `make test` runs the fuzzers briefly (the default profile), `make fuzz` runs
# them long with --hypothesis-profile=fuzz (NCTRANS_FUZZ_EXAMPLES sets the count).

settings.register_profile(
    "fuzz",
    max_examples=int(os.environ.get("NCTRANS_FUZZ_EXAMPLES", "20000")),
    deadline=None,
    suppress_health_check=list(HealthCheck),
    print_blob=True,
)
settings.register_profile("default", max_examples=60, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
FUZZING = bool(os.environ.get("NCTRANS_FUZZ_PROFILE_SET"))
if not FUZZING:
    settings.load_profile("default")


def examples(full: int, brief: int) -> int:
    """max_examples of a long property test (marked long_property): `brief` in `make test`, which
    must stay inside the CI budget on 2 cores, and `full` under `make fuzz`, which runs the marked
    tests again with NCTRANS_FUZZ_PROFILE_SET. `brief` stays large enough for the property to bite."""
    return full if FUZZING else brief


class TextSink:
    """An output stream that keeps what the writers send it, piece by piece (`parts`): for the
    tests that convert into a sink instead of a string (the streamed and compact paths)."""

    def __init__(self):
        self.parts: list[str] = []

    def write(self, s: str) -> None:
        self.parts.append(s)

    def reset(self) -> None:
        self.parts = []
