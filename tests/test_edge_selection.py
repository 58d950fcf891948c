"""ISO tool length state kept in conversions to Sinumerik (issue 9): G49 -> D0, G43 H<k> -> the
cutting edge that gives register k, refusals at the line where no edge does
(nctrans.dialects.sinumerik.edge_selection); the reverse direction writes no D outside G41/G42
(nctrans.dialects.iso_m.edge_length); a construct lowered to plain motion leaves the target in the
source's modes (nctrans.lower.constructs._restore). Expected machine positions are computed by hand
in the comments: machine Z = programmed Z + the length in force."""
from __future__ import annotations

import re

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from nctrans import api, pipeline
from nctrans.machine import Axis, Machine, Tool
from nctrans.source import from_text

AX = Axis(min=-1000.0, max=1000.0, max_feed=10000.0, rapid=30000.0)
TOOLS = (Tool(number=1, length=100.0, radius=5.0), Tool(number=2, length=50.0, radius=3.0),
         Tool(number=3, length=30.0, radius=1.0), Tool(number=7, length=70.0, radius=7.0),
         Tool(number=11, length=11.0, radius=1.5))


def mill(*tools):
    return Machine(name="lengths", kind="mill", axes={"X": AX, "Y": AX, "Z": AX}, tools=list(tools),
                   offsets={"G55": {"X": 100.0, "Y": -20.0, "Z": 5.0}})


M = mill(*TOOLS)


def convert(text, m=M, source="iso-m", target="sinumerik"):
    return api.transpile(text, source, target, machine=m)


def ends(text, dialect, m=M):
    ld = pipeline.load_source(from_text(text, "t"), "t", dialect)
    return [tuple(round(r.end[a], 6) for a in ("X", "Y", "Z"))
            for r in pipeline.toolpath_of(ld, m) if r.kind in ("rapid", "linear", "arc")]


def body(text):
    return [ln.split(";")[0].strip() for ln in text.splitlines()[1:] if ln.split(";")[0].strip()]


def same(text, conv, m=M, source="iso-m", target="sinumerik"):
    return api.equiv(text, conv.text, read_a=source, read_b=target, machine=m)


def refused_at(conv):
    return sorted({d.line for d in conv.diagnostics if d.rule == "NC402"})


def in_place_at(conv):
    """Lines refused in place (NC412: an alarm there, nothing of the line written; the rest kept)."""
    return sorted({d.line for d in conv.diagnostics if d.rule == "NC412"})


def alarm_stops_before(text, conv, m=M):
    """The conversion agrees with the source on everything before its alarm, where it stops."""
    eq = same(text, conv, m)
    stopped = [d for d in eq.diagnostics if d.rule == "NC221" and "alarm 65002" in d.message]
    return not eq and eq.difference is not None and eq.difference.at_end and bool(stopped)


# --------------------------------------------------------------------------- ISO -> Sinumerik

def test_g49_switches_the_length_off_as_d0():
    # the lead's case: tool 2 (50): Z10 -> 60; G49: Z5 -> 5 (was Z55 on Sinumerik, silently)
    text = "T2 M6\nG43 H2 D2\nG0 Z10\nG49\nG0 Z5\nM30\n"
    conv = convert(text)
    assert "D0" in body(conv.text)
    assert ends(conv.text, "sinumerik") == [(0, 0, 60), (0, 0, 5)]
    assert same(text, conv)


def test_h_of_another_register_selects_that_edge():
    # tool 2 in the spindle, H3 = register 3 (30): Z10 -> 40; Sinumerik D3 reads register 3
    text = "T2 M6\nG43 H3\nG0 X0 Y0 Z10\nM30\n"
    conv = convert(text)
    assert "D3" in body(conv.text)
    assert ends(conv.text, "sinumerik") == [(0, 0, 40)]
    assert same(text, conv)


def test_the_tools_own_register_stays_the_edge_m6_brings():
    # T3 M6 ... G43 Z95 H3 (a CAM post's order): Sinumerik M6 brings D1 = tool 3, no D word;
    # the XY move before G43 keeps machine Z (0): Z95 -> 125; G49 -> D0: Z50 -> 50
    text = ("G90 G17 G49 G40 G80\nT3 M06\nS3000 M03\nG54\nG00 X16. Y32.5\nG43 Z95. H03\n"
            "G49\nG0 Z50\nM30\n")
    conv = convert(text)
    lines = body(conv.text)
    assert not any(w.startswith("D") and w != "D0" for ln in lines for w in ln.split())
    assert ends(conv.text, "sinumerik") == [(16, 32.5, 0), (16, 32.5, 125), (16, 32.5, 50)]
    assert same(text, conv)


def test_register_1_under_another_tool_is_refused_at_its_line():
    # H1 is edge D1 of tool 1 only: with tool 2 in the spindle no edge gives 100
    # (no D is written for it: the line is an alarm in the Sinumerik program, NC412)
    text = "T2 M6\nG43 H1\nG0 X0 Y0 Z10\nM30\n"
    conv = convert(text)
    assert refused_at(conv) == [] and in_place_at(conv) == [2]
    assert body(conv.text)[1:3] == ["T2 M6", 'SETAL(65002, "NOT CONVERTED: SOURCE LINE 2")']
    assert not [ln for ln in body(conv.text) if re.search(r"\bD[1-9]", ln)]
    assert alarm_stops_before(text, conv)


def test_the_length_a_tool_change_leaves_is_refused_where_a_move_shows_it():
    # ISO keeps H1 (tool 1's 100) after T2 M6; Sinumerik's M6 brings tool 2's edge. Nothing
    # shows it until Z moves at line 5
    text = "T1 M6\nG43 H1\nG0 Z10\nT2 M6\nG0 Z5\nM30\n"
    conv = convert(text)
    assert refused_at(conv) == [] and in_place_at(conv) == [5]
    assert body(conv.text)[-3:] == ["T2 M6", 'SETAL(65002, "NOT CONVERTED: SOURCE LINE 5")', "M30"]
    assert alarm_stops_before(text, conv)


def test_negative_length_is_never_written_as_an_edge():
    # G44 H2: Z10 - 50 = -40. No D subtracts: the program is equivalent plain motion or refused
    text = "T2 M6\nG44 H2\nG0 Z10\nM30\n"
    conv = convert(text)
    assert conv.text is None or (ends(conv.text, "sinumerik") == [(0, 0, -40)] and same(text, conv))
    assert any("G44" in d.message for d in conv.diagnostics)


def test_compensation_with_one_edge_for_length_and_radius():
    # H7 and D7 name edge 7 = tool 7's own edge D1: nothing to write
    text = "T7 M6\nG43 H7\nG0 X0 Y0 Z10\nG41 D7 G1 X10 F100\nG1 Y10\nG40 X20\nG49\nG0 Z5\nM30\n"
    conv = convert(text)
    assert same(text, conv)
    assert not any("D7" in ln for ln in body(conv.text))


def test_length_and_radius_of_different_registers_are_not_one_edge():
    # H1 (100) with D11 (radius 1.5): Sinumerik D1 would cut with radius 5, D11 with length 11
    text = "T1 M6\nG43 H1\nG0 X0 Y0 Z10\nG41 D11 G1 X10 F100\nG1 Y10\nG40 X20\nM30\n"
    conv = convert(text)
    if conv.text is not None:       # lowered to plain motion: the same path
        assert same(text, conv)
        assert not any("G41" in ln for ln in body(conv.text))
    assert any("different Sinumerik cutting edges" in d.message for d in conv.diagnostics)


def test_radius_without_length_is_written_by_the_machines_data_with_a_warning():
    # no G43: ISO compensates by register 2's radius with no length; Sinumerik D2 adds register
    # 2's length too. The built-in machine holds no offsets: D2 is the same there, said (NC405)
    # (T1 M6: with no tool change before it an ISO register has no Sinumerik D at all,
    # test_register_without_tool)
    text = "T1 M6\nG0 X0 Y0 Z5\nG1 G41 D2 X10 Y0 F100\nY10\nG40 X20\nM30\n"
    conv = api.transpile(text, "iso-m", "sinumerik")
    assert conv.text is not None and [d.line for d in conv.diagnostics if d.rule == "NC405"] == [3]
    assert api.equiv(text, conv.text, read_a="iso-m", read_b="sinumerik")
    # on a machine whose register 2 has a length (tool 2: 50) D2 would cut 50 mm higher
    conv = convert(text)
    assert not any(d.rule == "NC405" for d in conv.diagnostics)
    assert conv.text is None or (same(text, conv) and not any("D2" in ln for ln in body(conv.text)))


def test_state_changed_in_a_loop_and_a_subprogram_stays_in_step():
    loop = ("T2 M6\nG43 H2\n#1=0\nWHILE [#1 LT 2] DO1\nG0 Z10\nG49\nG0 Z5\nG43 H3\n#1=#1+1\nEND1\n"
            "G0 Z1\nM30\n")
    # pass 1: Z10 + 50 = 60, Z5; pass 2: Z10 + 30 = 40, Z5; then Z1 + 30 = 31
    conv = convert(loop)
    assert ends(conv.text, "sinumerik") == [(0, 0, 60), (0, 0, 5), (0, 0, 40), (0, 0, 5), (0, 0, 31)]
    assert same(loop, conv)
    sub = "T2 M6\nG43 H2\nM98 P100\nG0 Z3\nM30\nO100\nG49\nG0 Z7\nG43 H3\nM99\n"
    conv = convert(sub)
    assert "L100" in body(conv.text)        # kept as a subprogram
    assert ends(conv.text, "sinumerik") == [(0, 0, 7), (0, 0, 33)]
    assert same(sub, conv)


def test_backward_jump_over_a_length_change():
    text = "T2 M6\nG43 H2\n#1=0\nN10 G0 Z10\nG49\n#1=#1+1\nIF [#1 LT 2] GOTO 10\nG0 Z1\nM30\n"
    conv = convert(text)
    # pass 1: 60; pass 2 (G49 from pass 1): 10; then Z1 with no length
    assert ends(conv.text, "sinumerik") == [(0, 0, 60), (0, 0, 10), (0, 0, 1)]
    assert same(text, conv)


# --------------------------------------------------------------------------- Sinumerik -> ISO

def test_sinumerik_edges_write_no_d_outside_compensation():
    # D0 -> G49 alone, D3 -> G43 H3 alone (LinuxCNC refuses a D word with no G41/G42); the
    # compensation block gets the edge's radius register: D1 of tool 7 -> D7
    text = "T7 M6\nG0 X0 Y0 Z10\nD0\nG0 Z5\nD3\nG0 Z4\nD1\nG41 G1 X10 F100\nY10\nG40 X20\nM30\n"
    conv = convert(text, source="sinumerik", target="iso-m")
    lines = [ln for ln in conv.text.splitlines() if ln and ln[0] not in "%("]
    assert "G49" in lines and "G43 H3" in lines
    d_words = [(w, ln) for ln in lines for w in ln.split() if w.startswith("D")]
    assert len(d_words) == 1 and d_words[0][0] == "D7" and "G41" in d_words[0][1]
    # 10 + 70 = 80, D0: 5, D3 (30): 34, D1 of tool 7 again: Z stays 4 + 70 = 74
    assert ends(conv.text, "iso-m")[:3] == [(0, 0, 80), (0, 0, 5), (0, 0, 34)]
    assert same(text, conv, source="sinumerik", target="iso-m")


def test_edge_change_under_compensation_is_refused_for_iso():
    conv = convert("T7 M6\nG0 X0 Y0 Z10\nG41 G1 X10 F100\nD3 Y10\nG40 X20\nM30\n",
                   source="sinumerik", target="iso-m")
    assert any(d.line == 4 and "while cutter compensation is on" in d.message for d in conv.diagnostics)


# --------------------------------------------------------------------------- modes after a lowered construct

G73 = "G98 G73 X1 Y1 Z-5 R2 Q2 F100\nX2\n"


def test_a_mode_set_in_a_lowered_construct_holds_after_it():
    # G73 has no exact Sinumerik cycle: its run (to the G80 block) is plain motion. The G18 of
    # that block set no move, so the plain motion wrote no plane: the G2 after it is an XZ arc
    # (it ended on X5 Y1 Z5... as the source) only if the plane is restored
    text = "G0 X0 Y0 Z10\n" + G73 + "G80 G18\nG0 X5 Z5\nG2 X10 Z0 R5 F100\nM30\n"
    conv = convert(text)
    assert any(ln.startswith("G18") for ln in body(conv.text))
    assert same(text, conv)


def test_a_length_set_in_a_lowered_construct_holds_after_it():
    text = "T2 M6 G43 H2\nG0 X0 Y0 Z10\n" + G73 + "G80 G49\nG0 X5 Z5\nM30\n"
    conv = convert(text)
    assert ends(conv.text, "sinumerik")[-1] == (5, 1, 5)      # no length after G49
    assert same(text, conv)


MODES = ["G90", "G91", "G54", "G55", "G17", "G18", "G19", "G49", "G43 H1", "G43 H2", "G43 H3",
         "T1 M6", "T2 M6", "T3 M6", "F250", ""]


@st.composite
def programs(draw):
    """Small ISO programs: modal changes, moves and full circles in the plane in force, with one
    G73 run (no Sinumerik cycle makes its strokes) somewhere, a modal change possibly in its G80
    block."""
    plane = ["G17"]

    def note(block):
        for p in ("G17", "G18", "G19"):
            if p in block:
                plane[0] = p
        return block

    def stretch():
        out = []
        for _ in range(draw(st.integers(0, 4))):
            kind = draw(st.sampled_from(["mode", "move", "circle"]))
            if kind == "mode":
                out.append(note(draw(st.sampled_from(MODES))))
            elif kind == "move":
                x, y, z = (draw(st.integers(-5, 5)) for _ in range(3))
                out.append(draw(st.sampled_from(["G0", "G1"])) + f" X{x} Y{y} Z{z} F100")
            else:       # a whole circle back to where it starts: centre 1 mm along the plane's first axis
                out.append("G2 " + ("J1" if plane[0] == "G19" else "I1") + " F100")
        return [b for b in out if b]
    blocks = ["G90 G17 G21 G0 X0 Y0 Z10"] + stretch()
    blocks += ["G90 G98 G73 X1 Y1 Z-5 R2 Q2 F100", "X2",
               note(("G80 " + draw(st.sampled_from(MODES))).strip())]
    blocks += stretch() + ["G0 X0 Y0 Z20", "M30"]
    return "\n".join(blocks) + "\n"


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(programs())
def test_programs_with_a_lowered_construct_stay_equivalent(text):
    conv = convert(text)
    if conv.text is None:           # refused: at a line of the program
        assert refused_at(conv) and all(line >= 1 for line in refused_at(conv)), conv.diagnostics
        return
    if in_place_at(conv):           # refused in place: the same up to the alarm
        assert alarm_stops_before(text, conv), conv.text
        return
    assert same(text, conv), conv.text
