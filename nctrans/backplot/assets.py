"""The viewer's files (top-level backplot/: viewer.html, viewer.js, viewer.css), read as text
through nctrans.resources, so an installed wheel and a checkout both find them."""
from __future__ import annotations

from nctrans import resources


def read_text(name: str) -> str:
    return resources.read_text("backplot", name)
