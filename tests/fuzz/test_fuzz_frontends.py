"""Property-based fuzzing of every front end and the interpreter behind it.

Mutated real corpus lines and random NC-like text must never raise: each front end returns a
Program (or diagnostics), every diagnostic is located (line/column inside the text) with a stable
code, and the interpreter on the result stops within its step budget.
"""
from __future__ import annotations

import itertools
import re
from pathlib import Path

import pytest
from hypothesis import given, strategies as st

from nctrans.dialects.base import get, names
from nctrans.interp import interpret
from conftest import CORPUS

RULE = re.compile(r"^NC\d{3}$")


def _corpus_lines(sub: str, limit: int = 4000) -> list[str]:
    lines: list[str] = []
    for path in sorted((CORPUS / sub).glob("*")):
        text = path.read_bytes().decode("utf-8", errors="replace")
        lines.extend(l for l in text.splitlines() if l.strip())
    return lines[:limit] or ["G0 X0"]


ISO_LINES = _corpus_lines("iso-mill")
SIN_LINES = _corpus_lines("sinumerik")
NC_ALPHABET = "GXYZIJKRFSTMNOPQHDL0123456789.-+ #[]()=;/,*<>:$'\"\t\x00é"


@st.composite
def mutated_program(draw, pool):
    start = draw(st.integers(0, max(0, len(pool) - 1)))
    count = draw(st.integers(1, 12))
    lines = list(itertools.islice(itertools.cycle(pool[start:] + pool[:start]), count))
    for _ in range(draw(st.integers(0, 6))):
        i = draw(st.integers(0, len(lines) - 1))
        line = lines[i]
        pos = draw(st.integers(0, len(line)))
        op = draw(st.sampled_from(["insert", "delete", "replace", "duplicate", "truncate"]))
        ch = draw(st.sampled_from(NC_ALPHABET))
        if op == "insert":
            line = line[:pos] + ch + line[pos:]
        elif op == "delete":
            line = line[:pos] + line[pos + 1:]
        elif op == "replace":
            line = line[:pos] + ch + line[pos + 1:]
        elif op == "duplicate":
            lines.insert(i, line)
        else:
            line = line[:pos]
        lines[i] = line
    return "\n".join(lines) + "\n"


def _check(dialect: str, text: str) -> None:
    result = get(dialect).parse(text, "fuzz.nc")
    n_lines = text.count("\n") + 1
    for d in result.diagnostics:
        assert RULE.match(d.rule), d
        assert d.severity in ("error", "warning", "info"), d
        assert 1 <= d.line <= n_lines + 1, d
        assert d.column >= 1, d
    if result.program is None:
        return
    diags: list = []
    for i, _record in enumerate(interpret(result.program, None, diagnostics=diags, max_steps=5000)):
        if i > 5000:
            break
    for d in diags:
        assert RULE.match(d.rule), d


@pytest.mark.parametrize("dialect", names())
@given(data=st.data())
def test_mutated_corpus_never_raises(dialect, data):
    pool = SIN_LINES if dialect == "sinumerik" else ISO_LINES
    _check(dialect, data.draw(mutated_program(pool)))


@pytest.mark.parametrize("dialect", names())
@given(text=st.text(alphabet=NC_ALPHABET + "\n", max_size=300))
def test_random_nc_text_never_raises(dialect, text):
    _check(dialect, text)
