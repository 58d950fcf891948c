"""Sinumerik writes to frame and tool data act on the moves after them, and nothing else written
or read passes silently (issue 8): settable frames $P_UIFR / $P_IFRAME / $P_UIFRNUM, cutting-edge
data $TC_DP3 / $TC_DP6 used by D, NC228 / NC237 / NC236 for writes and reads nothing models, NC238
for circle words on straight moves. Expected machine positions are computed by hand in comments."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from nctrans import pipeline
from nctrans.machine import Axis, Machine, Tool
from nctrans.source import from_text

ROOT = Path(__file__).resolve().parents[1]


def run(text: str, machine=None, dialect: str = "sinumerik"):
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", dialect)
    recs = list(pipeline.toolpath_of(ld, machine) if machine is not None else pipeline.toolpath_of(ld))
    return recs, ld.diagnostics


def ends(recs):
    return [tuple(round(r.end[a], 6) for a in ("X", "Y", "Z"))
            for r in recs if r.kind in ("rapid", "linear", "arc")]


def rules(diags):
    return [d.rule for d in diags]


def mill(*tools):
    ax = Axis(min=-1000.0, max=1000.0, max_feed=10000.0, rapid=30000.0)
    return Machine(name="m", kind="mill", axes={"X": ax, "Y": ax, "Z": ax}, tools=list(tools))


# --------------------------------------------------------------------------- settable frames

def test_uifr_translation_acts_at_the_next_g54_only():
    recs, diags = run("G90 G500\n$P_UIFR[1,X,TR]=100\n$P_UIFR[1,Y,TR]=-20\n"
                      "G0 X1 Y1\n"            # data only: still G500 -> (1, 1)
                      "G54\nG0 X1 Y1\n"       # (100 + 1, -20 + 1)
                      "M30\n")
    assert ends(recs) == [(1, 1, 0), (101, -19, 0)]
    assert diags == []


def test_uifr_rotation_turns_the_work_system_about_its_origin():
    # G54: TR (100, 50), RT Z 90. Program (10, 0) -> rotated (0, 10) -> + TR = (100, 60)
    recs, diags = run("$P_UIFR[1,X,TR]=100\n$P_UIFR[1,Y,TR]=50\n$P_UIFR[1,Z,RT]=90\nG54 G0 X10 Y0\n"
                      "TRANS X5\nG0 X0 Y0\n"   # programmable frame first: (5, 0) -> (0, 5) -> (100, 55)
                      "M30\n")
    assert ends(recs) == [(100, 60, 0), (100, 55, 0)]
    assert diags == []


def test_whole_uifr_frame_and_component_reads():
    # $P_UIFR[2] = CTRANS(X,10,Y,20):CROT(Z,30); G55 X0 -> (10, 20); the components read back
    recs, diags = run("$P_UIFR[2]=CTRANS(X,10,Y,20):CROT(Z,30)\nG55\n"
                      "R1=$P_UIFR[2,X,TR]\nR2=$P_UIFR[2,Z,RT]\nR3=$P_UIFRNUM\nR4=$P_UIFR[2,X,SC]\n"
                      "G0 X0 Y0\nG500 G0 X=R1 Y=R2 Z=R3+R4\nM30\n")
    assert ends(recs) == [(10, 20, 0), (10, 30, 3)]      # R3 = 2 (G55), R4 = scale 1
    assert diags == []


def test_chain_translation_after_rotation_is_in_the_rotated_system():
    # CROT(Z,90):CTRANS(X,10): the shift (10,0) turned by 90 deg = (0, 10); then the rotation
    recs, _ = run("$P_UIFR[1]=CROT(Z,90):CTRANS(X,10)\nG54 G0 X1 Y0\nM30\n")
    assert ends(recs) == [(0, 11, 0)]                    # (1,0) -> (0,1) + (0,10)


def test_iframe_acts_at_once_and_g54_brings_the_data_back():
    recs, diags = run("$P_UIFR[1,X,TR]=100\nG54 G0 X0\n$P_IFRAME=CTRANS(X,7)\nG0 X0\n"
                      "$P_IFRAME[Y,TR]=3\nG0 X0 Y0\nG54 G0 X0 Y0\nM30\n")
    assert ends(recs) == [(100, 0, 0), (7, 0, 0), (7, 3, 0), (100, 0, 0)]
    assert diags == []


def test_settable_mirror_reverses_arcs_and_scale_stretches():
    recs, _ = run("$P_UIFR[1,X,MI]=1\nG54 G0 X10 Y0\nG2 X0 Y10 I-10 J0 F100\nM30\n")
    arc = [r for r in recs if r.kind == "arc"][0]
    assert ends(recs) == [(-10, 0, 0), (0, 10, 0)] and arc.direction == "ccw"
    recs, _ = run("$P_UIFR[1,X,SC]=2\nG54 G0 X10 Y5\nM30\n")
    assert ends(recs) == [(20, 5, 0)]


def test_uifr_data_survives_a_programmable_frame_clear():
    recs, _ = run("$P_UIFR[1,Z,RT]=90\nG54\nTRANS X5\nTRANS\nG0 X10 Y0\nM30\n")
    assert ends(recs) == [(0, 10, 0)]


# --------------------------------------------------------------------------- tool edges

def test_tool_change_brings_d1_length_and_d0_removes_it():
    m = mill(Tool(number=1, length=100.0, radius=5.0))
    recs, diags = run("T1 M6\nG0 Z0\nD0\nG0 Z0\nD1\nG0 Z10\nM30\n", m)
    assert ends(recs) == [(0, 0, 100), (0, 0, 0), (0, 0, 110)]
    assert diags == []


def test_tc_dp_writes_act_at_the_next_d_and_read_back():
    # written after the change: acts at the next D (D1 again): 80 + 2 wear = 82
    m = mill(Tool(number=1, length=100.0, radius=5.0))
    recs, diags = run("T1 M6\n$TC_DP3[1,1]=80\n$TC_DP12[1,1]=2\nG0 Z0\nD1\nG0 Z0\n"
                      "R1=$TC_DP3[1,1]\nR2=$TC_DP6[1,1]\nG0 X=R1 Y=R2\nM30\n", m)
    assert ends(recs) == [(0, 0, 100), (0, 0, 82), (80, 5, 82)]
    assert diags == []


def test_tc_dp6_radius_compensates_and_d2_is_its_own_edge():
    # edge 2 of tool 1 written with radius 3: G41 left of a +X line moves the centre to Y+3
    recs, diags = run("$TC_DP6[1,2]=3\n$TC_DP3[1,2]=50\nT1 M6 D2\nG0 X0 Y0 Z0\nG41 G1 X10 Y0 F100\n"
                      "G1 X20\nM30\n", mill())
    assert ends(recs)[0] == (0, 0, 50)                    # D2 in the change block: length 50
    assert ends(recs)[-1] == (20, 3, 50)


def test_edge_radius_drives_the_milling_cycle_too():
    # the D of the tool changed in; the tool table has no radius: the written one is used
    recs, diags = run("$TC_DP6[1,1]=4\nT1 M6\nG17 G90 G0 X50 Y50 Z20 S2000 M3 F500\n"
                      "POCKET2(10, 0, 2, -5, , 15, 50, 50, 100, 300, 5, 3, 0, 1)\nM30\n", mill())
    assert "NC224" not in rules(diags)                  # the radius is known: the pocket runs
    assert len(ends(recs)) > 5


# --------------------------------------------------------------------------- nothing silent

def test_unmodelled_writes_are_reported_and_read_only_ones_refused():
    recs, diags = run("$AA_ETRANS[X]=5\n$AA_IW[X]=3\n$AC_MARKER[1]=4\n$AC_MARKER[2]=6\n"
                      "G0 X=$AC_MARKER[1] Y=$AC_MARKER[2]\nM30\n")
    by_line = sorted((d.line, d.rule, d.severity) for d in diags)
    assert by_line == [(1, "NC237", "warning"), (2, "NC228", "error")]
    assert ends(recs) == [(4, 6, 0)]                    # markers keep one value per index


def test_unmodelled_read_is_a_warning_never_zero():
    recs, diags = run("G0 X5\nR1=$AA_OFF[X]\nG0 X=R1\nR2=$P_UNKNOWN_THING\nM30\n")
    assert ends(recs) == [(5, 0, 0)]                    # the X word is left out, not 0
    got = sorted((d.line, d.rule) for d in diags if d.severity == "warning")
    # the read (NC236) and the X word it leaves out (NC107, line 3) are both said
    assert got == [(2, "NC236"), (3, "NC107"), (4, "NC236")]


def test_cr_on_g1_is_reported_and_the_line_is_straight():
    recs, diags = run("G0 X0 Y0\nG1 X10 Y10 CR=5 F100\nG1 X20 AR=90\nG1 X30 I1=5 J1=5\n"
                      "G1 X40 TURN=2\nG2 X50 Y0 CR=20\nM30\n")
    got = [(d.line, d.rule) for d in diags]
    assert got == [(2, "NC238"), (3, "NC238"), (4, "NC238"), (5, "NC238")]
    assert [r.kind for r in recs if r.kind != "stop"] == ["rapid"] + ["linear"] * 4 + ["arc"]


@pytest.mark.parametrize("command", ["lint", "toolpath", "check"])
def test_every_command_says_it_and_fails_under_fail_on_warning(tmp_path, command):
    src = tmp_path / "p.mpf"
    src.write_text("$AA_ETRANS[X]=5\nG0 X0 Y0 Z0\nM30\n")
    args = [sys.executable, "-m", "nctrans", command, str(src), "--from", "sinumerik"]
    if command != "toolpath":
        args += ["--fail-on", "warning"]
    out = subprocess.run(args, capture_output=True, text=True, cwd=ROOT)
    assert "NC237" in out.stdout + out.stderr
    if command != "toolpath":
        assert out.returncode == 1


def test_lathe_tool_length_is_said_not_applied_along_z():
    ax = Axis(min=-1000.0, max=1000.0, max_feed=10000.0, rapid=30000.0)
    lathe = Machine(name="l", kind="lathe", axes={"X": ax, "Z": ax},
                    tools=[Tool(number=1, length=40.0, radius=0.8)])
    recs, diags = run("T1 M6\nG0 X20 Z5\nM30\n", lathe)
    assert [tuple(round(r.end[a], 6) for a in ("X", "Z")) for r in recs if r.kind == "rapid"] == [(20, 5)]
    assert [(d.line, d.rule) for d in diags] == [(1, "NC220")]


# --------------------------------------------------------------------------- edge length in ISO

def to_iso(text, m):
    """Sinumerik -> ISO: the ISO text, its diagnostics and the ISO program's toolpath on `m`."""
    from nctrans import api
    conv = api.transpile(text, "sinumerik", "iso-m", machine=m)
    recs, _ = run(conv.text, m, "iso-m")
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m", machine=m)
    return conv.text, conv.diagnostics, recs


def iso_lines(text):
    return [ln for ln in text.splitlines() if ln and ln[0] not in "%("]


LENGTHS = (Tool(number=1, length=100.0, radius=5.0), Tool(number=2, length=50.0, radius=3.0),
           Tool(number=3, length=30.0, radius=1.0))


def test_sinumerik_d_length_survives_conversion_to_iso():
    # T1 D1: edge 1 of tool 1 = tool 1's length 100 -> ISO G43 H1; Z10 -> spindle at 110
    text, diags, recs = to_iso("T1 D1 M6\nG0 X0 Y0 Z10\nM30\n", mill(*LENGTHS))
    # no D word outside G41/G42: LinuxCNC refuses one ("D word with no G41 ... to use it")
    assert iso_lines(text)[0].split() == ["T1", "M6", "G43", "H1"]
    assert ends(recs) == [(0, 0, 110)]
    assert [d.rule for d in diags] == ["NC401"]


def test_d0_mid_program_is_g49():
    # T2 (50): Z10 -> 60; D0: no length, Z5 -> 5
    text, _, recs = to_iso("T2 M6\nG0 X0 Y0 Z10\nD0\nG0 Z5\nM30\n", mill(*LENGTHS))
    assert iso_lines(text)[0].split() == ["T2", "M6", "G43", "H2"]
    assert iso_lines(text)[2].split() == ["G49"]
    assert ends(recs) == [(0, 0, 60), (0, 0, 5)]


def test_d_change_without_tool_change_takes_the_register_of_its_number():
    # tool 1 (100): Z0 -> 100; D3 without data of its own: offset register 3 = tool 3's 30 -> 30;
    # D1 again: tool 1's own 100 -> 101
    text, _, recs = to_iso("T1 M6\nG0 X0 Y0 Z0\nD3\nG0 Z0\nD1\nG0 Z1\nM30\n", mill(*LENGTHS))
    assert iso_lines(text)[2].split() == ["G43", "H3"]
    assert iso_lines(text)[4].split() == ["G43", "H1"]
    assert ends(recs) == [(0, 0, 100), (0, 0, 30), (0, 0, 101)]


def test_tool_change_without_d_brings_d1_of_the_new_tool():
    # T2 selected while tool 1 (100) cuts: Z0 -> 100; M6: D1 of tool 2 (50) -> H2, Z0 -> 50
    text, _, recs = to_iso("T1 M6\nG0 X0 Y0 Z0\nT2\nG0 Z0\nM6\nG0 Z0\nD1\nG0 Z2\nM30\n",
                           mill(*LENGTHS))
    assert iso_lines(text)[0].split() == ["T1", "M6", "G43", "H1"]
    assert iso_lines(text)[4].split() == ["M6", "G43", "H2"]
    assert iso_lines(text)[6].split() == ["G0", "Z2."]    # D1 of tool 2: H2 is in effect already
    assert ends(recs) == [(0, 0, 100), (0, 0, 100), (0, 0, 50), (0, 0, 52)]


def test_length_under_g18_is_said_at_its_line():
    _, diags, _ = to_iso("G18\nT1 M6\nG0 X0 Z10\nM30\n", mill(*LENGTHS))
    said = [(d.line, d.rule) for d in diags if "normal to plane ZX" in d.message]
    assert said == [(2, "NC401")]


def test_d1_in_a_subprogram_is_said_at_its_line_and_flattened():
    # the subprogram's D1 is the caller's tool's edge, not known where its O block is written:
    # said at line 5, and the conversion falls back to plain motion (tool 1: Z5 -> 105)
    from nctrans import api
    m = mill(*LENGTHS)
    text = "T1 M6\nSUB1\nM30\nPROC SUB1\nD1\nG0 Z5\nRET\n"
    conv = api.transpile(text, "sinumerik", "iso-m", machine=m)
    assert [d.line for d in conv.diagnostics if "edge D1 of a tool not known" in d.message] == [5]
    assert ends(run(conv.text, m, "iso-m")[0]) == [(0, 0, 105)]
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-m", machine=m)


def test_iso_length_survives_conversion_to_sinumerik():
    # ISO T2 G43 H2 -> Sinumerik T2 M6 (D1 of tool 2): 50 either way, Z10 -> 60
    from nctrans import api
    m = mill(*LENGTHS)
    text = "T2 M6 G43 H2\nG0 X0 Y0 Z10\nM30\n"
    conv = api.transpile(text, "iso-m", "sinumerik", machine=m)
    assert ends(run(conv.text, m)[0]) == [(0, 0, 60)]
    assert api.equiv(text, conv.text, read_a="iso-m", read_b="sinumerik", machine=m)
