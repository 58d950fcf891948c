"""Sinumerik CYCLE800 (swivel plane, axis by axis): the built-in model (nctrans.interp.cycle_calls
._swivel_plane, rules/cycles.toml [[swivel]] [GK]) against cycle code run by nctrans (issue 8,
"Done when"): the moves after the call, in the workpiece's coordinates, agree move for move.

tests/data/cycle-procs/CYCLE800.SPF sets the frame with TRANS/ATRANS and AROT about the axes _MODE
names (decoded with TRUNC and MOD), a STRING _TC, no SAVE (the frame is its result; SAVE would
restore it, seed L4386-4389). The model's NC107 (the rotary axes are not positioned: the machine's
kinematics is not in its model) is said of the built-in run only and is not a disagreement.
"""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from nctrans import pipeline

import cycle_agreement
from cycle_agreement import procs

AFTER = "G0 X10 Y0 Z5\nG1 X20 Y5 Z0 F100\nG2 X30 Y5 I5 J0\nG0 Z40\n"


def records(where: Path, text: str):
    path = where / "MAIN.MPF"
    path.write_text(text)
    ld = pipeline.load(str(path), "sinumerik")
    recs = list(pipeline.toolpath_of(ld))
    bad = [d.format_text() for d in ld.diagnostics if d.severity in ("error", "warning") and d.rule != "NC107"]
    out = [(r.kind, tuple(r.end[a] for a in "XYZ"),
            tuple(r.center[a] for a in "XYZ") if r.kind == "arc" else None, r.direction)
           for r in recs if r.kind in ("rapid", "linear", "arc")]
    return out, bad


def agree(tmp_path: Path, text: str):
    return cycle_agreement.agree(tmp_path, text, procs("CYCLE800"), records)


CALLS = {
    "zyx-with-shifts": 'CYCLE800(0, "TC1", 0, 57, 10, 5, 0, 30, 0, 45, 2, 3, 1, -1, 0)',
    "z-only": 'CYCLE800(0, "TC1", 0, 27, 0, 0, 0, 90)',
    "additive-twice": 'CYCLE800(0, "TC1", 0, 57, 5, 0, 0, 0, 20)\nCYCLE800(0, "TC1", 1, 27, 0, 0, 3, 15, 0, 0, 1)',
    "deselect": 'CYCLE800(0, "TC1", 0, 57, 5, 5, 0, 10, 20, 30)\nCYCLE800(0, "", 0, 57, 0, 0, 0, 0, 0, 0)',
}


@pytest.mark.parametrize("name", sorted(CALLS))
def test_cycle800_model_agrees_with_cycle_code(tmp_path, name):
    agree(tmp_path, "G17 G90 G0 X0 Y0 Z50\n" + CALLS[name] + "\n" + AFTER + "M30\n")


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.lists(st.tuples(st.sampled_from(['"TC1"', '""', '"0"']), st.sampled_from([0, 1, 10, 11]),
                          st.sampled_from([0, 57, 27, 1, 2, 3, 9, 54, 6]),
                          st.lists(st.sampled_from([0, 0, 1.5, -4, 10]), min_size=6, max_size=6),
                          st.lists(st.sampled_from([0, 0, 15, -30, 90]), min_size=3, max_size=3)),
                min_size=1, max_size=3))
def test_cycle800_model_agrees_over_parameter_sets(tmp_path_factory, calls):
    text = "G17 G90 G0 X0 Y0 Z50\n"
    for tc, state, mode, shifts, angles in calls:
        x0, y0, z0, x1, y1, z1 = shifts
        text += (f"CYCLE800(0, {tc}, {state}, {mode}, {x0:g}, {y0:g}, {z0:g}, {angles[0]:g}, {angles[1]:g}, "
                 f"{angles[2]:g}, {x1:g}, {y1:g}, {z1:g})\n" + AFTER)
    agree(tmp_path_factory.mktemp("s"), text + "M30\n")


def test_cycle800_z_rotation_by_hand(tmp_path):
    # _MODE 27 = 0b011011: bits 1-0 = 3, the first rotation about Z by _A 90: X10 Y0 lands on X0 Y10
    want = agree(tmp_path, "G17 G90 G0 X0 Y0 Z50\n" + CALLS["z-only"] + "\n" + AFTER + "M30\n")
    assert [tuple(round(v, 6) for v in m[1]) for m in want[1:3]] == [(0, 10, 5), (-5, 20, 0)]
