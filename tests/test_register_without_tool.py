"""ISO `G41 D1` with no tool change before it, converted to a control whose D belongs to the tool.

ISO D1 is offset register 1 whatever tool is in the spindle; Sinumerik D1 is edge 1 and Fagor D1
corrector 1 of the active tool, here whichever tool the machine holds from before (their analysis:
NC123, radius 0). Written as D1 the converted program cut at another radius, exit 0. Now the
compensation is lowered to plain motion at the register's radius where the machine file gives it,
and refused at its line where it does not (NC125: plain motion would fold a radius of 0 in)."""
from __future__ import annotations

import pytest

import nctrans
from nctrans.machine import Axis, Machine, Tool

_AX = Axis(min=-500.0, max=500.0)
MILL = Machine(name="mill", kind="mill", axes={"X": _AX, "Y": _AX, "Z": _AX},
               tools=[Tool(number=1, length=0.0, radius=5.0), Tool(number=2, length=0.0, radius=3.0)])
FLAT = Machine(name="flat", kind="mill", axes={"X": _AX, "Y": _AX, "Z": _AX}, radius_offsets={1: 4.0})

G41_NO_TOOL = "G21 G90 G17\nG0 X0 Y0 Z5\nG41 D1 G1 X10 Y0 F100\nG1 Y10\nG40 G1 X0 Y0\nM30\n"


def _ends(text, dialect, machine, line):
    return [(round(r.end["X"], 6), round(r.end["Y"], 6)) for r in nctrans.toolpath(text, dialect, machine)
            if r.kind == "linear" and r.line == line]


@pytest.mark.parametrize("target", ["sinumerik", "fagor", "iso-t"])
def test_a_register_the_machine_file_gives_is_lowered_at_its_radius(target):
    # register 1 = tool 1's radius 5 on MILL: the left side of X0 -> X10 -> Y10 runs at X10 - 5:
    # the corner of Y0 -> X10 and X10 -> Y10 is (10 - 5, 0 + 5) = (5, 5) in the source
    assert _ends(G41_NO_TOOL, "iso-m", MILL, 3) == [(5.0, 5.0)]
    conv = nctrans.transpile(G41_NO_TOOL, read="iso-m", write=target, machine=MILL)
    assert conv.text is not None, conv.diagnostics
    assert "D1" not in conv.text and "G41" not in conv.text      # folded into the coordinates
    assert [d for d in conv.diagnostics if d.line == 3 and "no tool" in d.message]
    assert nctrans.equiv(G41_NO_TOOL, conv.text, read_a="iso-m", read_b=target, machine=MILL)


@pytest.mark.parametrize("target", ["fagor", "iso-t"])
def test_a_register_the_machine_file_does_not_give_is_refused_at_its_line(target):
    conv = nctrans.transpile(G41_NO_TOOL, read="iso-m", write=target)
    assert conv.text is None
    assert [d for d in conv.diagnostics if d.rule == "NC402" and d.line == 3 and "register D1" in d.message]


def test_sinumerik_refuses_it_in_place():
    # Sinumerik refuses at its place: the alarm stops the control at the line, nothing is guessed
    conv = nctrans.transpile(G41_NO_TOOL, read="iso-m", write="sinumerik")
    assert conv.text is not None and "D1" not in conv.text
    assert 'SETAL(65002, "NOT CONVERTED: SOURCE LINE 3")' in conv.text
    assert [d for d in conv.diagnostics if d.rule == "NC412" and d.line == 3 and "register D1" in d.message]


@pytest.mark.parametrize("target", ["sinumerik", "fagor"])
def test_a_flat_offset_number_is_the_same_d_in_both(target):
    # the machine file gives number 1 as a flat radius (radius_offsets): ISO register 1 and the
    # target's D1 both read 4 whatever tool is in: (10 - 4, 0 + 4) = (6, 4)
    assert _ends(G41_NO_TOOL, "iso-m", FLAT, 3) == [(6.0, 4.0)]
    conv = nctrans.transpile(G41_NO_TOOL, read="iso-m", write=target, machine=FLAT)
    assert "D1" in conv.text and "G41" in conv.text
    assert nctrans.equiv(G41_NO_TOOL, conv.text, read_a="iso-m", read_b=target, machine=FLAT)


def test_with_the_tool_changed_the_d_is_written():
    # T1 M6 before: ISO register 1 is tool 1's own radius, Sinumerik/Fagor D1 of T1 the same
    text = "G21 G90 G17\nT1 M6\nG0 X0 Y0 Z5\nG41 D1 G1 X10 Y0 F100\nG1 Y10\nG40 G1 X0 Y0\nM30\n"
    for target in ("sinumerik", "fagor"):
        conv = nctrans.transpile(text, read="iso-m", write=target, machine=MILL)
        assert "G41" in conv.text, conv.text
        assert nctrans.equiv(text, conv.text, read_a="iso-m", read_b=target, machine=MILL)


def test_flatten_keeps_the_warning():
    # --flatten is asked for: it folds the unknown register's 0 in and says so at the line
    conv = nctrans.transpile(G41_NO_TOOL, read="iso-m", write="sinumerik", flatten=True)
    assert conv.text is not None
    assert [d for d in conv.diagnostics if d.rule == "NC125" and d.line == 3]


SIN_NO_TOOL = "G17 G90 G71\nG0 X-20 Y-20 Z5\nD1\nG42 G1 X0 Y0 F100\nX30\nG40 G1 X-20 Y-20\nM30\n"


def test_a_sinumerik_edge_with_no_tool_change_is_no_iso_register():
    # the other way: Sinumerik D1 with no tool change is an edge of the held tool (NC123 in the
    # source's analysis); ISO D1 is register 1 (tool 1's radius 5 on MILL). It was written as D1,
    # exit 0, and cut 5 mm off the contour the source's analysis ran: now refused at its line
    tp = nctrans.toolpath(SIN_NO_TOOL, "sinumerik", MILL)
    list(tp)
    assert [d.line for d in tp.diagnostics if d.rule == "NC123"] == [4]
    for target in ("iso-m", "iso-t"):
        conv = nctrans.transpile(SIN_NO_TOOL, read="sinumerik", write=target, machine=MILL)
        assert conv.text is None, (target, conv.text)
        assert [d for d in conv.diagnostics if d.rule == "NC402" and d.line in (3, 4)], target
    # a Fagor D1 is a corrector of the active tool too: the same unknown, said the same (NC123)
    conv = nctrans.transpile(SIN_NO_TOOL, read="sinumerik", write="fagor", machine=MILL)
    assert "D1" in conv.text
    assert nctrans.equiv(SIN_NO_TOOL, conv.text, read_a="sinumerik", read_b="fagor", machine=MILL)
    # a flat offset number the machine file gives is the same D in both
    conv = nctrans.transpile(SIN_NO_TOOL, read="sinumerik", write="iso-m", machine=FLAT)
    assert conv.text is not None and "D1" in conv.text
    assert nctrans.equiv(SIN_NO_TOOL, conv.text, read_a="sinumerik", read_b="iso-m", machine=FLAT)


def test_a_fagor_corrector_with_no_tool_change_is_no_iso_register():
    # Fagor D2 with no tool change: corrector 2 of the held tool (NC123), not ISO register 2
    # (radius 3 on MILL): it was written D2, exit 0 (found by a fuzz of random Fagor programs)
    text = "G17 G90 G71\nG00 X-20 Y-20 Z5\nT3\nD2\nG42 G01 X0 Y0 F100\nX30\nG40 G01 X-20 Y-20\nM30\n"
    conv = nctrans.transpile(text, read="fagor", write="iso-m", machine=MILL)
    assert conv.text is None
    assert [d for d in conv.diagnostics if d.rule == "NC402" and d.line in (4, 5) and "D2" in d.message]
