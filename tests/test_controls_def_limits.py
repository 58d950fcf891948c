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


def test_limits_hold_for_every_element_of_an_array():
    # AA[1]=5 refused (stays 0), AA[2]=3 taken: X=0+3; REP(7) refused whole: AA[0] stays 0
    xs, diags = run("DEF INT LLI 0 ULI 4 AA[3]\nAA[1]=5\nAA[2]=3\nG0 X=AA[1]+AA[2]\n"
                    "AA[0]=REP(7)\nG0 X=AA[0]\nAA[0]=SET(1,9)\nG0 X=AA[0]+AA[1]\nM30\n")
    assert xs == [3, 0, 1]
    assert [(d.rule, d.line) for d in diags] == [("NC223", 2), ("NC223", 5), ("NC223", 7)]


def test_array_initial_values_outside_the_limits_are_not_taken():
    # BB[0]=0.5 taken, BB[1]=2 refused (stays 0): X=0.5, and the array still exists
    xs, diags = run("DEF REAL LLI -1 ULI 1 BB[2]=(0.5, 2)\nG0 X=BB[0]+BB[1]\nM30\n")
    assert xs == [0.5]
    assert [(d.rule, d.line) for d in diags] == [("NC223", 1)]


def test_refused_initial_value_leaves_the_default():
    xs, diags = run("DEF INT LLI 0 ULI 4 CC=6\nG0 X=CC+1\nM30\n")
    assert xs == [1]
    assert [(d.rule, d.line) for d in diags] == [("NC223", 1)]


def test_limits_hold_through_a_by_reference_parameter():
    """PROC SUB(VAR INT P, VAR REAL Q) bound to PASSES (0..4) and AR[1] (0..10): P=9 and Q=11
    are refused at their lines in the subprogram, P=3 and Q=7 reach the caller's variables."""
    from test_interp_sinumerik import ends, run as run_units
    recs, diags = run_units("DEF INT LLI 0 ULI 4 PASSES=1\nDEF REAL LLI 0 ULI 10 AR[2]\n"
                            "SUB(PASSES, AR[1])\nG0 X=PASSES Y=AR[1]\nM30\n%_N_SUB_SPF\n"
                            "PROC SUB(VAR INT P, VAR REAL Q)\nP=9\nQ=11\nG0 X=P Y=Q\nP=3\nQ=7\nRET")
    assert ends(recs) == [(1, 0, 0), (3, 7, 0)]
    assert [(d.rule, d.line) for d in diags] == [("NC223", 8), ("NC223", 9)]
    assert "PASSES" in diags[0].message and "AR" in diags[1].message
