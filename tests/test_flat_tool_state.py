"""Plain motion written for a construct the target lacks (a lowered segment, --flatten) keeps the
tool the source has: the cutting edge's length where a D selects an edge (Sinumerik: no G43 in
the source), a T preselection made inside the segment, and never a tool number the analysis made
up for a tool selected by name. Found by converting a ShopMill/NX-style program: `T1 D1 M6` then a
lowered MCALL CYCLE81 came out as `G54 G49 G0 X10. Y10.` (ISO) / `G54 X10 Y10 D0` (Fagor), so the
target drilled with the length switched off (the tool tip its length lower on a real machine), and
`T="CENTERDRILL"` became `T1` (whatever sits in pocket 1) or an M6 with no T, each with exit 0.
Machine positions are computed by hand: machine Z = programmed Z + the length in force."""
from __future__ import annotations

import re

from nctrans import api, pipeline
from nctrans.machine import Axis, Machine, Tool
from nctrans.source import from_text

AX = Axis(min=-1000.0, max=1000.0, max_feed=10000.0, rapid=30000.0)
M = Machine(name="lengths", kind="mill", axes={"X": AX, "Y": AX, "Z": AX},
            tools=[Tool(number=1, length=100.0, radius=5.0), Tool(number=2, length=50.0, radius=3.0),
                   Tool(number=7, length=70.0, radius=2.0, name="CENTERDRILL")])

DRILL = ("G17 G90 F100\nT1 D1 M6\nG0 X0 Y0 Z20\nMCALL CYCLE81(10,0,1,-3,)\nX10 Y10\nX30 Y10\n"
         "MCALL\nG0 Z100\nM30\n")


def machine_z(text, dialect):
    ld = pipeline.load_source(from_text(text, "t"), "t", dialect)
    return [round(r.end["Z"], 6) for r in pipeline.toolpath_of(ld, M) if r.kind in ("rapid", "linear")]


def words(text):
    return [ln.split(";")[0].split("(")[0].split() for ln in text.splitlines()]


def test_lowered_cycle_keeps_the_edge_length_on():
    # tool 1 (100): Z20 -> 120; the cycle at (10,10): RFP+SDIS = 1 -> 101, DP -3 -> 97, RTP 10
    # -> 110; again at (30,10); G0 Z100 -> 200. The old output drilled at Z1/-3 with G49 (machine
    # Z 1 and -3) and ended at Z100 uncompensated
    expected = [120, 120, 101, 97, 110, 110, 101, 97, 110, 200]
    assert machine_z(DRILL, "sinumerik") == expected
    for target in ("iso-m", "fagor"):
        conv = api.transpile(DRILL, "sinumerik", target, machine=M)
        assert conv.text, conv.diagnostics
        flat = [w for ws in words(conv.text) for w in ws]
        assert "G49" not in flat and "D0" not in flat
        assert machine_z(conv.text, target) == expected
        assert api.equiv(DRILL, conv.text, read_a="sinumerik", read_b=target, machine=M)


def test_flatten_writes_the_edge_length_instead_of_folding_it():
    # --flatten to ISO: the length goes on as G43 H1 and Z is written as programmed (Z20, not
    # 20 + 100), so the program runs with whatever tool 1 measures on the target machine
    conv = api.transpile(DRILL, "sinumerik", "iso-m", machine=M, flatten=True)
    blocks = words(conv.text)
    assert any("G43" in ws and "H1" in ws and "Z20." in ws for ws in blocks)
    assert not any("Z120." in ws for ws in blocks)
    assert machine_z(conv.text, "iso-m") == machine_z(DRILL, "sinumerik")


def test_d0_inside_a_lowered_segment_switches_the_length_off_in_the_target():
    # D0 at line 5 inside the lowered MCALL stretch: (10,10) drilled with the length (101/97/110),
    # then D0: X30 at machine Z 10 - 0 (the rapid to RTP under no length), 1, -3, 10; Z100 -> 100
    text = ("G17 G90 F100\nT1 D1 M6\nG0 X0 Y0 Z20\nMCALL CYCLE81(10,0,1,-3,)\nX10 Y10\nD0\n"
            "X30 Y10\nMCALL\nG0 Z100\nM30\n")
    src = machine_z(text, "sinumerik")
    assert src[-1] == 100 and src[2:5] == [101, 97, 110]
    for target in ("iso-m", "fagor"):
        conv = api.transpile(text, "sinumerik", target, machine=M)
        assert conv.text, conv.diagnostics
        assert machine_z(conv.text, target) == src


def test_named_tool_the_machine_does_not_number_is_refused_at_its_change():
    text = 'G17 G90 F100\nT="DRILL_8" D1\nM6\nMCALL CYCLE81(10,0,1,-3,)\nX10 Y10\nMCALL\nM30\n'
    for target in ("iso-m", "fagor"):
        conv = api.transpile(text, "sinumerik", target, machine=M)
        assert not conv.text
        errors = [d for d in conv.diagnostics if d.rule == "NC402" and d.severity == "error"]
        assert errors and all("DRILL_8" in d.message for d in errors)
        assert {d.line for d in errors} <= {2, 3}


def test_named_tool_the_machine_numbers_is_written_with_its_number():
    # CENTERDRILL is tool 7 (70) in the machine file: T7; Z20 -> 90
    text = 'G17 G90 F100\nT="CENTERDRILL" D1\nM6\nG0 X0 Y0 Z20\nMCALL CYCLE81(10,0,1,-3,)\nX10 Y10\nMCALL\nM30\n'
    assert machine_z(text, "sinumerik")[:3] == [90, 90, 71]
    for target in ("iso-m", "fagor"):
        conv = api.transpile(text, "sinumerik", target, machine=M)
        assert conv.text, conv.diagnostics
        assert re.search(r"\bT7\b", conv.text)
        assert api.equiv(text, conv.text, read_a="sinumerik", read_b=target, machine=M)


def test_preselection_inside_a_lowered_segment_reaches_the_next_change():
    # T2 is selected inside the lowered MCALL stretch and changed at line 7 (M6): without the
    # selection the target's M6 changes to tool 1 again. Tool 2 (50): X1 Z5 -> Z55, not 105
    text = "G17 G90 F100\nT1 D1 M6\nG0 X0 Y0 Z10\nMCALL CYCLE81(10,0,1,-3,)\nX10 T2\nMCALL\nM6\nG0 X1 Z5\nM30\n"
    assert machine_z(text, "sinumerik")[-1] == 55
    for target in ("iso-m", "fagor"):
        conv = api.transpile(text, "sinumerik", target, machine=M)
        assert conv.text, conv.diagnostics
        assert machine_z(conv.text, target)[-1] == 55
        assert api.equiv(text, conv.text, read_a="sinumerik", read_b=target, machine=M)


def test_fagor_offset_d_is_written_with_its_h_register():
    # Fagor `T1 D1` then M06 (which brings D1): ISO got a bare `G43`, which a Fanuc reads with the
    # last H programmed (none: no length) and only LinuxCNC with the loaded tool's. Tool 1 (100):
    # G0 Z5 -> machine Z 105 on both
    text = "G0 G17 G71 G90 G54\nT1 D1\nM6\nG0 X0 Y0 Z5\nM30\n"
    conv = api.transpile(text, "fagor", "iso-m", machine=M)
    blocks = words(conv.text)
    assert ["M6", "G43", "H1"] in blocks
    assert not any("G43" in ws and not any(w.startswith("H") for w in ws) for ws in blocks)
    assert machine_z(conv.text, "iso-m") == machine_z(text, "fagor") == [105]


def test_plain_motion_under_a_register_the_program_writes_says_so():
    # G10 L2 P2 writes G55 = (100, 50, 0) and the motion runs under G55; G10 L10 P1 writes
    # register H1 = 50 and the motion runs under G43 H1. The flattened program selects G55 and H1
    # but does not carry the writes: NC417 names each register once
    text = "G21 G17 G90\nG10 L2 P2 X100. Y50. Z0\nT1 M6\nG55 G0 X0 Y0 Z10.\nX5.\nM30\n"
    conv = api.transpile(text, "iso-m", "iso-m", flatten=True, machine=M)
    found = [d for d in conv.diagnostics if d.rule == "NC417"]
    assert [(d.severity, d.line) for d in found] == [("warning", 4)]
    assert "G55" in found[0].message and "X100 Y50 Z0" in found[0].message
    text = "G21 G17 G90\nG10 L10 P1 R50.\nT1 M6\nG43 H1 G0 X0 Y0 Z10.\nX5.\nM30\n"
    conv = api.transpile(text, "iso-m", "iso-m", flatten=True, machine=M)
    found = [d for d in conv.diagnostics if d.rule == "NC417"]
    assert len(found) == 1 and "H1" in found[0].message and "here 50" in found[0].message
    plain = api.transpile("G21 G17 G90\nT1 M6\nG55 G43 H1 G0 X0 Y0 Z10.\nM30\n", "iso-m", "iso-m",
                          flatten=True, machine=M)
    assert not [d for d in plain.diagnostics if d.rule == "NC417"]
