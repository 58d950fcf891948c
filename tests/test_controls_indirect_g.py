"""Sinumerik indirect G code programming `G[group]=value` (spec 3.6, seed L1536-1552): the code
numbered `value` in the G group, numbered as $P_GG reads them (rules [options.g_group_index])."""
from __future__ import annotations

from pathlib import Path

import nctrans
from nctrans import api

MACHINE = (Path(__file__).parent / "data" / "offsets-g54-g55.toml").read_text()

# the seed's example: INT_VAR=2 -> G54, +1 -> G55 (group 8: 1 G500, 2 G54, 3 G55)
SEED = ("DEF INT INT_VAR\nG500 G0 X0 Y0 Z0\nINT_VAR=2\nG[8]=INT_VAR G1 X0 Y0 F100\n"
        "INT_VAR=INT_VAR+1\nG[8]=INT_VAR G1 X0 Y0\nR10=$P_GG[8]\nG500 G0 X=R10\nM30\n")


def moves(text: str, machine) -> list[tuple]:
    return [(r.line, round(r.end["X"], 6), round(r.end["Y"], 6))
            for r in nctrans.toolpath(text, "sinumerik", machine) if r.kind in ("rapid", "linear")]


def lint(text: str, machine=None) -> list[tuple]:
    return [(d.rule, d.line, d.severity) for d in api.lint(text, "sinumerik", machine=machine)]


def test_seed_example_selects_g54_then_g55(tmp_path):
    machine = tmp_path / "m.toml"
    machine.write_text(MACHINE)
    # machine X = program X + offset: G54 (100, 0), G55 (200, 50); $P_GG[8] then reads 3, and
    # under G500 Y stays where the tool is (machine 50)
    assert moves(SEED, machine) == [(2, 0, 0), (4, 100, 0), (6, 200, 50), (8, 3, 50)]
    assert lint(SEED, machine) == []


def test_plane_by_number_sets_the_arc_plane():
    # G[6]=2 is G18: the half circle X0 -> X10 about I5 runs in ZX, centre (X5, Z0)
    text = "G17 G0 X0 Y0 Z0\nR1=2\nG[6]=R1\nG2 X10 Z0 I5 F100\nM30\n"
    arc = [r for r in nctrans.toolpath(text, "sinumerik") if r.kind == "arc"][0]
    assert arc.plane == "ZX" and (arc.center["X"], arc.center["Z"]) == (5.0, 0.0)
    assert lint(text) == []


def test_number_outside_the_group_is_an_error_and_changes_nothing(tmp_path):
    machine = tmp_path / "m.toml"
    machine.write_text(MACHINE)
    text = "G54 G0 X0 Y0 Z0\nR1=400\nG[8]=R1\nG0 X1\nM30\n"
    assert moves(text, machine)[-1] == (4, 101, 0)          # still G54
    assert ("NC105", 3, "error") in lint(text, machine)


def test_group_nctrans_cannot_number_stays_unmodelled_and_said():
    # group 10 (G60/G64..) is not in the index table: NC220 at its line, as before
    assert ("NC220", 1, "warning") in lint("G[10]=R1\nM30\n")


def test_written_back_to_sinumerik_and_lowered_for_iso(tmp_path):
    machine = tmp_path / "m.toml"
    machine.write_text(MACHINE)
    out = api.transpile(SEED, "sinumerik", "sinumerik").text
    assert "G[8]=INT_VAR" in out
    assert [m[1:] for m in moves(out, machine)] == [m[1:] for m in moves(SEED, machine)]
    iso = api.transpile(SEED, "sinumerik", "iso-m", machine=machine)
    assert iso.text is not None, [d.message for d in iso.diagnostics]
    assert api.equiv(SEED, iso.text, read_a="sinumerik", read_b="iso-m", machine=machine).equivalent
