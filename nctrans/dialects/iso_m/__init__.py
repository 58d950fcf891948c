"""ISO / Fanuc-style milling (`iso-m`): front end, emitter and detection.

Modules: prelex (comments, cleaning), fastpath + words (the word list of a block; lark grammar of
record in grammars/iso-m.lark), frontend (lowering to the IR), emitter (IR -> ISO text).
Imports stay light: lark is loaded only when a block needs the full grammar.
"""
from __future__ import annotations

import re

from nctrans.dialects.base import Dialect, EmitResult, ParseResult


def parse(text: str, file: str = "<stdin>") -> ParseResult:
    from .frontend import parse_program
    return parse_program(text, file)


def emit(program) -> EmitResult:
    from .emitter import emit_program
    return emit_program(program)


_ISO_HINTS = re.compile(r"(?im)^\s*(?:%\s*$|[O:]\d+|N\d+\s*G|G0?[0-3]\s*[XYZ]|G\d+G\d+|#\d+\s*=|"
                        r"IF\s*\[|WHILE\s*\[|G(?:28|43|54|80|81|83|90|91)\b|M(?:0?6|30|98|99)\b)")
_OTHER_HINTS = re.compile(r"(?im)(?:^\s*(?:N\d+\s+)?(?:DEF\s|DEFINE\s|PROC\s|MCALL|CYCLE\d|ENDIF|ENDWHILE|"
                          r"ENDLOOP|ENDFOR|STOPRE|O\d+\s+(?:sub|call|if|while|endsub)\b|#<|%_N_)|^\s*;|"
                          r"\bR\d+\s*=|GOTO[FB]\b|\$[A-Z]{2}_|\b(?:SIN|COS|TAN|SQRT|ABS|TRUNC|ROUND)\(|"
                          r"\bMSG\s*\(|\b[XYZ]\s*=\s*[A-Z(]|\bG(?:500|64[0-9])\b|\bM17\b)")


def sniff(text: str) -> float:
    """0..1: how ISO-milling-like `text` looks (ISO words and macro B vs Sinumerik/LinuxCNC marks)."""
    sample = text[:20000]
    iso = len(_ISO_HINTS.findall(sample))
    other = len(_OTHER_HINTS.findall(sample))
    if iso == 0:
        return 0.05 if re.search(r"(?i)\b[GM]\d", sample) else 0.0
    score = iso / (iso + 2 * other)
    return round(max(0.0, min(1.0, 0.3 + 0.7 * score)), 3)


DIALECT = Dialect(name="iso-m", extensions=(".nc", ".tap", ".cnc", ".iso", ".eia", ".ngc"),
                  parse=parse, emit=emit, sniff=sniff,
                  description="ISO / Fanuc-style milling with custom macro B")
