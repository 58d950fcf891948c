"""Diagnostics: the one record every stage reports problems with.

Stages never raise on bad user input; they return or collect `Diagnostic`s. Exceptions are for bugs.
Rule codes are stable and documented in `rules/lint-rules.toml` (the catalogue `nctrans rules` prints).
"""
from __future__ import annotations

from dataclasses import dataclass, field, asdict
from typing import Iterable, Iterator, Optional

SEVERITIES = ("info", "warning", "error")
SEVERITY_RANK = {s: i for i, s in enumerate(SEVERITIES)}


@dataclass(slots=True)
class Fix:
    replacement: str
    line: int
    column: int
    end_line: int
    end_column: int


@dataclass(slots=True)
class Diagnostic:
    rule: str
    severity: str
    message: str
    file: str = "<stdin>"
    line: int = 1
    column: int = 1
    end_line: int = 0
    end_column: int = 0
    fix: Optional[Fix] = None

    def __post_init__(self) -> None:
        if not self.end_line:
            self.end_line = self.line
        if not self.end_column:
            self.end_column = self.column + 1

    def to_dict(self) -> dict:
        d = asdict(self)
        if d["fix"] is None:
            del d["fix"]
        return d

    def format_text(self) -> str:
        return f"{self.file}:{self.line}:{self.column}: {self.severity}[{self.rule}] {self.message}"


def at_span(rule: str, severity: str, message: str, span) -> Diagnostic:
    """Build a diagnostic located at an IR Span (or None: line 1)."""
    if span is None:
        return Diagnostic(rule, severity, message)
    return Diagnostic(rule, severity, message, span.file, span.line, span.col,
                      span.end_line or span.line, span.end_col or span.col + 1)


def once_each(diags: Iterable[Diagnostic]) -> Iterator[Diagnostic]:
    """Each diagnostic once at its file:line. Several files analysed together report one file's
    diagnostic twice: a macro file's own line reached by its caller's run and again in its own."""
    import os
    seen: set = set()
    for d in diags:
        # a called file is named relative to the working directory, the same file given on the
        # command line as the user wrote it: one file either way
        place = os.path.abspath(d.file) if d.file and not d.file.startswith("<") and d.file != "-" else d.file
        key = (d.rule, place, d.line, d.column, d.message)
        if key not in seen:
            seen.add(key)
            yield d


# Diagnostics kept per list (one file's parse or run; NCTRANS_MAX_DIAGNOSTICS overrides it).
MAX_PER_FILE = 1000


class DiagnosticList(list):
    """A list of one file's diagnostics that stays small whatever the input: one diagnostic per
    block (line) and rule, the first found (its column and message), counting the rest ("(+3 more
    in this block)"); past MAX_PER_FILE of those the rest are only counted, in one closing NC009
    note. A 5 MB line of repeated X words gives one NC201, not 1.75 M of them."""

    def __init__(self, items=(), limit: Optional[int] = None):
        super().__init__()
        if limit is None:
            from nctrans.limits import setting
            limit = setting("MAX_DIAGNOSTICS", MAX_PER_FILE)
        self.limit = limit
        self._seen: dict[tuple, list] = {}       # place -> [diagnostic, first message, count]
        self._dropped = 0
        self._note: Optional[Diagnostic] = None
        self.extend(items)

    def append(self, d: Diagnostic) -> None:
        key = (d.rule, d.file, d.line)
        seen = self._seen.get(key)
        if seen is not None:
            seen[2] += 1
            seen[0].message = f"{seen[1]} (+{seen[2] - 1} more in this block)"
            return
        if len(self._seen) >= self.limit:
            self._drop(1, d)
            return
        self._seen[key] = [d, d.message, 1]
        super().append(d)

    def _drop(self, count: int, d: Diagnostic) -> None:
        self._dropped += count
        if self._note is None:
            self._note = Diagnostic("NC009", "info", "", d.file, d.line, d.column)
            super().append(self._note)
        self._note.message = (f"{self._dropped} more diagnostics in this file not listed "
                              f"(at most {self.limit} are reported per file)")

    def extend(self, ds) -> None:
        note = getattr(ds, "_note", None)
        for d in ds:
            if d is not note:
                self.append(d)
        if note is not None:                 # another capped list: carry its count over
            self._drop(ds._dropped, note)

    def __iadd__(self, ds):
        self.extend(ds)
        return self


@dataclass
class Report:
    """Collects diagnostics for one run; `worst()` drives the exit code."""
    diagnostics: list[Diagnostic] = field(default_factory=list)

    def add(self, d: Diagnostic) -> None:
        self.diagnostics.append(d)

    def extend(self, ds) -> None:
        self.diagnostics.extend(ds)

    def at_or_above(self, severity: str) -> list[Diagnostic]:
        rank = SEVERITY_RANK[severity]
        return [d for d in self.diagnostics if SEVERITY_RANK[d.severity] >= rank]
