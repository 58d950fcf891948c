"""Siemens Sinumerik 840D dialect: front end (frontend.py), emitter (emitter.py), sniffing."""
from __future__ import annotations

import re

from nctrans.dialects.base import Dialect

_MARKS = [re.compile(p, re.IGNORECASE | re.MULTILINE) for p in (
    r"^%_N_\w+_(?:MPF|SPF)\b", r"^\s*(?:N\d+\s+)?(?:DEF|PROC)\s+\w+", r"\bGOTO[FBC]\b",
    r"\b(?:ENDIF|ENDWHILE|ENDFOR|ENDLOOP|STOPRE|MSG\s*\()", r"\b[A-Z]\w*\s*=\s*(?:AC|IC)\s*\(",
    r"\bR\d+\s*=", r"\$[A-Z]{1,3}_\w+", r"\bCYCLE8\d\s*\(", r"^\s*(?:N\d+\s*)?;")]


def sniff(text: str) -> float:
    """0..1: share of Sinumerik markers found in the first 20 000 characters."""
    head = text[:20000]
    hits = sum(1 for m in _MARKS if m.search(head))
    return min(1.0, hits / 4)


def _parse(text, file="<stdin>"):
    from nctrans.dialects.sinumerik.frontend import parse
    return parse(text, file)


def _emit(program):
    from nctrans.dialects.sinumerik.emitter import emit
    return emit(program)


DIALECT = Dialect(name="sinumerik", extensions=(".mpf", ".spf", ".MPF", ".SPF"), parse=_parse,
                  emit=_emit, sniff=sniff,
                  description="Siemens Sinumerik 840D/840Di/810D (SW 6)")
