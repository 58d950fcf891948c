"""ISO / Fanuc-style turning (`iso-t`): the ISO family with the lathe's table (rules/iso-t.toml) and
a few handlers (frontend.py: U/W, T0101, G50, turning cycles; emitter.py: X in diameter).
Lathe semantics (diameter, constant surface speed, cycle passes) live in nctrans.interp.lathe."""
from __future__ import annotations

import re

from nctrans.dialects.base import Dialect, EmitResult, ParseResult

# What makes an ISO program a lathe program: U/W incremental words, T0101 tool+offset, G50 S speed
# clamp, G96 CSS, G99 feed per revolution, G70-G76 turning cycles with P..Q contours, X-Z only.
_LATHE = [re.compile(p, re.IGNORECASE | re.MULTILINE) for p in (
    r"\bG0*50\s*S\d", r"\bG0*9[69]\b", r"\bT\d{4}\b|^\s*(?:N\d+\s*)?(?:G0*0\s*)?T\d{3}\b",
    r"\bG0*7[0-6]\b.*\bP\d+.*\bQ\d+|\bG7[1-6]\b[^\n]*\b[UWDKI][-.\d]",
    r"^\s*(?:N\d+\s*)?(?:G0*[0-3]\s*)?[UW]-?[.\d]", r"\bG0*18\b", r"\bG0*28\s*U")]
_MILL = re.compile(r"\b(?:Y-?[.\d]|G0*17\b|G4[34]\b|H\d|M0*6\b|G8[1-9]\b)", re.IGNORECASE)


def evidence(text: str) -> list[str]:
    """The lathe markers found in `text` (for NC005's message)."""
    head = text[:20000]
    return [m.group(0).strip() for p in _LATHE for m in [p.search(head)] if m]


def sniff(text: str) -> float:
    """0..1: how much `text` looks like an ISO lathe program."""
    from nctrans.dialects.iso_m import sniff as iso_sniff
    base = iso_sniff(text)
    if base == 0.0:
        return 0.0
    head = text[:20000]
    hits = len(evidence(head))
    mill = len(_MILL.findall(head))
    if hits == 0:
        return 0.0
    score = min(1.0, 0.35 + 0.15 * hits) - min(0.5, 0.05 * mill)
    return round(max(0.0, score), 3)


def parse(text: str, file: str = "<stdin>") -> ParseResult:
    from .frontend import parse_program
    return parse_program(text, file)


def emit(program) -> EmitResult:
    from .emitter import emit_program
    return emit_program(program)


DIALECT = Dialect(name="iso-t", extensions=(".nc", ".tap", ".cnc"), parse=parse, emit=emit,
                  sniff=sniff, description="ISO / Fanuc-style turning, G-code system A")
