"""ISO canned cycles with values a control rejects or reads its own way (NC132): said at the block,
never silent; the motion is nctrans' reading (issue 8: nothing unmodelled passes silently)."""
from __future__ import annotations

import pytest

from nctrans import api

HEAD = "G21 G17 G90 G94\nS500 M3\nG0 X0 Y0 Z10.\n"


def _nc132(body: str, head: str = HEAD) -> list[int]:
    result = api.lint(head + body + "G80\nM30\n", dialect="iso-m")
    return [d.line for d in result if d.rule == "NC132"]


@pytest.mark.parametrize("block, what", [
    ("G99 G83 X10. Y10. Z-10. R2. F100.", "peck depth Q missing"),           # no Q ever programmed
    ("G99 G73 X10. Y10. Z-10. R2. Q0.000001 F100.", "pecks"),                 # 12 mm / 1e-6 mm pecks
    ("G99 G81 X10. Y10. Z5. R2. F100.", "R plane below the hole bottom"),     # bottom Z5 above R2
    ("G99 G76 X10. Y10. Z-5. R2. F100.", "shift Q"),                          # fine boring, no shift
])
def test_questionable_values_are_said_at_the_block(block, what):
    result = api.lint(HEAD + block + "\nG80\nM30\n", dialect="iso-m")
    found = [d for d in result if d.rule == "NC132"]
    assert [d.line for d in found] == [4] and what in found[0].message
    assert found[0].severity == "warning"


@pytest.mark.parametrize("block", [
    "G99 G83 X10. Y10. Z-10. R2. Q3. F100.",
    "G99 G81 X10. Y10. Z-5. R2. F100.",
    "G99 G76 X10. Y10. Z-5. R2. Q0.5 F100.",
    "G99 G84 X10. Y10. Z-5. R2. F500.",                                     # M3: a right-hand tap
])
def test_usual_values_are_not(block):
    assert _nc132(block + "\n") == []


def test_a_tap_against_the_spindle_direction_is_said_and_a_stopped_spindle_is_nc209_only():
    # G84 (right hand) under M4: NC132; under M5 the spindle stands: NC209 says it, not NC132 too
    assert _nc132("G99 G84 X10. Y10. Z-5. R2. F500.\n", HEAD.replace("M3", "M4")) == [4]
    stopped = api.lint(HEAD.replace("M3", "M5") + "G99 G84 X10. Y10. Z-5. R2. F500.\nG80\nM30\n",
                       dialect="iso-m")
    rules = {d.rule for d in stopped if d.line == 4}
    assert "NC209" in rules and "NC132" not in rules


def test_the_q_of_an_earlier_block_is_the_peck_depth_it_keeps():
    # Q is retained (seed L2631): the second G83 block pecks with the first one's Q3
    assert _nc132("G99 G83 X10. Y10. Z-10. R2. Q3. F100.\nX20.\n") == []
