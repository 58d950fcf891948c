"""Sinumerik G70 / G700 (seed group 13): G70 reads lengths in inch and leaves feeds in the basic
system (mm/min here); G700 reads both in inch. ISO's G20 is G700's twin, ISO has no G70: a
conversion to ISO (or Fagor) lowers the G70 stretch to plain motion, never reads an F in the wrong
unit. Expected values by hand: 1 inch = 25.4 mm, F100 inch/min = 2540 mm/min."""
from __future__ import annotations

import pytest

import nctrans
from nctrans import api

import rs274 as h

# G70 from line 3 to line 6 (G71): X1 inch = 25.4, Y1 = 25.4, incremental X1 -> 50.8; F stays mm/min
G70_PROGRAM = ("G71 G17 G90 G0 X0 Y0 Z0\nG1 X10 F250\nG70\nG1 X1\nY1 F100\nG91 X1\nG90\n"
               "G71 G1 X0 Y0\nM30\n")
G70_MOVES = [("rapid", 0, 0, None), ("linear", 10, 0, 250), ("linear", 25.4, 0, 250),
             ("linear", 25.4, 25.4, 100), ("linear", 50.8, 25.4, 100), ("linear", 0, 0, 100)]


def moves(text: str, dialect: str) -> list[tuple]:
    return [(r.kind, round(r.end["X"], 6), round(r.end["Y"], 6),
             None if r.kind == "rapid" else round(r.feed, 6))
            for r in nctrans.toolpath(text, dialect) if r.kind in ("rapid", "linear")]


def test_g70_moves_in_inch_and_feeds_in_mm():
    assert moves(G70_PROGRAM, "sinumerik") == G70_MOVES


@pytest.mark.parametrize("target", ["iso-m", "fagor"])
def test_g70_to_a_target_without_it_is_lowered_not_misread(target):
    out = api.transpile(G70_PROGRAM, "sinumerik", target)
    assert out.text is not None
    assert moves(out.text, target) == G70_MOVES
    lowered = [d for d in out.diagnostics if d.rule == "NC401" and "inch_geometry" in d.message]
    assert [d.line for d in lowered] == [3]
    assert api.equiv(G70_PROGRAM, out.text, read_a="sinumerik", read_b=target).equivalent


def test_g70_round_trip_through_iso_keeps_the_moves():
    iso = api.transpile(G70_PROGRAM, "sinumerik", "iso-m").text
    back = api.transpile(iso, "iso-m", "sinumerik").text
    assert moves(back, "sinumerik") == G70_MOVES


def test_g70_stays_g70_in_sinumerik_output():
    out = api.transpile(G70_PROGRAM, "sinumerik", "sinumerik").text
    assert "G70" in out.split() and "G700" not in out
    assert moves(out, "sinumerik") == G70_MOVES


def test_iso_g20_is_g700_both_ways():
    """ISO G20 reads F in inch/min too: Sinumerik G700, and back to G20."""
    iso = "G21 G17 G90 G94 G0 X0 Y0 Z0\nG20\nG1 X1 F10\nG21\nG1 X0 F100\nM30\n"
    want = [("rapid", 0, 0, None), ("linear", 25.4, 0, 254), ("linear", 0, 0, 100)]
    assert moves(iso, "iso-m") == want
    sin = api.transpile(iso, "iso-m", "sinumerik").text
    assert "G700" in sin.split() and "G70" not in sin.split()
    assert moves(sin, "sinumerik") == want
    back = api.transpile(sin, "sinumerik", "iso-m").text
    assert "G20" in back.split()
    assert moves(back, "iso-m") == want


def test_g70_stretch_in_a_branch_is_lowered_with_what_follows():
    """G70 inside an IF: the moves after it are inch lengths with the mm feed of F100."""
    text = "R1=0\nG0 X0 Y0 Z0\nIF R1==0\nG70\nENDIF\nG1 X1 F100\nY2\nM30\n"
    want = [("rapid", 0, 0, None), ("linear", 25.4, 0, 100), ("linear", 25.4, 50.8, 100)]
    assert moves(text, "sinumerik") == want
    out = api.transpile(text, "sinumerik", "iso-m")
    assert out.text is not None and moves(out.text, "iso-m") == want


def test_g70_flatten_writes_mm():
    out = api.transpile(G70_PROGRAM, "sinumerik", "iso-m", flatten=True)
    assert moves(out.text, "iso-m") == G70_MOVES


@pytest.mark.rs274
def test_g70_conversion_runs_in_rs274(rs274, tmp_path):
    """LinuxCNC reads the ISO output as the Sinumerik program means it: positions and feeds."""
    out = api.transpile(G70_PROGRAM, "sinumerik", "iso-m").text
    prog = tmp_path / "g70.ngc"
    prog.write_text(out)
    table = h.write_tool_table(tmp_path / "t.tbl", [(1, 0.0, 0.0)])
    run = h.run_rs274(prog, table, tmp_path / "g70.out")
    assert run.completed, run.message
    got = [(m.kind, round(m.end["X"], 3), round(m.end["Y"], 3),
            None if m.kind == "rapid" else round(m.feed, 3)) for m in run.moves]
    assert got == [(k, float(x), float(y), f if f is None else float(f)) for k, x, y, f in G70_MOVES]


# One block switching to inch with an F in it: Sinumerik reads the F in the block's new units
# (G700 F100 = 100 inch/min = 2540 mm/min); ISO (as LinuxCNC) and Fagor read F before the switch
# (G20 F100 = 100 mm/min). X2 inch = 50.8 mm either way.
IN_BLOCK = {
    "sinumerik": ("G0 X0 Y0 Z0\nG1 X1 F200\nG700 G1 X2 F100\nG710 G1 X3 F100\nM30\n",
                  [(1.0, 200.0), (50.8, 2540.0), (3.0, 100.0)]),
    "iso-m": ("G0 X0 Y0 Z0\nG1 X1 F200\nG20 G1 X2 F100\nG21 G1 X3 F100\nM30\n",
              [(1.0, 200.0), (50.8, 100.0), (3.0, 2540.0)]),
    "fagor": ("G0 X0 Y0 Z0\nG1 X1 F200\nG70 G1 X2 F100\nG71 G1 X3 F100\nM30\n",
              [(1.0, 200.0), (50.8, 100.0), (3.0, 2540.0)]),
}


def feeds(text: str, dialect: str) -> list[tuple]:
    return [(round(r.end["X"], 6), round(r.feed, 6)) for r in nctrans.toolpath(text, dialect)
            if r.kind == "linear"]


@pytest.mark.parametrize("source", sorted(IN_BLOCK))
def test_in_block_feed_and_units_order(source):
    text, want = IN_BLOCK[source]
    assert feeds(text, source) == want
    for target in IN_BLOCK:
        if target != source:
            out = api.transpile(text, source, target).text
            assert feeds(out, target) == want, (target, out)


@pytest.mark.rs274
def test_in_block_order_runs_in_rs274(rs274, tmp_path):
    """LinuxCNC reads the ISO written from the Sinumerik block with the feed Sinumerik meant."""
    text, want = IN_BLOCK["sinumerik"]
    prog = tmp_path / "order.ngc"
    prog.write_text(api.transpile(text, "sinumerik", "iso-m").text)
    run = h.run_rs274(prog, h.write_tool_table(tmp_path / "t.tbl", [(1, 0.0, 0.0)]), tmp_path / "o.out")
    assert run.completed, run.message
    assert [(round(m.end["X"], 3), round(m.feed, 3)) for m in run.moves
            # rs274 feeds to where it is on "G20 G1" alone (printed in inch: 0.0394)
            if m.kind == "linear" and abs(m.end["X"] - m.start["X"]) > 2 * m.tol] == want
