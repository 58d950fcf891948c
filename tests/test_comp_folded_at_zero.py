"""Compensation folded into plain motion where the machine model gives no radius (NC409).

A lowering (or --flatten) writes the tool-centre path with compensation off. On the built-in
machines no register or edge has a radius, so the path written is the programmed contour: right
only for a tool of radius 0. It used to be said only as the NC401 note "compensation folded"; it
is now a warning at the G41/G42 line, once per offset number, and the conversion goes ahead."""
from __future__ import annotations

from pathlib import Path

import pytest

import nctrans
from nctrans import cli
from nctrans.machine import Axis, Machine, Tool, default_lathe

DATA = Path(__file__).resolve().parent / "data" / "tool-programs"
_AX = Axis(min=-500.0, max=500.0)
MILL = Machine(name="mill", kind="mill", axes={"X": _AX, "Y": _AX, "Z": _AX},
               tools=[Tool(number=1, length=0.0, radius=5.0)])

ISO_MILL = "G21 G90 G17\nT1 M6\nG0 X0 Y0 Z5\nG41 D1 G1 X10 Y0 F100\nG1 Y10\nG40 G1 X0 Y0\nM30\n"
SINUMERIK_MILL = "G71 G90 G17\nT1 M6 D1\nG0 X0 Y0 Z5\nG41 G1 X10 Y0 F100\nG1 Y10\nG40 G1 X0 Y0\nM30\n"
# test_nose_comp.CHAMFER: OD chamfer under G42 with tool 1 (offset register 1)
CHAMFER = "G18 G21 G99\nT0101\nG00 X20. Z5.\nG42 G01 Z0. F0.1\nX30. Z-5.\nZ-20.\nG40 G00 X50.\nM30\n"


def _nc409(diags):
    return [(d.line, d.severity) for d in diags if d.rule == "NC409"]


def _ends(text, dialect, machine=None):
    return [(r.line, round(r.end["X"], 6), round(r.end.get("Y", r.end.get("Z")), 6))
            for r in nctrans.toolpath(text, dialect, machine) if r.kind in ("linear", "arc")]


@pytest.mark.parametrize("target", ["sinumerik", "fagor", "iso-t"])
def test_corpus_like_g71_under_g42_converts_and_warns_once(target):
    """t05: T0303, G71/G70 whose contour starts with G42 (line 10); the built-in lathe has no
    register 3. Lowered to plain motion for every target: written, with one NC409 at line 10."""
    src = (DATA / "t05-g71-comp.nc").read_text()
    conv = nctrans.transpile(src, read="iso-t", write=target, flatten=target == "iso-t")
    assert conv.text is not None, conv.diagnostics
    assert _nc409(conv.diagnostics) == [(10, "warning")]
    msg = next(d.message for d in conv.diagnostics if d.rule == "NC409")
    assert "register 3" in msg and "radius 0" in msg and "--machine" in msg


def test_lint_target_fails_on_warning(tmp_path, capsys):
    f = tmp_path / "t05.nc"
    f.write_text((DATA / "t05-g71-comp.nc").read_text())
    assert cli.main(["lint", str(f), "--from", "iso-t", "--target", "sinumerik"]) == 0
    assert cli.main(["lint", str(f), "--from", "iso-t", "--target", "sinumerik",
                     "--fail-on", "warning"]) == 1
    assert "t05.nc:10:1: warning[NC409]" in capsys.readouterr().out


@pytest.mark.parametrize("source,dialect", [(ISO_MILL, "iso-m"), (SINUMERIK_MILL, "sinumerik")])
def test_mill_radius_from_the_machine_file_offsets_the_path_and_is_not_warned(source, dialect):
    # built-in mill: no radius for register/edge 1 -> the programmed contour, NC409 at line 4
    conv = nctrans.transpile(source, read=dialect, write="iso-m", flatten=True)
    assert _nc409(conv.diagnostics) == [(4, "warning")]
    assert [e[1:] for e in _ends(conv.text, "iso-m")] == [(10.0, 0.0), (10.0, 10.0), (0.0, 0.0)]
    # tool 1 radius 5, left of X0 -> X10 then Y10: offset lines Y = 0 + 5 and X = 10 - 5 meet at
    # (5, 5); the Y cut ends at (10 - 5, 10) = (5, 10); G40 returns to (0, 0)
    conv = nctrans.transpile(source, read=dialect, write="iso-m", flatten=True, machine=MILL)
    assert not _nc409(conv.diagnostics), conv.diagnostics
    assert [e[1:] for e in _ends(conv.text, "iso-m")] == [(5.0, 5.0), (5.0, 10.0), (0.0, 0.0)]


def test_lathe_nose_radius_from_the_machine_file_and_not_warned():
    """Nose radius 0.8, tip 3 (test_nose_comp.test_od_chamfer_with_tip_3_by_hand): the entry's tip
    ends at radius 10, Z -0.468629 (the offset lines X = 10.8 and X + Z = 10 + 0.8*sqrt2 meet at
    centre (10.8, 0.331371); tip = centre - (0.8, 0.8)); the chamfer's tip at radius
    15.565685 - 0.8 = 14.765685, Z -4.434315 - 0.8 = -5.234315. Diameters: X20, X29.53137."""
    conv = nctrans.transpile(CHAMFER, read="iso-t", write="sinumerik")
    assert conv.text is not None
    bare = nctrans.transpile(CHAMFER, read="iso-t", write="iso-t", flatten=True)
    assert _nc409(bare.diagnostics) == [(4, "warning")]
    lathe = default_lathe()
    lathe.tools = [Tool(1, radius=0.8, tip=3)]
    conv = nctrans.transpile(CHAMFER, read="iso-t", write="iso-t", flatten=True, machine=lathe)
    assert conv.text is not None and not _nc409(conv.diagnostics), conv.diagnostics
    ends = [e[1:] for e in _ends(conv.text, "iso-t")]
    assert ends[:2] == [(10.0, -0.468629), (14.765685, -5.234315)]      # radii in the records
    assert "Z-0.468629\nX29.53137 Z-5.234315\n" in conv.text      # X20 held from the rapid


def test_one_warning_per_offset_number():
    two = ISO_MILL.replace("M30\n", "G41 D1 G1 X10 Y0\nG40 G1 X0 Y0\nG41 D2 G1 X10 Y0\nG40 G1 X0 Y0\nM30\n")
    conv = nctrans.transpile(two, read="iso-m", write="iso-m", flatten=True)
    assert _nc409(conv.diagnostics) == [(4, "warning"), (9, "warning")]


def test_not_said_where_nothing_is_folded():
    conv = nctrans.transpile(ISO_MILL, read="iso-m", write="sinumerik")
    assert not _nc409(conv.diagnostics)                 # compensation translated, not folded
    assert not _nc409(nctrans.lint(ISO_MILL, "iso-m"))  # analysis alone
