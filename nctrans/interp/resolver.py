"""Finding subprograms that live in other files (each dialect says how a name maps to file names:
Dialect.subprogram_files).

A Resolver is the `resolver` argument of `interpret`: resolver(name, from_file) -> Program | None.
It looks in the calling file's directory first, then in the configured search paths, and never
outside them: names with path separators or `..` are refused. Parsed programs are cached per file,
so a subprogram called a thousand times is read once.
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Callable, Iterable, Optional

from nctrans.ir.nodes import Program

_SAFE = re.compile(r"^[A-Za-z0-9_.$%-]+$")


def _default_stems(name: str) -> list[str]:
    return [name, name.upper()]


def candidate_names(name: str, stems: Callable[[str], list[str]] = _default_stems,
                    endings: Iterable[str] = ()) -> list[str]:
    """File names (without directory) that may hold the program `name`, most likely first: each of
    `stems(name)` (the dialect's spellings of the name) as written, then with each of `endings`
    (a stem that already has an ending is tried as written only). [] for a name that could leave
    the directory (path separators, `..`)."""
    s = name.strip().strip('"').strip("'")
    if not s or not _SAFE.match(s) or ".." in s:
        return []
    seen: set[str] = set()
    out = []
    for st in stems(s):
        for ext in ("", *endings):
            if "." in st and ext:
                continue
            f = st + ext
            if f not in seen:
                seen.add(f)
                out.append(f)
    return out


class Resolver:
    """Map a subprogram name to a parsed Program from the caller's directory or the search paths.

    parse_fn(path) -> Program | None reads and parses one file (the caller chooses the dialect);
    candidates(name) -> file names to try (the caller's dialect's Dialect.subprogram_files).
    """

    def __init__(self, search_paths: Iterable[str | Path] = (), parse_fn: Optional[Callable] = None,
                 candidates: Callable[[str], list[str]] = candidate_names):
        self.search_paths = [Path(p).resolve() for p in search_paths]
        self.parse_fn = parse_fn
        self.candidates = candidates
        self._cache: dict[Path, Optional[Program]] = {}

    def find_file(self, name: str, from_file: Optional[str] = None) -> Optional[Path]:
        dirs: list[Path] = []
        if from_file and from_file not in ("-", "<stdin>"):
            dirs.append(Path(from_file).resolve().parent)
        dirs += [d for d in self.search_paths if d not in dirs]
        for d in dirs:
            if not d.is_dir():
                continue
            for cand in self.candidates(name):
                p = d / cand
                if p.is_file() and p.resolve().parent == d:
                    return p.resolve()
        return None

    def __call__(self, name: str, from_file: Optional[str] = None) -> Optional[Program]:
        path = self.find_file(name, from_file)
        if path is None or self.parse_fn is None:
            return None
        if path not in self._cache:
            self._cache[path] = self.parse_fn(path)
        return self._cache[path]
