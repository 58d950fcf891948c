"""ISO turning (iso-t): hand-computed passes of the turning cycles (corpus/iso-t), the shared lathe
corpus, bad input, and conversion to Sinumerik and to a flat iso-m program that rs274 runs.

Expected moves are worked out by hand from the cycle definitions in nctrans/interp/lathe.py and
the numbers in each program's header comment; coordinates are radii (the toolpath convention)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from conftest import CORPUS
from nctrans.dialects.base import get
from nctrans.interp.interpreter import interpret
from nctrans.machine import default_lathe

REPO = Path(__file__).resolve().parent.parent
CONF = REPO / "corpus" / "iso-t"
TURN = CORPUS / "iso-turn"


def run(path: Path, text: str | None = None):
    text = path.read_text(encoding="utf-8") if text is None else text
    res = get("iso-t").parse(text, str(path))
    diags = list(res.diagnostics)
    recs = list(interpret(res.program, default_lathe(), diagnostics=diags))
    return recs, diags


def moves(recs, line=None):
    """(kind, X, Z) of the rapid/linear records (of one source line)."""
    return [(r.kind, round(r.end["X"], 6), round(r.end["Z"], 6)) for r in recs
            if r.kind in ("rapid", "linear") and (line is None or r.line == line)]


def level(x, z_stop, retract, z0):
    """One G71 level: across to x, cut to z_stop, 45-degree retract, back to z0."""
    return [("rapid", x, z0), ("linear", x, z_stop), ("rapid", x + retract, z_stop + retract),
            ("rapid", x + retract, z0)]


def test_g71_type1_levels_allowance_and_final_pass_then_g70():
    recs, diags = run(CONF / "g71-g70-type1.nc")
    assert not [d for d in diags if d.severity == "error"], diags
    # start (20, 2); depth 2; retract 0.5; allowance 0.2 in X (U0.4 diameter), 0.1 in Z.
    # shifted contour: (10.2, 2.1) -> (10.2, -9.9) -> (15.2, -19.9) -> (20.2, -19.9)
    # level 18/16 meet the last segment at Z-19.9; level 14 meets the taper at
    # Z = -9.9 - 10*(14-10.2)/5 = -17.5; level 12 at -9.9 - 10*(1.8/5) = -13.5; level 10 < 10.2: none
    want = (level(18.0, -19.9, 0.5, 2.0) + level(16.0, -19.9, 0.5, 2.0) + level(14.0, -17.5, 0.5, 2.0)
            + level(12.0, -13.5, 0.5, 2.0)
            + [("rapid", 10.2, 2.1), ("linear", 10.2, -9.9), ("linear", 15.2, -19.9),
               ("linear", 20.2, -19.9), ("rapid", 20.0, -19.9), ("rapid", 20.0, 2.0)])
    assert moves(recs, 10) == want
    # the contour blocks do not run again after G71; G70 runs them as programmed, then returns
    assert moves(recs, 11) == [("rapid", 10.0, 2.0)]
    assert [r.feed for r in recs if r.line in (12, 13, 14)] == [0.1, 0.1, 0.1]
    assert moves(recs, 15) == [("rapid", 20.0, 2.0)]
    assert all(r.feed == 0.25 for r in recs if r.line == 10 and r.kind == "linear")


def test_g90_g94_g92_box_passes_with_modal_repeat_and_css():
    recs, _ = run(CONF / "g90-g94-g92.nc")

    def box(x, z, x0=25.0, z0=2.0):
        return [("rapid", x, z0), ("linear", x, z), ("linear", x0, z), ("rapid", x0, z0)]
    assert moves(recs, 8) == box(20.0, -30.0)
    assert moves(recs, 9) == box(18.0, -30.0)          # X36. repeats G90 with Z-30.
    assert moves(recs, 10) == box(16.0, -30.0)
    # G94 facing: down Z, across to X, back along Z, rapid out in X
    assert moves(recs, 12) == [("rapid", 25.0, -2.0), ("linear", 5.0, -2.0), ("linear", 5.0, 2.0),
                               ("rapid", 25.0, 2.0)]
    assert moves(recs, 13)[1] == ("linear", 5.0, -4.0)
    # G92: thread pass at lead 1.5 per revolution
    assert moves(recs, 17) == [("rapid", 14.6, 5.0), ("linear", 14.6, -20.0), ("rapid", 20.0, -20.0),
                               ("rapid", 20.0, 5.0)]
    thread = [r for r in recs if r.line == 17 and r.kind == "linear"][0]
    assert (thread.feed, thread.feed_mode) == (1.5, "per_rev")
    # CSS S200 m/min: at radius 25 mm 200000/(2*pi*25) = 1273.2395 rpm; at radius 5 it would be
    # 6366 rpm, clamped by G50 S2000
    first = [r for r in recs if r.kind == "rapid" and r.line == 7][0]
    assert first.spindle == pytest.approx(1273.239545)
    faced = [r for r in recs if r.line == 12 and r.kind == "linear"][0]
    assert faced.spindle == 2000.0


def test_haas_g75_g74_pecks_and_g76_infeed_depths():
    recs, _ = run(CONF / "g75-g74-g76-haas.nc")
    # G75 from (15, -10) to X10 Z-14: pecks of 2 with 0.5 back-off, columns -10, -13, -14
    col = [("linear", 13.0, None), ("rapid", 13.5, None), ("linear", 11.0, None),
           ("rapid", 11.5, None), ("linear", 10.0, None), ("rapid", 15.0, None)]
    want = []
    for i, z in enumerate((-10.0, -13.0, -14.0)):
        if i:
            want.append(("rapid", 15.0, z))
        want += [(k, x, z) for k, x, _ in col]
    want.append(("rapid", 15.0, -10.0))
    assert moves(recs, 7) == want
    # G74 from Z5 to Z-6 in pecks of 2.5
    assert moves(recs, 9) == [("linear", 0.0, 2.5), ("rapid", 0.0, 3.0), ("linear", 0.0, 0.0),
                              ("rapid", 0.0, 0.5), ("linear", 0.0, -2.5), ("rapid", 0.0, -2.0),
                              ("linear", 0.0, -5.0), ("rapid", 0.0, -4.5), ("linear", 0.0, -6.0),
                              ("rapid", 0.0, 5.0)]
    # G76 K1.5 D0.5: depths 0.5*sqrt(n) until 1.5 (n = 9); root radius 12, crest 13.5
    depths = [0.5 * n ** 0.5 for n in range(1, 9)] + [1.5]
    cuts = [round(x, 6) for k, x, z in moves(recs, 12) if k == "linear"]
    assert cuts == [round(13.5 - d, 6) for d in depths]
    assert all(r.feed == 2.0 and r.feed_mode == "per_rev" for r in recs
               if r.line == 12 and r.kind == "linear")


def test_u_w_incremental_in_diameter_g50_setting_and_css_limit():
    recs, _ = run(CONF / "u-w-g50-css.nc")
    # G50 X100 Z50 at machine 0: program (50, 50); U-20 W-10 -> program (40, 40) = machine (-10, -10)
    assert moves(recs, 6) == [("rapid", -10.0, -10.0)]
    # G01 X50 Z0 -> program radius 25 -> machine -25; CSS 200 m/min at radius 25: 1273.2395 rpm
    line9 = [r for r in recs if r.line == 9 and r.kind == "linear"][0]
    assert (round(line9.end["X"], 6), line9.spindle) == (-25.0, pytest.approx(1273.239545))
    # U-40 (diameter) -> radius 5: 6366 rpm, clamped at G50 S2000
    line10 = [r for r in recs if r.line == 10 and r.kind == "linear"][0]
    assert (round(line10.end["X"], 6), line10.spindle) == (-45.0, 2000.0)
    assert [r.tool for r in recs if r.kind == "tool_change"] == [12]     # T1212 without M06
    assert all(set(r.end) == {"X", "Z"} for r in recs if r.kind in ("rapid", "linear"))


def test_repeated_sequence_number_each_cycle_takes_the_contour_that_follows_it():
    recs, diags = run(CONF / "repeated-n45.nc")
    assert not [d for d in diags if d.severity == "error"], diags
    # first G71 (line 7): N45 X20 -> the contour of lines 8-9 (radius 10, Z-5): levels 13, 11
    assert moves(recs, 7)[:2] == [("rapid", 13.0, 2.0), ("linear", 13.0, -5.0)]
    assert ("linear", 10.0, -5.0) in moves(recs, 7)
    # second G71 (line 11): the N45 after it (X24 -> radius 12, Z-8)
    assert ("linear", 12.0, -8.0) in moves(recs, 11)
    # G70 after both: no N45 follows, the nearest before it (lines 12-13) is finished
    assert moves(recs, 13) == [("linear", 12.0, -8.0)]


def test_non_monotonic_type1_contour_is_an_error_at_the_contour_block():
    text = ("G18 G21 G99\nT0101\nG00 X40. Z2.\nG71 P10 Q20 U0 W0 D2. F0.2\nN10 G00 X20.\n"
            "G01 Z-10.\nX30. Z-15.\nX24. Z-20.\nN20 X40.\nM30\n")
    recs, diags = run(Path("bad.nc"), text)
    bad = [d for d in diags if d.rule == "NC230"]
    assert bad and bad[0].line == 8 and bad[0].severity == "error"
    assert not [r for r in recs if r.line == 4 and r.kind == "linear"]   # the control alarms


@pytest.mark.parametrize("path", sorted(TURN.glob("*")), ids=lambda p: p.name)
def test_shared_lathe_corpus_parses_clean_and_runs(path):
    from nctrans.detection import detect
    from nctrans.source import read_source
    text = read_source(path).text
    assert detect(text, path.name).dialect == "iso-t"
    recs, diags = run(path, text)
    assert not [d for d in diags if d.rule.startswith("NC0")], diags
    assert [r for r in recs if r.kind in ("rapid", "linear", "arc")]
    if "snowman" in path.name:
        # G71 P45 Q58: no N58; the next G71's contour holds a G71 block: the control alarms
        assert {(d.rule, d.line) for d in diags} >= {("NC102", 15), ("NC133", 26)}
    else:
        assert not [d for d in diags if d.severity == "error"], diags


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "nctrans", *args], capture_output=True, text=True,
                          cwd=REPO, timeout=120)


def test_lathe_program_linted_as_iso_m_is_nc005_with_evidence():
    p = _cli("lint", "--from", "iso-m", str(TURN / "kiely-haas-L8-Ex1.nc"))
    assert p.returncode == 1
    assert "NC005" in p.stdout and "iso-t" in p.stdout


CONVERT = [CONF / "g71-g70-type1.nc", CONF / "g90-g94-g92.nc", TURN / "enier-haas-valve.nc",
           TURN / "kiely-haas-thumbscrew.nc", TURN / "enier-haas-o20013.nc"]


@pytest.mark.parametrize("path", CONVERT, ids=lambda p: p.name)
def test_iso_t_to_sinumerik_and_back_is_equivalent(path, tmp_path):
    mpf, back = tmp_path / "a.mpf", tmp_path / "b.nc"
    p = _cli("convert", "--from", "iso-t", str(path), "--to", "sinumerik", "-o", str(mpf))
    assert p.returncode == 0, p.stdout + p.stderr
    assert "G18" in mpf.read_text() and "G95" in mpf.read_text()
    p = _cli("equiv", "--from-a", "iso-t", "--from-b", "sinumerik", str(path), str(mpf))
    assert p.returncode == 0, p.stdout + p.stderr
    if "o20013" in path.name:           # no cycles: written structurally, not flattened
        text = mpf.read_text()
        assert "DIAMON" in text and "LIMS=3000" in text and "G96 S1000" in text, text[:800]
    p = _cli("convert", "--from", "sinumerik", str(mpf), "--to", "iso-t", "-o", str(back))
    assert p.returncode == 0, p.stdout + p.stderr
    p = _cli("lint", "--from", "iso-t", str(back))
    assert p.returncode == 0, p.stdout
    p = _cli("equiv", "--from-a", "iso-t", "--from-b", "iso-t", str(path), str(back))
    assert p.returncode == 0, p.stdout + p.stderr


@pytest.mark.rs274
@pytest.mark.parametrize("path", [CONF / "g71-g70-type1.nc", CONF / "g90-g94-g92.nc",
                                  CONF / "g71-type2-pockets.nc", TURN / "enier-haas-valve.nc"],
                         ids=lambda p: p.name)
def test_flattened_iso_t_runs_in_rs274_with_the_same_xz_moves(path, rs274, rs274_cache):
    import rs274 as h
    from nctrans.lower.flatten import flatten
    from test_flatten import rs274_run
    machine = default_lathe()
    src = get("iso-t").parse(path.read_text(encoding="utf-8"), path.name).program
    records = list(interpret(src, machine, diagnostics=[]))
    with h.linuxcnc():                      # G92's threads as LinuxCNC's G33 K
        flat = flatten(src, machine, diagnostics=[])
        res = get("iso-m").emit(flat)
    assert not [d for d in res.diagnostics if d.severity == "error"], res.diagnostics
    result = rs274_run(res.text, "isot-" + path.stem, machine, rs274_cache)
    assert result.completed, result.message
    source = [h.Motion.of(r) for r in records if r.kind in ("rapid", "linear", "arc")]
    problem = h.compare(result.moves, source, path.name)
    assert problem is None, problem


def test_radius_x_among_diameters_is_flagged_with_the_arc_as_evidence():
    text = "G18 G21 G99\nT0101\nG00 X20. Z2.\nG01 Z0. F0.1\nG03 X15. Z-5. I5. K0.\nM30\n"
    _, diags = run(Path("r.nc"), text)
    assert {(d.rule, d.line) for d in diags} >= {("NC203", 5), ("NC234", 5)}
    _, diags = run(Path("r.nc"), text.replace("X15.", "X30."))
    assert not [d for d in diags if d.rule in ("NC203", "NC234")]


def test_gcode_system_b_renames_onto_system_a():
    from nctrans.dialects.iso_m import frontend as iso
    from nctrans.dialects.iso_t.frontend import TurningLowering

    class SystemB(TurningLowering):
        def __init__(self, file, diags):
            super().__init__(file, diags)
            self.system = "B"
            self.renames = dict(self.table.options["gcode_systems"]["B"])
    text = ("G18 G21 G95\nT0101\nG97 S500 M03\nG00 X50. Z2.\nG77 X40. Z-30. F0.2\n"
            "G00 X50. Z2.\nG91 G00 X-10.\nG90 G78 X29.2 Z-20. F1.5\nM30\n")
    prog = iso.parse_program(text, "b.nc", SystemB).program
    prog.meta["defaults"]["diameter"] = "diameter"
    recs = list(interpret(prog, default_lathe(), diagnostics=[]))
    # G77 = system A's G90; G95 = G99 (per revolution); G91 X-10. is incremental in diameter
    assert moves(recs, 5) == [("rapid", 20.0, 2.0), ("linear", 20.0, -30.0), ("linear", 25.0, -30.0),
                              ("rapid", 25.0, 2.0)]
    assert [r.feed_mode for r in recs if r.line == 5 and r.kind == "linear"] == ["per_rev"] * 2
    assert moves(recs, 7) == [("rapid", 20.0, 2.0)]
    assert moves(recs, 8)[1] == ("linear", 14.6, -20.0)


def test_g72_facing_levels_and_g73_pattern_passes():
    recs, diags = run(CONF / "g72-g73.nc")
    assert not [d for d in diags if d.severity == "error"], diags

    def face(z):            # across to the level, cut X20 -> X10 (radius), 45-degree retract, back
        return [("rapid", 20.0, z), ("linear", 10.0, z), ("rapid", 10.5, z + 0.5), ("rapid", 20.0, z + 0.5)]
    assert moves(recs, 10) == (face(0.0) + face(-2.0) + face(-4.0)
                               + [("rapid", 20.0, -6.0), ("linear", 10.0, -6.0), ("linear", 10.0, 2.0),
                                  ("rapid", 20.0, 2.0)])
    want = []
    for od in (4.0, 2.0, 0.0):                      # relief 4 shrinking over 3 passes
        want += [("rapid", 10.0 + od, 2.0), ("linear", 10.0 + od, -10.0), ("linear", 20.0 + od, -10.0)]
        want += ([("rapid", 20.0, -10.0)] if od else []) + [("rapid", 20.0, 2.0)]
    assert moves(recs, 16) == want


def test_g71_type2_pockets_roughed_level_by_level_then_each_pocket():
    """corpus/iso-t/g71-type2-pockets.nc, worked out in radius from its contour: the boundary X
    (radius) at each Z is 10 to Z-5, 18 to Z-8, falls to 12 at Z-12, 12 to Z-15, 19 to Z-18, falls to
    11 at Z-22, 11 to Z-25. A level passes where the boundary is at or below it."""
    recs, diags = run(CONF / "g71-type2-pockets.nc")
    assert [(d.rule, d.severity) for d in diags] == [("NC231", "info")]

    def outer(x, z_stop):
        return level(x, z_stop, 0.5, 2.0)

    def pocket_level(x, z_from, z_to):     # plunge at the entry wall, cut, 45-degree retract
        return [("linear", x, z_from), ("linear", x, z_to), ("rapid", x + 0.5, z_to + 0.5)]
    want = outer(18.0, -15.0) + outer(16.0, -5.0) + outer(14.0, -5.0) + outer(12.0, -5.0)
    # pocket 1: 18 - 1.5 * (-8 - z) = 16 at z = -9.333333, = 14 at -10.666667; X12 runs on its floor
    want += [("rapid", 20.0, 2.0), ("rapid", 20.0, -9.333333), ("rapid", 18.5, -9.333333)]
    want += pocket_level(16.0, -9.333333, -15.0) + [("rapid", 16.5, -10.666667)]
    want += pocket_level(14.0, -10.666667, -15.0) + [("rapid", 14.5, -12.0)]
    want += pocket_level(12.0, -12.0, -15.0)
    # pocket 2: 19 - 2 * (-18 - z) = 18 at z = -18.5, 16 at -19.5, 14 at -20.5, 12 at -21.5
    want += [("rapid", 20.0, -14.5), ("rapid", 20.0, -18.5)]
    want += pocket_level(18.0, -18.5, -25.0) + [("rapid", 18.5, -19.5)]
    want += pocket_level(16.0, -19.5, -25.0) + [("rapid", 16.5, -20.5)]
    want += pocket_level(14.0, -20.5, -25.0) + [("rapid", 14.5, -21.5)]
    want += pocket_level(12.0, -21.5, -25.0)
    want += [("rapid", 20.0, -24.5), ("rapid", 20.0, 2.0)]
    contour = [("rapid", 10.0, 2.0), ("linear", 10.0, -5.0), ("linear", 18.0, -5.0), ("linear", 18.0, -8.0),
               ("linear", 12.0, -12.0), ("linear", 12.0, -15.0), ("linear", 19.0, -15.0),
               ("linear", 19.0, -18.0), ("linear", 11.0, -22.0), ("linear", 11.0, -25.0),
               ("linear", 20.0, -25.0)]
    assert moves(recs, 12) == want + contour + [("rapid", 20.0, 2.0)]
    # G70 runs the contour as programmed from the start point, then returns there
    assert moves(recs, 24) == [("rapid", 20.0, 2.0)]


def test_type2_contour_must_be_monotonic_in_z():
    text = ("G18 G21 G99\nT0101\nG00 X40. Z2.\nG71 P10 Q20 U0 W0 D2. F0.2\nN10 G00 X20. Z2.\n"
            "G01 Z-10.\nX30. Z-5.\nZ-20.\nN20 X40.\nM30\n")
    recs, diags = run(Path("bad2.nc"), text)
    bad = [d for d in diags if d.rule == "NC230"]
    assert bad and bad[0].line == 7 and "monotonic in Z" in bad[0].message
    assert not [r for r in recs if r.line == 4 and r.kind == "linear"]


def test_g72_type2_face_groove_is_roughed_after_the_outer_levels():
    """G72 type II: the levels step in Z, the passes run along X. Radius: start (X20, Z2); face at
    Z-6 out to X16, a shoulder up to Z-2 from X16 to X13, a groove down to Z-5 from X13 to X11.
    Levels Z0 and Z-2 pass over everything (Z-2 along the shoulder's top) to X11; Z-4 stops at the
    shoulder (X16); the groove is then cut at Z-4 from X13 to X11."""
    text = ("G18 G21 G99\nT0101\nG00 X40. Z2.\nG72 W2. R0.5\nG72 P10 Q20 U0 W0 F0.2\n"
            "N10 G00 X40. Z-6.\nG01 X32.\nZ-2.\nX26.\nZ-5.\nX22.\nN20 Z2.\nM30\n")
    recs, diags = run(Path("g72.nc"), text)
    assert [(d.rule, d.line) for d in diags] == [("NC231", 10)]

    def face(z, x_stop):
        return [("rapid", 20.0, z), ("linear", x_stop, z), ("rapid", x_stop + 0.5, z + 0.5),
                ("rapid", 20.0, z + 0.5)]
    want = face(0.0, 11.0) + face(-2.0, 11.0) + face(-4.0, 16.0)
    want += [("rapid", 20.0, 2.0), ("rapid", 13.0, 2.0), ("rapid", 13.0, -1.5), ("linear", 13.0, -4.0),
             ("linear", 11.0, -4.0), ("rapid", 11.5, -3.5), ("rapid", 11.5, 2.0), ("rapid", 20.0, 2.0)]
    want += [("rapid", 20.0, -6.0), ("linear", 16.0, -6.0), ("linear", 16.0, -2.0), ("linear", 13.0, -2.0),
             ("linear", 13.0, -5.0), ("linear", 11.0, -5.0), ("linear", 11.0, 2.0), ("rapid", 20.0, 2.0)]
    assert moves(recs, 5) == want


def test_g76_chamfer_pulls_out_at_45_degrees_over_tenths_of_the_lead():
    """P011060: 1 finishing pass, chamfer 10 tenths of the lead F2 = 2 mm, 60-degree tool. Start
    X30 (radius 15) Z5, root X24 (12), height P1500 = 1.5, first depth Q500 = 0.5, so the first pass
    cuts at 13.5 - 0.5 = 13.0 with the flank shift (1.5 - 0.5) * tan 30 = 0.57735 in +Z. Every pass
    leaves the root 2 before its (shifted) end and reaches the end 2 further out (45 degrees)."""
    text = ("G18 G21 G99\nT0101\nG97 S500 M03\nG00 X30. Z5.\nG76 P011060 Q100 R0.05\n"
            "G76 X24. Z-20. P1500 Q500 F2.0\nM30\n")
    recs, diags = run(Path("g76.nc"), text)
    assert not diags, diags
    got = moves(recs, 6)
    assert got[:5] == [("rapid", 15.0, 5.57735), ("rapid", 13.0, 5.57735), ("linear", 13.0, -17.42265),
                       ("linear", 15.0, -19.42265), ("rapid", 15.0, 5.0)]
    cuts = [r for r in recs if r.line == 6 and r.kind == "linear"]
    assert len(cuts) % 2 == 0 and all(r.feed_mode == "per_rev" and r.feed == 2.0 for r in cuts)
    for root, out in zip(cuts[::2], cuts[1::2]):
        shift = root.end["Z"] + 18.0                       # the flank shift of this pass
        assert out.end["Z"] == pytest.approx(-20.0 + shift, abs=1e-9)
        assert out.end["X"] - root.end["X"] == pytest.approx(2.0, abs=1e-9)
    assert cuts[-1].end["X"] == pytest.approx(12.0 + 2.0)   # the last pass at the root, X24
    _, plain = run(Path("g76.nc"), text.replace("P011060", "P010060"))
    assert not plain
