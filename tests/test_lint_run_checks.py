"""NC210-NC214 (nctrans/interp/run_checks.py): each defect is found at its line, with its rule, in
every dialect that can write it (iso-m, iso-t, sinumerik, fagor), through the neutral state the
interpreter runs on; the corrected program is clean. Expected lines are counted by hand."""
from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from nctrans import linting, pipeline
from nctrans.machine import Machine, ToolChange, default_mill
from nctrans.source import from_text

OURS = ("NC204", "NC209", "NC210", "NC211", "NC212", "NC213", "NC214")


def found(text: str, dialect: str, machine=None, stream: bool = True) -> list[tuple[int, str]]:
    ld = pipeline.load_source(from_text(text, f"t.{dialect}"), dialect=dialect, stream=stream)
    return sorted((d.line, d.rule) for d in linting.lint_loaded(ld, machine) if d.rule in OURS)


# --------------------------------------------------------------------------- NC210 arc plane

ARC_OFF_PLANE = {
    "iso-m": ("G18 G0 X0 Y0 Z0\nG2 X10 Z0 I5 J0 F100\nM30\n", 2),
    "fagor": ("G18 G0 X0 Y0 Z0\nG2 X10 Z0 I5 J0 F100\nM30\n", 2),
    "sinumerik": ("G18 G0 X0 Y0 Z0\nG2 X10 Z0 I5 J0 F100\nM30\n", 2),
    "iso-t": ("G18 G21 G99\nG0 X20 Z2\nG1 Z0 F0.1\nG2 X30 Z-5 I5 J0\nM30\n", 4),
}


@pytest.mark.parametrize("dialect", sorted(ARC_OFF_PLANE))
def test_arc_centre_off_the_plane(dialect):
    text, line = ARC_OFF_PLANE[dialect]
    assert found(text, dialect) == [(line, "NC210")]
    assert found(text.replace(" J0", " K0"), dialect) == []


@pytest.mark.parametrize("stream", [True, False])
@pytest.mark.parametrize("plane, word", [("G17", "K"), ("G18", "J"), ("G19", "I")])
def test_every_plane_names_its_normal_word(plane, word, stream):
    """A CAM-like run of arcs (the streamed ISO fast lane and the native kernel take such runs):
    the off-plane word is found at the one block that has it."""
    words = {"G17": ("X", "Y", "I", "J"), "G18": ("Z", "X", "K", "I"), "G19": ("Y", "Z", "J", "K")}[plane]
    a, b, i, j = words
    body = [f"{plane} G0 X0 Y0 Z0", f"G1 {a}1 F100"]
    for k in range(1, 12):            # half circles of radius 0.5 along the plane's first axis
        body.append(f"G2 {a}{k + 1} {b}0 {i}0.5 {j}0" if k != 7 else f"G2 {a}{k + 1} {b}0 {i}0.5 {word}0")
    body.append("M30")
    assert found("\n".join(body) + "\n", "iso-m", stream=stream) == [(9, "NC210")]   # k=7: line 2+7


# --------------------------------------------------------------------------- NC211 cycle plane

def test_drilling_cycle_outside_xy_plane_iso_and_fagor_free_sinumerik():
    iso = "G17 G0 X0 Y0 Z5\nS1000 M3\nG19\nG81 X10 Y10 Z-5 R2 F100\nY20\nG80\nM30\n"
    assert found(iso, "iso-m") == [(4, "NC211")]            # once for the plane, not per hole
    assert found(iso.replace("G19\n", "G17\n"), "iso-m") == []
    sin = "G17 G0 X0 Y0 Z5\nS1000 M3 F100\nG18\nCYCLE81(10, 0, 2, -5)\nG17\nCYCLE81(10, 0, 2, -5)\nM30\n"
    assert found(sin, "sinumerik") == [(4, "NC211")]
    # a new plane selection warns again
    again = "G0 X0 Y0 Z5\nS1000 M3\nG19 G81 X10 Y10 Z-5 R2 F100\nG80\nG18 G81 X10 Y10 Z-5 R2\nG80\nM30\n"
    assert found(again, "iso-m") == [(3, "NC211"), (5, "NC211")]


# --------------------------------------------------------------------------- NC212 comp on an arc

COMP = {
    "iso-m": "G17 G0 X0 Y0\nT1 M6\nS1000 M3\nG41 D1\nG0 Z-2\nG2 X10 Y10 R10 F100\nG1 X20\nG40 G3 X30 Y0 R10\nG0 Z5\nM30\n",
    "fagor": "G17 G0 X0 Y0\nT1 M6\nS1000 M3\nG41 D1\nG0 Z-2\nG2 X10 Y10 R10 F100\nG1 X20\nG40 G3 X30 Y0 R10\nG0 Z5\nM30\n",
    "sinumerik": "G17 G0 X0 Y0\nT1 D1\nS1000 M3\nG41\nG0 Z-2\nG2 X10 Y10 CR=10 F100\nG1 X20\nG40 G3 X30 Y0 CR=10\nG0 Z5\nM30\n",
    "iso-t": "G18 G21 G99\nT0101\nG0 X20 Z2\nG42\nM8\nG2 X30 Z-5 R5 F0.1\nG1 Z-10\nG40 G3 X40 Z-15 R5\nG0 X50\nM30\n",
}


@pytest.mark.parametrize("dialect", sorted(COMP))
@pytest.mark.parametrize("tool_radius", [0.0, 1.0])
def test_compensation_switched_on_and_off_on_arcs(dialect, tool_radius):
    """Line 6 starts compensation on an arc (line 5 moves only along the plane's normal, or not
    at all); line 8 ends it on an arc. Found with and without a known tool radius."""
    machine = default_mill() if dialect != "iso-t" else None
    if machine is not None:
        machine.radius_offsets = {1: tool_radius}
    got = found(COMP[dialect], dialect, machine)
    assert [x for x in got if x[1] == "NC212"] == [(6, "NC212"), (8, "NC212")]
    fixed = COMP[dialect].replace("G0 Z-2\n", "G0 Z-2\nG1 X-5 Y-5\n").replace("M8\n", "M8\nG1 X18 Z1\n")
    fixed = fixed.replace("G40 G3 X30 Y0 R10", "G40 G1 X30 Y0").replace("G40 G3 X30 Y0 CR=10", "G40 G1 X30 Y0")
    fixed = fixed.replace("G40 G3 X40 Z-15 R5", "G40 G1 X40 Z-15")
    assert [x for x in found(fixed, dialect, machine) if x[1] == "NC212"] == []


def test_short_entry_needs_the_radius():
    text = "G17 G0 X0 Y0\nT1 M6\nS1000 M3\nG41 D1 G1 X2 Y0 F100\nG1 X20\nG40 G1 X30 Y-10\nM30\n"
    assert found(text, "iso-m") == []
    m = default_mill()
    m.radius_offsets = {1: 3.0}
    assert found(text, "iso-m", m) == [(4, "NC204")]


# --------------------------------------------------------------------------- NC213 tool change

TOOL_CHANGE = {
    "iso-m": "G17 G0 X0 Y0 Z5\nT1 M6\nS1000 M3 M8\nG1 X10 F100\nT2 M6\nS1200 M3\nG1 X20\nM30\n",
    "fagor": "G17 G0 X0 Y0 Z5\nT1 M6\nS1000 M3 M8\nG1 X10 F100\nT2 M6\nS1200 M3\nG1 X20\nM30\n",
    "sinumerik": "G17 G0 X0 Y0 Z5\nT1 M6\nS1000 M3 M8\nG1 X10 F100\nT2 M6\nS1200 M3\nG1 X20\nM30\n",
}


@pytest.mark.parametrize("dialect", sorted(TOOL_CHANGE))
def test_tool_change_with_spindle_or_coolant_running(dialect):
    text = TOOL_CHANGE[dialect]
    both = Machine(name="m", tool_change=ToolChange(requires_stopped=["spindle", "coolant"]))
    assert found(text, dialect, both) == [(5, "NC213")]
    coolant_only = Machine(name="m", tool_change=ToolChange(requires_stopped=["coolant"]))
    assert found(text, dialect, coolant_only) == [(5, "NC213")]
    stopped = text.replace("T2 M6", "M5 M9\nT2 M6")
    assert found(stopped, dialect, both) == []
    assert found(text.replace("M8", ""), dialect, coolant_only) == []     # the spindle is allowed


def test_tool_change_that_stops_the_spindle():
    """iso-m's tool change stops the spindle (LinuxCNC, Haas): a cut before M3 is NC209."""
    text = "G17 G0 X0 Y0 Z5\nT1 M6\nS1000 M3\nG1 X10 F100\nT2 M6\nG1 X20\nS1200 M3\nG1 X30\nM30\n"
    assert found(text, "iso-m") == [(6, "NC209")]
    keeps = Machine(name="m", tool_change=ToolChange(stops_spindle=False))
    assert found(text, "iso-m", keeps) == []
    assert found(text, "sinumerik") == []          # no such default for Sinumerik
    # the kernel's fast lane must not skip it: a long plain run after the change
    run = "\n".join(f"G1 X{k} Y{k % 3}" for k in range(20, 120))
    assert found(text.replace("G1 X20\n", run + "\n"), "iso-m") == [(6, "NC209")]


def test_tool_change_before_the_spindle_was_ever_started():
    """A real program (a NIMS training part) changes to its face mill, sets S and cuts with no
    M03: the spindle stands from power-on through the change, so the first feed (line 4) is NC209.
    With the M03 it is clean; the change on a machine whose M6 leaves the spindle alone is not
    flagged (its power-on state is no program's stop); a program with no tool change and no
    spindle word stays unflagged (a fragment)."""
    text = "G90 G21\nT20 M06\nS1254\nG01 Z0 F564.\nG01 X50.\nM30\n"
    assert found(text, "iso-m") == [(4, "NC209")]                   # said once, at the first cut
    assert found(text.replace("S1254", "S1254 M03"), "iso-m") == []
    keeps = Machine(name="m", tool_change=ToolChange(stops_spindle=False))
    assert found(text, "iso-m", keeps) == []
    assert found(text.replace("T20 M06\n", ""), "iso-m") == []
    # M05, a cut (said), then a change: the spindle has stood since the M05, said once until it is
    # programmed again, so the cut after the change (line 7) is not said a second time
    two = "T1 M06\nS1000 M03\nG01 X10 F100\nM05\nG01 X20\nT2 M06\nG01 X30\nM30\n"
    assert found(two, "iso-m") == [(5, "NC209")]


# --------------------------------------------------------------------------- NC214 units

UNITS = {
    "iso-m": ("G21 G17 G0 X0 Y0 Z0\nG1 X10 F250\nG20\nG1 X1\nM30\n", "G20", "G21"),
    "fagor": ("G71 G17 G0 X0 Y0 Z0\nG1 X10 F250\nG70\nG1 X1\nM30\n", "G70", "G71"),
    # Sinumerik G70/G71 leave feeds in the basic system; G700/G710 switch them too
    "sinumerik": ("G710 G17 G0 X0 Y0 Z0\nG1 X10 F250\nG700\nG1 X1\nM30\n", "G700", "G710"),
    "iso-t": ("G21 G18 G99\nG0 X20 Z2\nG1 Z0 F0.1\nG20\nG1 Z-0.1\nM30\n", "G20", "G21"),
}


@pytest.mark.parametrize("dialect", sorted(UNITS))
def test_feed_after_a_unit_switch(dialect):
    text, inch, metric = UNITS[dialect]
    line = 4 if dialect != "iso-t" else 5
    assert found(text, dialect) == [(line, "NC214")]
    lines = text.splitlines()
    lines[line - 1] += " F10" if dialect != "iso-t" else " F0.004"
    assert found("\n".join(lines) + "\n", dialect) == []                 # F restated
    back = text.replace(f"{inch}\n", f"{inch}\nG0 Z5\n{metric}\n")        # switched back first
    assert found(back, dialect) == []


def test_sinumerik_g70_keeps_the_feed_unit():
    """G70 changes lengths only: F250 still means 250 mm/min, so nothing to report."""
    assert found("G71 G17 G0 X0 Y0 Z0\nG1 X10 F250\nG70\nG1 X1\nM30\n", "sinumerik") == []


def test_unit_switch_in_a_run_of_plain_blocks():
    """CAM output: thousands of plain blocks after the switch; reported once, at the first feed move."""
    body = "\n".join(f"X{k} Y{k % 5}" for k in range(2, 400))
    text = f"G21 G17 G0 X0 Y0 Z0\nG1 X1 F250\nG20\nG0 Z1\n{body}\nM30\n"
    assert found(text, "iso-m") == []          # G0 mode: no feed move yet
    text = f"G21 G17 G0 X0 Y0 Z0\nG1 X1 F250\nG20\nG1 Z1\n{body}\nM30\n"
    assert found(text, "iso-m") == [(4, "NC214")]
    text = f"G21 G17 G0 X0 Y0 Z0\nG1 X1 F250\nG20\nG1\n{body}\nM30\n"
    assert found(text, "iso-m") == [(5, "NC214")]      # the first feed move is in the run

# --------------------------------------------------------------------------- properties

PLANE_WORDS = {"G17": ("X", "Y", "I", "J", "K"), "G18": ("Z", "X", "K", "I", "J"), "G19": ("Y", "Z", "J", "K", "I")}


@settings(max_examples=30, deadline=None)
@given(plane=st.sampled_from(sorted(PLANE_WORDS)), arcs=st.integers(1, 40), data=st.data(),
       normal=st.sampled_from(["0", "0.5", "-2.25"]), stream=st.booleans())
def test_arc_off_plane_found_at_its_line_only(plane, arcs, data, normal, stream):
    """Runs of centre-format arcs in any plane, streamed (kernel lane) or not: only the one arc
    carrying the normal axis's centre word is NC210, at its line."""
    a, b, i, j, off = PLANE_WORDS[plane]
    k = data.draw(st.integers(0, arcs - 1))
    body = [f"{plane} G0 X0 Y0 Z0", f"G1 {a}1 F100"]
    for n in range(arcs):
        extra = f" {off}{normal}" if n == k else ""
        body.append(f"G{2 + n % 2} {a}{n + 2} {b}0 {i}0.5 {j}0{extra}")
    body.append("M30")
    assert found("\n".join(body) + "\n", "iso-m", stream=stream) == [(3 + k, "NC210")]


@settings(max_examples=40, deadline=None)
@given(steps=st.lists(st.sampled_from(["G20", "G21", "F", "G1", "G0"]), min_size=1, max_size=25),
       dialect=st.sampled_from(["iso-m", "fagor"]))
def test_feed_after_unit_switch_matches_a_model(steps, dialect):
    """Any sequence of unit switches, feed words and moves: NC214 at each first feed move after a
    switch that leaves the feed in force programmed in the other unit (the model below)."""
    inch, metric = ("G20", "G21") if dialect == "iso-m" else ("G70", "G71")
    lines, expected = [f"{metric} G17 G0 X0 Y0 Z0", "G1 X1 F100"], []
    units, fed_in, pending = "mm", "mm", False
    for n, step in enumerate(steps):
        if step in ("G20", "G21"):
            new = "inch" if step == "G20" else "mm"
            if new != units:
                pending = new != fed_in
                units = new
            lines.append(inch if step == "G20" else metric)
        elif step == "F":
            fed_in, pending = units, False
            lines.append(f"F{50 + n}")
        elif step == "G1":
            if pending:
                expected.append((len(lines) + 1, "NC214"))
                pending = False
            lines.append(f"G1 X{n % 7 + 1}")
        else:
            lines.append(f"G0 X{n % 5}")
    lines.append("M30")
    assert [x for x in found("\n".join(lines) + "\n", dialect) if x[1] == "NC214"] == expected
