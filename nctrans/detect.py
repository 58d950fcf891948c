"""Guessing a program's dialect from its file ending and its content.

Evidence is added up per registered dialect: the file ending (contract table plus each dialect's own
`extensions`), each dialect's `sniff(text)` when its module is importable, and the marker table below
(constructs one dialect has and the other lacks). Confidence is a dialect's share of all evidence.
A guess with too little evidence, or with the top two too close, is ambiguous: callers ask for --from.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from nctrans.dialects import base

# file endings per dialect (contract "Dialect names"; .ngc is LinuxCNC's rs274ngc, ISO-style).
EXTENSIONS: dict[str, tuple[str, ...]] = {
    "sinumerik": (".mpf", ".spf"),
    "iso-m": (".nc", ".tap", ".cnc", ".iso", ".eia", ".ngc"),
    "iso-t": (".nc", ".tap", ".cnc"),
    "pnc": (".npg", ".nc", ".din"),
    "fagor": (".nc", ".pim", ".fnc"),
}

# (dialect, weight, cap on counted lines, pattern): content markers, matched against each line with
# its comments removed (see _code_lines), so words inside an ISO "(...)" comment count for nothing.
_I = re.IGNORECASE
_MARKERS: list[tuple[str, float, int, re.Pattern]] = [
    ("sinumerik", 5.0, 1, re.compile(r"^%_N_\w+_(?:MPF|SPF)\b", _I)),
    ("sinumerik", 3.0, 3, re.compile(r"^[ \t]*(?:N\d+[ \t]+)?DEF[ \t]+(?:INT|REAL|BOOL|CHAR|STRING|AXIS|FRAME)\b", _I)),
    ("sinumerik", 4.0, 2, re.compile(r"^[ \t]*DEFINE[ \t]+\w+[ \t]+AS\b", _I)),
    ("sinumerik", 3.0, 2, re.compile(r"^[ \t]*(?:N\d+[ \t]+)?PROC[ \t]+\w+", _I)),
    ("sinumerik", 2.0, 3, re.compile(r"\bR\d+[ \t]*=", _I)),
    ("sinumerik", 3.0, 3, re.compile(r"\bGOTO[FBC]\b", _I)),
    ("sinumerik", 3.0, 3, re.compile(r"\bMSG[ \t]*\([ \t]*\"", _I)),
    ("sinumerik", 3.0, 3, re.compile(r"\bCYCLE\d+[ \t]*\(", _I)),
    ("sinumerik", 2.0, 3, re.compile(r"\b[XYZABCIJKFS]\d?[ \t]*=[ \t]*[-+(A-Z$0-9]", _I)),
    ("sinumerik", 2.0, 3, re.compile(r"\$[A-Z]{1,3}_\w+", _I)),
    ("sinumerik", 2.0, 3, re.compile(
        r"\b(?:A?TRANS|A?ROT|A?SCALE|A?MIRROR|ENDIF|ENDWHILE|ENDFOR|ENDLOOP|STOPRE|TRAFOOF|TRAORI|SUPA|"
        r"CFC|DIAMON|BRISK|SOFT|G64[12]|CIP|CR[ \t]*=|AC[ \t]*\(|IC[ \t]*\(|M17|RET)\b", _I)),
    ("sinumerik", 3.0, 2, re.compile(r"\bT[ \t]*=[ \t]*\"", _I)),
    ("sinumerik", 1.5, 1, re.compile(r"\bG7[01]\b", _I)),          # inch/metric (ISO mills: G20/G21)
    # array element assignment by name (GUD/LUD arrays: INI[53]=0); ISO writes #[..] instead
    ("sinumerik", 3.0, 2, re.compile(r"^[ \t]*(?:N\d+[ \t]+)?[A-Z_]{2,}\w*[ \t]*\[[^\]]*\][ \t]*=", _I)),
    ("iso-m", 3.0, 1, re.compile(r"^[ \t]*O\d{1,8}\b", _I)),
    # LinuxCNC rs274ngc (an ISO dialect): o-word control flow and named parameters
    ("iso-m", 4.0, 3, re.compile(r"^[ \t]*(?:N\d+[ \t]*)?O(?:\d+|<\w+>)[ \t]*(?:SUB|ENDSUB|IF|ELSEIF|ELSE|ENDIF|"
                                 r"WHILE|ENDWHILE|DO|REPEAT|ENDREPEAT|CALL|RETURN|BREAK|CONTINUE)\b", _I)),
    ("iso-m", 3.0, 3, re.compile(r"#<\w+>")),
    ("iso-m", 1.0, 3, re.compile(r"^[ \t]*%[ \t]*$")),
    ("iso-m", 3.0, 3, re.compile(r"#\d+[ \t]*=")),
    ("iso-m", 2.0, 3, re.compile(r"#\[")),
    ("iso-m", 3.0, 2, re.compile(r"\b(?:WHILE|IF)[ \t]*\[", _I)),
    ("iso-m", 2.0, 2, re.compile(r"\bEND[ \t]*\d\b", _I)),
    ("iso-m", 2.0, 2, re.compile(r"\bGOTO[ \t]*\d", _I)),
    ("iso-m", 2.0, 2, re.compile(r"\b(?:M98[ \t]*P|G65[ \t]*P|M99\b)", _I)),
    ("iso-m", 1.0, 2, re.compile(r"\bG43\b.*\bH\d", _I)),
    ("iso-m", 1.0, 2, re.compile(r"\bG(?:7[346]|8[1-9])\b.*\bR[-+.\d]", _I)),
    ("iso-m", 1.0, 2, re.compile(r"\bG0?[23]\b[^=]*\bR[-+.\d]", _I)),
    ("iso-m", 1.0, 2, re.compile(r"\bG28\b", _I)),
    # blocks of plain words only (N, G, M, axes, F, S, T...): both dialects allow them, ISO programs
    # are made of little else, so a small capped lean towards ISO.
    ("iso-m", 0.25, 6, re.compile(r"^[ \t]*(?:N\d+[ \t]*)?(?:[GMXYZIJKFSTHDPQRABC][ \t]*[-+]?\d*\.?\d+[ \t]*)+$", _I)),
]
# comment-shaped markers, counted while the comments are removed
_ISO_COMMENT_WEIGHT, _ISO_COMMENT_CAP = 1.0, 3
_SEMICOLON_LINE_WEIGHT, _SEMICOLON_LINE_CAP = 1.0, 3
_SEMICOLON_TAIL_WEIGHT, _SEMICOLON_TAIL_CAP = 0.5, 2     # "G1 X1 ; text": Sinumerik (and LinuxCNC) comments
# a "(" that opens an expression, not an ISO comment: after =, an operator, a bracket, a comma, a
# name (function call CYCLE81(, MSG() or a condition keyword (IF (R1>0)).
_EXPR_BEFORE_PAREN = re.compile(r"(?:[=+\-*/<>,(\[]|\b(?:IF|WHILE|UNTIL|ELSE|AND|OR|NOT|XOR|CASE|FOR|AS))$",
                                re.IGNORECASE)
_CALL_BEFORE_PAREN = re.compile(r"[A-Z_$][A-Z_$]+\w*$", re.IGNORECASE)   # CYCLE81( MSG( SIN( ...
_SCAN_LINES = 4000
_SNIFF_WEIGHT = 1.5   # front ends sniff coarsely; the marker table and file ending weigh more
_EXT_WEIGHT = 2.0
MIN_EVIDENCE = 1.0
MIN_MARGIN = 0.2


@dataclass
class Guess:
    """The outcome: best dialect (None when ambiguous), its confidence 0..1, every dialect's share,
    and where the first marker for each dialect was seen (line number) for NC005 messages."""
    dialect: Optional[str]
    confidence: float
    scores: dict[str, float] = field(default_factory=dict)
    evidence: dict[str, float] = field(default_factory=dict)
    first_marker: dict[str, tuple[int, int, str]] = field(default_factory=dict)
    ambiguous: bool = False
    content: dict[str, float] = field(default_factory=dict)   # evidence from the text alone

    def content_leader(self) -> tuple[Optional[str], float, float]:
        """(dialect, share, evidence) that the text alone points to, ignoring the file name."""
        total = sum(self.content.values())
        if not total:
            return None, 0.0, 0.0
        name, ev = max(self.content.items(), key=lambda kv: kv[1])
        return name, ev / total, ev

    def describe(self) -> str:
        ranked = sorted(self.scores.items(), key=lambda kv: -kv[1])
        return ", ".join(f"{d} {c:.2f}" for d, c in ranked)


def _code_lines(text: str):
    """(line number, code without comments, had an ISO comment, is a ';' comment line, has a ';'
    comment after code) per line."""
    for n, raw in enumerate(text.split("\n", _SCAN_LINES)[:_SCAN_LINES], 1):
        line = raw
        semi_line = line.lstrip().startswith(";")
        cut = line.find(";")
        semi_tail = False
        if cut >= 0:
            semi_tail = not semi_line and bool(line[cut + 1:].strip())
            line = line[:cut]
        comment = False
        if "(" in line:
            out, i = [], 0
            while True:
                j = line.find("(", i)
                if j < 0:
                    out.append(line[i:])
                    break
                k = line.find(")", j)
                if k < 0 or _EXPR_BEFORE_PAREN.search(line[:j].rstrip()) or _CALL_BEFORE_PAREN.search(line[:j]):
                    out.append(line[i:j + 1])
                    i = j + 1
                    continue
                if any(c.isalpha() for c in line[j + 1:k]):
                    comment = True
                out.append(line[i:j] + " " * (k - j + 1))
                i = k + 1
            line = "".join(out)
        yield n, line, comment, semi_line, semi_tail


def _extensions(name: str) -> tuple[str, ...]:
    exts = set(EXTENSIONS.get(name, ()))
    try:
        d = base.get(name)
        if d is not None:
            exts.update(e.lower() if e.startswith(".") else "." + e.lower() for e in d.extensions)
    except Exception:  # a dialect that is not written yet (ImportError) or fails to import
        pass
    return tuple(exts)


def _sniff(name: str, text: str) -> Optional[float]:
    try:
        d = base.get(name)
        if d is None:
            return None
        v = float(d.sniff(text))
    except Exception:  # module missing, or a sniff bug: fall back to the marker table alone
        return None
    return min(max(v, 0.0), 1.0)


def detect(text: str, filename: Optional[str] = None, candidates: Optional[list[str]] = None) -> Guess:
    """Guess the dialect of `text` (optionally named `filename`) among the registered dialects."""
    names = candidates or base.names()
    evidence = {n: 0.0 for n in names}
    first: dict[str, tuple[int, int, str]] = {}
    markers = [m for m in _MARKERS if m[0] in evidence]
    hits = [0] * len(markers)
    iso_comments = semi_lines = semi_tails = 0
    for lineno, code, comment, semi, tail in _code_lines(text):
        iso_comments += comment
        semi_lines += semi
        semi_tails += tail
        if not code.strip():
            continue
        for i, (dialect, weight, cap, rx) in enumerate(markers):
            if hits[i] >= cap:
                continue
            m = rx.search(code)
            if m is None:
                continue
            hits[i] += 1
            if weight >= 1.0 and dialect not in first:
                first[dialect] = (lineno, m.start() + 1, m.group(0).strip()[:30])
    for (dialect, weight, _cap, _rx), h in zip(markers, hits):
        evidence[dialect] += weight * h
    if "iso-m" in evidence:
        evidence["iso-m"] += _ISO_COMMENT_WEIGHT * min(iso_comments, _ISO_COMMENT_CAP)
    if "sinumerik" in evidence:
        evidence["sinumerik"] += _SEMICOLON_LINE_WEIGHT * min(semi_lines, _SEMICOLON_LINE_CAP)
        evidence["sinumerik"] += _SEMICOLON_TAIL_WEIGHT * min(semi_tails, _SEMICOLON_TAIL_CAP)
    head = text[:200_000]
    for n in names:
        s = _sniff(n, head)
        if s is not None:
            evidence[n] += _SNIFF_WEIGHT * s
    content = dict(evidence)
    if filename:
        suffix = Path(filename).suffix.lower()
        if suffix:
            owners = [n for n in names if suffix in _extensions(n)]
            # an ending only one dialect uses (.mpf) says more than a shared one (.nc)
            weight = _EXT_WEIGHT * 1.5 if len(owners) == 1 and all(
                suffix not in exts for d, exts in EXTENSIONS.items() if d not in owners) else _EXT_WEIGHT
            for n in owners:
                evidence[n] += weight / len(owners)
    total = sum(evidence.values())
    scores = {n: (e / total if total else 0.0) for n, e in evidence.items()}
    ranked = sorted(scores.items(), key=lambda kv: -kv[1])
    top, conf = ranked[0] if ranked else (None, 0.0)
    second = ranked[1][1] if len(ranked) > 1 else 0.0
    ambiguous = total < MIN_EVIDENCE or conf - second < MIN_MARGIN
    return Guess(None if ambiguous else top, conf, scores, evidence, first, ambiguous, content)
