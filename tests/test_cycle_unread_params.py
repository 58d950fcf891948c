"""NC239 for parameters the drilling-cycle models bind but do not read (rules/cycles.toml
[unmodelled_param]): _AXN (tool axis) unless 0 or the plane's applicate, _PTAB (pitch unit)
unless 0 or the program's own unit. Said at the call's line; the path stays the model's."""
from __future__ import annotations

import pytest

from nctrans import api

HEAD = "G17 G90 G0 X0 Y0 Z50 F100 S1000 M3\n"


def nc239(call: str, head: str = HEAD) -> list[int]:
    return [d.line for d in api.lint(head + call + "\nM30\n", "sinumerik") if d.rule == "NC239"]


@pytest.mark.parametrize("call, said", [
    # CYCLE83(RTP, RFP, SDIS, DP, DPR, FDEP, FDPR, DAM, DTB, DTS, FRF, VARI, _AXN): _AXN 13th
    ("CYCLE83(10, 0, 2, -20, , -5, , 2, 0, 0, 1, 0, 2)", [2]),        # Y under G17: said
    ("CYCLE83(10, 0, 2, -20, , -5, , 2, 0, 0, 1, 0, 3)", []),         # Z = the applicate
    ("CYCLE83(10, 0, 2, -20, , -5, , 2, 0, 0, 1, 0, 0)", []),
    # CYCLE84(RTP, RFP, SDIS, DP, DPR, DTB, SDAC, MPIT, PIT, POSS, SST, SST1, _AXN, _PTAB)
    ("CYCLE84(10, 0, 2, -15, , , 3, , 1.25, 0, 1000, , 0, 1)", []),   # mm in a mm program
    ("CYCLE84(10, 0, 2, -15, , , 3, , 1.25, 0, 1000, , 0, 2)", [2]),  # threads per inch
    ("CYCLE84(10, 0, 2, -15, , , 3, , 1.25, 0, 1000, , 1, 0)", [2]),  # tool axis X
    # CYCLE840(RTP, RFP, SDIS, DP, DPR, DTB, SDR, SDAC, ENC, MPIT, PIT, _AXN, _PTAB)
    ("CYCLE840(10, 0, 2, -10, , 0, 3, 3, 0, , 1.0, 3, 3)", [2]),      # inch pitch in mm
    ("CYCLE840(10, 0, 2, -10, , 0, 3, 3, 0, , 1.0, 3, 0)", []),
])
def test_unread_parameters_are_said_where_they_change_the_path(call, said):
    assert nc239(call) == said


def test_axis_and_unit_follow_the_plane_and_the_program():
    # under G18 the applicate is Y (the 2nd geometry axis): _AXN 2 is what the model does
    g18 = "G18 G90 G0 X0 Y50 Z0 F100 S1000 M3\n"
    assert nc239("CYCLE83(10, 0, 2, -20, , -5, , 2, 0, 0, 1, 0, 2)", g18) == []
    # in an inch program (G700) _PTAB 3 (inch) is the program's own unit, 1 (mm) is not
    inch = "G17 G90 G700 G0 X0 Y0 Z2 F4 S1000 M3\n"
    assert nc239("CYCLE84(1, 0, 0.1, -0.6, , , 3, , 0.05, 0, 1000, , 0, 3)", inch) == []
    assert nc239("CYCLE84(1, 0, 0.1, -0.6, , , 3, , 0.05, 0, 1000, , 0, 1)", inch) == [2]


# NC419: a turning model's built-in 1 mm (_VRT 0 or omitted) taken in an inch program
LATHE_INCH = "G18 G90 G700 DIAMON T1 D1\nS800 M3 G95 F0.004\nG0 X2 Z0.2\n"
GROOVE = "CYCLE93(1.5, -0.5, 0.2, 0.1, 0, 0, 0, 0, 0, 0, 0, 0.01, 0.01, 0.05, 0, 5{vrt})"


def nc419(text: str) -> list[int]:
    return [d.line for d in api.lint(text, "sinumerik") if d.rule == "NC419"]


def test_turning_default_distance_in_inch_is_said_at_the_call():
    assert nc419(LATHE_INCH + GROOVE.format(vrt="") + "\nM30\n") == [4]
    assert nc419(LATHE_INCH + GROOVE.format(vrt=", 0") + "\nM30\n") == [4]
    assert nc419(LATHE_INCH + GROOVE.format(vrt=", 0.04") + "\nM30\n") == []
    # in mm the default is the manual's own 1 mm: nothing to say
    mm = "G18 G90 DIAMON T1 D1\nS800 M3 G95 F0.1\nG0 X50 Z5\n"
    assert nc419(mm + "CYCLE93(38, -12, 5, 2.5, 0, 0, 0, 0, 0, 0, 0, 0.2, 0.2, 1, 0, 5)\nM30\n") == []
    # CYCLE97 (thread) too: _VRT is its 17th parameter
    thread = "CYCLE97(0.0625, , 0, -1, 1, 1, 0.1, 0.1, 0.04, 0.004, 30, 0, 4, 1, 3, 1{vrt})\nM30\n"
    assert nc419(LATHE_INCH + thread.format(vrt="")) == [4]
    assert nc419(LATHE_INCH + thread.format(vrt=", 0.04")) == []
