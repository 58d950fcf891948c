"""Sinumerik $P_GG[n] (issue 8): the active G code of group n as its index in the group (seed
L26809; group 8 order from the seed example L1534-1552, the others [GK] as rules/sinumerik.toml
says). Expected indices are read off the lists by hand."""
from __future__ import annotations

import pytest

from nctrans import pipeline
from nctrans.source import from_text


def values(program: str, count: int):
    """Run `program`, whose R1..R<count> are then moved to one by one with G0 X=R<i>: the values."""
    text = program + "".join(f"G0 X=R{i}\n" for i in range(1, count + 1)) + "M30\n"
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld, None) if r.kind == "rapid"]
    return [r.end["X"] for r in recs], ld.diagnostics


@pytest.mark.parametrize("setup,group,want", [
    ("", 6, 1.0),                 # power-on G17: first of G17 G18 G19
    ("G18\n", 6, 2.0),
    ("G19\n", 6, 3.0),
    ("G54\n", 8, 2.0),            # the seed: G[8]=2 selects G54
    ("G55\n", 8, 3.0),            # ... and 3 G55
    ("G500\n", 8, 1.0),
    ("G505\n", 8, 6.0),           # G500 G54 G55 G56 G57 G505
    ("G70\n", 13, 25.4),          # index 1, read as X1 in inch: 25.4 mm
    ("G710\n", 13, 4.0),          # G710 and G71 both mean mm: the code spelt last decides
    ("G710\nG71\n", 13, 2.0),
    ("G91\n", 14, 2.0),
    ("T1 M6 D1\nG42\n", 7, 3.0),   # (a tool changed first: G42 D1 of no tool is NC123)
    ("G0 Y0\n", 1, 1.0),
    ("G1 Y0 F100\n", 1, 2.0),
])
def test_p_gg_reads_the_index_of_the_active_code(setup, group, want):
    got, diags = values(setup + f"R1=$P_GG[{group}]\n", 1)
    assert got[-1] == want
    assert not [d for d in diags if d.severity in ("error", "warning")]


def test_p_gg_follows_changes_as_the_program_runs():
    got, _ = values("R1=$P_GG[6]\nG18\nR2=$P_GG[6]\nG17\nR3=$P_GG[6]\n", 3)
    assert got == [1.0, 2.0, 1.0]


def test_p_gg_of_an_unmodelled_motion_code_in_force_is_its_index():
    # G34 moves nothing in the analysis (NC220), but $P_GG[1] still names it: index 16
    got, diags = values("G34 Z-1 K1 F=0.1\nR1=$P_GG[1]\n", 1)
    assert got[-1] == 16.0 and any(d.rule == "NC220" for d in diags)


def test_p_gg_of_rigid_tapping_is_its_index():
    got, diags = values("S100 M3\nG331 Z-1 K1\nR1=$P_GG[1]\nG332 Z0 K1\nR2=$P_GG[1]\n", 2)
    assert got[-2:] == [11.0, 12.0] and not any(d.rule == "NC220" for d in diags)


@pytest.mark.parametrize("setup,group", [("", 99),            # no such group
                                         ("", 10),            # G64/G641..: the state cannot tell
                                         ("G5 X1 Y1\n", 1)])  # unmodelled, and not in the list
def test_p_gg_of_what_is_not_modelled_is_unknown_and_said(setup, group):
    got, diags = values(setup + f"R1=$P_GG[{group}]\n", 1)
    assert any(d.rule == "NC107" for d in diags)
