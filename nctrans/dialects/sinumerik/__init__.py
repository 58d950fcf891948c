"""Siemens Sinumerik 840D dialect: front end (frontend.py), emitter (emitter.py), detection."""
from __future__ import annotations

import re

from nctrans.dialects.base import Dialect, EmitResult, Marker, ParseResult

_I = re.IGNORECASE

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


# Content markers, per line of code with its comments removed (nctrans.detect).
MARKERS = (
    Marker(5.0, 1, re.compile(r"^%_N_\w+_(?:MPF|SPF)\b", _I)),
    Marker(3.0, 3, re.compile(r"^[ \t]*(?:N\d+[ \t]+)?DEF[ \t]+(?:INT|REAL|BOOL|CHAR|STRING|AXIS|FRAME)\b", _I)),
    Marker(4.0, 2, re.compile(r"^[ \t]*DEFINE[ \t]+\w+[ \t]+AS\b", _I)),
    Marker(3.0, 2, re.compile(r"^[ \t]*(?:N\d+[ \t]+)?PROC[ \t]+\w+", _I)),
    Marker(2.0, 3, re.compile(r"\bR\d+[ \t]*=", _I)),
    Marker(3.0, 3, re.compile(r"\bGOTO[FBC]\b", _I)),
    Marker(3.0, 3, re.compile(r"\bMSG[ \t]*\([ \t]*\"", _I)),
    Marker(3.0, 3, re.compile(r"\bCYCLE\d+[ \t]*\(", _I)),
    Marker(2.0, 3, re.compile(r"\b[XYZABCIJKFS]\d?[ \t]*=[ \t]*[-+(A-Z$0-9]", _I)),
    Marker(2.0, 3, re.compile(r"\$[A-Z]{1,3}_\w+", _I)),
    Marker(2.0, 3, re.compile(
        r"\b(?:A?TRANS|A?ROT|A?SCALE|A?MIRROR|ENDIF|ENDWHILE|ENDFOR|ENDLOOP|STOPRE|TRAFOOF|TRAORI|SUPA|"
        r"CFC|DIAMON|BRISK|SOFT|G64[12]|CIP|CR[ \t]*=|AC[ \t]*\(|IC[ \t]*\(|M17|RET)\b", _I)),
    Marker(3.0, 2, re.compile(r"\bT[ \t]*=[ \t]*\"", _I)),
    Marker(1.5, 1, re.compile(r"\bG7[01]\b", _I)),          # inch/metric (ISO mills: G20/G21)
    # array element assignment by name (GUD/LUD arrays: INI[53]=0); ISO writes #[..] instead
    Marker(3.0, 2, re.compile(r"^[ \t]*(?:N\d+[ \t]+)?[A-Z_]{2,}\w*[ \t]*\[[^\]]*\][ \t]*=", _I)),
    # a subprogram called by its name alone on a line (RECSUB), written in capitals as programs
    # name them; ISO keywords that stand alone (END1, GOTO10, DO2) are numbered words, not names
    Marker(1.5, 2, re.compile(r"^[ \t]*(?:N\d+[ \t]+)?(?!(?:END|GOTO|DO|THEN)\d)[A-Z_]{2,}[A-Z0-9_]*[ \t]*$")),
)

class Sinumerik(Dialect):
    name = "sinumerik"
    opening_lines = r"%|;\$PATH="
    description = "Siemens Sinumerik 840D/840Di/810D (SW 6)"
    extensions = (".mpf", ".spf", ".MPF", ".SPF")
    markers = MARKERS
    comment_evidence = {"semicolon_line": (1.0, 3), "semicolon_tail": (0.5, 2)}
    definition_files = (".def",)       # GUD modules _N_*GUD*_DEF (spec 1.8)
    streams = True                     # CAM programs: frontend.streamable
    subprogram_endings = (".spf", ".SPF", ".mpf", ".MPF", ".txt")
    refuses_in_place = True            # emitter.SinumerikEmitter.refused_in_place

    def sniff(self, text: str) -> float:
        return sniff(text)

    def subprogram_file(self, program) -> bool:
        """An .SPF file, or a program whose archive header says `%_N_NAME_SPF` (an MPF is a main
        program)."""
        meta = program.meta or {}
        if meta.get("program_type"):
            return meta["program_type"] == "SPF"
        return str(program.file).lower().endswith(".spf")

    def subprogram_stems(self, name: str) -> list[str]:
        """L10 -> L10, and an archive name %_N_NAME_SPF -> NAME as well."""
        stems = super().subprogram_stems(name)
        upper = name.upper()
        if upper.startswith("%_N_") and upper.endswith(("_SPF", "_MPF")):
            stems.append(upper[4:-4])
        return stems

    def parse(self, text: str, file: str = "<stdin>") -> ParseResult:
        return _parse(text, file)

    def parse_stream(self, text: str, file: str = "<stdin>") -> ParseResult | None:
        from nctrans.dialects.sinumerik.frontend import parse_stream
        return parse_stream(text, file)

    def parse_compact(self, text: str, file: str = "<stdin>", jumps: bool = False) -> ParseResult | None:
        from nctrans.dialects.sinumerik.frontend import parse_compact
        return parse_compact(text, file, jumps=jumps)

    def emit(self, program) -> EmitResult:
        return _emit(program)

    def emit_stream(self, program, chunks, write):
        from nctrans.dialects.sinumerik.emitter import emit_stream
        return emit_stream(program, chunks, write)
