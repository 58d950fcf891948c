"""Parsed definition files remembered between processes (nctrans.parse_cache).

What is read back must be what a parse gives, and anything that could change the parse (the
file's text, its label, the code that parses it, the NCTRANS_* limits) must make a new entry; a
damaged entry is parsed again, never an error.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from nctrans import parse_cache, pipeline
from nctrans.dialects.base import get

GUD = ("DEF NCK REAL FEEDMAX=2500\nDEF CHAN INT COUNT[3]\nDEF NCK BOOL READY\nDEF NCK STRING[16] NAME=\"A\"\n"
       "M17\n")


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    d = tmp_path / "cache"
    monkeypatch.setenv("NCTRANS_CACHE_DIR", str(d))
    return d


def counted(text: str, label: str):
    calls = []

    def parse():
        calls.append(1)
        return get("sinumerik").parse(text, label).program
    return parse, calls


def test_second_read_is_the_parse_without_parsing(cache):
    parse, calls = counted(GUD, "GUD.DEF")
    first = parse_cache.definition(GUD, "GUD.DEF", "sinumerik", parse)
    again = parse_cache.definition(GUD, "GUD.DEF", "sinumerik", parse)
    assert calls == [1]
    assert again == first == get("sinumerik").parse(GUD, "GUD.DEF").program
    assert again is not first
    assert len(list((cache / "parsed").iterdir())) == 1


@pytest.mark.parametrize("change", ["text", "label", "code", "limits"])
def test_what_changes_the_parse_makes_a_new_entry(cache, monkeypatch, change):
    parse, calls = counted(GUD, "GUD.DEF")
    parse_cache.definition(GUD, "GUD.DEF", "sinumerik", parse)
    text, label = GUD, "GUD.DEF"
    if change == "text":
        text = GUD.replace("2500", "2600")
    elif change == "label":
        label = "sub/GUD.DEF"
    elif change == "code":
        monkeypatch.setattr(parse_cache, "code_stamp", lambda: "0000000099")
    else:
        monkeypatch.setenv("NCTRANS_MAX_BLOCK_CHARS", "20")
    parse2, calls2 = counted(text, label)
    got = parse_cache.definition(text, label, "sinumerik", parse2)
    assert calls2 == [1]
    assert got == get("sinumerik").parse(text, label).program
    assert len(list((cache / "parsed").iterdir())) == 2


def test_limits_are_part_of_the_key_because_they_change_the_parse(cache, monkeypatch):
    """Blocks longer than 20 characters are NC010 and dropped under NCTRANS_MAX_BLOCK_CHARS=20 (of
    the four DEF lines only `DEF NCK BOOL READY`, 18 characters, is kept): the entry parsed without
    the limit must not be read back under it."""
    def decls(program):
        return [s.name for b in program.body for s in getattr(b, "body", []) if type(s).__name__ == "VarDecl"]
    full = parse_cache.definition(GUD, "GUD.DEF", "sinumerik", counted(GUD, "GUD.DEF")[0])
    assert decls(full) == ["FEEDMAX", "COUNT", "READY", "NAME"]
    monkeypatch.setenv("NCTRANS_MAX_BLOCK_CHARS", "20")
    limited = parse_cache.definition(GUD, "GUD.DEF", "sinumerik", counted(GUD, "GUD.DEF")[0])
    assert decls(limited) == ["READY"]


@pytest.mark.parametrize("damage", ["truncate", "flip", "garbage", "other_object"])
def test_a_damaged_entry_is_parsed_again(cache, damage):
    import pickle
    import zlib
    parse, calls = counted(GUD, "GUD.DEF")
    good = parse_cache.definition(GUD, "GUD.DEF", "sinumerik", parse)
    (entry,) = (cache / "parsed").iterdir()
    blob = entry.read_bytes()
    if damage == "truncate":
        entry.write_bytes(blob[:len(blob) // 2])
    elif damage == "flip":
        entry.write_bytes(blob[:-5] + bytes([blob[-5] ^ 0xFF]) + blob[-4:])
    elif damage == "garbage":
        entry.write_bytes(b"NCTP" + b"\x00" * 40)
    else:                       # a well-formed entry of another shape
        payload = pickle.dumps({"not": "a program"})
        entry.write_bytes(b"NCTP" + zlib.crc32(payload).to_bytes(4, "little")
                          + len(payload).to_bytes(4, "little") + payload)
    again = parse_cache.definition(GUD, "GUD.DEF", "sinumerik", parse)
    assert calls == [1, 1]
    assert again == good


def test_no_writable_cache_directory_still_parses(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    monkeypatch.setenv("NCTRANS_CACHE_DIR", str(blocker / "cache"))
    parse, calls = counted(GUD, "GUD.DEF")
    assert parse_cache.definition(GUD, "GUD.DEF", "sinumerik", parse) is not None
    assert parse_cache.definition(GUD, "GUD.DEF", "sinumerik", parse) is not None
    assert calls == [1, 1]


def test_a_program_reads_the_same_declarations_cold_and_warm(cache, tmp_path, monkeypatch):
    """End to end: a program beside its GUD file, linted with an empty cache and again from it
    (the in-process cache cleared, as a new process starts): the same diagnostics and toolpath."""
    d = tmp_path / "prog"
    d.mkdir()
    (d / "_N_SGUD.DEF").write_text(GUD)
    (d / "PART.MPF").write_text("R1=FEEDMAX\nG1 X=COUNT[1]+10 F=R1\nIF READY GOTOF END\nG0 X0\nEND:\nM30\n")
    results = []
    for _ in range(2):
        monkeypatch.setattr(pipeline, "_DEFINITION_CACHE", {})
        ld = pipeline.load(str(d / "PART.MPF"), "sinumerik")
        records = [r.to_dict() for r in pipeline.toolpath_of(ld, pipeline.load_machine(None, "sinumerik"))]
        results.append((records, [repr(x) for x in ld.diagnostics]))
    assert results[0] == results[1]
    assert len(list((cache / "parsed").iterdir())) == 1
    moves = [r for r in results[0][0] if r["kind"] == "linear"]
    assert moves and moves[0]["end"]["X"] == 10.0 and moves[0]["feed"] == 2500.0
