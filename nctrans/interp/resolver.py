"""Finding subprograms that live in other files (ISO `O1000` -> 1000.nc, Sinumerik `L10` -> L10.SPF).

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

EXTENSIONS = ("", ".nc", ".NC", ".mpf", ".MPF", ".spf", ".SPF", ".tap", ".TAP", ".ngc", ".cnc",
              ".iso", ".eia", ".txt")
_SAFE = re.compile(r"^[A-Za-z0-9_.$%-]+$")


def candidate_names(name: str) -> list[str]:
    """File names (without directory) that may hold the program `name`, most likely first."""
    s = name.strip().strip('"').strip("'")
    if not s or not _SAFE.match(s) or ".." in s:
        return []
    stems: list[str] = []
    m = re.match(r"^[Oo]?0*(\d+)$", s)
    if m:
        num = m.group(1)
        stems += [f"O{num.zfill(4)}", f"O{num}", num.zfill(4), num, f"o{num.zfill(4)}", f"o{num}"]
    else:
        stems += [s, s.upper()]
        if s.upper().startswith("%_N_"):          # Sinumerik archive names %_N_NAME_SPF
            core = s.upper()[4:]
            for ext in ("_SPF", "_MPF"):
                if core.endswith(ext):
                    stems.append(core[:-4])
    seen: set[str] = set()
    out = []
    for st in stems:
        for ext in EXTENSIONS:
            if "." in st and ext:
                continue
            f = st + ext
            if f not in seen:
                seen.add(f)
                out.append(f)
    return out


class Resolver:
    """Map a subprogram name to a parsed Program from the caller's directory or the search paths.

    parse_fn(path) -> Program | None reads and parses one file (the caller chooses the dialect).
    """

    def __init__(self, search_paths: Iterable[str | Path] = (), parse_fn: Optional[Callable] = None):
        self.search_paths = [Path(p).resolve() for p in search_paths]
        self.parse_fn = parse_fn
        self._cache: dict[Path, Optional[Program]] = {}

    def find_file(self, name: str, from_file: Optional[str] = None) -> Optional[Path]:
        dirs: list[Path] = []
        if from_file and from_file not in ("-", "<stdin>"):
            dirs.append(Path(from_file).resolve().parent)
        dirs += [d for d in self.search_paths if d not in dirs]
        for d in dirs:
            if not d.is_dir():
                continue
            for cand in candidate_names(name):
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
