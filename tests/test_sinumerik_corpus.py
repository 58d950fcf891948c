"""Sinumerik corpora: every real program parses without NC0xx; the conformance programs (one per
feature area, corpus/sinumerik) give the toolpath facts computed by hand in the comments below."""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from nctrans.dialects import base
from nctrans.dialects.sinumerik.frontend import parse
from nctrans.interp import interpret
from nctrans.ir import nodes as ir
from nctrans.source import read_source
from conftest import CORPUS

REPO = Path(__file__).resolve().parents[1]
OWN_DIR = REPO / "corpus" / "sinumerik"
REAL = sorted((CORPUS / "sinumerik").glob("*"))
OWN = sorted(OWN_DIR.glob("*"))


def syntax_diags(path: Path):
    src = read_source(path)
    res = parse(src.text, str(path))
    return res, [d for d in res.diagnostics if d.rule.startswith("NC0")]


@pytest.mark.parametrize("path", REAL, ids=lambda p: p.name)
def test_real_programs_parse_without_syntax_diagnostics(path):
    res, bad = syntax_diags(path)
    assert bad == [], [d.format_text() for d in bad]
    assert res.program.body or res.program.subprograms


def test_real_corpus_covers_encodings_and_file_kinds():
    assert len(REAL) >= 30
    texts = [read_source(p).text for p in REAL]
    assert any(any("\u4e00" <= ch <= "\u9fff" for ch in t) for t in texts)      # Chinese comments
    assert any(any(ch in "čćšžđČĆŠŽĐ" for ch in t) for t in texts)             # Serbian (CP1250 region)
    assert {p.suffix.upper() for p in REAL} >= {".MPF", ".SPF", ".DEF"}


@pytest.mark.parametrize("path", OWN, ids=lambda p: p.name)
def test_conformance_programs_parse_cleanly(path):
    _, bad = syntax_diags(path)
    assert bad == []


def test_one_conformance_program_per_feature_area():
    names = {p.stem for p in OWN}
    assert names >= {"lexical", "variables", "expressions", "control_flow", "calls", "motion_arcs",
                     "modes_units", "frames", "cycles", "protection_zone", "sync_actions", "iso_mode",
                     "macros"}


# --------------------------------------------------------------------------- toolpath facts

def run(name: str):
    res = parse(read_source(OWN_DIR / name).text, name)
    diags: list = []
    recs = list(interpret(res.program, diagnostics=diags))
    return recs, diags


def moves(recs):
    return [r for r in recs if r.kind in ("rapid", "linear", "arc")]


def ends(recs):
    return [tuple(round(r.end[a], 4) for a in ("X", "Y", "Z")) for r in moves(recs)]


def close(p, q, tol=1e-4):
    return all(math.isclose(p[a], q[a], abs_tol=tol) for a in q)


def test_motion_arcs_centres_and_helix():
    recs, diags = run("motion_arcs.mpf")
    arcs = [r for r in recs if r.kind == "arc"]
    # N50 CR=10 from (10,0) to (0,10) ccw -> centre (0,0); N60 I=AC(10) J=AC(10) -> (10,10);
    # N70 incremental I0 J-10 from (10,20) -> (10,10); N80 CIP through (22.93, 2.93) -> (30,10);
    # N90 AR=90 ccw from (30,0) to (40,10) -> (30,10); N110 helix about (55,10) with one extra turn.
    centres = [{"X": 0, "Y": 0}, {"X": 10, "Y": 10}, {"X": 10, "Y": 10}, {"X": 30, "Y": 10},
               {"X": 30, "Y": 10}, {"X": 55, "Y": 10}]
    assert len(arcs) == 6
    for arc, c in zip(arcs, centres):
        assert close(arc.center, c, 1e-5), (arc.line, arc.center, c)
    assert [a.direction for a in arcs] == ["ccw", "cw", "cw", "ccw", "ccw", "ccw"]
    assert arcs[-1].turns == 1 and close(arcs[-1].end, {"X": 50, "Y": 10, "Z": -2})
    assert ends(recs)[-1] == (50, 10, 50)
    assert not [d for d in diags if d.severity == "error"]


def test_modes_units_words_and_dwells():
    recs, _ = run("modes_units.mpf")
    e = ends(recs)
    assert e[1] == (15, 0, 2)            # G91 X5 from X10, Y=AC(0)
    assert e[2] == (20, 0, -1)           # X=IC(5), Z=AC(-1)
    assert e[3][0] == pytest.approx(25.4)   # G70 X1 -> 1 inch
    dwells = [r.dwell_s for r in recs if r.kind == "dwell"]
    assert dwells == [pytest.approx(1.5), pytest.approx(0.5)]    # G4 S10 at 1200 rpm
    feeds = {r.feed_mode for r in recs if r.kind == "linear"}
    assert feeds == {"per_min"}


def test_frames_move_the_workpiece_system():
    recs, _ = run("frames.mpf")
    e = [p[:2] for p in ends(recs)]
    # TRANS X10 Y5; AROT 90 + ATRANS X5 -> (10,10); ROT RPL=45 alone -> X10 at (7.07,7.07);
    # SCALE 2 -> (10,10); MIRROR X -> (-5,5); TRANS clears -> (5,5)
    assert e[1:7] == [(10, 5), (10, 10), (7.0711, 7.0711), (10, 10), (-5, 5), (5, 5)]


def test_control_flow_paths():
    recs, diags = run("control_flow.mpf")
    xs = [p[0] for p in ends(recs)]
    assert xs[1:4] == [10, 20, 30]                      # FOR I=1 TO 3
    assert (30, 20, 5) in ends(recs)                    # IF COUNT==2 branch, not Y99
    assert 222 in xs and 111 not in xs                  # CASE R1=2 -> TWO
    assert 333 not in xs and 444 not in xs              # LOOP left by GOTOF DONE, then FINISH
    assert not [d for d in diags if d.severity == "error"]


def test_calls_subprograms_repetition_and_modal_call():
    recs, _ = run("calls.mpf")
    e = ends(recs)
    assert e[1][0] == 3                                 # BORDER(3, WIDTH): G91 X=LEN
    assert [p[0] for p in e[3:5]] == [4, 5]             # L47 P2: X+1 twice
    assert e[5][0] == 20 and [p[2] for p in e[5:8]] == [0, 1, 2]   # MCALL L48 after G0 X20, CALL


def test_calls_var_parameter_is_by_reference():
    recs, _ = run("calls.mpf")
    assert ends(recs)[2][1] == 6                        # WIDTH=4, BORDER adds 2 through VAR WID


def test_expressions_evaluate_with_sinumerik_semantics():
    recs, _ = run("expressions.mpf")
    # SIN(30)+COS(60)=1; 7 DIV 2 + 7 MOD 2 = 4; POT(3)-SQRT(16)+ABS(-2) = 7;
    # 2.5EX1+'H10'+'B11' = 44; ATAN2(1,1)=45; TRUNC(-2.7)+ROUND(2.5) = 1; X999 is jumped over
    assert ends(recs) == [(1, 4, 7), (44, 45, 1)]


def test_variables_r_parameters():
    recs, _ = run("variables.mpf")
    assert ends(recs)[0] == (0, 20, 0)                  # R[2]=R1*2 with R1=10


def test_variables_arrays_set_rep():
    recs, _ = run("variables.mpf")
    # TABLE[0,1]=2 from SET(1,2,,4); FIELD[4]=0 after FIELD[2]=REP(0) over REP(9)
    assert ends(recs)[1] == (2, 20, 0)


def test_cycle81_strokes():
    recs, _ = run("cycles.mpf")
    at = [r for r in moves(recs) if close(r.end, {"X": 10, "Y": 10})]
    zs = [round(r.end["Z"], 4) for r in at]
    # rapid to RFP+SDIS = 2, feed to DP = -5, rapid back to RTP = 10
    assert zs[-3:] == [2, -5, 10]
    feed = [r for r in at if r.kind == "linear"]
    assert feed and feed[0].end["Z"] == -5
    deepest = min(r.end["Z"] for r in moves(recs))
    assert deepest == pytest.approx(-30)                # CYCLE83 to DP=-30
    dwell = [r for r in recs if r.kind == "dwell"]
    assert dwell and dwell[0].dwell_s == pytest.approx(0.5)   # CYCLE82 DTB


def test_hole_patterns_drill_at_pattern_positions():
    recs, _ = run("cycles.mpf")
    bottoms = {(round(r.end["X"], 3), round(r.end["Y"], 3)) for r in moves(recs)
               if r.kind == "linear" and math.isclose(r.end["Z"], -5)}
    assert bottoms >= {(10, 30), (20, 30), (70, 50), (50, 70), (30, 50), (50, 30)}


def test_lexical_program_positions():
    recs, _ = run("lexical.mpf")
    e = ends(recs)
    assert e[:3] == [(0, 0, 1), (10, 0, 1), (10, 10, 1)]
    assert e[-1] == (10, 0, 1)                          # X=R10/15, Y=-R11/255+1; X999 jumped over


def test_sync_actions_do_not_move():
    recs, _ = run("sync_actions.mpf")
    assert ends(recs) == [(0, 0, 0), (20, 20, 0)]


def test_protection_zone_contour_is_not_executed():
    recs, _ = run("protection_zone.mpf")
    assert ends(recs) == [(100, 100, 50)]
    res = parse(read_source(OWN_DIR / "protection_zone.mpf").text, "pz")
    zone = res.program.meta["protection_zones"][0]
    assert [(e.get("X"), e.get("Y")) for e in zone["contour"]] == [
        (0, -10), (40, None), (None, 10), (0, None), (None, -10)]


@pytest.mark.skipif(base.get("iso-m") is None, reason="iso-m front end not installed")
def test_iso_mode_section_runs_through_the_iso_front_end():
    recs, _ = run("iso_mode.mpf")
    assert ends(recs) == [(0, 0, 10), (10, 10, 10), (10, 10, -1), (10, 10, 10)]


def test_macros_expand_in_the_definition_file():
    res = parse(read_source(OWN_DIR / "macros.def").text, "macros.def")
    line = [b for b in res.program.body if isinstance(b, ir.Block) and any(
        isinstance(s, ir.Motion) for s in b.body)][0]
    m = [s for s in line.body if isinstance(s, ir.Motion)][0]
    assert m.target["Z"].value.value == -5 and ir.Feed(ir.Num(300.0, "300")) in line.body
