"""A machine file is validated (tomllib + pydantic) once per content; later runs rebuild the same
machine from the table cache without importing pydantic (nctrans.machine.load, tables.remembered)."""
from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import pytest

from nctrans import machine
from nctrans.machine import MachineError

VMC = """
name = "vmc"
kind = "mill"
shop_note = "kept: a key the model does not know"
tool_change_s = 6.5
[axes.X]
min = -300.0
max = 300.0
max_feed = 8000.0
probe = "renishaw"
[axes.Y]
min = -200.0
max = 200.0
[spindle]
max_rpm = 12000
[offsets.g54]
x = 10.0
[[tools]]
number = 1
length = 100.0
radius = 5.0
holder = [{ radius = 12.0, length = 20.0 }]
[[tools]]
number = 7
radius = 0.4
tip = 3
[length_offsets]
3 = 42.5
[stock]
box = { min = [-50, -50, -20], max = [30, 50, 0] }
[tool_change]
requires_stopped = ["coolant"]
"""


@pytest.fixture
def cache(tmp_path, monkeypatch):
    d = tmp_path / "cache"
    monkeypatch.setenv("NCTRANS_CACHE_DIR", str(d))
    return d


def _everything(obj):
    """Every attribute, nested, including keys the model does not know."""
    if dataclasses.is_dataclass(obj):
        return (type(obj).__name__, {k: _everything(v) for k, v in vars(obj).items()})
    if isinstance(obj, dict):
        return {k: _everything(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_everything(v) for v in obj]
    return obj


def test_remembered_machine_is_the_validated_one(tmp_path, cache):
    path = tmp_path / "vmc.toml"
    path.write_text(VMC)
    first = machine.load(path)
    assert len(list(cache.glob("machine-*.marshal"))) == 1
    again = machine.load(path)
    assert again is not first and _everything(again) == _everything(first)
    # what the validation made of the file, checked by hand
    assert again.shop_note.startswith("kept") and again.axes["X"].probe == "renishaw"
    assert again.offsets == {"G54": {"X": 10.0}} and again.length_offset(3) == 42.5
    assert again.tool(1).holder[0].radius == 12.0 and again.tool(7).tip == 3
    assert again.tool_change.requires_stopped == ["coolant"] and again.stock.box["max"] == [30, 50, 0]
    assert again.source_dir == str(tmp_path)
    assert again.copy().tool(1).radius == 5.0           # deep copies (the interpreter's G10) work


def test_a_cached_run_does_not_import_pydantic(tmp_path, cache):
    path = tmp_path / "vmc.toml"
    path.write_text(VMC)
    script = ("import sys; from nctrans import machine; m = machine.load(sys.argv[1]); "
              "print(m.tool(1).radius, 'pydantic' in sys.modules)")
    env = {**os.environ, "NCTRANS_CACHE_DIR": str(cache)}
    runs = [subprocess.run([sys.executable, "-c", script, str(path)], capture_output=True, text=True,
                           env=env, timeout=120) for _ in range(2)]
    assert [r.stdout.split() for r in runs] == [["5.0", "True"], ["5.0", "False"]], [r.stderr for r in runs]


def test_an_edited_file_is_validated_again(tmp_path, cache):
    path = tmp_path / "vmc.toml"
    path.write_text(VMC)
    machine.load(path)
    path.write_text(VMC.replace("radius = 5.0", "radius = -5.0"))
    with pytest.raises(MachineError, match="radius"):
        machine.load(path)
    path.write_text(VMC.replace("max_rpm = 12000", "max_rpm = 9000"))
    assert machine.load(path).spindle.max_rpm == 9000


def test_a_damaged_entry_is_a_miss(tmp_path, cache):
    path = tmp_path / "vmc.toml"
    path.write_text(VMC)
    machine.load(path)
    (entry,) = cache.glob("machine-*.marshal")
    blob = bytearray(entry.read_bytes())
    blob[-3] ^= 0xFF                                   # the CRC no longer matches
    entry.write_bytes(bytes(blob))
    assert machine.load(path).tool(1).radius == 5.0
    # an intact entry of another shape (not a machine) is a miss too
    from nctrans import tables
    tables._store(entry, {"name": "not a machine"})
    assert isinstance(machine.load(path), machine.Machine)


def test_without_a_cache_directory_every_run_validates(tmp_path, monkeypatch):
    blocked = tmp_path / "file"
    blocked.write_text("")
    monkeypatch.setenv("NCTRANS_CACHE_DIR", str(blocked / "cache"))    # under a file: not creatable
    path = tmp_path / "vmc.toml"
    path.write_text(VMC)
    assert machine.load(path).tool(1).radius == 5.0
    assert machine.load(Path(path)).tool(7).tip == 3
