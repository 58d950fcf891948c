"""Silent gaps found by the wave-8 audit (issue 8): programs written as a shop writes them, where
nctrans moved the tool wrongly or said nothing about something it does not model. Every expected
position is computed by hand in the comments."""
from __future__ import annotations

import subprocess
import sys

from nctrans import pipeline
from nctrans.source import from_text


def run(text: str, dialect: str = "sinumerik"):
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", dialect)
    recs = list(pipeline.toolpath_of(ld)) if ld.program is not None else []
    return recs, ld.diagnostics


def said(diags, severities=("warning", "error")):
    return sorted((d.line, d.rule) for d in diags if d.severity in severities)


def ends(recs, axis="X"):
    return [round(r.end[axis], 6) for r in recs if r.kind in ("rapid", "linear", "arc")]


# --------------------------------------------------------------------------- variable names

def test_a_variable_named_like_an_address_is_refused_at_its_declaration():
    # seed "Variable names": the first two characters of a name are letters or '_'. `S=5` then
    # programs the spindle speed, which the run must not take for the variable
    recs, diags = run("DEF REAL S\nS=5\nG0 X=S\nM30\n")
    (d,) = [d for d in diags if d.rule == "NC126"]
    assert (d.line, d.column, d.severity) == (1, 10, "error") and "'S'" in d.message
    # a string into S: the spindle word refuses it too (NC104), never a speed
    _, diags = run('DEF STRING[8] S\nS="AB"\nG0 X1\nM30\n')
    assert said(diags) == [(1, "NC126"), (2, "NC104")]


def test_a_loop_counter_named_i_is_refused_not_an_endless_loop_at_x0():
    # `I=0` is the arc centre word I (and `I=I+1` does not parse): the loop never counted and ran
    # at X0 until the step budget, nothing said at the declaration the control refuses
    ld = pipeline.load_source(from_text("DEF INT I\nI=0\nWHILE I<3\nI=I+1\nG1 X=I*10 F100\n"
                                        "ENDWHILE\nM30\n", "t.mpf"), "t.mpf", "sinumerik")
    assert said(ld.diagnostics) == [(1, "NC126"), (4, "NC002")]
    # the same loop with a name the control takes: X10, X20, X30
    recs, diags = run("DEF INT II\nII=0\nWHILE II<3\nII=II+1\nG1 X=II*10 F100\nENDWHILE\nM30\n")
    assert ends(recs) == [10.0, 20.0, 30.0] and said(diags) == []


def test_axis_and_extended_address_names_are_refused_in_def_and_proc():
    # `A=5` moves the rotary axis A; `CR=5` is an arc radius; PROC parameters alike
    _, diags = run("DEF REAL A, DEPTH\nDEF REAL CR\nA=5\nG0 X=A\nM30\n")
    assert [(d.line, d.column) for d in diags if d.rule == "NC126"] == [(1, 10), (2, 10)]
    _, diags = run("PROC CUT(REAL SPOS, REAL DEPTH, INT AP)\nG1 Z=-DEPTH F100\nRET\n")
    (d,) = [d for d in diags if d.rule == "NC126"]        # one per block, the rest counted
    assert "'SPOS'" in d.message and "+1 more" in d.message


def test_lint_exits_1_on_a_refused_name(tmp_path):
    src = tmp_path / "p.mpf"
    src.write_text("DEF REAL F\nF=100\nG1 X10\nM30\n")
    out = subprocess.run([sys.executable, "-m", "nctrans", "lint", str(src), "--from", "sinumerik"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 1 and ":1:10: error[NC126]" in out.stdout


# --------------------------------------------------------------------------- corner elements

HEAD = "G17 G90 G0 X0 Y0 Z0 F1000\n"


def test_rounding_before_an_in_plane_rapid_is_said_as_not_modelled():
    # Siemens traverses the rounding at rapid before an in-plane G0 [GK]: not "inserts none"
    recs, diags = run(HEAD + "G1 X10 RND=2\nG0 Y10\nM30\n")
    assert [(round(r.end["X"], 6), round(r.end["Y"], 6)) for r in recs if r.kind != "stop"][1:] == [
        (10.0, 0.0), (10.0, 10.0)]
    (d,) = [d for d in diags if d.severity == "warning"]
    assert (d.rule, d.line) == ("NC219", 2)
    assert "at rapid" in d.message and "inserts none" not in d.message
    # a G0 out of the plane: the control inserts none, as the analysed corner (NC217)
    _, diags = run(HEAD + "G1 X10 RND=2\nG0 Z10\nM30\n")
    assert said(diags) == [(2, "NC217")] and "inserts none" in diags[-1].message


def test_flattening_writes_the_corner_the_control_shrinks(tmp_path):
    # RND=20 on two 10 mm / 5 mm lines: the control shrinks it [GK] (nctrans: to 5, the largest
    # that fits, NC229); a sharp corner in the flattened output would be silently wrong, so it
    # carries the arc from (5, 0) about (5, 5) to (10, 5)
    src = tmp_path / "p.mpf"
    src.write_text(HEAD + "G1 X10 RND=20\nY5\nM30\n")
    out = subprocess.run([sys.executable, "-m", "nctrans", "convert", str(src), "--from", "sinumerik",
                          "--to", "iso-m", "--flatten"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and ":2:1: warning[NC229]" in out.stderr, out.stderr
    assert "X5." in out.stdout and "G3" in out.stdout, out.stdout


# --------------------------------------------------------------------------- unknown values

def test_a_word_or_condition_from_an_unknown_value_is_a_warning():
    # G31 probing result #5061 is unknown: the X word is left out, the IF taken as false; both
    # change the analysed path, so --fail-on warning must not pass
    recs, diags = run("G0 X0 Y0\nG1 X#5061 F100\nIF[#5063LT-4.]THEN #3000=1 (NOT FOUND)\nM30\n",
                      "iso-m")
    assert ends(recs) == [0.0]
    assert said(diags) == [(2, "NC107"), (3, "NC107")]


def test_cycle800_rotary_axes_are_said_not_modelled():
    # rotate 90 about Z: X10 -> (0, 10) in the swivelled frame; the rotary axes the control
    # positions are not modelled (warning), the tool tip path is
    recs, diags = run('G0 X0 Y0 Z50\nCYCLE800(0,"TABLE",0,57,0,0,0,0,0,90,0,0,0,1,0)\nG1 X10 Y0 F100\n'
                      "M30\n")
    last = [r for r in recs if r.kind == "linear"][-1]
    assert (round(last.end["X"], 6), round(last.end["Y"], 6)) == (0.0, 10.0)
    assert said(diags) == [(2, "NC107")] and "'TABLE'" in diags[-1].message
    # a swivel mode nctrans does not interpret keeps the old frame: X10 stays X10, said
    recs, diags = run('G0 X0 Y0 Z50\nCYCLE800(0,"T",0,121,0,0,0,0,0,90,0,0,0,1,0)\nG1 X10 Y0 F100\n'
                      "M30\n")
    assert ends(recs)[-1] == 10.0 and said(diags) == [(2, "NC107")]


# --------------------------------------------------------------------------- additive frames

def _last_xy(text: str):
    recs, diags = run("G17 G90 G0 X0 Y0 Z0\n" + text + "\nM30\n")
    last = [r for r in recs if r.kind in ("rapid", "linear", "arc")][-1]
    return (round(last.end["X"], 6), round(last.end["Y"], 6)), diags


def test_amirror_after_a_rotation_mirrors_the_rotated_axis():
    # spec 7.3: AMIRROR is P := P . Mi. TRANS X20 Y10, AROT 30, AMIRROR X0, X10 Y0:
    # mirror (10,0) -> (-10,0); rotate 30 -> (-8.660254, -5); shift -> (11.339746, 5).
    # Before, the mirror acted on the unrotated X axis: (11.339746, 15)
    assert _last_xy("TRANS X20 Y10\nAROT RPL=30\nAMIRROR X0\nG1 X10 Y0 F100")[0] == (11.339746, 5.0)
    # ROT Z90, AMIRROR Y0, X10 Y5: mirror -> (10,-5); rotate 90 -> (5, 10)
    assert _last_xy("ROT Z90\nAMIRROR Y0\nG1 X10 Y5 F100")[0] == (5.0, 10.0)
    # a second AMIRROR of the same axis switches it off; of another axis adds it
    assert _last_xy("MIRROR X0\nAMIRROR X0\nG1 X10 Y5 F100")[0] == (10.0, 5.0)
    assert _last_xy("AMIRROR X0\nAMIRROR Y0\nG1 X10 Y5 F100")[0] == (-10.0, -5.0)


def test_ascale_after_a_rotation_scales_the_rotated_axis():
    # AROT Z30, ASCALE X2: (10,0) -> (20,0) -> (17.320508, 10); before (17.320508, 5)
    assert _last_xy("AROT Z30\nASCALE X2\nG1 X10 Y0 F100")[0] == (17.320508, 10.0)
    # ROT Z90, ASCALE X2: (10,0) -> (20,0) -> (0, 20)
    assert _last_xy("ROT Z90\nASCALE X2\nG1 X10 Y0 F100")[0] == (0.0, 20.0)


def test_an_additive_mirror_converts_to_fagor_as_the_same_path():
    # Fagor's G10/G14 replace the mirror set: AMIRROR X0 then AMIRROR Y0 was written as
    # G10 G14 Y-1 (Y only); now lowered to the moves it makes: X-10 Y-5
    import nctrans
    src = "G17 G90 G0 X0 Y0 Z0\nAMIRROR X0\nAMIRROR Y0\nG1 X10 Y5 F100\nM30\n"
    conv = nctrans.transpile(src, read="sinumerik", write="fagor")
    assert conv.ok and "G14 Y-1" not in conv.text
    assert nctrans.equiv(src, conv.text, read_a="sinumerik", read_b="fagor")


# --------------------------------------------------------------------------- arcs on a lathe

def test_three_point_arc_to_iso_turning_writes_x_as_a_diameter():
    # CIP from (30,20) through (35,25) to (40,20): centre (35,20), radius 5, clockwise. On a
    # lathe X is a diameter: the end is X80 (it was written X40, a radius, which the lathe reads
    # as a 20 mm end radius: an arc that does not close, NC203 on the output)
    import nctrans
    src = "G17 G90 G0 X30 Y20 Z0 F300\nCIP X40 Y20 I1=35 J1=25\nM30\n"
    conv = nctrans.transpile(src, read="sinumerik", write="iso-t")
    assert conv.ok and "G2 X80. Y20. I5. J0." in conv.text.splitlines()
    assert nctrans.equiv(src, conv.text, read_a="sinumerik", read_b="iso-t")


def test_three_point_and_opening_angle_arcs_under_diamon_convert_to_the_same_path():
    # DIAMON: X words are diameters. The CIP and the AR= arc were computed on the diameters
    # (G3 Z-20. X60. K-16. I4.5: radius 16.6 at the start, 36.0 at the end)
    import nctrans
    src = ("G18 G90 DIAMON\nG0 X20 Z0\nG1 X40 Z-10 F0.2\nCIP X60 Z-20 I1=56 K1=-14\n"
           "G3 X80 Z-30 AR=90\nG1 X100\nM30\n")
    for target in ("iso-m", "iso-t"):
        conv = nctrans.transpile(src, read="sinumerik", write=target)
        assert conv.ok, target
        back = [d for d in nctrans.lint(conv.text, dialect=target) if d.rule == "NC203"]
        assert back == [], target
        assert nctrans.equiv(src, conv.text, read_a="sinumerik", read_b=target), target
    # hand: from radius 20 at Z-10 through (28, -14) to (30, -20): centre (20, -20), radius 10
    recs, _ = run(src)
    arc = [r for r in recs if r.kind == "arc"][0]
    assert (round(arc.center["X"], 6), round(arc.center["Z"], 6)) == (20.0, -20.0)


def test_fagor_g73_alone_cancels_the_accumulated_rotation():
    # G73 Q30 (incremental, spec 10.5): X10 -> (8.660254, 5); `G73` alone cancels it, so X20 Y0
    # is (20, 0). Before, the accumulated rotation stayed: (17.320508, 10)
    recs, _ = run("%T\nG00 X0 Y0 Z0\nG73 Q30\nG01 X10 Y0 F100\nG73\nG01 X20 Y0\nM30\n", "fagor")
    ends_xy = [(round(r.end["X"], 6), round(r.end["Y"], 6)) for r in recs if r.kind == "linear"]
    assert ends_xy == [(8.660254, 5.0), (20.0, 0.0)]


def test_a_fagor_mirror_set_converts_to_sinumerik_as_the_same_path():
    # G14 X-1 Y-1 then G14 X1: Y alone stays mirrored, X10 Y5 -> (10, -5). Written as AMIRROR
    # (which adds to the mirror in force) it came out unmirrored: (10, 5)
    import nctrans
    src = "%T\nG00 X0 Y0 Z5\nG14 X-1 Y-1\nG01 X10 Y5 F100\nG14 X1\nG01 X10 Y5\nG10\nG01 X10 Y5\nM30\n"
    recs, _ = run(src, "fagor")
    assert [(r.end["X"], r.end["Y"]) for r in recs if r.kind == "linear"] == [
        (-10.0, -5.0), (10.0, -5.0), (10.0, 5.0)]
    conv = nctrans.transpile(src, read="fagor", write="sinumerik")
    assert conv.ok and nctrans.equiv(src, conv.text, read_a="fagor", read_b="sinumerik")
