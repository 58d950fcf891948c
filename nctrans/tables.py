"""The data tables under rules/: TOML, validated by pydantic, remembered per content.

Each table's schema is a set of plain dataclasses (rules.RulesTable, interp.cycles.CycleTable,
catalogue.Catalogue); pydantic validates the TOML against them (TypeAdapter) and dumps the
validated, normalised data, from which the caller builds its objects. Every run needs the
dialect's code table, and tomllib plus pydantic's import cost ~80 ms, more than the native kernel
takes for a 20,000-line program. So the validated data is kept (marshal) in the user's cache
directory under a key made of the table's bytes and the schema module's source: a table is
validated again whenever either changes, and runs in between skip tomllib and pydantic. With no
writable cache directory every run validates.
"""
from __future__ import annotations

import zlib
import marshal
import os
import sys
from pathlib import Path
from typing import Any, Callable, Optional, TypeVar

T = TypeVar("T")

CACHE_VERSION = 2     # 2: entries carry a checked header (_read_cached)


class TableError(Exception):
    """A table that does not read or validate; the message names the file."""


def cache_dir() -> Path:
    """$NCTRANS_CACHE_DIR, else $XDG_CACHE_HOME/nctrans, else ~/.cache/nctrans."""
    env = os.environ.get("NCTRANS_CACHE_DIR")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "nctrans"


def load(path, schema: type, build: Callable[[Any], T], section: tuple[str, ...] = (),
         prepare: Optional[Callable[[Any], Any]] = None) -> T:
    """build(validated data) for the TOML file at `path` (a Path or importlib.resources Traversable)
    validated against the dataclass `schema`. `section`: validate only that table (("tool",
    "nctrans") in a pyproject.toml; missing = empty); `prepare`: applied to it before validation."""
    try:
        raw = path.read_bytes()
    except OSError as e:
        raise TableError(f"{path}: cannot read: {e.strerror or e}") from None
    cached = _entry(Path(path.name).stem, raw, schema)
    data = _read_cached(cached)
    if data is not _MISS and _has_fields(data, schema):
        try:
            return build(data)
        except Exception:            # a cached entry of the wrong shape: a miss, rebuilt below
            pass
    data = _validate(path, raw, schema, section, prepare)
    _store(cached, data)
    return build(data)


def remembered(name: str, raw: bytes, schema: type, make: Callable[[], T], dump: Callable[[T], Any],
               build: Callable[[Any], T]) -> T:
    """make() -- which reads `raw` and validates it against `schema` -- remembered per content as
    `load` remembers tables: while the bytes and the schema's module are unchanged, later runs get
    build(the stored dump(result)) and skip make (tomllib and pydantic). `dump` returns marshal
    data; a result it cannot dump is simply not remembered."""
    cached = _entry(name, raw, schema)
    data = _read_cached(cached)
    if data is not _MISS:
        try:
            return build(data)
        except Exception:            # an entry of the wrong shape: a miss, made again below
            pass
    result = make()
    try:
        data = dump(result)
    except (TypeError, ValueError):
        return result
    _store(cached, data)
    return result


def _entry(name: str, raw: bytes, schema: type) -> Path:
    module = Path(sys.modules[schema.__module__].__file__).read_bytes()
    # a cache key, not a signature: CRC-32 and length of both texts (hashlib's import alone costs
    # more than reading the cached table)
    key = (f"{zlib.crc32(raw):08x}{len(raw):x}-{zlib.crc32(module):08x}{len(module):x}-"
           f"{CACHE_VERSION}{marshal.version}{sys.version_info[0]}{sys.version_info[1]}")
    return cache_dir() / f"{name}-{key}.marshal"


# The cache is trusted only as far as it is checked: an entry is a header (magic, CRC-32 and length
# of the payload) and the marshal payload. Any entry larger than MAX_ENTRY, whose length or CRC
# does not match (a truncated write, a flipped byte: marshal.loads of a corrupted byte once asked
# for 15 GB), or that does not load or build, is a miss and is rebuilt from the TOML. What this
# saves is ~80 ms per run (tomllib + pydantic imports and validation); what it risks is bounded by
# these checks to one rebuild. A deliberately forged entry with a correct CRC needs write access to
# the user's own cache directory, which is no boundary nctrans could defend.
_MAGIC = b"NCTC"
MAX_ENTRY = 4 * 1024 * 1024
_MISS = object()


def _has_fields(data: Any, schema: type) -> bool:
    """The shape pydantic dumps: a dict with every field of the dataclass (defaults included)."""
    import dataclasses
    if not dataclasses.is_dataclass(schema):
        return True
    return isinstance(data, dict) and all(f.name in data for f in dataclasses.fields(schema))


def _read_cached(cached: Path) -> Any:
    try:
        with open(cached, "rb") as fh:
            blob = fh.read(MAX_ENTRY + 1)
    except OSError:
        return _MISS
    if len(blob) > MAX_ENTRY or len(blob) < 12 or blob[:4] != _MAGIC:
        return _MISS
    crc, size = int.from_bytes(blob[4:8], "little"), int.from_bytes(blob[8:12], "little")
    payload = blob[12:]
    if size != len(payload) or zlib.crc32(payload) != crc:
        return _MISS
    try:
        return marshal.loads(payload)
    except (ValueError, EOFError, TypeError, MemoryError):
        return _MISS


def _validate(path: Path, raw: bytes, schema: type, section: tuple[str, ...] = (),
              prepare: Optional[Callable[[Any], Any]] = None) -> Any:
    import tomllib

    from pydantic import TypeAdapter, ValidationError
    try:
        parsed = tomllib.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        raise TableError(f"{path}: invalid TOML: {e}") from None
    for name in section:
        parsed = parsed.get(name, {}) if isinstance(parsed, dict) else {}
    if prepare is not None:
        parsed = prepare(parsed)
    adapter = TypeAdapter(schema)
    try:
        return adapter.dump_python(adapter.validate_python(parsed))
    except ValidationError as e:
        raise TableError(f"{path}: invalid table:\n{e}") from None


def _store(cached: Path, data: Any) -> None:
    """Write atomically (parallel test workers share the directory); a failure only costs speed."""
    try:
        cached.parent.mkdir(parents=True, exist_ok=True)
        tmp = cached.with_name(f"{cached.name}.{os.getpid()}.tmp")
        payload = marshal.dumps(data)
        tmp.write_bytes(_MAGIC + zlib.crc32(payload).to_bytes(4, "little")
                        + len(payload).to_bytes(4, "little") + payload)
        os.replace(tmp, cached)
    except (OSError, ValueError):
        pass
