"""The project configuration: `nctrans.toml`, or `[tool.nctrans]` in pyproject.toml.

Found by walking up from the working directory to the repository root (a directory holding .git)
or the filesystem root; the first directory with either file wins (nctrans.toml before
pyproject.toml). Everything is optional:

    dialects = { "lathe/*.nc" = "iso-t", "*.nc" = "iso-m" }   # file pattern -> dialect, first match wins
    machine = "machines/vmc.toml"                            # relative to the configuration file
    select = ["NC1", "NC2"]                                  # rule codes or prefixes
    ignore = ["NC501"]
    fail-on = "warning"
    per-file-ignores = { "legacy/*" = ["NC5"] }

The command line wins over the file: --from over `dialects`, --machine over `machine`, --select
replaces `select`, --ignore adds to `ignore`, --fail-on replaces `fail-on`. Validated by pydantic
once per content (nctrans.tables), so runs in between pay neither tomllib nor pydantic.
"""
from __future__ import annotations

import fnmatch
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal, Optional

from nctrans import tables

FILE_NAME = "nctrans.toml"


class ConfigError(Exception):
    """A configuration file that does not read or validate; the message names it."""


@dataclass
class ProjectConfig:
    __pydantic_config__ = {"extra": "forbid"}
    dialects: dict[str, str] = field(default_factory=dict)
    machine: Optional[str] = None
    select: list[str] = field(default_factory=list)
    ignore: list[str] = field(default_factory=list)
    fail_on: Optional[Literal["error", "warning", "info"]] = None
    per_file_ignores: dict[str, list[str]] = field(default_factory=dict)
    # where the file is (set after loading): patterns and the machine path are relative to it
    root: str = ""
    path: str = ""

    def _relative(self, file: str) -> Optional[str]:
        try:
            return Path(os.path.abspath(file)).relative_to(self.root).as_posix()
        except ValueError:
            return None

    def _matches(self, pattern: str, file: str) -> bool:
        rel = self._relative(file)
        if rel is not None and fnmatch.fnmatch(rel, pattern):
            return True
        return "/" not in pattern and fnmatch.fnmatch(os.path.basename(file), pattern)

    def dialect_for(self, file: str) -> Optional[str]:
        """The dialect the first matching pattern names for `file`, or None."""
        for pattern, dialect in self.dialects.items():
            if self._matches(pattern, file):
                return dialect
        return None

    def ignored_for(self, file: str) -> list[str]:
        out: list[str] = []
        for pattern, codes in self.per_file_ignores.items():
            if self._matches(pattern, file):
                out.extend(c.upper() for c in codes)
        return out

    def machine_path(self) -> Optional[str]:
        if not self.machine:
            return None
        return str(Path(self.root) / self.machine)


def _normalised(data):
    """TOML spells keys with hyphens (fail-on); the dataclass with underscores."""
    if not isinstance(data, dict):
        return data
    return {k.replace("-", "_") if k in ("fail-on", "per-file-ignores") else k: v for k, v in data.items()}


def load(path: str | Path) -> ProjectConfig:
    """The configuration in `path` (nctrans.toml, or pyproject.toml's [tool.nctrans])."""
    path = Path(path)
    section = ("tool", "nctrans") if path.name == "pyproject.toml" else ()
    try:
        cfg = tables.load(path, ProjectConfig, lambda d: ProjectConfig(**d), section=section,
                          prepare=_normalised)
    except tables.TableError as e:
        raise ConfigError(str(e)) from None
    cfg.root = str(path.resolve().parent)
    cfg.path = str(path)
    return cfg


def find(start: Optional[str] = None) -> Optional[Path]:
    """The configuration file that applies in `start` (default: the working directory), or None."""
    d = Path(start or os.getcwd()).resolve()
    for here in (d, *d.parents):
        own = here / FILE_NAME
        if own.is_file():
            return own
        py = here / "pyproject.toml"
        if py.is_file():
            try:
                if b"[tool.nctrans" in py.read_bytes():
                    return py
            except OSError:
                pass
        if (here / ".git").exists():
            return None
    return None


def discover(explicit: Optional[str] = None) -> Optional[ProjectConfig]:
    """The project configuration: `explicit` (--config) or the one found from the working directory."""
    if explicit:
        if not os.path.isfile(explicit):
            raise ConfigError(f"{explicit}: no such configuration file")
        return load(explicit)
    found = find()
    return load(found) if found is not None else None
