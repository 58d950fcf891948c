"""Where a compensation radius comes from (NC123, interp/comp_radius.py), when a T word changes
the tool (interp/tool_change.py, rules `tool_change.by_t_word`), and `equiv --profile`.
Expected points by hand in the comments."""
from __future__ import annotations

from pathlib import Path

import pytest

import nctrans
from nctrans import cli
from nctrans.machine import Axis, Machine, Tool, ToolChange

_AX = Axis(min=-500.0, max=500.0)
MILL = Machine(name="m", kind="mill", axes={"X": _AX, "Y": _AX, "Z": _AX},
               tools=[Tool(number=1, length=0.0, radius=5.0), Tool(number=2, length=0.0, radius=2.0)])
LATHE = Machine(name="l", kind="lathe", axes={"X": _AX, "Z": _AX})

# G41 along +X then +Y: the tool is left of the path, +Y of the first side and -X of the second,
# so with radius 5 the corner (10,0) is run at the intersection (10-5, 0+5) = (5,5); with no
# radius at (10,0) itself
BODY = "G0 X0 Y0 Z5\nG41 D1\nG1 X10 Y0 F500\nG1 X10 Y10\nG40\nG1 X0 Y0\nM30\n"
SOURCES = {"sinumerik": "G90 G17 G71\n", "fagor": "G90 G17 G71\n", "iso-m": "G90 G17 G21\n"}


def corner(text: str, dialect: str, machine=MILL):
    tp = nctrans.toolpath(text, dialect, machine)
    recs = [r for r in tp if r.kind == "linear" and r.line == 4]
    return (round(recs[-1].end["X"], 6), round(recs[-1].end["Y"], 6)), tp.diagnostics


@pytest.mark.parametrize("dialect", ["sinumerik", "fagor"])
def test_a_d_of_a_tool_the_program_never_chose_is_said_and_not_invented(dialect):
    # D1 belongs to the tool in the spindle, and no tool change precedes G41: before, the
    # analysis took tool 1's radius 5 from the machine file and cut at (5,5) silently
    point, diags = corner(SOURCES[dialect] + BODY, dialect)
    assert point == (10.0, 0.0)                     # the programmed contour, radius 0
    said = [d for d in diags if d.rule == "NC123"]
    assert [(d.line, d.severity) for d in said] == [(3, "warning")], diags
    assert "G41 with D1" in said[0].message


@pytest.mark.parametrize("dialect", ["sinumerik", "fagor"])
def test_a_tool_change_before_makes_the_radius_known(dialect):
    text = SOURCES[dialect] + "T1 M6\n" + BODY
    tp = nctrans.toolpath(text, dialect, MILL)
    recs = [r for r in tp if r.kind == "linear" and r.line == 5]
    assert (round(recs[-1].end["X"], 6), round(recs[-1].end["Y"], 6)) == (5.0, 5.0)
    assert not [d for d in tp.diagnostics if d.rule == "NC123"]


def test_a_flat_offset_the_machine_file_gives_is_known():
    # Sinumerik flat D numbers: the machine file's radius_offsets[1] = 3 -> corner (7,3)
    m = MILL.copy()
    m.radius_offsets = {1: 3.0}
    point, diags = corner(SOURCES["sinumerik"] + BODY, "sinumerik", m)
    assert point == (7.0, 3.0)
    assert not [d for d in diags if d.rule == "NC123"]


def test_sinumerik_g41_with_no_d_and_no_tool_names_the_default_edge():
    text = SOURCES["sinumerik"] + BODY.replace("G41 D1", "G41")
    point, diags = corner(text, "sinumerik")
    assert point == (10.0, 0.0)
    assert [d for d in diags if d.rule == "NC123" and "D1 (the default edge)" in d.message]


def test_an_iso_d_is_a_register_whatever_tool_is_loaded():
    # Fanuc D1 is offset register 1 (here tool 1's radius 5 by the machine file's convention)
    point, diags = corner(SOURCES["iso-m"] + BODY, "iso-m")
    assert point == (5.0, 5.0)
    assert not [d for d in diags if d.rule == "NC123"]


def test_lint_and_check_fail_on_it(tmp_path: Path, capsys):
    f = tmp_path / "a.nc"
    f.write_text(SOURCES["fagor"] + BODY)
    assert cli.main(["lint", str(f), "--from", "fagor", "--fail-on", "warning"]) == 1
    assert "a.nc:3:1: warning[NC123]" in capsys.readouterr().out
    mf = tmp_path / "m.toml"
    mf.write_text('name = "m"\nkind = "mill"\n[axes.X]\nmin = -500.0\nmax = 500.0\n[axes.Y]\nmin = -500.0\n'
                  'max = 500.0\n[axes.Z]\nmin = -500.0\nmax = 500.0\n[[tools]]\nnumber = 1\nlength = 0.0\n'
                  'radius = 5.0\n')
    assert cli.main(["check", str(f), "--from", "fagor", "--machine", str(mf)]) == 1
    assert "warning[NC123]" in capsys.readouterr().out


def test_flatten_goes_ahead_and_keeps_the_warning():
    conv = nctrans.transpile(SOURCES["fagor"] + BODY, read="fagor", write="iso-m", flatten=True)
    assert conv.text is not None
    assert [d for d in conv.diagnostics if d.rule == "NC123" and d.line == 3]


# ------------------------------------------------------------------ T without M6

LATHE_PROGRAM = "G18 G90 G95\nT1 D1\nS500 M3\nG0 X40 Z2\nG1 Z-20 F0.2\nX50\nG0 Z2\nT2 D2\nG0 X30 Z2\nG1 Z-10\nM30\n"


@pytest.mark.parametrize("dialect", ["sinumerik", "fagor"])
def test_on_a_lathe_t_changes_the_tool_at_once(dialect):
    # the turret indexes at T1 (line 2) and T2 (line 8); on a mill the same words preselect only
    changes = [(r.line, r.tool) for r in nctrans.toolpath(LATHE_PROGRAM, dialect, LATHE)
               if r.kind == "tool_change"]
    assert changes == [(2, 1), (8, 2)]
    assert [r for r in nctrans.toolpath(LATHE_PROGRAM, dialect, MILL) if r.kind == "tool_change"] == []


def test_m6_after_t_on_a_turret_changes_nothing_more():
    text = "G18 G90\nT1 M6 D1\nG0 X40 Z2\nT1\nM6\nM30\n"
    assert [r.line for r in nctrans.toolpath(text, "sinumerik", LATHE) if r.kind == "tool_change"] == [2]


def test_the_machine_file_says_t_changes_on_its_mill():
    # Sinumerik MD 22550 TOOL_CHANGE_MODE = 0 on a mill: T1 changes, so D1 is tool 1's (radius 5)
    m = MILL.copy()
    m.tool_change = ToolChange(by_t_word=True)
    text = SOURCES["sinumerik"] + "T1\n" + BODY
    tp = nctrans.toolpath(text, "sinumerik", m)
    recs = list(tp)
    assert [r.line for r in recs if r.kind == "tool_change"] == [2]
    end = [r for r in recs if r.kind == "linear" and r.line == 5][-1].end
    assert (round(end["X"], 6), round(end["Y"], 6)) == (5.0, 5.0)
    assert not [d for d in tp.diagnostics if d.rule == "NC123"]


@pytest.mark.parametrize("dialect", ["sinumerik", "fagor"])
def test_a_lathe_program_and_its_iso_t_conversion_are_equivalent(dialect):
    # T1 D1 -> T0101: both change the tool at line 2 on the lathe both run on (before, the
    # Sinumerik/Fagor side ran on the default mill, where T only preselects: "tool change 1 in B")
    conv = nctrans.transpile(LATHE_PROGRAM, read=dialect, write="iso-t")
    assert "T0101" in conv.text and "T0202" in conv.text
    result = nctrans.equiv(LATHE_PROGRAM, conv.text, read_a=dialect, read_b="iso-t")
    assert result.equivalent, result.message


CORPUS = Path(__file__).resolve().parents[2] / "shared" / "corpus" / "iso-turn"
TURNING = ["enier-haas-valve.nc", "enier-haas-weld-pin-01.nc", "kiely-haas-L8-Ex1.nc", "enier-haas-o20013.nc"]


@pytest.mark.parametrize("name", TURNING)
@pytest.mark.parametrize("dialect", ["sinumerik", "fagor"])
def test_corpus_turning_programs_written_without_m6_stay_equivalent(name, dialect):
    """A corpus lathe program converted, then written as a Sinumerik/Fagor turner writes it (T
    alone, no M6): equivalent to its source, and back to ISO turning."""
    src = CORPUS / name
    if not src.is_file():
        pytest.skip("shared corpus not present")
    text = nctrans.transpile(src, read="iso-t", write=dialect).text
    assert text is not None and " M6" in text
    bare = "\n".join(line.replace(" M6", "") for line in text.splitlines()) + "\n"
    assert " M6" not in bare
    result = nctrans.equiv(src, bare, read_a="iso-t", read_b=dialect)
    assert result.equivalent, result.message
    back = nctrans.transpile(bare, read=dialect, write="iso-t").text
    assert back is not None
    result = nctrans.equiv(src, back, read_a="iso-t", read_b="iso-t")
    assert result.equivalent, result.message


# ------------------------------------------------------------------ equiv --profile

# A G99 hole then a G98 hole: a Fanuc moves to X20 at the R level (Z2) and returns to the initial
# Z50 after it; LinuxCNC rises to Z50 first, moves there, and comes down to R (issue 8). So the
# same program under the two profiles differs at line 4, and agrees when both run as LinuxCNC.
HOLES = "G17 G90 G21\nG0 X0 Y0 Z50\nG99 G81 X10 Y0 Z-5 R2 F100\nG98 X20\nG80\nM30\n"


def test_equiv_profile_runs_a_and_b_as_that_control(tmp_path: Path, capsys):
    f = tmp_path / "h.nc"
    f.write_text(HOLES)
    assert cli.main(["equiv", str(f), str(f), "--profile-b", "linuxcnc"]) == 1
    assert "h.nc:4" in capsys.readouterr().out
    assert cli.main(["equiv", str(f), str(f), "--profile", "linuxcnc"]) == 0
    assert cli.main(["equiv", str(f), str(f), "--profile", "linuxcnc", "--profile-b", "haas"]) == 1
    capsys.readouterr()
    assert cli.main(["equiv", str(f), str(f), "--profile", "nonesuch"]) == 2
    assert "nonesuch" in capsys.readouterr().err


def test_equiv_profile_applies_to_b_only_where_b_knows_it():
    conv = nctrans.transpile(HOLES, read="iso-m", write="sinumerik")
    # linuxcnc is iso-m's profile only: A runs as LinuxCNC, the Sinumerik B as itself
    # (CYCLE81 positions where the call finds the tool, as the Fanuc does): different
    assert not nctrans.equiv(HOLES, conv.text, read_a="iso-m", read_b="sinumerik", profile="linuxcnc")
    assert nctrans.equiv(HOLES, conv.text, read_a="iso-m", read_b="sinumerik")
