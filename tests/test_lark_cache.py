"""Grammar tables cached on disk (nctrans.lark_cache): same parses from the cache, a corrupt or
unwritable cache never breaks a run."""
from __future__ import annotations

import pytest

from nctrans import lark_cache
from nctrans.dialects.sinumerik import frontend as sin

PROGRAM = "DEF REAL AA=2\nR1=AA*3\nIF R1>5 GOTOF END\nG1 X=R1 Y10 F100\nEND:\nM30\n"


def _parse_fresh():
    sin.parser.cache_clear()
    return sin.parse(PROGRAM, "t.mpf")


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("NCTRANS_CACHE_DIR", str(tmp_path / "cache"))
    yield tmp_path / "cache"
    sin.parser.cache_clear()


def test_the_cached_grammar_parses_as_the_built_one(cache_dir):
    built = _parse_fresh()                       # builds the tables and writes the cache file
    files = list(cache_dir.glob("sinumerik-*.lark"))
    assert len(files) == 1 and files[0].stat().st_size > 0
    loaded = _parse_fresh()                      # loads them
    assert loaded.program == built.program and loaded.diagnostics == built.diagnostics == []


def test_a_corrupt_cache_file_is_rebuilt(cache_dir):
    built = _parse_fresh()
    (f,) = cache_dir.glob("sinumerik-*.lark")
    f.write_bytes(f.read_bytes()[:200])          # truncated, hash line intact
    assert _parse_fresh().program == built.program
    f.write_bytes(b"garbage\n")
    assert _parse_fresh().program == built.program


def test_an_unusable_cache_directory_means_no_cache(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    monkeypatch.setenv("NCTRANS_CACHE_DIR", str(blocker / "cache"))
    assert lark_cache.cache_option("sinumerik") is False
    try:
        assert _parse_fresh().diagnostics == []
    finally:
        sin.parser.cache_clear()
