"""Tokens of one Sinumerik block (the statement part, after block number, label and comment).

Sinumerik words are context-sensitive in a way a regular-expression lexer cannot decide alone
(spec section 2.2): `X100` is address X with 100, `G0X-170` is two words glued together, `R1` is an
R parameter, `L140(1)` is a call of program L140, `X1=5` is the axis X1 (a configured name) and
`S1=300` an extended address. This lexer decides by the next character: a name followed by `=`,
`(` or `[` is a name (IDENT); otherwise a letter followed by digits is an address with its number.
Keywords are matched case-insensitively and names are upper-cased (strings keep their case).
"""
from __future__ import annotations

import math
import re
from typing import Iterator


KEYWORDS = {k: k for k in (
    "DEF PROC VAR EXTERN IF ELSE ENDIF WHILE ENDWHILE FOR TO ENDFOR LOOP ENDLOOP REPEAT UNTIL CASE OF "
    "DEFAULT CALL PCALL MCALL ISOCALL EXTCALL BLOCK RET ENDPROC AND OR XOR NOT B_AND B_OR B_XOR B_NOT "
    "DIV MOD SET REP TRUE FALSE").split()}
for _k in ("GOTO", "GOTOF", "GOTOB", "GOTOC"):
    KEYWORDS[_k] = "GOTOKW"
for _k in ("INT", "REAL", "BOOL", "CHAR", "STRING", "AXIS", "FRAME", "DOUBLE"):
    KEYWORDS[_k] = "TYPE"
for _k in ("NCK", "CHAN"):
    KEYWORDS[_k] = "SCOPE"
for _k in ("SYNR", "SYNW", "SYNRW"):
    KEYWORDS[_k] = "SYNC"
for _k in ("SAVE", "DISPLOF", "SBLOF"):
    KEYWORDS[_k] = "PROCATTR"
for _k in ("TRANS", "ATRANS", "ROT", "AROT", "SCALE", "ASCALE", "MIRROR", "AMIRROR"):
    KEYWORDS[_k] = "FRAMEOP"

_DIGITS = frozenset("0123456789")
_LETTERS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_")
_NUMBER = re.compile(r"(?:\d+\.?\d*|\.\d+)(?:EX[+-]?\d+)?", re.IGNORECASE)
_SIGNED = re.compile(r"\s*[+-]?(?:\d+\.?\d*|\.\d+)(?:EX[+-]?\d+)?", re.IGNORECASE)
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_SYSVAR = re.compile(r"\$+[A-Za-z0-9_]+")
_DEF_ATTRIBUTES = frozenset(("LLI", "ULI", "PHU", "APR", "APW"))
_GLUED_CODE = re.compile(r"[GM](\d+)(?=[A-Z])")
_HEXBIN = re.compile(r"'([HhBb])([0-9A-Fa-f]+)'")
_OPS = [("==", "CMPOP"), ("<>", "CMPOP"), ("<=", "CMPOP"), (">=", "CMPOP"), ("=<", "CMPOP"),
        ("=>", "CMPOP"), ("<<", "CONCAT"), ("<", "CMPOP"), (">", "CMPOP"), ("=", "EQ"), ("+", "PLUS"),
        ("-", "MINUS"), ("*", "STAR"), ("/", "SLASH"), (":", "COLON"), ("(", "LPAR"), (")", "RPAR"),
        ("[", "LSQB"), ("]", "RSQB"), (",", "COMMA")]


class LexError(Exception):
    """Bad input in a block: `rule` NC002/NC003 at 0-based `pos` of the statement text."""

    def __init__(self, rule: str, message: str, pos: int):
        super().__init__(message)
        self.rule = rule
        self.message = message
        self.pos = pos


def number_value(text: str) -> float:
    """Value of a Sinumerik numeric spelling: 1.5EX-3, 'H81', 'B101', TRUE/FALSE."""
    t = text.upper()
    if t == "TRUE":
        return 1.0
    if t == "FALSE":
        return 0.0
    m = _HEXBIN.fullmatch(text)
    if m:
        return float(int(m.group(2), 16 if m.group(1).upper() == "H" else 2))
    return float(t.replace("EX", "E"))


_BARE_EXPONENT = re.compile(r"E[+-]?\d", re.IGNORECASE)
_BARE_EXPONENT_WORD = re.compile(r"E[+-]?\d+", re.IGNORECASE)


def _check_number(text: str, m: "re.Match", start: int, standalone: bool = False) -> None:
    """A numeric literal must be finite (NC108), and an exponent is written EX: `1E400` would
    otherwise read as the number 1 and an address word E400."""
    t = m.group()
    if (len(t) > 15 or "X" in t or "x" in t) and not math.isfinite(number_value(t.strip())):
        raise LexError("NC108", f"{m.group().strip()!r} is out of range (it would read as infinity)",
                       start)
    if standalone and _BARE_EXPONENT.match(text, m.end()):
        e = _BARE_EXPONENT_WORD.match(text, m.end()).group()
        raise LexError("NC002", f"'{t}{e}': a Sinumerik exponent is written EX ({t}EX{e[1:]})",
                       m.end())


def tokenize(text: str, col0: int = 1) -> Iterator[Token]:
    """Tokens of `text`; columns are 1-based and offset by `col0 - 1` (the statement's place in the line)."""
    from lark import Token          # here: the module is imported by code that never parses a block
    i, n = 0, len(text)
    last = [""]
    state = {"def": False, "depth": 0}

    def tok(kind: str, value: str, start: int, end: int) -> Token:
        last[0] = kind
        if kind == "DEF" and start == 0:
            state["def"] = True
        elif kind in ("LPAR", "LSQB"):
            state["depth"] += 1
        elif kind in ("RPAR", "RSQB"):
            state["depth"] -= 1
        return Token(kind, value, start, 1, col0 + start, 1, col0 + end, end)

    while i < n:
        ch = text[i]
        if ch in " \t":
            i += 1
            continue
        if ch == "$":
            m = _SYSVAR.match(text, i)
            if not m:
                raise LexError("NC002", "'$' without a system variable name", i)
            yield tok("SYSVAR", m.group().upper(), i, m.end())
            i = m.end()
            continue
        if ch == '"':
            j = text.find('"', i + 1)
            if j < 0:
                raise LexError("NC003", "string quote opened and not closed", i)
            yield tok("STR", text[i + 1:j], i, j + 1)
            i = j + 1
            continue
        if ch == "'":
            m = _HEXBIN.match(text, i)
            if m:
                yield tok("HEXBIN", m.group(), i, m.end())
                i = m.end()
                continue
            j = text.find("'", i + 1)
            if j < 0:
                raise LexError("NC003", "quote opened and not closed", i)
            yield tok("STR", text[i + 1:j], i, j + 1)
            i = j + 1
            continue
        if ch in _DIGITS or (ch == "." and i + 1 < n and text[i + 1] in _DIGITS):
            m = _NUMBER.match(text, i)
            _check_number(text, m, i, standalone=True)
            yield tok("NUMBER", m.group(), i, m.end())
            i = m.end()
            continue
        if ch in _LETTERS:
            m = _WORD.match(text, i)
            word, end = m.group(), m.end()
            upper = word.upper()
            j = end
            while j < n and text[j] in " \t":
                j += 1
            nxt = text[j] if j < n else ""
            nxt2 = text[j:j + 2]
            if state["def"] and state["depth"] == 0 and upper in _DEF_ATTRIBUTES and last[0] in (
                    "TYPE", "RSQB"):
                m2 = _SIGNED.match(text, end)
                if m2:
                    # DEF CHAN INT LLI 0 ULI 4 NAME: limits, unit and access levels of a GUD
                    # (spec 1.8); they constrain the HMI and later writes, not the motion
                    i = m2.end()
                    continue
            if upper in KEYWORDS and not (nxt == "=" and nxt2 not in ("==", "=<", "=>")):
                yield tok(KEYWORDS[upper], upper, i, end)
                i = end
                continue
            glued = _GLUED_CODE.match(upper) if nxt == "=" else None
            if glued:
                # G01G90X=R12: a G/M word glued before the assigned address (spec 2.2)
                yield tok("ADDR", upper[0], i, i + 1)
                yield tok("NUMBER", glued.group(1), i + 1, i + glued.end())
                i += glued.end()
                continue
            if nxt in "([" and nxt or (nxt == "=" and nxt2 not in ("==", "=<", "=>")):
                yield tok("IDENT", upper, i, end)
                i = end
                continue
            declared = last[0] == "TYPE" or (state["def"] and state["depth"] == 0 and last[0] in (
                "COMMA", "IDENT", "RSQB") and not (upper in KEYWORDS))
            if last[0] in ("PROC", "EXTERN") or declared or (
                    last[0] in ("LPAR", "COMMA", "LSQB") and not re.fullmatch(r"R\d+", upper)
                    and nxt in ",)]"):
                # an axis name such as X1 as an argument or index: DEF AXIS A=(X1), A[I1]
                yield tok("IDENT", upper, i, end)
                i = end
                continue
            if len(word) > 1 and word[1] in _DIGITS and word[0] in _LETTERS and word[0] != "_":
                # glued address words: G0X.. / R1 / X100 / g18g500
                letter = upper[0]
                m2 = _NUMBER.match(text, i + 1)
                if letter == "R" and m2 and "." not in m2.group() and "EX" not in m2.group().upper():
                    # R12 alone, or glued to the next word (X=R12F800: R12, then F800)
                    yield tok("RPARAM", upper[:m2.end() - i], i, m2.end())
                    i = m2.end()
                    continue
                _check_number(text, m2, i + 1)
                yield tok("ADDR", letter, i, i + 1)
                yield tok("NUMBER", m2.group(), i + 1, m2.end())
                i = m2.end()
                continue
            if len(word) == 1:
                m2 = _SIGNED.match(text, end)
                if m2:
                    num = m2.group().strip()
                    _check_number(text, m2, m2.end() - len(num))
                    yield tok("ADDR", upper, i, end)
                    yield tok("NUMBER", num, m2.end() - len(num), m2.end())
                    i = m2.end()
                    continue
            yield tok("IDENT", upper, i, end)
            i = end
            continue
        for op, kind in _OPS:
            if text.startswith(op, i):
                yield tok(kind, op, i, i + len(op))
                i += len(op)
                break
        else:
            raise LexError("NC002", f"unexpected character {ch!r}", i)
