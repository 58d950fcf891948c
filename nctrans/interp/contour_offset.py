"""Sinumerik OFFN: an allowance normal to the contour, added to the tool radius while cutter
compensation (G41/G42) runs (seed L12466-12492: `G1 X10 Y-10 G41 OFFN=1` roughs a square with
1 mm allowance; `G40 OFFN=0` resets it; L12632: effective only with compensation selected).

The interpreter keeps the value (`contour_offset`, modal, 0 at start) and the compensator offsets
the path by radius + OFFN. A value that changes while a compensated contour runs is taken at the
next G41/G42 and said at its line (NC220): the control's transition between the two offsets is not
modelled. Which word it is, is data: `[options.contour_offset] word` of the rules table.
Not modelled either (and not reached: the transformations are unmodelled): OFFN under TRACYL,
where it is the groove wall offset (seed L12625-12674).
"""
from __future__ import annotations

from functools import lru_cache

from nctrans.ir import nodes as n


@lru_cache(maxsize=None)
def _word(dialect: str) -> str:
    from nctrans.rules import option
    return str((option(dialect, "contour_offset") or {}).get("word", "")).upper()


def is_offset_word(s: n.Passthrough) -> bool:
    """True for the dialect's contour offset word with a value (Sinumerik OFFN=...)."""
    return bool(s.address) and s.value is not None and s.address.upper() == _word(s.dialect)


def compile_word(it, s: n.Passthrough):
    return (_h_offset, (it, it.ev.compile(s.value), s))


def _h_offset(d) -> None:
    it, f, s = d
    v = it._value(f, s.text.strip())
    if v is None:
        return
    v = float(v) * it.st.scale
    if it.comp is not None and it.st.comp_side != "off" and v != it.contour_offset:
        it.diag("NC220", "warning", f"{s.text.strip()!r} changes the contour offset while cutter "
                "compensation runs: not modelled; the analysed toolpath keeps the old offset until "
                "the next G41/G42")
    it.contour_offset = v
