"""Data tables (nctrans/tables.py): validated by pydantic, the validated data cached per content."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from nctrans import tables
from nctrans.interp.cycles import CycleTable
from nctrans.rules import RULES_DIR, RulesTable

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def cache(tmp_path, monkeypatch):
    d = tmp_path / "cache"
    monkeypatch.setenv("NCTRANS_CACHE_DIR", str(d))
    return d


def test_first_load_validates_and_caches_later_loads_skip_validation(cache, monkeypatch):
    path = RULES_DIR / "iso-m.toml"
    first = tables.load(path, RulesTable, RulesTable.from_data)
    assert len(list(cache.iterdir())) == 1

    def no_validation(*a):
        raise AssertionError("validated again although the table did not change")
    monkeypatch.setattr(tables, "_validate", no_validation)
    second = tables.load(path, RulesTable, RulesTable.from_data)
    assert second == first and second.lookup("G1").value == "linear"


def test_changed_table_is_validated_again(cache, tmp_path):
    src = (RULES_DIR / "iso-m.toml").read_text(encoding="utf-8")
    path = tmp_path / "iso-m.toml"
    path.write_text(src, encoding="utf-8")
    tables.load(path, RulesTable, RulesTable.from_data)
    path.write_text(src.replace('meaning = "Linear interpolation"', 'meaning = "straight feed"'),
                    encoding="utf-8")
    again = tables.load(path, RulesTable, RulesTable.from_data)
    assert again.lookup("G1").meaning == "straight feed"
    assert len(list(cache.iterdir())) == 2


def test_invalid_table_names_the_file_and_the_field(cache, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('dialect = "x"\n[[codes]]\ncode = "G1"\ngroup = "motion"\nmodal = "often"\n',
                    encoding="utf-8")
    with pytest.raises(tables.TableError) as err:
        tables.load(path, RulesTable, RulesTable.from_data)
    assert "bad.toml" in str(err.value) and "modal" in str(err.value)
    path.write_text('dialect = "x"\nsurprise = 1\n', encoding="utf-8")      # extra keys: forbidden
    with pytest.raises(tables.TableError, match="surprise"):
        tables.load(path, RulesTable, RulesTable.from_data)
    path.write_text('dialect = "x\n', encoding="utf-8")
    with pytest.raises(tables.TableError, match="invalid TOML"):
        tables.load(path, RulesTable, RulesTable.from_data)
    assert not cache.exists() or not list(cache.iterdir())       # nothing invalid is remembered


def test_corrupt_cache_entry_is_revalidated(cache):
    path = RULES_DIR / "cycles.toml"
    good = tables.load(path, CycleTable, CycleTable.from_data)
    (entry,) = cache.iterdir()
    entry.write_bytes(b"\x00garbage")
    assert tables.load(path, CycleTable, CycleTable.from_data) == good


def test_unwritable_cache_directory_still_loads(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    monkeypatch.setenv("NCTRANS_CACHE_DIR", str(blocker / "cache"))
    table = tables.load(RULES_DIR / "iso-m.toml", RulesTable, RulesTable.from_data)
    assert table.lookup("G0").value == "rapid"


def test_streamed_iso_toolpath_does_not_import_pydantic(tmp_path):
    """The point of the cache: a plain toolpath run never pays for pydantic (~60-150 ms)."""
    env = dict(os.environ, NCTRANS_CACHE_DIR=str(tmp_path / "cache"))
    code = ("import sys, io\nfrom nctrans import cli\nsys.stdout = io.StringIO()\n"
            "for _ in range(2):\n"
            "    cli.main(['toolpath', 'corpus/iso-m/sample-pocket.nc', '--from', 'iso-m'])\n"
            "    loaded = 'pydantic' in sys.modules\n"
            "sys.__stdout__.write(str(loaded))\n")
    # first process fills the cache, the second must not need pydantic at all
    for expected in ("True", "False"):
        out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True,
                             text=True)
        assert out.stdout.strip() == expected, out.stderr


def _entry(cache):
    (entry,) = cache.iterdir()
    return entry


@pytest.mark.parametrize("damage", ["flip", "truncate", "huge", "wrong_type", "missing_keys"])
def test_damaged_cache_entry_is_a_miss_and_is_rebuilt(cache, damage):
    """Any load, shape or size failure of a cached entry is a miss: the table is validated again
    from its TOML, gives the same table, and the entry is rewritten (not trusted again)."""
    import marshal
    import zlib
    path = RULES_DIR / "iso-m.toml"
    good = tables.load(path, RulesTable, RulesTable.from_data)
    entry = _entry(cache)
    original = entry.read_bytes()
    blob = bytearray(original)

    def forged(payload: bytes) -> bytes:       # a well-formed entry holding the wrong data
        return tables._MAGIC + zlib.crc32(payload).to_bytes(4, "little") + \
            len(payload).to_bytes(4, "little") + payload
    if damage == "flip":
        blob[len(blob) // 2] ^= 0x40
        entry.write_bytes(bytes(blob))
    elif damage == "truncate":
        entry.write_bytes(bytes(blob[:len(blob) // 3]))
    elif damage == "huge":
        entry.write_bytes(bytes(blob) + b"\0" * tables.MAX_ENTRY)
    elif damage == "wrong_type":
        entry.write_bytes(forged(marshal.dumps([1, 2, 3])))
    else:
        data = marshal.loads(bytes(blob[12:]))
        data.pop("codes", None)
        entry.write_bytes(forged(marshal.dumps(data)))
    again = tables.load(path, RulesTable, RulesTable.from_data)
    assert again == good and again.lookup("G1").value == "linear"
    assert entry.read_bytes() == original                 # rewritten whole
