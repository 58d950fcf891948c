"""Diagnostic output formats (text, json, sarif, github) and the rule catalogue behind them."""
import json
import re
from pathlib import Path

import jsonschema
import pytest
from hypothesis import given, settings, strategies as st

from nctrans import catalogue
from nctrans.diagnostics import Diagnostic, Fix
from nctrans.output import format_github, render, sarif_document, summary

SCHEMA = json.loads((Path(__file__).parent / "data" / "sarif-schema-2.1.0.json").read_text())
VALIDATOR = jsonschema.Draft4Validator(SCHEMA)

DIAGS = [
    Diagnostic("NC202", "error", "feed move without feed rate", "part.nc", 12, 5, 12, 14),
    Diagnostic("NC201", "warning", "G90 and G91 in one block, G91 wins", "sub dir/o1000.nc", 3, 1),
    Diagnostic("NC501", "info", "lower-case words", "/abs/path/a.mpf", 1, 1,
               fix=Fix("G1 X10", 1, 1, 1, 7)),
    Diagnostic("NC001", "error", "UTF-16 text: save as UTF-8/ASCII", "<stdin>", 1, 1),
]


def test_text_is_gcc_style():
    out = render("text", DIAGS, 3).splitlines()
    rx = re.compile(r"^(.+):(\d+):(\d+): (error|warning|info)\[(NC\d{3})\] (.+)$")
    assert all(rx.match(line) for line in out), out
    assert "part.nc:12:5: error[NC202] feed move without feed rate" in out


def test_json_document_shape():
    doc = json.loads(render("json", DIAGS, 3))
    assert set(doc) == {"diagnostics", "files", "summary"}
    assert doc["files"] == 3
    assert doc["summary"] == {"error": 2, "warning": 1, "info": 1}
    for d in doc["diagnostics"]:
        assert {"rule", "severity", "file", "line", "column", "end_line", "end_column", "message"} <= set(d)
    fixed = [d for d in doc["diagnostics"] if "fix" in d]
    assert fixed and fixed[0]["fix"]["replacement"] == "G1 X10"


def test_json_with_no_diagnostics():
    doc = json.loads(render("json", [], 0))
    assert doc == {"diagnostics": [], "files": 0, "summary": {"error": 0, "warning": 0, "info": 0}}


def test_sarif_is_valid_against_the_official_schema():
    doc = json.loads(render("sarif", DIAGS, 3))
    VALIDATOR.validate(doc)
    run = doc["runs"][0]
    ids = [r["id"] for r in run["tool"]["driver"]["rules"]]
    assert ids == catalogue.load().codes()
    levels = {r["ruleId"]: r["level"] for r in run["results"]}
    assert levels == {"NC202": "error", "NC201": "warning", "NC501": "note", "NC001": "error"}
    res = next(r for r in run["results"] if r["ruleId"] == "NC202")
    assert run["tool"]["driver"]["rules"][res["ruleIndex"]]["id"] == "NC202"
    loc = res["locations"][0]["physicalLocation"]
    assert loc["artifactLocation"]["uri"] == "part.nc"
    assert loc["region"] == {"startLine": 12, "startColumn": 5, "endLine": 12, "endColumn": 14}
    uris = {r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] for r in run["results"]}
    assert "sub%20dir/o1000.nc" in uris and "file:///abs/path/a.mpf" in uris


def test_sarif_schema_rejects_a_broken_document():
    """The vendored schema is really checking: a result without message fails."""
    doc = sarif_document(DIAGS[:1])
    del doc["runs"][0]["results"][0]["message"]
    with pytest.raises(jsonschema.ValidationError):
        VALIDATOR.validate(doc)


diag_strategy = st.builds(
    Diagnostic,
    st.sampled_from(catalogue.load().codes() + ["NC999"]),
    st.sampled_from(["error", "warning", "info"]),
    st.text(min_size=1, max_size=40),
    st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=20),
    st.integers(1, 10_000), st.integers(1, 500), st.integers(0, 10_000), st.integers(0, 500),
)


@settings(max_examples=60, deadline=None)
@given(st.lists(diag_strategy, max_size=6))
def test_sarif_valid_for_any_diagnostics(diags):
    VALIDATOR.validate(json.loads(render("sarif", diags, 1)))


def test_github_workflow_commands():
    lines = format_github(DIAGS).splitlines()
    assert lines[0] == "::error file=part.nc,line=12,col=5,endLine=12,endColumn=14,title=NC202::feed move without feed rate"
    assert lines[1].startswith("::warning file=sub dir/o1000.nc,line=3,col=1,")
    assert lines[2].startswith("::notice ")


def test_github_escapes_newlines_percent_and_property_separators():
    d = Diagnostic("NC002", "error", "50% bad\nsecond line", "a,b:c.nc", 1, 1)
    line = format_github([d]).rstrip("\n")
    assert "\n" not in line
    assert line.endswith("::50%25 bad%0Asecond line")
    assert "file=a%2Cb%3Ac.nc," in line


def test_render_sorts_by_file_and_position():
    ds = [Diagnostic("NC002", "error", "m", "b.nc", 1, 1), Diagnostic("NC002", "error", "m", "a.nc", 9, 1),
          Diagnostic("NC002", "error", "m", "a.nc", 2, 7)]
    out = render("text", ds, 2).splitlines()
    assert [l.split(": ")[0] for l in out] == ["a.nc:2:7", "a.nc:9:1", "b.nc:1:1"]


def test_summary_counts_every_severity():
    assert summary(DIAGS) == {"error": 2, "warning": 1, "info": 1}


# --------------------------------------------------------------------------- catalogue

def test_catalogue_rules_are_complete_and_unique():
    cat = catalogue.load()
    codes = cat.codes()
    assert len(codes) == len(set(codes)) >= 20
    for r in cat.rule:
        assert re.match(r"^NC\d{3}$", r.code)
        assert r.summary and r.why and r.good and r.name
        assert r.code[:3] in catalogue.FAMILIES


def test_catalogue_rejects_a_duplicate_or_malformed_rule(tmp_path):
    good = catalogue.CATALOGUE_PATH.read_text()
    p = tmp_path / "dup.toml"
    first = good[good.index("[[rule]]"):good.index("[[rule]]", good.index("[[rule]]") + 1)]
    p.write_text(good + "\n" + first)
    with pytest.raises(ValueError, match="twice"):
        catalogue.load(p)
    p.write_text(first.replace('code = "NC001"', 'code = "X1"'))
    with pytest.raises(ValueError):
        catalogue.load(p)


def test_rule_documentation_has_every_part():
    text = catalogue.format_rule(catalogue.load().get("NC202"))
    for part in ("NC202", "missing-feed", "Why:", "Bad:", "G1 X10", "Good:", "F200", "Fix:"):
        assert part in text


# --------------------------------------------------------------------------- toolpath writers

import csv
import io
import math

from nctrans.toolpath import ToolpathRecord
from nctrans.toolpath_io import CSV_COLUMNS, Summary, to_json_line, write_csv, write_jsonl

coords = st.dictionaries(st.sampled_from(["X", "Y", "Z", "A"]), st.floats(-1e4, 1e4), min_size=1, max_size=4)
records = st.builds(
    ToolpathRecord, st.integers(1, 10**6), st.sampled_from(["a.nc", "dir/b c.mpf", 'q"x.nc', "info.nc"]),
    st.integers(1, 10**5), st.sampled_from(["rapid", "linear", "arc", "dwell", "spindle", "stop"]),
    st.none() | coords, st.none() | coords, st.none() | coords, st.none() | st.sampled_from(["cw", "ccw"]),
    st.none() | st.sampled_from(["XY", "ZX", "YZ"]), st.none() | st.integers(0, 3),
    st.none() | st.floats(0, 1e5), st.none() | st.sampled_from(["per_min", "per_rev", "inverse_time"]),
    st.none() | st.floats(0, 3e4), st.none() | st.integers(0, 99), st.none() | st.floats(0, 100))


def _rounded(x):
    if isinstance(x, dict):
        return {k: _rounded(v) for k, v in x.items()}
    if isinstance(x, float):
        return round(x, 6) + 0.0
    return x


@settings(max_examples=200, deadline=None)
@given(records)
def test_jsonl_line_is_the_record_rounded_with_absent_keys(rec):
    line = to_json_line(rec)
    assert "\n" not in line and ", " not in line.replace('b c', '')
    assert json.loads(line) == _rounded(rec.to_dict())


def test_jsonl_non_finite_and_negative_zero():
    rec = ToolpathRecord(1, "a.nc", 1, "linear", start={"X": -0.0, "Y": float("nan")}, end={"X": 1.23456789},
                         feed=float("inf"))
    assert json.loads(to_json_line(rec)) == {"seq": 1, "file": "a.nc", "line": 1, "kind": "linear",
                                             "start": {"X": 0.0, "Y": None}, "end": {"X": 1.234568}}
    # (a non-finite scalar is an unknown value: its key is left out, never null)


def test_writers_stream_one_record_at_a_time():
    seen = []

    def gen():
        for i in range(1, 4):
            seen.append(i)
            yield ToolpathRecord(i, "a.nc", i, "rapid", start={"X": 0.0}, end={"X": float(i)})

    class Sink(io.StringIO):
        def write(self, s):
            # by the time line i is written, the generator has produced exactly i records
            if s.startswith('{"seq":'):
                assert len(seen) == json.loads(s)["seq"]
            return super().write(s)

    out = Sink()
    assert write_jsonl(gen(), out) == 3 and len(out.getvalue().splitlines()) == 3
    out = io.StringIO()
    assert write_csv((ToolpathRecord(i, "a.nc", i, "arc", start={"X": 1.0}, end={"Y": 2.0}, center={"Z": 0.5},
                                     direction="cw", plane="XY", turns=0) for i in (1, 2)), out) == 2
    rows = list(csv.reader(io.StringIO(out.getvalue())))
    assert rows[0] == CSV_COLUMNS and len(rows) == 3
    row = dict(zip(rows[0], rows[1]))
    assert (row["start_X"], row["end_Y"], row["center_Z"], row["direction"], row["start_Y"]) == ("1.0", "2.0", "0.5", "cw", "")


def test_summary_lengths_bbox_time_and_tools():
    s = Summary()
    s.add(ToolpathRecord(1, "a", 1, "tool_change", tool=3))
    s.add(ToolpathRecord(2, "a", 2, "rapid", start={"X": 0.0, "Y": 0.0, "Z": 0.0}, end={"X": 10.0, "Y": 0.0, "Z": 0.0}))
    # a half circle ccw from (10,0) to (-10,0) round (0,0): passes Y=+10
    s.add(ToolpathRecord(3, "a", 3, "arc", start={"X": 10.0, "Y": 0.0, "Z": 0.0}, end={"X": -10.0, "Y": 0.0, "Z": 0.0},
                         center={"X": 0.0, "Y": 0.0, "Z": 0.0}, direction="ccw", plane="XY", turns=0,
                         feed=600.0, feed_mode="per_min"))
    s.add(ToolpathRecord(4, "a", 4, "dwell", dwell_s=2.0))
    assert math.isclose(s.rapid_mm, 10.0) and math.isclose(s.feed_mm, 10 * math.pi)
    assert (s.lo["Y"], s.hi["Y"]) == (0.0, 10.0) and (s.lo["X"], s.hi["X"]) == (-10.0, 10.0)
    assert math.isclose(s.time_s, 60 * 10 / 10000 + 60 * 10 * math.pi / 600 + 2.0)
    text = s.format(diagnostics=4)
    assert "tools: T3" in text and "diagnostics: 4" in text and "arc 1" in text
