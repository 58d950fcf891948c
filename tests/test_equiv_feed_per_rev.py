"""equiv compares motion: a feed per revolution at a constant spindle speed S is the same motion as
that feed x S per minute (an ISO G84 tapped at G95 against a CYCLE84 written with a feed per minute),
so the two compare equal; a different feed still differs."""
from __future__ import annotations

from nctrans import api

PER_REV = "%\nO1\nG21 G17 G90\nS400 M3\nG95 G1 X10. F0.5\nG1 Y10.\nM30\n%\n"
PER_MIN = "%\nO1\nG21 G17 G90\nS400 M3\nG94 G1 X10. F200.\nG1 Y10.\nM30\n%\n"


def test_feed_per_rev_equals_its_feed_per_minute_at_the_spindle_speed():
    same = api.equiv(PER_REV, PER_MIN, read_a="iso-m", read_b="iso-m")
    assert same, same.message                      # 0.5 mm/rev x 400 rev/min = 200 mm/min


def test_a_different_feed_per_minute_still_differs():
    other = api.equiv(PER_REV, PER_MIN.replace("F200.", "F201."), read_a="iso-m", read_b="iso-m")
    assert not other and "feed" in other.message


def test_the_same_feed_per_rev_at_another_spindle_speed_differs():
    other = api.equiv(PER_REV, PER_REV.replace("S400", "S500"), read_a="iso-m", read_b="iso-m")
    assert not other
