"""The viewer's files (top-level backplot/: viewer.html, viewer.js, viewer.css), read as text.

Read through nctrans.resources where this installation has it (a wheel carries the directory inside
the package); from the checkout beside the package otherwise.
"""
from __future__ import annotations

from pathlib import Path


def read_text(name: str) -> str:
    try:
        from nctrans import resources
    except ImportError:
        return (Path(__file__).resolve().parents[2] / "backplot" / name).read_text(encoding="utf-8")
    return resources.read_text("backplot", name)
