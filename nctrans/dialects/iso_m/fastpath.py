"""Fast path for plain address-word blocks (letters and plain numbers only).

CAM output is almost entirely blocks like `N1234G1X1.234Y-5.6F800.`; running them through the LALR
parser costs ~40 µs each, a compiled regex ~2 µs. The word list is exactly what words.lark_words
gives for the same text (tests/test_iso_fastpath.py checks this on generated blocks and on every
corpus line), so the lowering cannot tell which reader ran.
"""
from __future__ import annotations

import re
from typing import Optional

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)"
PLAIN = re.compile(rf"(?:[A-Z]{_NUMBER})+")
WORD = re.compile(rf"([A-Z])({_NUMBER})")


def fast_words(code: str) -> Optional[list[tuple[str, str]]]:
    """Word list of a cleaned block, or None when the block needs the full grammar."""
    if PLAIN.fullmatch(code) is None:
        return None
    return WORD.findall(code)
