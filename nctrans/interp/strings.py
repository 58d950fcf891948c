"""Sinumerik string functions (spec 4.5, seed L2106-2578): STRLEN, INDEX, RINDEX, MINDEX, MATCH,
SUBSTR, TOUPPER, TOLOWER, NUMBER, ISNUMBER, AXSTRING, AXNAME, ISAXIS.

Each takes the evaluated arguments (str, float or an axis name) and returns a str, a float, or
raises ValueError with what the control would alarm on (the evaluator reports it as NC104).
Positions are 0-based and -1 means "not found", as on the control. The length cap of a declared
STRING[n] is enforced where values are stored, not here.
"""
from __future__ import annotations

import re
from typing import Any, Callable

# a REAL literal of the language: digits, a point, an optional EX exponent (spec 2.3)
_REAL = re.compile(r"\s*[+-]?(?:\d+\.?\d*|\.\d+)(?:EX?[+-]?\d+)?\s*", re.IGNORECASE)


def _text(v: Any, fn: str) -> str:
    if not isinstance(v, str):
        raise ValueError(f"{fn} needs a STRING argument")
    return v.split("\0", 1)[0]


def _index(v: Any, fn: str) -> int:
    if isinstance(v, str) or v is None or v != int(v):
        raise ValueError(f"{fn} needs an INT position")
    return int(v)


def _strlen(s):
    return float(len(_text(s, "STRLEN")))


def _find(fn: str, s, c, last=False):
    text, ch = _text(s, fn), _text(c, fn)
    return float(text.rfind(ch) if last else text.find(ch)) if ch else -1.0


def _mindex(s, chars):
    text, chars = _text(s, "MINDEX"), _text(chars, "MINDEX")
    return float(next((i for i, ch in enumerate(text) if ch in chars), -1))


def _substr(s, start, length=None):
    text = _text(s, "SUBSTR")
    a = _index(start, "SUBSTR")
    if a < 0:
        raise ValueError("SUBSTR start position is negative")
    if length is None:
        return text[a:]
    n = _index(length, "SUBSTR")
    if n < 0:
        raise ValueError("SUBSTR length is negative")
    return text[a:a + n]


def _number(s):
    text = _text(s, "NUMBER")
    if not _REAL.fullmatch(text):
        raise ValueError(f"NUMBER: {text!r} is not a number")
    return float(text.upper().replace("EX", "E"))


def _isnumber(s):
    return 1.0 if isinstance(s, str) and _REAL.fullmatch(s) else 0.0


def _axname(s):
    """AXNAME("X") -> the axis identifier X (seed L2217-2238: "an alarm is output if the string
    cannot be assigned to any configured axis identifier"): the axis letters X Y Z A B C U V W,
    optionally numbered (X1), as nctrans knows axis identifiers everywhere else."""
    from nctrans.interp.evaluate import AXIS_NAME, AxisName
    name = _text(s, "AXNAME").strip().upper()
    if not AXIS_NAME.match(name):
        raise ValueError(f"AXNAME: {name!r} is not an axis identifier (the control stops with an alarm)")
    return AxisName(name)


def _isaxis(n):
    return 1.0 if n in (1.0, 2.0, 3.0) else 0.0       # geometry axes 1..3 of a mill or a lathe


FUNCTIONS: dict[str, Callable[..., Any]] = {
    "STRLEN": _strlen,
    "INDEX": lambda s, c: _find("INDEX", s, c),
    "RINDEX": lambda s, c: _find("RINDEX", s, c, last=True),
    "MINDEX": _mindex,
    "MATCH": lambda s, sub: _find("MATCH", s, sub),
    "SUBSTR": _substr,
    "TOUPPER": lambda s: _text(s, "TOUPPER").upper(),
    "TOLOWER": lambda s: _text(s, "TOLOWER").lower(),
    "NUMBER": _number,
    "ISNUMBER": _isnumber,
    "AXSTRING": lambda a: str(a).upper(),
    "AXNAME": _axname,
    "ISAXIS": _isaxis,
}
