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


def test_an_endless_side_runs_to_the_smaller_endless_budget(monkeypatch):
    # M99 restarts the ISO main program for ever: equiv stops both sides at MAX_ENDLESS_STEPS, not
    # at MAX_STEPS (a 39-line Haas program took minutes there); 300 steps < the fixture's 400
    monkeypatch.setenv("NCTRANS_MAX_ENDLESS_STEPS", "300")
    same = api.equiv(ISO, LOOP, read_a="iso-m", read_b="sinumerik")
    assert same and same.endless, same.message
    assert any("step budget of 300 " in d.message for d in same.diagnostics)
    assert not any("step budget of 400 " in d.message for d in same.diagnostics)


def test_a_finite_loop_keeps_the_full_step_budget(monkeypatch):
    # no restart on either side: a 350-pass WHILE runs to its end although 350 > the endless budget
    monkeypatch.setenv("NCTRANS_MAX_STEPS", "5000")    # 350 passes of ~3 steps fit
    monkeypatch.setenv("NCTRANS_MAX_ENDLESS_STEPS", "50")
    loop = "G71 G17 G90 G94\nR1=0\nWHILE R1<350\nR1=R1+1\nG1 X=R1 F100\nENDWHILE\nM30\n"
    same = api.equiv(loop, loop, read_a="sinumerik", read_b="sinumerik")
    assert same and not same.endless, same.message
    assert not any(d.rule == "NC205" for d in same.diagnostics)
    assert same.records[0] > 350                 # every pass ran: X1 .. X350 and the stop
