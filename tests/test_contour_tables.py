"""Contour tables CONTPRON / CONTDCON .. EXECUTE and EXECTAB (seed 14.2-14.5, L23169-23985;
nctrans.interp.contour_tables): the seed's own example tables reproduced exactly, small contours
computed by hand, and what is refused at its line."""
from __future__ import annotations

import math

import pytest

from hypothesis import given, settings, strategies as st

from nctrans.dialects.sinumerik.frontend import parse
from nctrans.interp.interpreter import Interpreter


def run(text: str):
    res = parse(text, "t.mpf")
    diags: list = list(res.diagnostics)
    it = Interpreter(res.program, diagnostics=diags)
    recs = list(it.run())
    return it, recs, diags


def table(it, name: str) -> list[list[float]]:
    arr = it.ev.scope.names.get(name) or it.ev.global_names.get(name)
    return [[float(arr.get((r, c))) for c in range(arr.dims[1])] for r in range(arr.dims[0])]


def var(it, name: str):
    return (it.ev.scope.names.get(name) if name in it.ev.scope.names else it.ev.global_names.get(name))


def rules(diags) -> list[str]:
    return [d.rule for d in diags if d.severity in ("error", "warning")]


def same(got: list[list[float]], want: list[list[float]]) -> None:
    for r, (g, w) in enumerate(zip(got, want)):
        assert all(math.isclose(a, b, abs_tol=1e-7) for a, b in zip(g, w)), (r, g, w)
    assert len(got) == len(want)


# ------------------------------------------------------------------ the seed's examples

SEED_1 = """N10 DEF REAL KTAB[30,11]
N20 DEF INT ANZHINT
N30 DEF INT ERROR
N40 G18
N50 CONTPRON (KTAB, "G", ANZHINT)
N60 G1 X150 Z20
N70 X110 Z30
N80 X50 RND=15
N90 Z70
N100 X40 Z85
N110 X30 Z90
N120 X0
N130 EXECUTE(ERROR)
M30
"""
# seed L23355-23365 (the tool at Z0 X0 when CONTPRON is called); rows 8.. are zeros
SEED_1_TABLE = [
    [7, 7, 11, 0, 0, 20, 150, 0, 82.40535663, 0, 0],
    [0, 2, 11, 20, 150, 30, 110, -1111, 104.0362435, 0, 0],
    [1, 3, 11, 30, 110, 30, 65, 0, 90, 0, 0],
    [2, 4, 13, 30, 65, 45, 50, 0, 180, 45, 65],
    [3, 5, 11, 45, 50, 70, 50, 0, 0, 0, 0],
    [4, 6, 11, 70, 50, 85, 40, 0, 146.3099325, 0, 0],
    [5, 7, 11, 85, 40, 90, 30, 0, 116.5650512, 0, 0],
    [6, 0, 11, 90, 30, 90, 0, 0, 90, 0, 0],
] + [[0] * 11] * 22


def test_contpron_seed_example_1():
    it, recs, diags = run(SEED_1)
    assert rules(diags) == []
    got = table(it, "KTAB")
    same([[round(v, 7) for v in row] for row in got], [[round(v, 7) for v in row] for row in SEED_1_TABLE])
    assert var(it, "ANZHINT") == 0 and var(it, "ERROR") == 0
    assert [r.kind for r in recs] == ["stop"]          # the contour's blocks move nothing


SEED_2 = """N10 DEF REAL KTAB[92,11]
N20 DEF CHAR BT="L"
N30 DEF INT HE=0
N40 DEF INT MODE=1
N50 DEF INT ERR=0
N100 G18 X100 Z100 F1000
N105 CONTPRON (KTAB, BT, HE, MODE)
N110 G1 G90 Z20 X20
N120 X45
N130 Z0
N140 G2 Z-15 X30 K=AC(-15) I=AC(45)
N150 G1 Z-30
N160 X80
N170 Z-40
N180 EXECUTE(ERR)
N190 G1 X0
M30
"""
# seed L23440-23460 (forwards and backwards); every other row is zeros
SEED_2_ROWS = {
    0: [6, 7, 11, 100, 100, 20, 20, 0, 45, 0, 0],
    1: [0, 2, 11, 20, 20, 20, 45, -3, 90, 0, 0],
    2: [1, 3, 11, 20, 45, 0, 45, 0, 0, 0, 0],
    3: [2, 4, 12, 0, 45, -15, 30, 5, 90, -15, 45],
    4: [3, 5, 11, -15, 30, -30, 30, 0, 0, 0, 0],
    5: [4, 7, 11, -30, 30, -30, 45, -1111, 90, 0, 0],
    6: [7, 0, 11, -30, 80, -40, 80, 0, 0, 0, 0],
    7: [5, 6, 11, -30, 45, -30, 80, 0, 90, 0, 0],
    8: [1, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0],
    83: [84, 0, 11, 20, 45, 20, 80, 0, 90, 0, 0],
    84: [90, 83, 11, 20, 20, 20, 45, -1111, 90, 0, 0],
    85: [0, 86, 11, -40, 80, -30, 80, 0, 0, 0, 0],
    86: [85, 87, 11, -30, 80, -30, 30, 88, 90, 0, 0],
    87: [86, 88, 11, -30, 30, -15, 30, 0, 0, 0, 0],
    88: [87, 89, 13, -15, 30, 0, 45, -90, 90, -15, 45],
    89: [88, 90, 11, 0, 45, 20, 45, 0, 0, 0, 0],
    90: [89, 84, 11, 20, 45, 20, 20, 84, 90, 0, 0],
    91: [83, 85, 11, 20, 20, 100, 100, 0, 45, 0, 0],
}


def test_contpron_seed_example_2_both_directions():
    it, recs, diags = run(SEED_2)
    assert rules(diags) == []
    same(table(it, "KTAB"), [SEED_2_ROWS.get(r, [0] * 11) for r in range(92)])
    assert var(it, "HE") == 1 and var(it, "ERR") == 0          # NN: relief cuts forwards [NC]
    # the tool stayed at X100 Z100: the G1 after EXECUTE starts there
    moves = [r for r in recs if r.kind == "linear"]
    assert moves[-1].start == {"X": 100.0, "Y": 0.0, "Z": 100.0}
    assert moves[-1].end["X"] == 0.0


SEED_3 = """N10 DEF REAL KTAB[9,6]
N20 DEF INT MODE = 0
N30 DEF INT ERROR = 0
N100 G18 G64 G90 G94 G710
N101 G1 Z100 X100 F1000
N105 CONTDCON (KTAB, MODE)
N110 G1 Z20 X20 F200
N120 G9 X45 F300
N130 Z0 F400
N140 G2 Z-15 X30 K=AC(-15) I=AC(45)F100
N150 G1 G64 Z-30 F600
N160 X80 F700
N170 Z-40 F800
N180 EXECUTE(ERROR)
M30
"""
# seed L23660-23672. The seed's N150 has no G1 (G2 would stay in force); its table codes G1.
SEED_3_TABLE = [
    [30, 100, 100, 0, 0, 7],
    [11031, 20, 20, 0, 0, 200],
    [111031, 20, 45, 0, 0, 300],
    [11031, 0, 45, 0, 0, 400],
    [11032, -15, 30, -15, 45, 100],
    [11031, -30, 30, 0, 0, 600],
    [11031, -30, 80, 0, 0, 700],
    [11031, -40, 80, 0, 0, 800],
    [0, 0, 0, 0, 0, 0],
]


def test_contdcon_seed_example():
    it, recs, diags = run(SEED_3)
    assert rules(diags) == []
    same(table(it, "KTAB"), SEED_3_TABLE)
    assert var(it, "ERROR") == 0


# ------------------------------------------------------------------ small contours by hand

def test_contpron_line_arc_hand_computed():
    # G17 (abscissa X, ordinate Y), "L": from (0,0) G1 to (10,0), G3 to (20,10) about (10,10),
    # G1 to (20,30). Row 0 the first line: angle 0. Row 1 the arc: its tangent turns from 0 to
    # 90 degrees (ccw, start radius (0,-10) -> tangent (10,0)): largest value 90.
    # Row 2 the line up: 90. The ordinate rises all the way: no relief, no marker, NN 0.
    # The end Y30 is the contour's highest level: no extension.
    it, _, diags = run("DEF REAL TB[6,11]\nDEF INT NN=7, ER=5\nG17 G0 X0 Y0\nCONTPRON(TB, \"L\", NN, 0)\n"
                       "G1 X10\nG3 X20 Y10 I0 J10\nG1 Y30\nEXECUTE(ER)\nM30\n")
    assert rules(diags) == []
    same(table(it, "TB")[:4], [
        [2, 2, 11, 0, 0, 10, 0, 0, 0, 0, 0],
        [0, 2, 13, 10, 0, 20, 10, 0, 90, 10, 10],
        [1, 0, 11, 20, 10, 20, 30, 0, 90, 0, 0],
        [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
    ])
    assert var(it, "NN") == 0 and var(it, "ER") == 0


def test_contpron_relief_split_hand_computed():
    # G18 "L" (level X), start Z0 X50. Row 0: G1 Z-5 (flat); row 1: Z-10 X40 (falls from 50: a
    # relief starts, counted); row 2: Z-20 (flat); row 3: X20 (falls, the relief still open);
    # row 4: Z-30 X60 rises 20 -> 60, above the relief's start level 50: split at X50,
    # t = (50-20)/(60-20) = 0.75 -> Z = -20 + 0.75 * -10 = -27.5. Row 4 keeps (-20,20)->(-27.5,50)
    # (relief end, no further relief: -1111); the rest (-27.5,50)->(-30,60) goes to row 5.
    # Markers: row 1 -> 4. The end X60 is the highest level: no extension. Row 6: NN 1, 0.
    # Angles: row 1 atan2(-10,-5) = -116.565 -> 63.435; rows 4/5 atan2(30,-7.5) = 104.036.
    it, _, diags = run("DEF REAL TB[9,11]\nDEF INT NN, ER\nG18 G0 X50 Z0\nCONTPRON(TB, \"L\", NN)\n"
                       "G1 Z-5\nZ-10 X40\nZ-20\nX20\nZ-30 X60\nEXECUTE(ER)\nM30\n")
    assert rules(diags) == []
    a = math.degrees(math.atan2(30, -7.5))
    same(table(it, "TB")[:8], [
        [5, 5, 11, 0, 50, -5, 50, 0, 0, 0, 0],
        [0, 2, 11, -5, 50, -10, 40, 4, 180 + math.degrees(math.atan2(-10, -5)), 0, 0],
        [1, 3, 11, -10, 40, -20, 40, 0, 0, 0, 0],
        [2, 4, 11, -20, 40, -20, 20, 0, 90, 0, 0],
        [3, 5, 11, -20, 20, -27.5, 50, -1111, a, 0, 0],
        [4, 0, 11, -27.5, 50, -30, 60, 0, a, 0, 0],
        [1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
        [0] * 11,
    ])
    assert var(it, "NN") == 1 and var(it, "ER") == 0


def test_contpron_relief_from_the_call_point_is_not_split():
    # [NC] start Z0 X50, row 0 G1 Z-10 X40 falls from the call point's level 50; row 1 Z-20 X60
    # rises above 50: the end of that relief (marker -1111) but no split (row 0 is the way from
    # where the tool stood), no count; X60 the highest level: no extension. Rows 0-1, row 2 the
    # counts 0, 0.
    it, _, diags = run("DEF REAL TB[5,11]\nDEF INT NN, ER\nG18 G0 X50 Z0\nCONTPRON(TB, \"L\", NN)\n"
                       "G1 Z-10 X40\nZ-20 X60\nEXECUTE(ER)\nM30\n")
    assert rules(diags) == []
    t = table(it, "TB")
    assert [row[:2] + row[5:8] for row in t[:3]] == [[1, 1, -10, 40, 0], [0, 0, -20, 60, -1111],
                                                      [0, 0, 0, 0, 0]]
    assert var(it, "NN") == 0


def test_contpron_extension_to_the_extreme_level():
    # "L", written from the top down: start Z0 X60, row 0 G1 Z-10 X60 (flat), row 1 Z-20 X40
    # (falls: relief from 60, counted), row 2 Z-30 (flat). The end X40 is not the highest level
    # (60): extended along X to X60 as row 3 (-30,40)->(-30,60), which rises to 60 = the relief's
    # start level: its end (-1111), no split. Row 1 marks row 3. NN 1; row 4 the counts.
    it, _, diags = run("DEF REAL TB[6,11]\nDEF INT NN, ER\nG18 G0 X60 Z0\nCONTPRON(TB, \"L\", NN)\n"
                       "G1 Z-10\nZ-20 X40\nZ-30\nEXECUTE(ER)\nM30\n")
    assert rules(diags) == []
    t = table(it, "TB")
    assert t[3] == [2, 0, 11, -30, 40, -30, 60, -1111, 90, 0, 0]
    assert t[1][7] == 3 and t[0][:2] == [3, 3] and t[4][:2] == [1, 0] and var(it, "NN") == 1


def test_contpron_counts_a_relief_after_the_start():
    # "L", start Z0 X30: row 0 to Z-5 X30 (flat), row 1 Z-10 X20 (falls from 30: relief 1 starts,
    # counted), row 2 Z-15 (flat), row 3 Z-20 X30 (rises back to 30: its end, no split).
    # Markers: row 1 -> 3, row 3 -> -1111. NN 1; rows 0-3 used, so row 4 holds the counts 1, 0.
    it, _, diags = run("DEF REAL TB[6,11]\nDEF INT NN, ER\nG18 G0 X30 Z0\nCONTPRON(TB, \"L\", NN)\n"
                       "G1 Z-5\nZ-10 X20\nZ-15\nZ-20 X30\nEXECUTE(ER)\nM30\n")
    assert rules(diags) == []
    t = table(it, "TB")
    assert [row[7] for row in t[:4]] == [0, 3, 0, -1111]
    assert t[4][:2] == [1, 0] and var(it, "NN") == 1


def test_contdcon_inch_incremental_and_diameter():
    # G700 (unit code 2), G91 (hundreds 1), G95 (thousands 2), G60 default (0); DIAMON: the table
    # holds X as programmed (a diameter [NC]): G91 X2 from X10 (diameter) ends at X12.
    # Row 0: 10*2 = 20, start (Z0, X10), last row 2. Row 1: 1 + 20 + 100 + 2000 = 2121, end
    # (Z-1, X12), feed F0.2 (as programmed). Row 2: G0 (0) + 20 + 100 + 2000 = 2120, Z-1 -> Z-2.
    it, _, diags = run("DEF REAL TB[4,6]\nDEF INT ER\nG18 DIAMON G700 G95 G0 X10 Z0\nCONTDCON(TB)\n"
                       "G91 G1 X2 Z-1 F0.2\nG0 Z-1\nEXECUTE(ER)\nM30\n")
    assert rules(diags) == []
    same(table(it, "TB"), [[20, 0, 10, 0, 0, 2], [2121, -1, 12, 0, 0, 0.2], [2120, -2, 12, 0, 0, 0.2],
                          [0] * 6])


def test_exectab_runs_rows_as_blocks():
    # rows 1, 2 and 3 of seed example 2's table (forwards), from X100 Z100: row 1 ends at (Z20, X45),
    # row 2 at (Z0, X45), row 3 is the G2 arc to (Z-15, X30) about (Z-15, X45)
    it, recs, diags = run(SEED_2.replace("N190 G1 X0\n", "N190 EXECTAB(KTAB[1])\nN200 EXECTAB(KTAB[2])\n"
                                         "N210 EXECTAB(KTAB[3])\n"))
    assert rules(diags) == []
    moves = [r for r in recs if r.kind in ("linear", "arc")]
    assert [(m.kind, m.end["Z"], m.end["X"]) for m in moves[-3:]] == [
        ("linear", 20.0, 45.0), ("linear", 0.0, 45.0), ("arc", -15.0, 30.0)]
    arc = moves[-1]
    assert arc.direction == "cw" and (arc.center["Z"], arc.center["X"]) == (-15.0, 45.0)


def test_exectab_arc_away_from_its_start_alarms():
    # row 3's arc (radius 15 about (-15,45)) run from (Z20, X45), 35 from its centre: NC203, no move
    it, recs, diags = run(SEED_2.replace("N190 G1 X0\n", "N190 EXECTAB(KTAB[1])\nN200 EXECTAB(KTAB[3])\n"))
    assert [(d.rule, d.line) for d in diags if d.severity != "info"] == [("NC203", 17)]
    assert [r.kind for r in recs if r.kind == "arc"] == []


# ------------------------------------------------------------------ refused at the line

@pytest.mark.parametrize("text, line", [
    ("DEF REAL TB[2,11]\nDEF INT NN, ER\nG18 G0 X0 Z0\nCONTPRON(TB, \"L\", NN)\nG1 X1\nX2\nX3\nEXECUTE(ER)\n", 8),
    ("DEF REAL TB[9,10]\nDEF INT NN, ER\nG18 G0 X0 Z0\nCONTPRON(TB, \"L\", NN)\nG1 X1\nEXECUTE(ER)\n", 4),
    ("DEF REAL TB[9,11]\nDEF INT NN, ER\nG18 G0 X0 Z0\nCONTPRON(TB, \"Q\", NN)\nG1 X1\nEXECUTE(ER)\n", 4),
    ("DEF REAL TB[9,11]\nDEF INT NN, ER\nG18 G0 X0 Z0\nCONTPRON(TB, \"L\", NN, 2)\nG1 X1\nEXECUTE(ER)\n", 4),
    ("DEF REAL TB[9,6]\nDEF INT ER\nG18 G0 X0 Z0\nCONTDCON(TB, 1)\nG1 X1\nEXECUTE(ER)\n", 4),
    ("DEF REAL TB[9,6]\nDEF INT ER\nG18 G0 X0 Z0\nCONTDCON(TB)\nG33 Z-10 K1\nEXECUTE(ER)\n", 5),
    ("DEF REAL TB[9,6]\nDEF INT ER\nG18 G0 X0 Z0\nCONTDCON(TB)\nG1 X1 Y5\nEXECUTE(ER)\n", 5),
    ("DEF REAL TB[9,6]\nDEF INT ER\nG18 G0 X0 Z0\nCONTDCON(TB)\nG1 X1\nG70 Z-1\nEXECUTE(ER)\n", 6),
    ("DEF REAL TB[9,6]\nDEF INT ER\nG18 G0 X0 Z0\nCONTDCON(TB)\nEXECUTE(ER)\n", 5),
    ("DEF INT ER\nEXECUTE(ER)\n", 2),
])
def test_refused_contours_say_nc242_and_err_1(text, line):
    it, recs, diags = run(text + "M30\n")
    bad = [d for d in diags if d.rule == "NC242"]
    assert bad and bad[0].line == line, diags
    if "TB[" in text and "EXECUTE(ER)" in text and "CONTD" in text or "CONTP" in text:
        assert var(it, "ER") == 1
    assert not [r for r in recs if r.kind in ("linear", "arc")]


def test_arc_turning_inside_is_nc243_not_silent():
    # G3 from Z0 X20 to Z-20 X20, radius 10 about Z-10 X20: X rises to 30 inside the arc
    it, _, diags = run("DEF REAL TB[10,11]\nDEF INT NN, ER\nG18 G0 X0 Z10\nCONTPRON(TB, \"L\", NN)\n"
                       "G1 X20 Z0\nG3 X20 Z-20 CR=10\nG1 X40\nEXECUTE(ER)\nM30\n")
    assert [(d.rule, d.line) for d in diags] == [("NC243", 6)]
    assert var(it, "ER") == 0


def test_no_execute_before_the_end_is_said_at_the_call():
    # the table is never ended: its blocks moved nothing, which must not pass silently
    it, recs, diags = run("DEF REAL TB[9,11]\nDEF INT NN\nG18 G0 X50 Z0\nCONTPRON(TB, \"L\", NN)\n"
                          "G1 Z-5 F100\nZ-10 X40\nM30\n")
    assert [(d.rule, d.line) for d in diags if d.severity != "info"] == [("NC242", 4)]
    assert [r.kind for r in recs if r.kind in ("linear", "arc")] == []


def test_a_cycle_among_the_table_blocks_is_refused():
    it, recs, diags = run("DEF REAL TB[9,6]\nDEF INT ER\nG17 G0 X0 Y0 Z5\nCONTDCON(TB)\nG1 X10 F100\n"
                          "CYCLE81(10, 0, 2, -5)\nY10\nEXECUTE(ER)\nM30\n")
    assert [(d.rule, d.line) for d in diags if d.severity != "info"] == [("NC242", 6)]
    assert var(it, "ER") == 1
    assert [r.kind for r in recs if r.kind in ("linear", "arc")] == []


def test_intersec_of_seed_example_2_rows():
    # rows of seed example 2 (forwards): row 2 the line (20,45) -> (0,45), row 3 the G2 arc
    # (0,45) -> (-15,30) about (-15,45): they meet at (0,45), the line's end (t = 1 along row 2).
    # Row 1 (20,20) -> (20,45) and row 6 (-30,80) -> (-40,80) do not meet: FALSE, CUT unchanged.
    # Row 4 (-15,30) -> (-30,30) against row 86 backwards (-30,80) -> (-30,30): (-30,30).
    text = SEED_2.replace("N50 DEF INT ERR=0\n", "N50 DEF INT ERR=0\nN51 DEF REAL CUT[2]\n"
                          "N52 DEF BOOL HITA, HITB, HITC\n")
    text = text.replace("N190 G1 X0\n", "N192 HITA=INTERSEC(KTAB[2],KTAB[3],CUT) R1=CUT[0] R2=CUT[1]\n"
                        "N193 HITB=INTERSEC(KTAB[1],KTAB[6],CUT)\n"
                        "N194 HITC=INTERSEC(KTAB[4],KTAB[86],CUT) R3=CUT[0] R4=CUT[1]\n")
    it, _, diags = run(text)
    assert rules(diags) == []
    assert var(it, "HITA") and not var(it, "HITB") and var(it, "HITC")
    assert [it.ev.R.get(k) for k in (1, 2, 3, 4)] == [0.0, 45.0, -30.0, 30.0]


def test_intersec_line_through_an_arc_hand_computed():
    # G17: TA row 1 a quarter circle about (10,10), radius 10, from (20,10) to (10,20) (G3); TC row 1
    # the line (10,0) -> (20,20): x = 10 + 10t, y = 20t; on the circle (10t)^2 + (20t-10)^2 = 100
    # -> 500t^2 - 400t = 0 -> t = 0.8: (18, 16), inside the quarter (angle atan2(6,8) = 36.9 deg)
    it, _, diags = run("DEF REAL TA[4,11]\nDEF REAL TC[4,11]\nDEF REAL CUT[2]\nDEF BOOL HIT\n"
                       "DEF INT NN, ER\nG17 G0 X20 Y0\nCONTPRON(TA, \"L\", NN)\nG1 Y10\n"
                       "G3 X10 Y20 I-10 J0\nEXECUTE(ER)\nG0 X0 Y0\nCONTPRON(TC, \"L\", NN)\nG1 X10 Y0\n"
                       "X20 Y20\nEXECUTE(ER)\nHIT=INTERSEC(TA[1],TC[1],CUT) R1=CUT[0] R2=CUT[1]\nM30\n")
    assert rules(diags) == []
    assert var(it, "HIT") and it.ev.R.get(1) == pytest.approx(18) and it.ev.R.get(2) == pytest.approx(16)


def test_transverse_angle_and_g91_code_hand_computed():
    # "P" (face, external): col 8 measured from the ordinate [NC]: the line (Z0,X30) -> (Z-10,X40)
    # has (d_abs, d_ord) = (-10, 10): atan2(-10, 10) = -45 -> 135. G91 (a digit 1): code 111.
    # The level for "P" is Z: the first element falls from Z0 to Z-10 (a relief from row 0, no
    # count); row 1 Z-10 -> Z-10 (X50, flat); the end Z-10 is not Z0, the contour's highest
    # level excluding the call point (Z0 is row 0's start): extreme Z -10 -> no extension. Row 1
    # runs along the ordinate X: 0 degrees to it.
    it, _, diags = run("DEF REAL TB[5,11]\nDEF INT NN, ER\nG18 G0 X30 Z0\nCONTPRON(TB, \"P\", NN)\n"
                       "G91 G1 Z-10 X10\nX10\nEXECUTE(ER)\nM30\n")
    assert rules(diags) == []
    t = table(it, "TB")
    assert t[0][2] == 111 and t[0][8] == pytest.approx(135.0)
    assert t[1][2] == 111 and t[1][3:7] == [-10, 40, -10, 50] and t[1][8] == 0.0   # along X
    assert t[2][:2] == [0, 0]


def test_one_block_cannot_be_prepared_in_both_directions():
    it, _, diags = run("DEF REAL TB[5,11]\nDEF INT NN, ER\nG18 G0 X30 Z0\nCONTPRON(TB, \"L\", NN, 1)\n"
                       "G1 Z-10\nEXECUTE(ER)\nM30\n")
    assert [(d.rule, d.line) for d in diags if d.severity != "info"] == [("NC242", 6)] and var(it, "ER") == 1


@st.composite
def contours(draw):
    """Contours of lines and arcs (CR with the sign chosen, G2/G3), any MACH, MODE 0/1."""
    lines, x, z = [], 30.0, 0.0
    for _ in range(draw(st.integers(1, 6))):
        dx, dz = draw(st.sampled_from([-10, -5, 0, 5, 10])), draw(st.sampled_from([-10, -5, 0, 5]))
        if dx == dz == 0:
            dz = -5
        x, z = x + dx, z + dz
        if draw(st.booleans()) and (dx or dz):
            cr = math.hypot(dx, dz) / 2 * draw(st.sampled_from([1, 1.5, -1.5]))
            lines.append(f"{draw(st.sampled_from(['G2', 'G3']))} X{x:g} Z{z:g} CR={cr:g}")
        else:
            lines.append(f"G1 X{x:g} Z{z:g}")
    mach = draw(st.sampled_from("GLNP"))
    return mach, draw(st.integers(0, 1)), lines


@settings(max_examples=60, deadline=None)
@given(contours())
def test_any_contour_gives_a_continuous_chain_or_a_located_refusal(c):
    # the forward chain runs from row 0's end through the "next" pointers, each row starting
    # where the one before ends, to the contour's last point or (extension) along the level axis;
    # backwards likewise from the last row's "contour start" pointer; never an exception
    mach, mode, lines = c
    text = (f"DEF REAL TB[60,11]\nDEF INT NN, ER\nG18 G0 X30 Z0\nCONTPRON(TB, \"{mach}\", NN, {mode})\n"
            + "\n".join(lines) + "\nEXECUTE(ER)\nM30\n")
    it, _, diags = run(text)
    assert all(d.rule in ("NC242", "NC243", "NC203") for d in diags if d.severity != "info"), diags
    if var(it, "ER") == 1 or any(d.rule == "NC203" for d in diags):
        return
    t = table(it, "TB")

    def walk(first: int, start: tuple) -> tuple:
        at, row, seen = start, first, 0
        while row:
            assert t[row][3:5] == pytest.approx(list(at), abs=1e-6)
            at, row, seen = tuple(t[row][5:7]), int(t[row][1]), seen + 1
            assert seen < 60
        return at
    end = walk(1, tuple(t[0][5:7])) if int(t[0][0]) != 0 else tuple(t[0][5:7])
    assert int(t[0][1]) + 1 < 60 and t[int(t[0][1]) + 1][0] == var(it, "NN")
    if mode == 1:
        walk(int(t[59][1]), tuple(t[int(t[59][1])][3:5]))
    assert end is not None


def test_a_dwell_or_spindle_word_among_the_table_blocks_is_refused_not_recorded():
    it, recs, diags = run("DEF REAL TB[9,6]\nDEF INT ER\nG17 G0 X0 Y0 Z5\nCONTDCON(TB)\nG1 X10 F100\n"
                          "G4 F2\nY10\nEXECUTE(ER)\nM30\n")
    assert [(d.rule, d.line) for d in diags if d.severity != "info"] == [("NC242", 6)]
    assert var(it, "ER") == 1 and [r.kind for r in recs if r.kind == "dwell"] == []


def test_diamon_table_holds_diameters_and_true_angles():
    # DIAMON, from X20 (radius 10) Z1: row 0 G1 Z0; row 1 X40 Z-10 (radius 10 -> 20 over 10 in Z):
    # held as X20 -> X40 as programmed [NC], its angle the true one, atan2(+10, -10) = 135 degrees
    # (not atan2(20, -10) = 116.57 of the diameters). Row 2 G2 X60 Z-20 CR=10 from (Z-10, r20) to
    # (Z-20, r30): the minor arc's centre is (Z-10, r30), held as X60; its direction turns from
    # 180 (along -Z) clockwise to 90 (+X): inside values (90, 180) -> largest 180.
    it, _, diags = run("DEF REAL TB[6,11]\nDEF INT NN, ER\nG18 DIAMON G0 X20 Z1\nCONTPRON(TB, \"L\", NN)\n"
                       "G1 Z0\nX40 Z-10\nG2 X60 Z-20 CR=10\nEXECUTE(ER)\nM30\n")
    assert rules(diags) == []
    t = table(it, "TB")
    assert t[1][3:7] == [0, 20, -10, 40] and t[1][8] == pytest.approx(135.0)
    assert t[2][3:7] == [-10, 40, -20, 60] and t[2][9:11] == [-10, 60] and t[2][8] == pytest.approx(180.0)


def test_intersec_under_diamon_works_in_radius():
    # the DIAMON table above: row 1 X20 -> X40 (Z0 -> Z-10; radius 10 -> 20) and a second table's
    # line at radius 15 along Z (X30 from Z5 to Z-15): they meet at Z-5, radius 15, held as X30.
    # Row 2's arc (centre Z-10 r30, radius 10) against the line at radius 25 (X50) from Z0 to Z-30:
    # (Z+10)^2 + (25-30)^2 = 100 -> Z = -10 -/+ 8.660: on the arc (Z -10 .. -20) Z = -18.660; X50.
    it, _, diags = run("DEF REAL TB[6,11]\nDEF REAL TL[6,11]\nDEF REAL TM[6,11]\nDEF REAL CUT[2]\n"
                       "DEF BOOL HITA, HITB\nDEF INT NN, ER\nG18 DIAMON G0 X20 Z1\n"
                       "CONTPRON(TB, \"L\", NN)\nG1 Z0\nX40 Z-10\nG2 X60 Z-20 CR=10\nEXECUTE(ER)\n"
                       "G0 X30 Z10\nCONTPRON(TL, \"L\", NN)\nG1 Z5\nZ-15\nEXECUTE(ER)\n"
                       "G0 X50 Z10\nCONTPRON(TM, \"L\", NN)\nG1 Z0\nZ-30\nEXECUTE(ER)\n"
                       "HITA=INTERSEC(TB[1],TL[1],CUT) R1=CUT[0] R2=CUT[1]\n"
                       "HITB=INTERSEC(TB[2],TM[1],CUT) R3=CUT[0] R4=CUT[1]\nM30\n")
    assert rules(diags) == []
    assert var(it, "HITA") and var(it, "HITB")
    assert [it.ev.R.get(k) for k in (1, 2, 3, 4)] == pytest.approx([-5, 30, -10 - math.sqrt(75), 50])


# ------------------------------------------------------------- the session ends cleanly (review)

def test_a_frame_set_among_the_table_blocks_is_refused_and_undone():
    """TRANS X100 between CONTPRON and EXECUTE (forbidden, seed L23311): the frame is edited in
    place, so the old identity test never saw it; lint was clean and the move after EXECUTE went
    to X101. Now NC242 at EXECUTE and the call's frame again: G0 X1 Z1 ends at X1 Z1."""
    it, recs, diags = run('DEF REAL TABC[12,11]\nDEF INT NN, ER\nG18 G0 X0 Z0 F100\n'
                          'CONTPRON(TABC,"L",NN)\nTRANS X100\nG1 X10 Z-5\nEXECUTE(ER)\n'
                          'G0 X1 Z1\nM30\n')
    assert [(d.rule, d.line) for d in diags if d.severity == "error"] == [("NC242", 7)]
    moves = [r for r in recs if r.kind in ("rapid", "linear", "arc")]
    assert moves[-1].end["X"] == pytest.approx(1.0) and moves[-1].end["Z"] == pytest.approx(1.0)
    assert var(it, "ER") == 1


def test_a_bad_err_argument_still_ends_the_session():
    """EXECUTE(UNDEFX): the name was resolved before the session closed, so the error left it
    capturing and every later block moved nothing. Now NC101 at EXECUTE and the move after runs."""
    it, recs, diags = run('DEF REAL TABC[12,11]\nDEF INT NN\nG18 G0 X0 Z0 F100\n'
                          'CONTPRON(TABC,"L",NN)\nG1 X10 Z-5\nEXECUTE(UNDEFX)\nG1 X4 Z-8\nM30\n')
    assert ("NC101", 6) in [(d.rule, d.line) for d in diags]
    ends = [(r.end["X"], r.end["Z"]) for r in recs if r.kind == "linear"]
    assert ends == [(4.0, -8.0)]                    # the table's G1 moved nothing, line 7 moves


def test_a_subprogram_that_returns_without_execute_gives_the_caller_its_moves_back(tmp_path):
    """CONTPRON in a PROC that returns with no EXECUTE: the caller's blocks were captured and
    vanished (one record). Now NC242 at the CONTPRON line; the caller's G1 X50 Y50 and G0 X0 Y0
    run, from where the PROC's call left the tool (its G1 X10 Y5 only described a contour)."""
    from nctrans import pipeline
    (tmp_path / "SUBT.SPF").write_text('PROC SUBT\nDEF REAL TABC[8,11]\nDEF INT NN\n'
                                       'CONTPRON(TABC,"L",NN)\nG1 X10 Y5\nM17\n')
    main = tmp_path / "MAIN.MPF"
    main.write_text("G17 G0 X0 Y0 F100\nSUBT\nG1 X50 Y50\nG0 X0 Y0\nM30\n")
    ld = pipeline.load(str(main), "sinumerik")
    recs = list(pipeline.toolpath_of(ld))
    found = [(d.rule, d.file.endswith("SUBT.SPF"), d.line) for d in ld.diagnostics
             if d.severity == "error"]
    assert found == [("NC242", True, 4)]
    ends = [(r.kind, r.end["X"], r.end["Y"]) for r in recs if r.kind in ("rapid", "linear")]
    # line 1's rapid, then the caller's two moves after the return
    assert ends == [("rapid", 0.0, 0.0), ("linear", 50.0, 50.0), ("rapid", 0.0, 0.0)]


def test_values_where_the_calls_write_their_results_are_said():
    """NN and ERR receive the call's results (seed L23242, L23247): `CONTPRON(T,"L",3)` refused
    the table with no word before, and `EXECUTE(3)` dropped the status silently."""
    head = 'DEF REAL TABC[12,11]\nDEF INT NN\nG18 G0 X0 Z0 F100\n'
    _, _, diags = run(head + 'CONTPRON(TABC,"L",3)\nG1 X10 Z-5\nEXECUTE(NN)\nM30\n')
    # said at the CONTPRON line (4), as the other refusals of the call are
    assert [(d.rule, d.line) for d in diags if d.severity == "error"] == [("NC242", 4)]
    assert "NN must be a variable" in " ".join(d.message for d in diags)
    _, _, diags = run(head + 'CONTPRON(TABC,"L",NN)\nG1 X10 Z-5\nEXECUTE(3)\nM30\n')
    assert [(d.rule, d.line) for d in diags if d.severity == "error"] == [("NC242", 6)]
    _, _, diags = run(head + 'CONTPRON(TABC,"L",NN)\nG1 X10 Z-5\nEXECUTE(NN)\nM30\n')
    assert [d for d in diags if d.severity == "error"] == []
