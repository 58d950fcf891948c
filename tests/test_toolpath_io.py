"""toolpath_io's fast number spelling must be byte-identical to the plain rounding it replaces."""
from __future__ import annotations

import json
import math

from hypothesis import given, strategies as st

from nctrans import toolpath_io
from nctrans.toolpath import ToolpathRecord


def reference(v: float) -> str:
    return repr(round(v, 6) + 0.0)


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_spell_matches_repr_of_rounded_value(v):
    toolpath_io._SPELLED.clear()
    assert toolpath_io._spell(v) == reference(v)
    assert toolpath_io._spell(v) == reference(v)      # cached spelling too


@given(st.decimals(min_value=-100000, max_value=100000, places=7, allow_nan=False,
                   allow_infinity=False))
def test_spell_on_cam_like_decimals(d):
    v = float(d)
    assert toolpath_io._spell(v) == reference(v)


def test_negative_zero_and_tiny_values():
    for v in (-0.0, 0.0, -1e-7, 4e-7, 5e-5, -9.99999e-5, 1e-4, 123456789.1234564, 1e9, 1e17):
        assert toolpath_io._spell(v) == reference(v), v


@given(st.lists(st.tuples(st.floats(-1e4, 1e4), st.floats(-1e4, 1e4), st.floats(-1e4, 1e4)),
                min_size=1, max_size=5))
def test_json_lines_with_shared_start_dicts(points):
    """Records whose start is the previous end (as the interpreter makes them) and records with
    fresh dicts both serialise to what json gives for the rounded values."""
    prev = {"X": 0.0, "Y": 0.0, "Z": 0.0}
    for i, (x, y, z) in enumerate(points):
        end = {"X": x, "Y": y, "Z": z}
        start = prev if i % 2 == 0 else dict(prev)
        rec = ToolpathRecord(i + 1, "a.nc", i + 1, "linear", start, end, feed=100.0,
                             feed_mode="per_min")
        line = json.loads(toolpath_io.to_json_line(rec))
        assert line["start"] == {k: round(v, 6) + 0.0 for k, v in prev.items()}
        assert line["end"] == {k: round(v, 6) + 0.0 for k, v in end.items()}
        prev = end


def test_non_finite_numbers_stay_valid_json():
    # a coordinate never arrives non-finite (NC108 stops it first); were one to, the line stays valid
    # JSON (null); a non-finite scalar is an unknown value and its key is left out
    rec = ToolpathRecord(1, "a.nc", 1, "linear", {"X": 0.0}, {"X": math.nan}, feed=math.inf)
    d = json.loads(toolpath_io.to_json_line(rec))
    assert d["end"] == {"X": None} and "feed" not in d
