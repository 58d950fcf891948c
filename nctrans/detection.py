"""Guessing a program's dialect from its file ending and its content.

Evidence is added up per registered dialect (nctrans.dialects.base): its file endings (`extensions`),
its `sniff(text)`, its content `markers` (constructs it has and others lack) and the comment shapes it
claims (`comment_evidence`). Confidence is a dialect's share of all evidence.
A guess with too little evidence, or with the top two too close, is ambiguous: callers ask for --from.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from nctrans.dialects import base

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


def extensions(name: str) -> tuple[str, ...]:
    """The registered dialect's file endings, lower case with the dot."""
    d = base.get(name)
    if d is None:
        return ()
    return tuple(sorted({e.lower() if e.startswith(".") else "." + e.lower() for e in d.extensions}))


def _sniff(d: base.Dialect, text: str) -> float:
    return min(max(float(d.sniff(text)), 0.0), 1.0)


# The header comment nctrans writes into a converted program (nctrans.convert.header), among its
# opening lines: "converted by nctrans 0.1.0 from iso-m to iso-t: part.nc".
_OWN_HEADER = re.compile(r"converted by nctrans \S+ from [\w.-]+ to ([\w.-]+): ")
_HEADER_LINES = 6


def written_by_nctrans(text: str) -> Optional[str]:
    """The dialect a file nctrans wrote says it is in (its header comment), or None. Its content
    alone may not tell: a lathe program written from a mill program has no lathe construct, and
    the header's own comment shape speaks for another family."""
    for line in text[:4000].split("\n", _HEADER_LINES)[:_HEADER_LINES]:
        m = _OWN_HEADER.search(line)
        if m is not None:
            return m.group(1)
    return None


def detect(text: str, filename: Optional[str] = None, candidates: Optional[list[str]] = None) -> Guess:
    """Guess the dialect of `text` (optionally named `filename`) among the registered dialects; a
    file nctrans converted is in the dialect its header names."""
    names = [n for n in candidates or base.names() if base.get(n) is not None]
    own = written_by_nctrans(text)
    if own in names:
        return Guess(own, 1.0, {n: float(n == own) for n in names}, {n: float(n == own) for n in names},
                     {}, False, {n: float(n == own) for n in names})
    dialects = [base.get(n) for n in names]
    evidence = {n: 0.0 for n in names}
    first: dict[str, tuple[int, int, str]] = {}
    markers = [(d.name, m.weight, m.cap, m.pattern) for d in dialects for m in d.markers]
    hits = [0] * len(markers)
    shapes = dict.fromkeys(base.COMMENT_SHAPES, 0)
    for lineno, code, comment, semi, tail in _code_lines(text):
        shapes["paren_comment"] += comment
        shapes["semicolon_line"] += semi
        shapes["semicolon_tail"] += tail
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
    specific = dict.fromkeys(names, 0.0)   # constructs other dialects lack (not plain words, not sniffing)
    for (dialect, weight, _cap, _rx), h in zip(markers, hits):
        evidence[dialect] += weight * h
        if weight >= 1.0:
            specific[dialect] += weight * h
    for d in dialects:
        for shape, (weight, cap) in d.comment_evidence.items():
            evidence[d.name] += weight * min(shapes[shape], cap)
            specific[d.name] += weight * min(shapes[shape], cap)
    head = text[:200_000]
    for d in dialects:
        evidence[d.name] += _SNIFF_WEIGHT * _sniff(d, head)
    content = dict(evidence)
    if filename:
        suffix = Path(filename).suffix.lower()
        if suffix:
            owners = [n for n in names if suffix in extensions(n)]
            # an ending only one dialect uses (.mpf) says more than a shared one (.nc)
            exclusive = len(owners) == 1 and suffix not in base.COMMON_ENDINGS and all(
                suffix not in extensions(n) for n in base.names() if n not in owners)
            weight = _EXT_WEIGHT * 1.5 if exclusive else _EXT_WEIGHT
            for n in owners:
                evidence[n] += weight / len(owners)
            if exclusive:
                # plain word blocks (G0 X10, M30) are valid in the ending's own dialect too: they
                # speak for another dialect only next to one of its own constructs
                for n in names:
                    family = getattr(base.get(n), "family_evidence", None)
                    if n not in owners and not (specific[n] and specific.get(family or n, 1.0)):
                        evidence[n] = 0.0
    total = sum(evidence.values())
    scores = {n: (e / total if total else 0.0) for n, e in evidence.items()}
    ranked = sorted(scores.items(), key=lambda kv: -kv[1])
    top, conf = ranked[0] if ranked else (None, 0.0)
    second = ranked[1][1] if len(ranked) > 1 else 0.0
    ambiguous = total < MIN_EVIDENCE or conf - second < MIN_MARGIN
    return Guess(None if ambiguous else top, conf, scores, evidence, first, ambiguous, content)


# Evidence of one marker hit that, on a line a front end could not read, points to another dialect.
FOREIGN_WEIGHT = 2.0


def foreign_marker(line: str, dialect: str) -> Optional[tuple[str, int, str]]:
    """(other dialect, column, marked text) when one line of code carries a strong marker of another
    dialect and none of `dialect`'s own: a syntax error on such a line most likely means the file
    is read as the wrong dialect (NC005 at that line). None otherwise."""
    code = next(_code_lines(line.split("\n", 1)[0]), None)
    if code is None or not code[1].strip():
        return None
    best: Optional[tuple[float, str, int, str]] = None
    for d in base.dialects():
        for m in d.markers:
            hit = m.pattern.search(code[1])
            if hit is None:
                continue
            if d.name == dialect and m.weight >= 1.0:
                return None
            if d.name != dialect and m.weight >= FOREIGN_WEIGHT and (best is None or m.weight > best[0]):
                best = (m.weight, d.name, hit.start() + 1, hit.group(0).strip()[:30])
    return None if best is None else best[1:]
