"""Fagor CNC 8060/8065 (`fagor`): front end, emitter and detection.

Fagor extends the ISO family: its blocks are ISO word-address blocks (G/M codes, axis words, F S T
D), to which it adds its own high-level language (`$` flow control, `#` instructions, P parameters,
`V.` variables) and its own comment, label and subroutine shapes. Modules: blocks (line shape:
headers, comments, skip, labels), frontend (lark grammar of record in grammars/fagor.lark, lowering
to the IR), emitter (IR -> Fagor text). Spec: shared/specs/fagor8065.md.
"""
from __future__ import annotations

import re

from nctrans.dialects.base import EmitResult, Marker, ParseResult
from nctrans.dialects.iso_m import IsoFamily

_I = re.IGNORECASE

# Constructs only Fagor writes, per line of code with its comments removed (nctrans.detect).
MARKERS = (
    Marker(4.0, 3, re.compile(r"^[ \t]*(?:N\d+:?[ \t]*)?\$(?:IF|ELSEIF|ELSE|ENDIF|WHILE|ENDWHILE|DO|ENDDO|FOR|"
                              r"ENDFOR|SWITCH|CASE|ENDSWITCH|GOTO|BREAK|CONTINUE)\b", _I)),
    Marker(4.0, 3, re.compile(r"#(?:MSG|WARNING|ERROR)[ \t]*\[", _I)),
    Marker(3.0, 3, re.compile(r"#(?:CALL|PCALL|MCALL|MDOFF|RET|TIME|SCALE|RPT|PATH|MCS|TOOL[ \t]+AX|CS|ACS|"
                              r"KIN[ \t]+ID|RTCP|HSC|FLUSH|DGWZ|COMMENT|DEF)\b", _I)),
    Marker(5.0, 1, re.compile(r"^[ \t]*%L[ \t]+\w+", _I)),
    Marker(3.0, 3, re.compile(r"\bV\.(?:\[\d\]\.)?(?:A|G|P|S|E|TM|SP|MPA|MPG|MTB|C|PLC)\.\w+", _I)),
    Marker(2.0, 3, re.compile(r"(?:^|[ \t])P\d+[ \t]*=", _I)),
    Marker(2.0, 2, re.compile(r"^[ \t]*N\d+:", _I)),
    Marker(3.0, 2, re.compile(r"^[ \t]*(?:N\d+:?[ \t]*)?LL[ \t]+\w+", _I)),
    Marker(3.0, 2, re.compile(r"\bG159[ \t]*=", _I)),
    # a "%NAME" program header (ISO writes a bare "%", Sinumerik "%_N_NAME_MPF")
    Marker(3.0, 1, re.compile(r"^[ \t]*%(?!_N_)[A-Za-z0-9]{1,14}[ \t]*$")),
    Marker(2.0, 2, re.compile(r"\bG0?4[ \t]*K", _I)),                      # dwell G04 K<s>
    Marker(2.0, 2, re.compile(r"\bG(?:198|199|261|262|263|72[ \t]*S|73[ \t]*Q)", _I)),
    Marker(1.5, 1, re.compile(r"\bG7[01]\b", _I)),                        # inch / mm
)


class Fagor(IsoFamily):
    """Fagor is an ISO-family dialect in its word-address blocks (its table, rules/fagor.toml,
    gives the G/M codes their neutral meaning), but the rest of its block language (`[ ]`
    expressions, `( )` comments anywhere, `$` flow, `#` instructions, P/V variables, `N<n>:` and
    `[LABEL]` targets) has its own grammar of record, so it brings its own front end and emitter
    instead of the ISO Lowering/IsoEmitter. A program that runs straight through (CAM output) is
    parsed as it runs (stream.py says where the line is; the rest is read as a whole), and a
    program converted to Fagor that runs straight through is written as it is read (stream_emit)."""
    name = "fagor"
    description = "Fagor CNC 8060/8065"
    extensions = (".nc", ".pim", ".fnc")
    markers = MARKERS
    comment_evidence = {"semicolon_line": (0.5, 2)}
    subprogram_endings = (".nc", ".NC", ".pim", ".fnc", ".fst")
    streams = True                     # CAM programs: stream.streamable
    lowering_passes = ()      # Fagor has $FOR, $WHILE, $DO and $SWITCH of its own

    def sniff(self, text: str) -> float:
        """0..1: share of Fagor markers found in the first 20 000 characters."""
        head = text[:20000]
        hits = sum(1 for m in MARKERS if m.pattern.search(head) or
                   re.search(m.pattern.pattern, head, re.I | re.M))
        return min(1.0, hits / 3)

    def subprogram_stems(self, name: str) -> list[str]:
        """Global subroutines are called by file name, with or without ending (spec §1.3)."""
        stem = name.rsplit(".", 1)[0] if "." in name else name
        return list(dict.fromkeys([name, stem, name.upper(), stem.upper()]))

    def parse(self, text: str, file: str = "<stdin>") -> ParseResult:
        from .frontend import parse
        return parse(text, file)

    def parse_stream(self, text: str, file: str = "<stdin>") -> ParseResult | None:
        from .stream import parse_stream
        return parse_stream(text, file)

    def lowering(self):
        raise NotImplementedError("fagor has its own front end (nctrans.dialects.fagor.frontend)")

    def emitter(self):
        raise NotImplementedError("fagor has its own emitter (nctrans.dialects.fagor.emitter)")

    def emit(self, program) -> EmitResult:
        from .emitter import emit_program
        return emit_program(program)

    def emit_stream(self, program, chunks, write):
        """emit() chunk by chunk, for a program that runs straight through (stream_emit)."""
        from .stream_emit import emit_stream
        return emit_stream(program, chunks, write)
