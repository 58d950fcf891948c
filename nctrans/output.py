"""Diagnostic output formats: one switch over one list of diagnostics (as ruff does).

- text:   `file:line:col: severity[rule] message` (gcc style, parsed by editors and CI)
- json:   `{"diagnostics": [...], "files": N, "summary": {"error": n, "warning": n, "info": n}}`
- sarif:  SARIF 2.1.0 with the rule catalogue in tool.driver.rules
- github: `::error file=F,line=L,col=C,title=RULE::message` workflow commands

SARIF is written as plain dicts and held to the official 2.1.0 JSON schema by the tests (jsonschema).
sarif-pydantic was tried (offline, from its wheel): its models are all-optional with extra fields
allowed, so they accepted documents the schema rejects (startLine -5, startColumn 0, a bogus
columnKind), and importing them cost about four times pydantic's own import on every SARIF run.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Iterable, Optional

from nctrans import __version__
from nctrans.diagnostics import SEVERITIES, Diagnostic

FORMATS = ("text", "json", "sarif", "github")
SARIF_SCHEMA = "https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/sarif-schema-2.1.0.json"
_SARIF_LEVEL = {"error": "error", "warning": "warning", "info": "note"}
_GITHUB_COMMAND = {"error": "error", "warning": "warning", "info": "notice"}


def sort_key(d: Diagnostic):
    return (d.file, d.line, d.column, d.rule)


def summary(diags: Iterable[Diagnostic]) -> dict[str, int]:
    counts = {s: 0 for s in reversed(SEVERITIES)}
    for d in diags:
        counts[d.severity] = counts.get(d.severity, 0) + 1
    return counts


def format_text(diags: list[Diagnostic]) -> str:
    return "".join(d.format_text() + "\n" for d in diags)


def format_json(diags: list[Diagnostic], files: int) -> str:
    doc = {"diagnostics": [d.to_dict() for d in diags], "files": files, "summary": summary(diags)}
    return json.dumps(doc, indent=2) + "\n"


# --------------------------------------------------------------------------- github

def _gh_data(s: str) -> str:
    return s.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def _gh_prop(s: str) -> str:
    return _gh_data(s).replace(":", "%3A").replace(",", "%2C")


def format_github(diags: list[Diagnostic]) -> str:
    out = []
    for d in diags:
        cmd = _GITHUB_COMMAND.get(d.severity, "warning")
        # GitHub matches annotations to repository paths: "./a.nc" (a directory walk) as "a.nc"
        file = d.file[2:] if d.file.startswith("./") else d.file
        props = (f"file={_gh_prop(file)},line={d.line},col={d.column},"
                 f"endLine={d.end_line},endColumn={d.end_column},title={_gh_prop(d.rule)}")
        out.append(f"::{cmd} {props}::{_gh_data(d.message)}\n")
    return "".join(out)


# --------------------------------------------------------------------------- sarif

def artifact_uri(file: str) -> str:
    """A URI reference for a diagnostic's file: relative paths stay relative (SARIF consumers
    resolve them against the checkout), absolute ones become file: URIs."""
    p = Path(file)
    if p.is_absolute():
        return p.as_uri()
    from urllib.parse import quote          # SARIF only; urllib.parse costs ~3 ms to import
    return quote(p.as_posix(), safe="/._-~")


def _region(d: Diagnostic) -> dict:
    end_line = max(d.end_line or d.line, d.line)
    end_col = d.end_column if d.end_column else d.column + 1
    if end_line == d.line and end_col <= d.column:
        end_col = d.column + 1
    return {"startLine": max(d.line, 1), "startColumn": max(d.column, 1),
            "endLine": max(end_line, 1), "endColumn": max(end_col, 1)}


def _sarif_rule(r: "_catalogue.Rule") -> dict:
    help_text = f"{r.summary}\n\nWhy: {r.why}\n\nBad: {r.bad or '(an empty file)'}\nGood: {r.good}"
    if r.fix:
        help_text += f"\nFix: {r.fix}"
    return {
        "id": r.code,
        "name": r.name,
        "shortDescription": {"text": r.summary},
        "fullDescription": {"text": r.why},
        "help": {"text": help_text},
        "defaultConfiguration": {"level": _SARIF_LEVEL[r.severity]},
        "properties": {"tags": [r.code[:3] + "xx"]},
    }


class _Fingerprints:
    """partialFingerprints for code scanning: a hash of the rule, the file and the text of the
    diagnostic's line (not its number), plus which occurrence of that triple it is. A finding keeps
    its fingerprint when lines are inserted above it, so code scanning tracks it across commits
    instead of closing and reopening it."""
    KEY = "nctransLineHash/v1"

    def __init__(self) -> None:
        self._lines: dict[str, list[str]] = {}
        self._seen: dict[str, int] = {}

    def _line_text(self, file: str, line: int) -> str:
        if file not in self._lines:
            try:
                with open(file, "rb") as fh:
                    self._lines[file] = [ln.strip().decode("latin-1") for ln in fh]
            except (OSError, ValueError):      # stdin, a vanished file, a name the OS refuses
                self._lines[file] = []
        lines = self._lines[file]
        return " ".join(lines[line - 1].split()) if 0 < line <= len(lines) else f"#{line}"

    def of(self, d: Diagnostic, uri: str) -> dict[str, str]:
        import hashlib
        text = self._line_text(d.file, d.line)
        digest = hashlib.sha256(f"{d.rule}\0{uri}\0{text}".encode("utf-8", "replace")).hexdigest()[:32]
        n = self._seen.get(digest, 0) + 1
        self._seen[digest] = n
        return {self.KEY: f"{digest}:{n}"}


def sarif_document(diags: list[Diagnostic], cat: Optional[_catalogue.Catalogue] = None) -> dict:
    from nctrans import catalogue as _catalogue    # pydantic: only SARIF needs the catalogue
    cat = cat or _catalogue.load()
    rules = [_sarif_rule(r) for r in cat.rule]
    index = {r.code: i for i, r in enumerate(cat.rule)}
    results = []
    prints = _Fingerprints()
    for d in diags:
        uri = artifact_uri(d.file)
        loc = {"physicalLocation": {"artifactLocation": {"uri": uri}, "region": _region(d)}}
        res = {"ruleId": d.rule, "level": _SARIF_LEVEL.get(d.severity, "warning"),
               "message": {"text": d.message}, "locations": [loc],
               "partialFingerprints": prints.of(d, uri)}
        if d.rule in index:
            res["ruleIndex"] = index[d.rule]
        if d.fix is not None:
            f = d.fix
            res["fixes"] = [{"artifactChanges": [{
                "artifactLocation": {"uri": artifact_uri(d.file)},
                "replacements": [{
                    "deletedRegion": {"startLine": f.line, "startColumn": f.column,
                                      "endLine": f.end_line, "endColumn": f.end_column},
                    "insertedContent": {"text": f.replacement}}]}]}]
        results.append(res)
    return {
        "$schema": SARIF_SCHEMA,
        "version": "2.1.0",
        "runs": [{
            "tool": {"driver": {"name": "nctrans", "version": __version__,
                                "rules": rules}},
            "columnKind": "unicodeCodePoints",
            "results": results,
        }],
    }


def format_sarif(diags: list[Diagnostic], cat: Optional[_catalogue.Catalogue] = None) -> str:
    return json.dumps(sarif_document(diags, cat), indent=2) + "\n"


def render(fmt: str, diags: list[Diagnostic], files: int) -> str:
    """The whole report in format `fmt` (text/json/sarif/github)."""
    diags = sorted(diags, key=sort_key)
    if fmt == "json":
        return format_json(diags, files)
    if fmt == "sarif":
        return format_sarif(diags)
    if fmt == "github":
        return format_github(diags)
    return format_text(diags)
