"""ISO M99 at the end of a main program restarts it for ever; converted to Sinumerik it is a LOOP.
equiv runs both as the control does (the ISO program restarts, its state kept) as far as the step
budget allows, and calls them equivalent when they agree on everything both ran."""
from __future__ import annotations

import pytest

from nctrans import api

# each pass moves one step further in X: a one-pass analysis could not tell pass 2 from pass 1
ISO = "%\nO1\nG21 G17 G90 G94\n#100=#100+1\nG0 X[#100*2] Y0\nG1 Y5. F100.\nM99\n%\n"
LOOP = "G71 G17 G90 G94\nLOOP\nR100=R100+1\nG0 X=R100*2 Y0\nG1 Y5 F100\nENDLOOP\nM30\n"


@pytest.fixture(autouse=True)
def small_budget(monkeypatch):
    monkeypatch.setenv("NCTRANS_MAX_STEPS", "400")


def test_m99_main_program_and_loop_are_equivalent_within_the_step_budget():
    same = api.equiv(ISO, LOOP, read_a="iso-m", read_b="sinumerik")
    assert same, same.message
    assert same.endless and "step budget" in same.message
    assert min(same.records) > 40          # many passes compared, not one


def test_a_loop_that_differs_on_a_later_pass_is_different():
    other = api.equiv(ISO, LOOP.replace("R100=R100+1", "R100=R100+1\nIF R100==3\nR100=7\nENDIF"),
                      read_a="iso-m", read_b="sinumerik")
    assert not other and "X6" in other.message.replace(".0000", "")


def test_m99_main_program_against_one_pass_is_different():
    other = api.equiv(ISO, LOOP.replace("LOOP\n", "").replace("ENDLOOP\n", ""), read_a="iso-m",
                      read_b="sinumerik")
    assert not other and not other.endless


def test_a_call_event_past_the_end_of_the_other_toolpath_is_a_difference_at_its_end():
    # two endless runs cut by the step budget at different points: when the longer one's next
    # record is a kept call (an event, not motion), the difference is still "the other ended"
    # (at_end), so both-endless runs that agreed on everything both ran are equivalent
    from nctrans.equivalence import compare
    from nctrans.toolpath import ToolpathRecord as R
    o, p = {"X": 0.0, "Y": 0.0, "Z": 0.0}, {"X": 1.0, "Y": 0.0, "Z": 0.0}
    q = {"X": 1.0, "Y": 2.0, "Z": 0.0}
    move = R(0, "a", 1, "rapid", o, p)
    call = R(0, "a", 2, "call", call="FOO", args=[2.0])
    d = compare([move, call], [move])
    assert d is not None and d.at_end and "no counterpart" in d.message
    # a call missing in the middle is not at the end
    d = compare([move, call, R(0, "a", 3, "rapid", p, q)], [move, R(0, "b", 3, "rapid", p, q)])
    assert d is not None and not d.at_end
