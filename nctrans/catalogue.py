"""The lint-rule catalogue (`rules/lint-rules.toml`), validated with pydantic.

One source for `nctrans rules`, the SARIF `tool.driver.rules` and rule-code checks, so the
documentation and what the tool reports cannot drift apart.
"""
from __future__ import annotations

import re
import tomllib
from functools import lru_cache
from typing import Literal, Optional

from pydantic import BaseModel, ConfigDict, field_validator

from nctrans import resources
from nctrans.dialects.base import DEFAULT_DIALECT

CATALOGUE_PATH = resources.path("rules", "lint-rules.toml")
_CODE = re.compile(r"^NC\d{3}$")

FAMILIES = {
    "NC0": "syntax and lexical errors",
    "NC1": "names, types and values",
    "NC2": "modal and motion logic",
    "NC3": "machine",
    "NC4": "portability and conversion",
    "NC5": "style",
}


class Rule(BaseModel):
    """One rule. `bad` and `good` are real programs in `dialect`: tests/test_rule_examples.py runs
    each through `nctrans <example_command> FILE --from DIALECT <example_args>` and requires the bad
    one to report this rule and the good one not to. Examples that need more than one file declare
    it: `example_files` (name -> text, written beside the example, e.g. a called subprogram),
    `example_machine` (MACHINE.toml text, passed with --machine), `example_encoding` (how the bad
    example's bytes are encoded, e.g. utf-16)."""
    model_config = ConfigDict(extra="forbid")
    code: str
    name: str
    severity: Literal["error", "warning", "info"]
    summary: str
    why: str
    bad: str
    good: str
    fix: Optional[str] = None
    dialect: str = DEFAULT_DIALECT
    example_command: Literal["lint", "convert", "check", "backplot"] = "lint"
    example_args: list[str] = []
    example_files: dict[str, str] = {}
    example_machine: Optional[str] = None
    example_encoding: str = "utf-8"
    # environment the examples run with: limits lowered (NCTRANS_MAX_DIAGNOSTICS=2) so an example
    # of a limit stays a few lines long
    example_env: dict[str, str] = {}
    # A rule kept for its stable code that no dialect reports yet: why. Its test then requires
    # that the bad example does NOT fire, so the day it does, the entry must be completed.
    reserved: Optional[str] = None

    @field_validator("code")
    @classmethod
    def _code_form(cls, v: str) -> str:
        if not _CODE.match(v):
            raise ValueError(f"rule code {v!r} is not NC followed by three digits")
        return v


class Catalogue(BaseModel):
    model_config = ConfigDict(extra="forbid")
    rule: list[Rule]

    def model_post_init(self, _ctx) -> None:
        seen: dict[str, Rule] = {}
        for r in self.rule:
            if r.code in seen:
                raise ValueError(f"rule {r.code} is defined twice")
            seen[r.code] = r
        self._by_code = seen

    def get(self, code: str) -> Optional[Rule]:
        return self._by_code.get(code.upper())

    def codes(self) -> list[str]:
        return [r.code for r in self.rule]


@lru_cache(maxsize=None)
def load(path=CATALOGUE_PATH) -> Catalogue:
    with path.open("rb") as fh:
        return Catalogue.model_validate(tomllib.load(fh))


def format_catalogue(cat: Catalogue) -> str:
    """The catalogue as a plain table grouped by family."""
    lines: list[str] = []
    family = None
    for r in sorted(cat.rule, key=lambda r: r.code):
        if r.code[:3] != family:
            family = r.code[:3]
            if lines:
                lines.append("")
            lines.append(f"{family}xx  {FAMILIES.get(family, '')}")
        lines.append(f"  {r.code}  {r.severity:<7}  {r.name:<26} {r.summary}")
    lines.append("")
    lines.append("`nctrans rules NCxxx` shows one rule in full.")
    return "\n".join(lines)


def format_rule(r: Rule) -> str:
    """One rule's documentation: summary, why, a failing and a passing example, the fix."""
    return "\n".join([
        f"{r.code} {r.name} ({r.severity})" + (" - reserved: no dialect reports it yet" if r.reserved else ""),
        "",
        r.summary,
        "",
        f"Why: {r.why}",
        "",
        "Bad:",
        _indent(r.bad) if r.bad.strip() else "    (an empty file)",
        "",
        "Good:",
        _indent(r.good),
        "",
        f"(examples run as: {_example_context(r)})",
        "",
        f"Fix: {r.fix}" if r.fix else "Fix: no automatic fix; edit the program as in the good example.",
    ])


def _indent(program: str) -> str:
    return "\n".join("    " + line for line in program.strip("\n").splitlines())


def _example_context(r: Rule) -> str:
    """How the examples are run, e.g. `nctrans lint --from sinumerik`."""
    words = ["nctrans", r.example_command, "--from", r.dialect, *r.example_args]
    if r.example_machine:
        words += ["--machine", "MACHINE.toml"]
    if r.example_encoding != "utf-8":
        words.append(f"(file encoded as {r.example_encoding})")
    return " ".join(words)
