"""Fagor block splitting: one source line -> its block parts, before the grammar sees the code.

What the grammar of record (grammars/fagor.lark) does not do, because it is line shape rather than
block syntax (spec §2, §21.1): program headers (`%name`, `%L name`), `#COMMENT BEGIN .. END`
regions, `( )` and `;` comments (never inside strings), the leading `/` skip mark, `N<n>` / `N<n>:`
block numbers and `[LABEL]` labels, unquoted subroutine paths after LL / L / #CALL / #PCALL / #MCALL
(made strings so a path such as `C:\\Cnc8070\\Users\\sub.nc` lexes), spindle qualifiers of M words
(`M3.S2`, `M19.POS.S1`), and upper-casing everything outside strings.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Optional

_HEADER_LOCAL = re.compile(r"^\s*%\s*L\s+([A-Za-z0-9_]+)\s*(?:[;(].*)?$", re.I)
_HEADER = re.compile(r"^\s*%\s*([A-Za-z0-9_]*)\s*(?:[;(].*)?$")
_COMMENT_BEGIN = re.compile(r"^\s*(?:N\d+:?\s*)?#COMMENT\s+BEGIN\b", re.I)
_COMMENT_END = re.compile(r"^\s*(?:N\d+:?\s*)?#COMMENT\s+END\b", re.I)
_SKIP = re.compile(r"\s*/")
_NUMBER = re.compile(r"\s*N\s*(\d+)\s*(:?)", re.I)
_NR = re.compile(r"\s*NR", re.I)
_LABEL = re.compile(r"\s*\[\s*([A-Za-z0-9_]+)\s*\]")
# call keywords followed by an unquoted program name or path (spec §13.2)
_CALL_PATH = re.compile(r'(?i)(^|\s)(LL|L|#CALL|#PCALL|#MCALL)(\s+)(?!")([^\s"\[]+)')
# M word with spindle / direction qualifiers (spec §4): M3.S2, M5.S, M19.POS.S1
_M_QUAL = re.compile(r"(?i)\bM\s*(\d+)((?:\.(?:POS|NEG|S\d?))+)")


@dataclass
class Line:
    """One source line, split. kind: "block", "local_sub" (`%L name`), "header" (`%name`),
    "blank" (nothing or only comments). code is upper-cased outside strings; col is the 1-based
    column where code starts in the raw line."""
    lineno: int
    raw: str
    kind: str = "block"
    name: Optional[str] = None
    code: str = ""
    col: int = 1
    skip: bool = False
    number: Optional[str] = None
    target: bool = False            # N<n>: (a jump target)
    label: Optional[str] = None
    comment: Optional[str] = None
    qualifiers: list[tuple[str, str]] = field(default_factory=list)   # (M number, ".S2" ...)
    error: Optional[tuple[str, str, int]] = None                      # (rule, message, column)


def lines(text: str):
    """Split a whole program into Lines (a #COMMENT region becomes blank lines)."""
    in_comment = False
    for n, raw in enumerate(text.split("\n"), 1):
        raw = raw.rstrip("\r")
        if in_comment:
            if _COMMENT_END.match(raw):
                in_comment = False
            yield Line(n, raw, "blank", comment=raw.strip())
            continue
        if _COMMENT_BEGIN.match(raw):
            in_comment = True
            yield Line(n, raw, "blank", comment=raw.strip())
            continue
        yield split(n, raw)
    if in_comment:
        # the region runs to the end of the file: the controller reads nothing of it
        yield Line(-1, "", "unclosed_comment")


def split(n: int, raw: str) -> Line:
    m = _HEADER_LOCAL.match(raw)
    if m:
        return Line(n, raw, "local_sub", name=m.group(1))
    if raw.lstrip().startswith("%"):
        m = _HEADER.match(raw)
        if m:
            return Line(n, raw, "header", name=m.group(1) or None)
    line = Line(n, raw)
    code, comment, err = _strip_comments(raw)
    line.comment = comment
    if err is not None:
        line.error = err
    pos = 0
    m = _SKIP.match(code, pos)
    if m:
        line.skip = True
        pos = m.end()
    m = _NUMBER.match(code, pos)
    if m and not _NR.match(code, pos):
        line.number = m.group(1)
        line.target = bool(m.group(2))
        pos = m.end()
    m = _LABEL.match(code, pos)
    if m:
        line.label = m.group(1).upper()
        pos = m.end()
    rest = code[pos:]
    stripped = rest.lstrip()
    line.col = pos + len(rest) - len(stripped) + 1
    stripped = stripped.rstrip()
    if "L" in stripped or "l" in stripped or "#" in stripped:
        stripped = _CALL_PATH.sub(lambda k: f'{k.group(1)}{k.group(2)}{k.group(3)}"{k.group(4)}"',
                                  stripped)

    def qual(k):
        line.qualifiers.append((k.group(1), k.group(2).upper()))
        return f"M{k.group(1)}"
    if "." in stripped:
        stripped = _M_QUAL.sub(qual, stripped)
    line.code = upper_outside_strings(stripped)
    if not line.code and line.number is None and line.label is None and not line.skip:
        line.kind = "blank"
    return line


def upper_outside_strings(text: str) -> str:
    if '"' not in text:
        return text.upper()
    out, inq, i = [], False, 0
    while i < len(text):
        ch = text[i]
        if ch == "\\" and inq and i + 1 < len(text):
            out.append(text[i:i + 2])
            i += 2
            continue
        if ch == '"':
            inq = not inq
        out.append(ch if inq else ch.upper())
        i += 1
    return "".join(out)


def _strip_comments(raw: str) -> tuple[str, Optional[str], Optional[tuple[str, str, int]]]:
    """(code with comments blanked out, comment text, error): `;` to the end of the line and
    `( .. )` anywhere, both only outside strings. Columns are kept (comments become blanks)."""
    if ";" not in raw and "(" not in raw and '"' not in raw:
        return raw, None, None
    out = []
    comments = []
    inq = False
    i = 0
    while i < len(raw):
        ch = raw[i]
        if inq:
            if ch == "\\" and i + 1 < len(raw):
                out.append(raw[i:i + 2])
                i += 2
                continue
            if ch == '"':
                inq = False
            out.append(ch)
            i += 1
            continue
        if ch == '"':
            inq = True
            out.append(ch)
            i += 1
            continue
        if ch == ";":
            comments.append(raw[i + 1:].strip())
            break
        if ch == "(":
            j = raw.find(")", i + 1)
            if j < 0:
                return "".join(out), " ".join(comments) or None, (
                    "NC003", "comment '(' is not closed on this line", i + 1)
            comments.append(raw[i + 1:j].strip())
            out.append(" " * (j - i + 1))
            i = j + 1
            continue
        out.append(ch)
        i += 1
    if inq:
        return "".join(out), " ".join(comments) or None, ("NC003", 'string \'"\' is not closed', len(raw))
    return "".join(out), " ".join(c for c in comments if c) or None, None
