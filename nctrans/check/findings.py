"""What the machine check finds: plain records a person, lint and the backplot can all read.

A Finding names the block (file:line), what it is about (an axis, a fixture, the stock, the
spindle), where the machine is (the controlled point in machine coordinates) and by how much a
limit is exceeded. `to_diagnostic` turns it into the Diagnostic every output format prints.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from nctrans.diagnostics import Diagnostic

# rule code -> (kind, default severity); the catalogue (rules/lint-rules.toml) documents each
RULES = {
    "NC301": ("overtravel", "error"),
    "NC302": ("programmable-limit", "error"),
    "NC303": ("feed-over-axis-maximum", "warning"),
    "NC304": ("spindle-over-maximum", "error"),
    "NC305": ("axis-not-on-machine", "warning"),
    "NC306": ("check-not-modelled", "info"),
    "NC307": ("limits-not-modelled", "warning"),
    "NC310": ("tool-hits-fixture", "error"),
    "NC311": ("holder-hits-fixture", "error"),
    "NC312": ("holder-hits-stock", "error"),
    "NC313": ("rapid-into-stock", "error"),
}


def fmt_point(p: Optional[dict]) -> str:
    if not p:
        return "?"
    return " ".join(f"{a}{v:.3f}" for a, v in p.items())


@dataclass(slots=True)
class Finding:
    rule: str
    file: str
    line: int
    subject: str                    # axis ("X"), fixture name, "stock", "spindle", ...
    message: str
    position: Optional[dict[str, float]] = None   # controlled point, machine coordinates
    amount: Optional[float] = None  # by how much (mm, mm/min, rpm) the limit is exceeded

    @property
    def kind(self) -> str:
        return RULES[self.rule][0]

    @property
    def severity(self) -> str:
        return RULES[self.rule][1]

    def to_dict(self) -> dict:
        return {"rule": self.rule, "kind": self.kind, "severity": self.severity, "file": self.file,
                "line": self.line, "subject": self.subject, "position": self.position,
                "amount": self.amount, "message": self.message}

    def to_diagnostic(self) -> Diagnostic:
        return Diagnostic(self.rule, self.severity, self.message, self.file, self.line, 1)
