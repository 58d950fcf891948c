"""What a program says about its own linting, in its own comment syntax.

- `; nctrans: ignore NC201` (or `( nctrans: ignore NC201, NC202 )` where `;` is no comment) at the
  end of a line drops those rules' diagnostics on that line; with no codes, every rule's.
- `; nctrans: ignore-file NC501` anywhere drops the rules in the whole file.
- `; nctrans: dialect=sinumerik` (or `dialect sinumerik`) in the first line's comment names the
  file's dialect (a leading `%` line may come first).

Codes may be prefixes (`NC5` = every NC5xx), as with --select/--ignore. The text is searched for
"nctrans" once, so a program without markers costs one str.find.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Iterable, Optional

from nctrans.diagnostics import Diagnostic

_MARK = re.compile(r"[;(]\s*nctrans\s*:\s*(ignore-file|ignore|dialect)\b\s*(=?)\s*([^)\n\r]*)", re.IGNORECASE)
_CODE = re.compile(r"^NC\d{0,3}$", re.IGNORECASE)
ALL = "*"


@dataclass
class Suppressions:
    by_line: dict[int, tuple[str, ...]] = field(default_factory=dict)   # line -> codes (ALL = every rule)
    whole_file: tuple[str, ...] = ()
    where: dict[int, int] = field(default_factory=dict)                 # line -> column of the marker
    bad: list[Diagnostic] = field(default_factory=list)                 # malformed markers

    def __bool__(self) -> bool:
        return bool(self.by_line or self.whole_file or self.bad)


def _codes(text: str) -> tuple[str, ...]:
    words = [w for w in re.split(r"[\s,]+", text.strip()) if w]
    return tuple(w.upper() for w in words)


def _matches(code: str, patterns: Iterable[str]) -> bool:
    return any(p == ALL or code.startswith(p) for p in patterns)


def scan(text: str, file: str) -> Suppressions:
    """The suppression markers of one program."""
    out = Suppressions()
    if text.find("nctrans") < 0 and text.lower().find("nctrans") < 0:
        return out
    line, pos = 1, 0
    for m in _MARK.finditer(text):
        line += text.count("\n", pos, m.start())
        pos = m.start()
        kind = m.group(1).lower()
        if kind == "dialect":
            continue
        codes = _codes(m.group(3))
        wrong = [c for c in codes if not _CODE.match(c)]
        col = m.start() - (text.rfind("\n", 0, m.start()) + 1) + 1
        if wrong:
            out.bad.append(Diagnostic("NC503", "warning",
                                      f"suppression names {', '.join(wrong)}, not rule codes (NC201 or a prefix such as NC2)",
                                      file, line, col, line, col + len(m.group(0))))
            codes = tuple(c for c in codes if _CODE.match(c))
            if not codes:
                continue
        if kind == "ignore-file":
            out.whole_file += codes or (ALL,)
        else:
            out.by_line[line] = out.by_line.get(line, ()) + (codes or (ALL,))
            out.where[line] = col
    return out


def apply(diags: list[Diagnostic], sup: Suppressions, file: str) -> list[Diagnostic]:
    """The diagnostics that survive the markers, plus NC502 for markers that suppress nothing
    and NC503 for malformed ones."""
    if not sup:
        return diags
    kept: list[Diagnostic] = []
    used: set[int] = set()
    for d in diags:
        if d.file == file or not file:
            if sup.whole_file and _matches(d.rule, sup.whole_file):
                continue
            codes = sup.by_line.get(d.line)
            if codes and _matches(d.rule, codes):
                used.add(d.line)
                continue
        kept.append(d)
    for line, codes in sup.by_line.items():
        if line not in used:
            col = sup.where.get(line, 1)
            what = "any rule" if ALL in codes else ", ".join(codes)
            kept.append(Diagnostic("NC502", "info",
                                   f"unused suppression: no diagnostic of {what} on this line",
                                   file, line, col, line, col + 1))
    kept.extend(sup.bad)
    return kept


def dialect_pragma(text: str) -> Optional[tuple[str, int, int]]:
    """(dialect name, line, column) named by a pragma in the first line's comment (after a lone `%`
    line), or None."""
    head = text[:400]
    first_lines = head.split("\n", 2)
    for i, ln in enumerate(first_lines[:2]):
        m = _MARK.search(ln)
        if m and m.group(1).lower() == "dialect":
            name = m.group(3).strip().split()[0] if m.group(3).strip() else ""
            return name.lower(), i + 1, m.start() + 1
        if ln.strip() not in ("%", ""):
            break
    return None
