"""`nctrans lint` for one file: the parse and interpreter diagnostics, the IR analyses, what the
program's own suppression comments drop.

The CLI (and so pre-commit) and the Python API (nctrans.api.lint) both lint through
`lint_loaded`, so a suppression means the same everywhere; the CLI adds the configuration's
dialect patterns and rule selection.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

from nctrans import pipeline
from nctrans.diagnostics import Diagnostic
from nctrans.linting import suppress


@dataclass
class Selection:
    """Which rules are reported: codes or prefixes (NC2 = every NC2xx). Empty select = all."""
    select: list[str] = field(default_factory=list)
    ignore: list[str] = field(default_factory=list)

    @staticmethod
    def parse(groups) -> list[str]:
        return [p.strip().upper() for g in groups or () for p in str(g).split(",") if p.strip()]

    def keeps(self, code: str, extra_ignore: list[str] = ()) -> bool:
        code = code.upper()
        if self.select and not any(code.startswith(p) for p in self.select):
            return False
        return not any(code.startswith(p) for p in (*self.ignore, *extra_ignore))


def lint_loaded(ld: pipeline.Loaded, machine=None, target: Optional[str] = None,
                run=None) -> list[Diagnostic]:
    """The diagnostics of an already loaded program (see pipeline.load), after its own
    suppression comments; the program is run once (a streamed one is consumed) by `run(ld,
    machine) -> diagnostics`: pipeline.lint, or the machine check (nctrans.check.check_loaded)."""
    m = machine or pipeline.load_machine(None, ld.dialect)
    from nctrans.linting import checks
    diags = list(checks.run(ld, m, target, run))
    if ld.source.ok:
        diags = suppress.apply(diags, suppress.scan(ld.source.text, ld.label), ld.label)
    return diags
