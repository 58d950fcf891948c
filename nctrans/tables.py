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

CACHE_VERSION = 1


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
    module = Path(sys.modules[schema.__module__].__file__).read_bytes()
    # a cache key, not a signature: CRC-32 and length of both texts (hashlib's import alone costs
    # more than reading the cached table)
    key = (f"{zlib.crc32(raw):08x}{len(raw):x}-{zlib.crc32(module):08x}{len(module):x}-"
           f"{CACHE_VERSION}{marshal.version}{sys.version_info[0]}{sys.version_info[1]}")
    cached = cache_dir() / f"{Path(path.name).stem}-{key}.marshal"
    try:
        data = marshal.loads(cached.read_bytes())
    except (OSError, ValueError, EOFError, TypeError):
        data = _validate(path, raw, schema, section, prepare)
        _store(cached, data)
    return build(data)


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
        tmp.write_bytes(marshal.dumps(data))
        os.replace(tmp, cached)
    except (OSError, ValueError):
        pass
