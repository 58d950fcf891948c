"""Diagnostics: the one record every stage reports problems with.

Stages never raise on bad user input; they return or collect `Diagnostic`s. Exceptions are for bugs.
Rule codes are stable and documented in `rules/lint-rules.toml` (the catalogue `nctrans rules` prints).
"""
from __future__ import annotations

from dataclasses import dataclass, field, asdict
from typing import Optional

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
