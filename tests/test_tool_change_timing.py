"""A converted program changes the tool where its source does (nctrans.dialects.tool_timing).

A mill's T preselects and its M6 changes; ISO turning's T word (and a Sinumerik or Fagor T on a
lathe) changes at once. Written word for word, ISO milling `T2` ... `M6` became ISO turning
`T0202` at the T: tool 2 cut the blocks tool 1 cuts in the source, exit 0. Each case is run on a
machine with real radii and held to equiv and to the source's own tool-change records."""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

import nctrans
from nctrans.machine import Axis, Machine, Tool, ToolChange

_AX = Axis(min=-500.0, max=500.0)
MILL = Machine(name="mill", kind="mill", axes={"X": _AX, "Y": _AX, "Z": _AX},
               tools=[Tool(number=t, length=0.0, radius=r) for t, r in ((1, 5.0), (2, 3.0), (3, 2.0))])
LATHE = Machine(name="lathe", kind="lathe", axes={"X": _AX, "Z": _AX},
                tools=[Tool(number=t, length=0.0, radius=r, tip=3) for t, r in ((1, 0.8), (2, 0.4), (3, 1.2))])

ISO_MILL = ("O1000\nG21 G90 G17\nT1 M6\nG43 H1 G0 X0 Y0 Z10\nT2\nG1 Z-1 F100\nX10\nM6\n"
            "G43 H2 G0 Z10\nX20\nM30\n")


def _changes(text, dialect, machine):
    """(line, tool) of each tool change the program makes on `machine`."""
    return [(r.line, r.tool) for r in nctrans.toolpath(text, dialect, machine) if r.kind == "tool_change"]


def _tools(text, dialect, machine):
    return [t for _, t in _changes(text, dialect, machine)]


@pytest.mark.parametrize("machine", [None, LATHE], ids=["built-in lathe", "lathe with radii"])
def test_a_mill_preselect_is_written_to_iso_turning_at_the_m6(machine):
    conv = nctrans.transpile(ISO_MILL, read="iso-m", write="iso-t", machine=machine)
    assert conv.text is not None
    lines = conv.text.splitlines()
    # tool 2 comes in after the cut of tool 1 (G1 Z-1, X10 -> X20. in diameter), at the M6
    t2 = next(i for i, ln in enumerate(lines) if ln.startswith("T02"))
    assert t2 > lines.index("X20."), conv.text
    assert "" not in lines[1:-1], conv.text     # no blank line where the T and the M6 were
    # the source changes at line 3 (tool 1) and line 8, the M6 (tool 2); so does the output
    assert _changes(ISO_MILL, "iso-m", machine or LATHE) == [(3, 1), (8, 2)]
    assert _tools(conv.text, "iso-t", machine or LATHE) == [1, 2]
    assert nctrans.equiv(ISO_MILL, conv.text, read_a="iso-m", read_b="iso-t", machine=machine)


def test_the_register_in_force_goes_with_the_change():
    # ISO milling keeps H1 in force through the M6 until G43 H2: tool 2 with register 1, then 2
    text = nctrans.transpile(ISO_MILL, read="iso-m", write="iso-t").text
    assert [ln for ln in text.splitlines() if ln.startswith("T")] == ["T0101", "T0201", "T0202 G0 Z10."]
    # no offset word in the source at all: each tool with its own register, as the first
    plain = "G21 G90\nT1 M6\nG0 X10 Z5\nT2\nG1 Z-5 F100\nM6\nG1 Z-6\nM30\n"
    text = nctrans.transpile(plain, read="iso-m", write="iso-t").text
    assert [ln for ln in text.splitlines() if ln.startswith("T")] == ["T0101", "T0202"]


SIN_MILL = "G17 G90 G71\nT1 M6\nD1\nG0 X0 Y0 Z10\nT2\nG1 Z-1 F100\nX10\nM6\nD1\nG0 Z10\nX20\nM30\n"
FAGOR_MILL = "G17 G90 G71\nT1 D1 M6\nG0 X0 Y0 Z10\nT2\nG1 Z-1 F100\nX10\nM6\nD1\nG0 Z10\nX20\nM30\n"


@pytest.mark.parametrize("text,dialect,m6_line", [(SIN_MILL, "sinumerik", 8), (FAGOR_MILL, "fagor", 7)])
def test_sinumerik_and_fagor_mill_preselect_on_a_mill_is_written_at_the_m6(text, dialect, m6_line):
    # on a mill (MD 22550 / Fagor: T preselects, M6 loads) tool 2 comes in at the M6
    assert _changes(text, dialect, MILL)[-1] == (m6_line, 2)
    conv = nctrans.transpile(text, read=dialect, write="iso-t", machine=MILL)
    lines = conv.text.splitlines()
    assert lines.index("T0202") > lines.index("X20."), conv.text
    assert _tools(conv.text, "iso-t", MILL) == [1, 2]
    assert nctrans.equiv(text, conv.text, read_a=dialect, read_b="iso-t", machine=MILL)


@pytest.mark.parametrize("text,dialect", [(SIN_MILL, "sinumerik"), (FAGOR_MILL, "fagor")])
def test_on_a_lathe_their_t_word_changes_the_tool_at_once(text, dialect):
    # the same words on a lathe (T changes: rules tool_change.by_t_word lathe = true) change at the T
    assert _changes(text, dialect, LATHE)[-1] == (5 if dialect == "sinumerik" else 4, 2)
    conv = nctrans.transpile(text, read=dialect, write="iso-t", machine=LATHE)
    assert nctrans.equiv(text, conv.text, read_a=dialect, read_b="iso-t", machine=LATHE)


def test_a_preselect_never_loaded_is_not_written_as_a_change():
    text = "G21 G90\nT1 M6\nG0 X10 Z5\nT2\nG1 Z-5 F100\nM30\n"
    conv = nctrans.transpile(text, read="iso-m", write="iso-t")
    assert "T02" not in conv.text
    assert _tools(conv.text, "iso-t", LATHE) == [1]
    assert nctrans.equiv(text, conv.text, read_a="iso-m", read_b="iso-t", machine=LATHE)


def test_an_m6_whose_preselect_is_not_known_there_is_not_written_as_a_guess():
    # N10 is reached from the GOTO too: which T the M6 loads depends on the path (T2, or T3
    # then T2 again here, but the emitter does not follow jumps): the block is refused at its
    # line and lowered to plain motion, which writes the tool the run loads
    text = ("G21 G90\nT1 M6\nG0 X10 Z5\nT2\n#1=0\nN10 M6\nG1 Z-5 F100\n#1=#1+1\nT3\n"
            "IF [#1 LT 2] GOTO 10\nM30\n")
    conv = nctrans.transpile(text, read="iso-m", write="iso-t", machine=LATHE)
    assert [d for d in conv.diagnostics if d.rule in ("NC402", "NC401") and d.line == 6], conv.diagnostics
    if conv.text is not None:
        assert _tools(conv.text, "iso-t", LATHE) == _tools(text, "iso-m", LATHE) == [1, 2, 3]
        assert nctrans.equiv(text, conv.text, read_a="iso-m", read_b="iso-t", machine=LATHE)


ISO_LATHE = ("O2000\nG21 G18 G99\nT0101\nG97 S800 M3\nG0 X40. Z2.\nG1 Z-10. F0.2\nG0 X60. Z20.\n"
             "T0202\nG0 X30. Z2.\nG1 Z-5. F0.2\nG0 X60. Z20.\nM30\n")


@pytest.mark.parametrize("target", ["iso-m", "sinumerik", "fagor"])
def test_a_lathe_t_word_is_a_change_in_every_target(target):
    conv = nctrans.transpile(ISO_LATHE, read="iso-t", write=target, machine=LATHE)
    assert _tools(conv.text, target, LATHE) == [1, 2]
    assert nctrans.equiv(ISO_LATHE, conv.text, read_a="iso-t", read_b=target, machine=LATHE)


SIN_LATHE = "G18 G90 G95 DIAMON\nT1 D1\nG97 S800 M3\nG0 X40 Z2\nG1 Z-10 F0.2\nG0 X60 Z20\nT2 D1\nG0 X30 Z2\nM30\n"


def test_a_sinumerik_lathe_t_is_written_to_iso_milling_with_its_m6():
    # on the lathe Sinumerik's T2 changes the tool; ISO milling's T2 alone would only preselect
    conv = nctrans.transpile(SIN_LATHE, read="sinumerik", write="iso-m", machine=LATHE)
    assert [ln.split()[:2] for ln in conv.text.splitlines() if ln.startswith("T")] == [["T1", "M6"], ["T2", "M6"]]
    assert _tools(conv.text, "iso-m", LATHE) == [1, 2]
    assert nctrans.equiv(SIN_LATHE, conv.text, read_a="sinumerik", read_b="iso-m", machine=LATHE)


@pytest.mark.parametrize("target", ["sinumerik", "fagor"])
def test_an_iso_mill_preselect_on_a_machine_whose_t_changes_is_written_at_the_m6(target):
    # a machine file whose Sinumerik/Fagor T changes the tool: ISO milling's T2 preselects there
    # still (its M6 loads it), so the target's T2 goes where the M6 is
    conv = nctrans.transpile(ISO_MILL, read="iso-m", write=target, machine=LATHE)
    assert _tools(conv.text, target, LATHE) == [1, 2]
    assert nctrans.equiv(ISO_MILL, conv.text, read_a="iso-m", read_b=target, machine=LATHE)


# -------------------------------------------------------------- property: random T / M6 sequences
_SPELL = {
    # event -> text per source dialect: preselect, change, select-and-change, a move
    "iso-m": ("T{k}", "M6", "T{k} M6", "G1 X{x} Z{z} F100"),
    "sinumerik": ("T{k}", "M6", "T{k} M6", "G1 X{x} Z{z} F100"),
    "fagor": ("T{k}", "M6", "T{k} M6", "G1 X{x} Z{z} F100"),
    "iso-t": ("T0{k}0{k}", None, "T0{k}0{k}", "G1 X{x} Z{z} F100"),
}
_HEAD = {"iso-m": "G21 G90", "sinumerik": "G90 G71", "fagor": "G90 G71", "iso-t": "G21 G98"}
_EVENT = st.one_of(st.tuples(st.just(0), st.integers(1, 3)), st.tuples(st.just(1), st.just(0)),
                   st.tuples(st.just(2), st.integers(1, 3)),
                   st.tuples(st.just(3), st.integers(0, 40)))


def _program(dialect, events):
    out = [_HEAD[dialect]]
    for kind, v in events:
        form = _SPELL[dialect][kind]
        if form is None:
            continue
        out.append(form.format(k=v, x=v, z=-v / 2))
    out.append("M30")
    return "\n".join(out) + "\n"


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(source=st.sampled_from(sorted(_SPELL)), target=st.sampled_from(sorted(_SPELL)),
       machine=st.sampled_from(["mill", "lathe", "lathe-by-m6"]),
       events=st.lists(_EVENT, min_size=1, max_size=10))
def test_a_converted_run_changes_the_same_tools_as_its_source(source, target, machine, events):
    if source == target:
        return
    m = {"mill": MILL, "lathe": LATHE,
         # a lathe whose Sinumerik / Fagor T preselects (machine data: M6 changes)
         "lathe-by-m6": Machine(name="l6", kind="lathe", axes=LATHE.axes, tools=LATHE.tools,
                                tool_change=ToolChange(by_t_word=False))}[machine]
    # an M6 before any T (a change to no tool, NC105) has its own test
    first_t = next((i for i, (kind, _) in enumerate(events) if kind in (0, 2)), len(events))
    events = [e for i, e in enumerate(events) if i > first_t or e[0] != 1]
    text = _program(source, events)
    conv = nctrans.transpile(text, read=source, write=target, machine=m)
    assert conv.text is not None, conv.diagnostics
    ours, theirs = _tools(text, source, m), _tools(conv.text, target, m)
    if ours != theirs:
        # a repeated M6 of the tool in place is a change cycle on an ISO mill and nothing on a
        # control whose T changes (the turret stays): said at its line (NC401), the tools the same
        assert _distinct(ours) == _distinct(theirs), conv.text
        assert [d for d in conv.diagnostics if d.rule == "NC401" and "already loaded" in d.message]
        return
    assert nctrans.equiv(text, conv.text, read_a=source, read_b=target, machine=m)


def _distinct(tools):
    return [t for i, t in enumerate(tools) if i == 0 or tools[i - 1] != t]


def test_an_m6_with_no_tool_selected_is_refused_to_iso_turning_at_its_line():
    # the source changes to no tool (NC105); a turret's T word always names a tool
    text = "G90 G71\nG0 X10 Z5\nM6\nG1 Z-5 F100\nM30\n"
    conv = nctrans.transpile(text, read="fagor", write="iso-t", machine=MILL)
    assert conv.text is None
    assert [d for d in conv.diagnostics if d.rule == "NC402" and d.line == 3 and "no tool selected" in d.message]


def test_an_iso_turning_turret_that_stays_is_no_second_change_on_a_mill():
    # T0101 then T0102: the turret keeps tool 1 and takes offset 2; a Fagor/Sinumerik M6 would
    # change the tool again on a mill (a second record)
    text = "G21 G98\nT0101\nG1 X20 Z-5 F100\nT0102\nG1 X30 Z-10\nM30\n"
    for target in ("fagor", "sinumerik", "iso-m"):
        conv = nctrans.transpile(text, read="iso-t", write=target, machine=MILL)
        assert _tools(conv.text, target, MILL) == _tools(text, "iso-t", MILL) == [1], (target, conv.text)


def test_a_preselect_that_changes_on_the_conversions_lathe_is_said_at_the_m6():
    # the Sinumerik mill program on the built-in lathe: T2 (line 5) changes the tool there, so the
    # G1 Z-1 / X10 are cut with tool 2 and written so; the M6 at line 8 changes nothing: NC124
    conv = nctrans.transpile(SIN_MILL, read="sinumerik", write="iso-t")
    assert [d.line for d in conv.diagnostics if d.rule == "NC124"] == [8]
    # on a mill machine the M6 is the change, nothing to say
    conv = nctrans.transpile(SIN_MILL, read="sinumerik", write="iso-t", machine=MILL)
    assert not [d for d in conv.diagnostics if d.rule == "NC124"]
    # T and M6 in one block (or nothing cut between): nothing to say
    text = "G17 G90 G71\nT1 M6\nD1\nG0 X0 Y0 Z10\nT2\nM6\nD1\nG0 Z10\nM30\n"
    assert not [d for d in nctrans.transpile(text, read="sinumerik", write="iso-t").diagnostics
                if d.rule == "NC124"]


def test_an_iso_milling_m6_that_stops_the_spindle_is_followed_by_its_direction():
    # ISO turning T0202 indexes the turret with the spindle turning; ISO milling's M6 stops it
    # (rules tool_change.stops_spindle: Haas, LinuxCNC), so G1 Z-5 after `T2 M6` cut with the
    # spindle stopped (NC209 when the output is read): M3 is written again after the change
    conv = nctrans.transpile(ISO_LATHE, read="iso-t", write="iso-m", machine=LATHE)
    lines = conv.text.splitlines()
    i = next(i for i, ln in enumerate(lines) if ln.startswith("T2 M6"))
    assert lines[i + 1] == "M3", conv.text
    assert [d.line for d in conv.diagnostics if "stops the spindle" in d.message] == [8]
    out = nctrans.toolpath(conv.text, "iso-m", LATHE)
    list(out)
    assert not [d for d in out.diagnostics if d.rule == "NC209"]
    assert nctrans.equiv(ISO_LATHE, conv.text, read_a="iso-t", read_b="iso-m", machine=LATHE)
    # with the spindle stopped before the change nothing is written
    stopped = ISO_LATHE.replace("G0 X60. Z20.\nT0202", "G0 X60. Z20.\nM5\nT0202")
    conv = nctrans.transpile(stopped, read="iso-t", write="iso-m", machine=LATHE)
    assert "M3" not in conv.text.split("T2 M6", 1)[1].splitlines()
