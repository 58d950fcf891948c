"""ISO / Fanuc-style milling (`iso-m`), and `IsoFamily`, the base of every ISO-style dialect.

Modules: prelex (comments, cleaning), fastpath + words (the word list of a block; lark grammar of
record in grammars/iso-m.lark), frontend (lowering to the IR), emitter (IR -> ISO text).
Imports stay light: lark is loaded only when a block needs the full grammar.

ISO turning and Fagor extend the family: `class IsoTurning(IsoFamily)` sets its name, endings and
table and overrides what differs (see nctrans.dialects.base).
"""
from __future__ import annotations

import re

from nctrans.dialects.base import Dialect, EmitResult, Marker, ParseResult
from nctrans.lower.loops import for_to_while

_I = re.IGNORECASE

# Content markers of ISO-style programs (Fanuc macro B and LinuxCNC rs274ngc), per line of code with
# its comments removed (nctrans.detect).
ISO_MARKERS = (
    Marker(3.0, 1, re.compile(r"^[ \t]*O\d{1,8}\b", _I)),
    # LinuxCNC rs274ngc (an ISO dialect): o-word control flow and named parameters
    Marker(4.0, 3, re.compile(r"^[ \t]*(?:N\d+[ \t]*)?O(?:\d+|<\w+>)[ \t]*(?:SUB|ENDSUB|IF|ELSEIF|ELSE|ENDIF|"
                              r"WHILE|ENDWHILE|DO|REPEAT|ENDREPEAT|CALL|RETURN|BREAK|CONTINUE)\b", _I)),
    Marker(3.0, 3, re.compile(r"#<\w+>")),
    Marker(1.0, 3, re.compile(r"^[ \t]*%[ \t]*$")),
    Marker(3.0, 3, re.compile(r"#\d+[ \t]*=")),
    Marker(2.0, 3, re.compile(r"#\[")),
    Marker(3.0, 2, re.compile(r"\b(?:WHILE|IF)[ \t]*\[", _I)),
    Marker(2.0, 2, re.compile(r"\bEND[ \t]*\d\b", _I)),
    Marker(2.0, 2, re.compile(r"\bGOTO[ \t]*\d", _I)),
    Marker(2.0, 2, re.compile(r"\b(?:M98[ \t]*P|G65[ \t]*P|M99\b)", _I)),
    Marker(1.0, 2, re.compile(r"\bG43\b.*\bH\d", _I)),
    Marker(1.0, 2, re.compile(r"\bG(?:7[346]|8[1-9])\b.*\bR[-+.\d]", _I)),
    Marker(1.0, 2, re.compile(r"\bG0?[23]\b[^=]*\bR[-+.\d]", _I)),
    Marker(1.0, 2, re.compile(r"\bG28\b", _I)),
    # blocks of plain words only (N, G, M, axes, F, S, T...): other dialects allow them too, ISO
    # programs are made of little else, so a small capped lean towards ISO.
    Marker(0.25, 6, re.compile(r"^[ \t]*(?:N\d+[ \t]*)?(?:[GMXYZIJKFSTHDPQRABC][ \t]*[-+]?\d*\.?\d+[ \t]*)+$", _I)),
)


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


_PROGRAM_NUMBER = re.compile(r"^[Oo]?0*(\d+)$")


class IsoFamily(Dialect):
    """ISO-style (Fanuc-like) dialects: word-address blocks, `( )` comments, macro B variables,
    O-numbered subprograms. Not registered itself (it has no name). A member sets name, endings and
    `table`, and returns its own front-end and emitter classes from `lowering()` / `emitter()`:
    subclasses of frontend.Lowering and emitter.IsoEmitter with the same table and the handlers
    that differ overridden."""
    markers = ISO_MARKERS
    line_comment = "({})"
    opening_lines = r"%|[Oo]\d+\b|:\d+\b"
    comment_evidence = {"paren_comment": (1.0, 3)}
    subprogram_endings = (".nc", ".NC", ".tap", ".TAP", ".ngc", ".cnc", ".iso", ".eia", ".txt")
    streams = True
    lowering_passes = (for_to_while,)     # macro B has WHILE..DO..END but no FOR

    def lowering(self):
        """The front end's Lowering class (imported here so that registering stays light)."""
        from .frontend import Lowering
        return Lowering

    def emitter(self):
        """The emitter class (an IsoEmitter)."""
        from .emitter import IsoEmitter
        return IsoEmitter

    def parse(self, text: str, file: str = "<stdin>") -> ParseResult:
        from .frontend import parse_program
        return parse_program(text, file, self.lowering())

    def parse_stream(self, text: str, file: str = "<stdin>") -> ParseResult | None:
        from .frontend import parse_stream
        return parse_stream(text, file, self.lowering())

    def parse_compact(self, text: str, file: str = "<stdin>", jumps: bool = False) -> ParseResult | None:
        """None for a member with a front end of its own (Fagor, ISO turning): parse() then."""
        if type(self).parse is not IsoFamily.parse:
            return None
        from .frontend import parse_compact
        return parse_compact(text, file, self.lowering(), jumps=jumps)

    def emit(self, program) -> EmitResult:
        from .emitter import emit_program
        return emit_program(program, self.emitter())

    def emit_stream(self, program, chunks, write):
        """emit() chunk by chunk (nctrans.dialects.iso_m.stream_emit); None for a member with an
        emitter of its own (not an IsoEmitter)."""
        if type(self).emit is not IsoFamily.emit:
            return None
        from .stream_emit import emit_stream
        return emit_stream(program, chunks, write, self.emitter())

    def sniff(self, text: str) -> float:
        return sniff(text)

    def subprogram_stems(self, name: str) -> list[str]:
        """O1000 / 1000 -> O1000, 1000 (and the zero-padded and lower-case spellings)."""
        m = _PROGRAM_NUMBER.match(name)
        if m:
            num = m.group(1)
            return [f"O{num.zfill(4)}", f"O{num}", num.zfill(4), num, f"o{num.zfill(4)}", f"o{num}"]
        return super().subprogram_stems(name)


class IsoMilling(IsoFamily):
    name = "iso-m"
    description = "ISO / Fanuc-style milling with custom macro B"
    extensions = (".nc", ".tap", ".cnc", ".iso", ".eia", ".ngc")
