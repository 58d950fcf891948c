"""ISO / Fanuc-style turning (`iso-t`): the ISO family with the lathe's table (rules/iso-t.toml) and
a few handlers (frontend.py: U/W, T0101, G50, turning cycles; emitter.py: X in diameter).
Lathe semantics (diameter, constant surface speed, cycle passes) live in nctrans.interp.lathe."""
from __future__ import annotations

import re

from nctrans.dialects.base import Marker, ParseResult
from nctrans.dialects.iso_m import IsoFamily

_I = re.IGNORECASE

# What makes an ISO program a lathe program (per line of code, comments removed).
LATHE_MARKERS = (
    Marker(8.0, 3, re.compile(r"(?<![A-Z])G0*50[ \t]*S\d", _I)),                 # maximum spindle speed
    Marker(6.0, 3, re.compile(r"(?<![A-Z])G0*96\b", _I)),                        # constant surface speed
    Marker(6.0, 1, re.compile(r"(?<![A-Z])G0*99\b(?!.*\bR[-+.\d])", _I)),         # feed per revolution
    Marker(8.0, 3, re.compile(r"(?:^|[ \t])T\d{4}\b|^[ \t]*(?:N\d+[ \t]*)?(?:G0*0[ \t]*)?T\d{3}\b", _I)),
    Marker(8.0, 3, re.compile(r"(?<![A-Z])G0*7[0-3]\b.*P\d+.*Q\d+", _I)),    # stock removal with P..Q
    Marker(4.0, 2, re.compile(r"(?<![A-Z])G0*7[4-6]\b.*[XU][-+.\d]", _I)),      # peck / thread cycles
    Marker(6.0, 3, re.compile(r"^[ \t]*(?:N\d+[ \t]*)?(?:G0*[0-3][ \t]*)?[UW][-+]?[.\d]", _I)),
    Marker(1.0, 1, re.compile(r"(?<![A-Z])G0*18\b", _I)),
    Marker(4.0, 1, re.compile(r"(?<![A-Z])G0*28[ \t]*[UW]", _I)),
)


def evidence(text: str) -> list[str]:
    """The lathe constructs found in the head of `text`."""
    head = text[:20000]
    return [m.group(0).strip() for mk in LATHE_MARKERS for m in [mk.pattern.search(head)] if m]


class IsoTurning(IsoFamily):
    name = "iso-t"
    description = "ISO / Fanuc-style turning, G-code system A (Fanuc 0i-T, Haas lathes)"
    extensions = (".nc", ".tap", ".cnc")
    table = "iso-t"
    # Only lathe constructs count: the family's markers are iso-m's evidence, and a lathe program
    # outweighs them (a mill program gives iso-t nothing, so detection between others is unchanged).
    markers = LATHE_MARKERS
    comment_evidence: dict = {}
    family_evidence = "iso-m"
    machine_kind = "lathe"

    def sniff(self, text: str) -> float:
        """ISO-like and with a lathe construct stronger than a G18; 0 without one."""
        head = text[:20000]
        strong = any(m.weight >= 4.0 and m.pattern.search(head) for m in LATHE_MARKERS)
        return super().sniff(text) if strong else 0.0

    streams = True                      # programs without G70-G73 (frontend.parse_stream)

    def lowering(self):
        from .frontend import TurningLowering
        return TurningLowering

    def emitter(self):
        from .emitter import TurningEmitter
        return TurningEmitter

    def parse(self, text: str, file: str = "<stdin>") -> ParseResult:
        from .frontend import parse_program
        return parse_program(text, file)

    def parse_stream(self, text: str, file: str = "<stdin>") -> ParseResult | None:
        from .frontend import parse_stream
        return parse_stream(text, file)
