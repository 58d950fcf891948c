"""Pre-lexer for ISO lines: what a regular grammar cannot do, done once per line in plain Python.

- Comments: `( )` nest on Siemens ISO (spec §1.4, seed L483-493) and `;` runs to the end of the line
  (or ends the block, profile `eob_semicolon = "eob"`). Nesting needs a depth counter, so comments
  are cut here and their text kept for Block.comment. A Fanuc control does not nest: when the nested
  reading leaves a `(` open at the end of the line but the flat reading (comment ends at the first
  `)`) closes everything, the line is read the Fanuc way, since it runs on such controls.
- Cleaning: whitespace and stray control characters go (ISO ignores spaces, also inside a word:
  `X 10.`), letters are upper-cased (the lexer is case-insensitive, §2.1).
"""
from __future__ import annotations

from typing import Optional

# Every whitespace and control character is dropped from code text (tabs, CR, NUL, ^Z, DEL, NBSP).
_DROP = {c: None for c in list(range(0x00, 0x21)) + [0x7F, 0x85, 0xA0, 0xFEFF]}


def clean(code: str) -> str:
    """Code text as the grammar sees it: no whitespace or control characters, upper case."""
    return code.translate(_DROP).upper()


class CommentScan:
    """Result of cutting comments from one line. `code` keeps every column (comments blanked)."""
    __slots__ = ("code", "comments", "open_col", "stray_col")

    def __init__(self, code: str, comments: list[str], open_col: Optional[int],
                 stray_col: Optional[int]):
        self.code = code
        self.comments = comments
        self.open_col = open_col        # 1-based column of an unclosed "(" (NC003)
        self.stray_col = stray_col      # 1-based column of a ")" outside any comment (NC003)


def _scan(line: str, nested: bool, semicolon_comment: bool) -> CommentScan:
    out: list[str] = []
    comments: list[str] = []
    depth = 0
    start = 0
    open_col = None
    stray_col = None
    i = 0
    n = len(line)
    while i < n:
        ch = line[i]
        if depth:
            if ch == "(" and nested:
                depth += 1
            elif ch == ")":
                depth -= 1
                if not depth:
                    comments.append(line[start:i])
                    open_col = None
            out.append(" ")
        elif ch == "(":
            depth = 1
            start = i + 1
            open_col = i + 1
            out.append(" ")
        elif ch == ")":
            if stray_col is None:
                stray_col = i + 1
            out.append(" ")
        elif ch == ";" and semicolon_comment:
            text = line[i + 1:].strip()
            if text:                    # a bare ";" is the Fanuc EOB symbol, not a comment
                comments.append(text)
            out.append(" " * (n - i))
            break
        else:
            out.append(ch)
        i += 1
    if depth:
        comments.append(line[start:])
    return CommentScan("".join(out), comments, open_col if depth else None, stray_col)


def strip_comments(line: str, semicolon_comment: bool = True) -> CommentScan:
    """Cut the comments out of `line` (nested reading first, then the flat Fanuc reading)."""
    scan = _scan(line, True, semicolon_comment)
    if scan.open_col is not None:
        flat = _scan(line, False, semicolon_comment)
        if flat.open_col is None and flat.stray_col is None:
            return flat
    return scan
