"""Sinumerik DEF limit attributes (issue 8): LLI / ULI are enforced when a value is assigned, as the
control refuses it (NC223 at the assignment; the variable keeps its value), and written back."""
from __future__ import annotations

from nctrans import api, pipeline
from nctrans.source import from_text


def run(text: str):
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind == "rapid"]
    return [r.end["X"] for r in recs], ld.diagnostics


def test_values_outside_the_limits_are_refused_at_their_line():
    # PASSES 0..4: 5 refused (stays 0), 4 taken; RR up to 10.5: 11 refused (stays 3), then 10
    text = ("DEF CHAN INT LLI 0 ULI 4 PASSES\nDEF REAL ULI 10.5 RR=3\nPASSES=5\nG0 X=PASSES\n"
            "RR=11\nG0 X=RR\nPASSES=4\nRR=10\nG0 X=PASSES+RR\nM30\n")
    xs, diags = run(text)
    assert xs == [0, 3, 14]
    assert [(d.rule, d.line, d.severity) for d in diags] == [("NC223", 3, "error"),
                                                            ("NC223", 5, "error")]


def test_limits_hold_for_every_name_of_the_def_and_for_initial_values():
    _, diags = run("DEF INT LLI -2 ULI 2 AA=1, BB=3\nAA=-3\nAA=-2\nM30\n")
    assert [(d.rule, d.line) for d in diags] == [("NC223", 1), ("NC223", 2)]


def test_no_limits_no_check():
    _, diags = run("DEF INT AA\nAA=100000\nM30\n")
    assert diags == []


def test_limits_are_written_back():
    out = api.transpile("DEF CHAN INT LLI 0 ULI 4 PASSES\nDEF INT CC\nPASSES=2\nM30\n",
                        "sinumerik", "sinumerik")
    lines = [ln for ln in out.text.splitlines() if not ln.startswith("; converted by nctrans")]
    assert lines[:2] == ["DEF CHAN INT LLI 0 ULI 4 PASSES", "DEF INT CC"]
