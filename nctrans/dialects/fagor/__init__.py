"""Fagor CNC 8060/8065 (`fagor`): front end, emitter and detection.

Modules: blocks (line shape: headers, comments, skip, labels), frontend (lark grammar of record in
grammars/fagor.lark, lowering to the IR), emitter (IR -> Fagor text). Spec: shared/specs/fagor8065.md.
"""
from __future__ import annotations

import re

from nctrans.dialects.base import Dialect, EmitResult, ParseResult


def parse(text: str, file: str = "<stdin>") -> ParseResult:
    from .frontend import parse as _parse
    return _parse(text, file)


def emit(program) -> EmitResult:
    from .emitter import emit_program
    return emit_program(program)


# constructs only Fagor writes: $ flow keywords, # instructions with [ ] arguments, %L local
# subroutines, V. variables, P parameters assigned with =, N<n>: targets, [LABEL] labels
_MARKS = [re.compile(p, re.IGNORECASE | re.MULTILINE) for p in (
    r"^\s*(?:N\d+:?\s*)?\$(?:IF|ELSEIF|ELSE|ENDIF|WHILE|ENDWHILE|DO|ENDDO|FOR|ENDFOR|SWITCH|CASE|"
    r"ENDSWITCH|GOTO|BREAK|CONTINUE)\b",
    r"#(?:MSG|WARNING|ERROR|CALL|PCALL|MCALL|MDOFF|RET|TIME|SCALE|RPT|PATH|MCS|COMMENT|TOOL\s+AX|"
    r"CS|ACS|KIN|RTCP|HSC|FLUSH|SYNC|DGWZ)\b",
    r"^\s*%L\s+\w+", r"\bV\.(?:\[\d\]\.)?[A-Z]{1,3}\.\w+", r"\bP\d+\s*=", r"^\s*N\d+:",
    r"\bLL\s+\w+", r"\bG159\s*=")]


def sniff(text: str) -> float:
    """0..1: share of Fagor markers found in the first 20 000 characters."""
    head = text[:20000]
    hits = sum(1 for m in _MARKS if m.search(head))
    return min(1.0, hits / 3)


DIALECT = Dialect(name="fagor", extensions=(".nc", ".pim", ".fnc"), parse=parse, emit=emit,
                  sniff=sniff, description="Fagor CNC 8060/8065")
