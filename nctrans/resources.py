"""The data files nctrans reads at run time: rules/, grammars/ and backplot/.

In the repository they are top-level directories (the design fixes that layout). A wheel carries
them inside the package as nctrans/_data/<kind>/ (setup.py copies them at build time), because an
installed tool has no checkout beside it. Every reader goes through `root`, so both an installed
wheel and a checkout (editable install, tests, `python -m nctrans` from the source tree) work.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

# The package directory. nctrans is installed as files (a wheel or a checkout, never run from a
# zip archive), so a Path serves where importlib.resources.files would (importing that costs ~10 ms
# of every command's start-up).
PACKAGE = Path(__file__).resolve().parent
Traversable = Path

KINDS = ("rules", "grammars", "backplot")
PACKAGED = "_data"      # nctrans/_data/<kind> in a built wheel


class ResourceError(Exception):
    """A data directory or file that is missing from this installation (a broken build)."""


@lru_cache(maxsize=None)
def root(kind: str) -> Traversable:
    """The directory of one kind of data file, wherever this installation keeps it."""
    if kind not in KINDS:
        raise ValueError(f"unknown resource kind {kind!r} (known: {', '.join(KINDS)})")
    package = PACKAGE
    packaged = package / PACKAGED / kind
    if packaged.is_dir():
        return packaged
    # A checkout: the package directory sits beside the top-level data directories.
    checkout = Path(str(package)).parent / kind
    if checkout.is_dir():
        return checkout
    raise ResourceError(f"nctrans data directory {kind!r} is missing from this installation "
                        f"(looked in {packaged} and {checkout}); reinstall nctrans")


def path(kind: str, name: str) -> Traversable:
    """One data file, e.g. path("rules", "iso-m.toml"); it may not exist (callers report that)."""
    return root(kind) / name


def read_text(kind: str, name: str) -> str:
    p = path(kind, name)
    try:
        return p.read_text(encoding="utf-8")
    except OSError as e:
        raise ResourceError(f"{p}: cannot read: {e.strerror or e}") from None
