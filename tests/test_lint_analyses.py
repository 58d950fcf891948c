"""The analyses added for shops: each finds its defect at the defect's line with the right rule, in
every dialect it applies to, and stays silent on the corrected program. Expected lines are counted
by hand from the programs below."""
from __future__ import annotations

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from nctrans import linting, pipeline, plainrun
from nctrans.source import from_text

OURS = ("NC104", "NC110", "NC111", "NC112", "NC208", "NC209")


def found(text: str, dialect: str, machine=None, stream: bool = True) -> list[tuple[int, str]]:
    ld = pipeline.load_source(from_text(text, f"t.{dialect}"), dialect=dialect, stream=stream)
    return sorted((d.line, d.rule) for d in linting.lint_loaded(ld, machine) if d.rule in OURS)


# --------------------------------------------------------------------------- Sinumerik types

@pytest.mark.parametrize("text, expected", [
    ('DEF REAL LEN\nDEF STRING[8] TXT="12"\nLEN=TXT\nM30\n', [(3, "NC104")]),
    ('DEF INT COUNT\nCOUNT="3"\nM30\n', [(2, "NC104")]),
    ('DEF STRING[8] TXT\nDEF REAL LEN=2\nTXT=LEN\nM30\n', [(3, "NC104")]),       # REAL -> STRING: no
    ('DEF BOOL FLAG\nDEF STRING[8] TXT="A"\nFLAG=TXT\nM30\n', []),              # STRING -> BOOL: yes
    ('DEF STRING[8] TXT\nDEF BOOL FLAG=1\nTXT=FLAG\nM30\n', []),                # BOOL -> STRING: yes
    ('DEF STRING[3] CODE="ABCD"\nM30\n', [(1, "NC110")]),
    ('DEF STRING[3] CODE\nCODE="ABC"\nCODE="ABCDE"\nM30\n', [(3, "NC110")]),
])
def test_sinumerik_assignment_types(text, expected):
    assert found(text, "sinumerik") == expected


# --------------------------------------------------------------------------- never set

def test_never_set_variables():
    assert found("DEF REAL LEN, WIDTH\nLEN=5\nG1 X=LEN F100\nG1 Y=WIDTH\nM30\n", "sinumerik") == [(4, "NC111")]
    assert found("DEF INT I\nDEF REAL DEPTH\nFOR I=1 TO 2\nDEPTH=I*2\nENDFOR\nG1 X=DEPTH F100\nM30\n", "sinumerik") == []
    iso = "#101=5\nG0 X0 Y0\nG1 X#101 Y#102 F100\nG1 X#1\nM30\n"
    assert found(iso, "iso-m") == [(3, "NC111"), (4, "NC111")]
    assert found("#1=0\nWHILE [#1 LT 2] DO1\nG1 X#1 F100\n#1=#1+1\nEND1\nM30\n", "iso-m") == []
    # a macro file (ends M99, called with G65): its #1-#33 are the caller's arguments
    assert found("G1 X#1 Y#24 F100\nM99\n", "iso-m") == []
    # G65 arguments are bound in the callee, not read in the caller
    assert found("G65 P9001 A1. C2.\nM30\nO9001\nG1 X#1 Y#3 F100\nM99\n", "iso-m") == []


# --------------------------------------------------------------------------- unreachable

@pytest.mark.parametrize("stream", [True, False])
def test_code_after_program_end(stream):
    assert found("G0 X0 Y0\nM30\nG1 X10 F100\nG1 X20\n", "iso-m", stream=stream) == [(3, "NC112")]
    assert found("G0 X0 Y0\nM30\nM2\n%\n", "iso-m", stream=stream) == []
    assert found("G0 X0\nG1 X5 F100\nM30\n", "iso-m", stream=stream) == []


def test_jump_target_after_end_is_reachable():
    text = "#1=1\nIF [#1 EQ 1] GOTO 100\nM30\nN100 G1 X10 F100\nM30\n"
    assert found(text, "iso-m") == []
    assert found("G0 X0\nM30\nN20 G1 X10 F100\n", "iso-m") == [(3, "NC112")]
    assert found("G0 X0\nM30\nG1 X10 F100\n", "sinumerik") == [(3, "NC112")]


# --------------------------------------------------------------------------- cutter compensation

MACHINE_TEXT = ('name = "m"\nkind = "mill"\n[axes.X]\nkind = "linear"\nmin = -500.0\nmax = 500.0\n'
                '[axes.Y]\nkind = "linear"\nmin = -500.0\nmax = 500.0\n[axes.Z]\nkind = "linear"\n'
                'min = -500.0\nmax = 500.0\n[[tools]]\nnumber = 1\nlength = 50.0\nradius = 3.0\n')


@pytest.fixture
def machine(tmp_path):
    p = tmp_path / "m.toml"
    p.write_text(MACHINE_TEXT)
    return pipeline.load_machine(str(p))


def test_compensation_without_d_word_iso(machine):
    text = "T1 M6\nS1000 M3\nG0 X0 Y0\nG42 G1 X10 Y10 F100\nG1 X20\nG40 G1 X30\nM30\n"
    assert found(text, "iso-m", machine) == [(4, "NC208")]
    assert found(text.replace("G42 G1", "G42 D1 G1"), "iso-m", machine) == []


def test_sinumerik_compensates_with_the_default_edge(machine):
    text = "T1 M6\nS1000 M3\nG0 X0 Y0\nG41 G1 X10 Y0 F100\nG1 X20\nG40 G0 X30 Y30\nM30\n"
    assert found(text, "sinumerik", machine) == []
    ld = pipeline.load_source(from_text(text, "t.mpf"), dialect="sinumerik")
    with_default = [r for r in pipeline.toolpath_of(ld, machine) if r.kind == "linear"]
    ld = pipeline.load_source(from_text(text.replace("G41 G1", "G41 D1 G1"), "t.mpf"), dialect="sinumerik")
    with_d1 = [r for r in pipeline.toolpath_of(ld, machine) if r.kind == "linear"]
    assert [r.end for r in with_default] == [r.end for r in with_d1]
    assert with_default[0].end["Y"] == pytest.approx(3.0)      # left of +X by the 3 mm radius


# --------------------------------------------------------------------------- spindle stopped

@pytest.mark.parametrize("native", [True, False])
def test_feed_move_after_m5(native, monkeypatch):
    if not native:
        monkeypatch.setattr(plainrun, "native", None)
    body = "".join(f"G1 X{i} Y{i % 7}.5 F300\n" for i in range(1, 40))
    text = "S1000 M3\nG0 X0 Y0\n" + body + "M5\nG0 Z50\n" + body + "M30\n"
    assert found(text, "iso-m") == [(44, "NC209")]     # lines 3-41 cut, 42 M5, 43 G0, 44 the first G1
    assert found(text.replace("M5\n", "M5\nM3\n"), "iso-m") == []
    assert found("G0 X0\nG1 X10 F100\nM30\n", "iso-m") == []       # the program never mentions the spindle


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(["G0", "G1"]), st.integers(-50, 50), st.integers(-50, 50)),
                min_size=2, max_size=30), st.data())
def test_correct_programs_stay_clean_and_a_stop_is_found_where_it_is(moves, data):
    lines = ["S2000 M3", "F200"] + [f"{g} X{x} Y{y}" for g, x, y in moves] + ["M5", "M30"]
    assert found("\n".join(lines) + "\n", "iso-m") == []
    feeds = [i for i, (g, _, _) in enumerate(moves) if g == "G1"]
    if not feeds:
        return
    k = data.draw(st.sampled_from(feeds))
    lines.insert(2 + k, "M5")                          # stop the spindle just before a feed move
    assert found("\n".join(lines) + "\n", "iso-m") == [(2 + k + 2, "NC209")]
