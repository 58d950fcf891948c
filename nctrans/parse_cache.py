"""Parsed definition files remembered between processes.

A program is run with the declarations of the definition files beside it (Dialect.definition_files:
Sinumerik GUD modules, `*.DEF`). They are parsed on every run, although they rarely change: for a
small program that is a large share of a short run (two GUD files of 470 lines took ~24 ms of a
~150 ms `nctrans lint`, and they need the grammar). So the parsed Program is kept (pickle) in the
user's nctrans cache directory (tables.cache_dir), under a key made of the file's text and label,
the dialect, the NCTRANS_* environment (limits) and a stamp of the code that parses it: the name,
size and modification time of every file of the nctrans package and of its grammars and rules. Any
change to them, or to the file, makes a new key; an entry that does not read (truncated, corrupted,
of another shape) is a miss, and the file is parsed again. With no writable cache directory every
run parses.

The entries are pickles, as lark's own table cache is: loading one runs what it names, so the cache
directory is the user's own (never a shared temporary directory). An entry carries a header (magic,
CRC-32 and length of the payload) so a damaged write is a miss, not an error.
"""
from __future__ import annotations

import os
import pickle
import sys
import zlib
from functools import lru_cache
from pathlib import Path
from typing import Callable, Optional

from nctrans.ir.nodes import Program

_MAGIC = b"NCTP"
MAX_ENTRY = 16 * 1024 * 1024


def definition(text: str, label: str, dialect: str, parse: Callable[[], Optional[Program]]
               ) -> Optional[Program]:
    """parse() of the definition file `label` (decoded `text`) in `dialect`, remembered per
    content and code (see the module's docstring)."""
    path = _entry(text, label, dialect)
    if path is not None:
        found = _read(path)
        if found is not None:
            return found
    program = parse()
    if path is not None and program is not None:
        _write(path, program)
    return program


def _entry(text: str, label: str, dialect: str) -> Optional[Path]:
    from nctrans.tables import cache_dir
    stamp = code_stamp()
    if stamp is None:
        return None
    raw = text.encode("utf-8", "surrogatepass")
    # the environment's limits (NCTRANS_MAX_BLOCK_CHARS ...) change what a parse keeps
    env = "".join(f"{k}={v}\0" for k, v in sorted(os.environ.items()) if k.startswith("NCTRANS_"))
    ident = f"{dialect}\0{label}\0{env}".encode("utf-8", "surrogatepass")
    key = (f"{zlib.crc32(raw):08x}{len(raw):x}-{zlib.crc32(ident):08x}-{stamp}-"
           f"{pickle.HIGHEST_PROTOCOL}{sys.version_info[0]}{sys.version_info[1]}")
    return cache_dir() / "parsed" / f"{dialect}-{key}.pickle"


@lru_cache(maxsize=1)
def code_stamp() -> Optional[str]:
    """A stamp of the code and data that parse a program: (relative name, size, modification
    time) of every file of the package, its grammars and its rules, folded into CRC-32s. None
    when they cannot be listed (nothing is cached then)."""
    from nctrans import resources
    crc, count = 0, 0
    try:
        roots = [resources.PACKAGE, resources.root("grammars"), resources.root("rules")]
        for root in roots:
            for rel, st in _files(Path(root)):
                line = f"{rel}\0{st.st_size}\0{st.st_mtime_ns}\n"
                crc = zlib.crc32(line.encode("utf-8", "surrogatepass"), crc)
                count += 1
    except (OSError, resources.ResourceError):
        return None
    return f"{crc:08x}{count:x}"


def _files(root: Path, prefix: str = ""):
    """(relative name, stat) of the files under root, in a stable order; __pycache__ left out."""
    with os.scandir(root) as it:
        entries = sorted(it, key=lambda e: e.name)
    for e in entries:
        if e.name == "__pycache__" or e.name.startswith("."):
            continue
        rel = prefix + e.name
        if e.is_dir(follow_symlinks=False):
            yield from _files(Path(e.path), rel + "/")
        elif e.is_file():
            yield rel, e.stat()


def _read(path: Path) -> Optional[Program]:
    try:
        with open(path, "rb") as fh:
            blob = fh.read(MAX_ENTRY + 1)
    except OSError:
        return None
    if len(blob) > MAX_ENTRY or len(blob) < 12 or blob[:4] != _MAGIC:
        return None
    crc, size = int.from_bytes(blob[4:8], "little"), int.from_bytes(blob[8:12], "little")
    payload = blob[12:]
    if size != len(payload) or zlib.crc32(payload) != crc:
        return None
    try:
        program = pickle.loads(payload)
    except Exception:          # an entry of another version or shape: a miss, parsed again
        return None
    return program if type(program) is Program else None


def _write(path: Path, program: Program) -> None:
    try:
        payload = pickle.dumps(program, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception:          # a program that does not pickle is simply not remembered
        return
    if len(payload) > MAX_ENTRY:
        return
    blob = _MAGIC + zlib.crc32(payload).to_bytes(4, "little") + len(payload).to_bytes(4, "little") + payload
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(tmp, "wb") as fh:
            fh.write(blob)
        os.replace(tmp, path)
    except OSError:
        try:
            tmp.unlink()
        except OSError:
            pass
