"""The one round-trip helper of the tests, for every dialect.

- `assert_ir_round_trip(dialect, text)`: parse -> emit -> parse gives the same IR (up to spans and
  spellings: a number's source text, the code a mode was written with), and the text written
  parses without a syntax error.
- `assert_toolpath_round_trip(dialect, text)`: the text written moves the tool as the source does
  (`nctrans.equivalence` on the two toolpaths).
- `ConversionRoundTrip(path, via)`: source -> `via` -> source through the `nctrans convert` policy
  (structural, or lowered to plain motion where the target cannot say it), for the rs274 tests.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Iterable, Optional

from nctrans import equivalence as equiv
from nctrans import source as _source
from nctrans.convert import convert
from nctrans.dialects.base import get
from nctrans.interp import interpret
from nctrans.ir import nodes as n
from nctrans.lower.flatten import flatten
from nctrans.machine import default_mill

# fields that only say how the source spelled something
_SPELLING = {n.Num: ("text",), n.ModeChange: ("code",), n.PolarPole: ("code",)}
# ISO writers keep comments flat (Fanuc and rs274 do not nest): "(" and ")" in the text come back as brackets
_FLAT_COMMENT = str.maketrans("()", "[]")


def norm(obj: Any, digits: Optional[int] = None) -> Any:
    """IR as plain comparable data without spans and spellings; `digits`: numbers rounded (for a
    dialect that writes numbers to fewer significant digits than a float holds)."""
    if isinstance(obj, n.Num):
        return ("Num", obj.value if digits is None else round(obj.value, digits))
    if dataclasses.is_dataclass(obj):
        skip = _SPELLING.get(type(obj), ())
        return (type(obj).__name__,) + tuple(
            (f.name, _comment(getattr(obj, f.name)) if f.name == "comment" else norm(getattr(obj, f.name), digits))
            for f in dataclasses.fields(obj) if f.name != "span" and f.name not in skip)
    if isinstance(obj, dict):
        return {k: norm(v, digits) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [norm(v, digits) for v in obj]
    return obj


def _comment(text: Optional[str]) -> Optional[str]:
    return text.translate(_FLAT_COMMENT) if text is not None else None


def ir_round_trip(dialect: str, text: str, file: str = "t.nc"):
    """(first parse, emit result, second parse) of `text` in `dialect`."""
    d = get(dialect)
    first = d.parse(text, file)
    out = d.emit(first.program)
    return first, out, d.parse(out.text, file)


def assert_ir_round_trip(dialect: str, text: str, file: str = "t.nc", *, digits: Optional[int] = None,
                         meta_ignored: Iterable[str] = (), refusals: bool = True) -> str:
    """parse(emit(parse(text))) == parse(text); `meta_ignored`: header facts the text need not
    carry back; `refusals=False`: the emitter must write everything (no NC402). The text written."""
    first, out, second = ir_round_trip(dialect, text, file)
    if not refusals:
        assert [d for d in out.diagnostics if d.rule == "NC402"] == [], out.text
    syntax = [d.format_text() for d in second.diagnostics if d.rule.startswith("NC0")]
    assert syntax == [], out.text + "\n" + "\n".join(syntax)
    a, b = first.program, second.program
    assert b.name == a.name, out.text
    assert norm(b.body, digits) == norm(a.body, digits), out.text
    assert norm(b.subprograms, digits) == norm(a.subprograms, digits), out.text
    ignored = set(meta_ignored)
    meta = lambda p: norm({k: v for k, v in (p.meta or {}).items() if k not in ignored}, digits)
    assert meta(b) == meta(a), out.text
    return out.text


def assert_toolpath_round_trip(dialect: str, text: str, machine=None, file: str = "t.nc") -> str:
    """The text the emitter writes parses clean and moves the tool as `text` does. The text."""
    machine = machine or default_mill()
    d = get(dialect)
    res = d.parse(text, file)
    a = list(interpret(res.program, machine, diagnostics=[]))
    out = d.emit(res.program)
    assert not [x for x in out.diagnostics if x.severity == "error"], out.diagnostics
    back = d.parse(out.text, "back-" + file)
    bad = [x for x in back.diagnostics if x.severity == "error" or x.rule.startswith("NC0")]
    assert not bad, out.text + "\n".join(x.format_text() for x in bad)
    b = list(interpret(back.program, machine, diagnostics=[]))
    diff = equiv.compare(a, b)
    assert diff is None, out.text + diff.format()
    return out.text


def read(path: Path) -> str:
    return _source.decode(path.read_bytes(), path.name).text


def convert_policy(program, target: str):
    """`nctrans convert` on one program: structural, or lowered to plain motion where the target
    cannot say it (nctrans.convert)."""
    return convert(program, get(target),
                   flatten_with=lambda diags: flatten(program, default_mill(), diagnostics=diags))


class ConversionRoundTrip:
    """`path` (in `source`) converted to `via`, that text parsed, and converted back to `source`."""

    def __init__(self, path: Path, via: str, source: str = "iso-m", via_suffix: str = ".nc"):
        self.source = get(source).parse(read(path), path.name).program
        there = convert_policy(self.source, via)
        self.via_text, self.via_diags = there.text or "", there.diagnostics
        back = get(via).parse(self.via_text, path.name + via_suffix)
        self.parse_diags = back.diagnostics
        self.intermediate = back.program
        again = convert_policy(back.program, source)
        self.back_text, self.back_diags = again.text or "", again.diagnostics
