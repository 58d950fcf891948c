"""The Fagor 8060/8065 dialect: conformance programs with hand-computed toolpath facts, constructs
read one by one, lint findings, detection, and parse∘emit round trips (a table of constructs and a
hypothesis strategy that writes valid Fagor programs).

Every expected value below was worked out by hand from the program text and the manual
(../shared/specs/fagor8065.md), not taken from nctrans's output.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from nctrans import cli
from nctrans import detection as detect
from nctrans import equivalence as equiv
from nctrans.dialects.base import get
from nctrans.interp import interpret
from nctrans.machine import Axis, Machine, Tool, default_mill
from roundtrip import assert_toolpath_round_trip

REPO = Path(__file__).resolve().parents[1]
CORPUS = REPO / "corpus" / "fagor"
PROGRAMS = sorted(CORPUS.glob("*.nc"))
MOVES = ("rapid", "linear", "arc")


def _parse(text: str, name: str = "t.nc"):
    return get("fagor").parse(text, name)


def _run(text: str, machine=None, name: str = "t.nc"):
    res = _parse(text, name)
    diags: list = []
    recs = list(interpret(res.program, machine or default_mill(), diagnostics=diags))
    return res, recs, diags


def _moves(recs):
    return [r for r in recs if r.kind in MOVES]


def _end(r) -> tuple:
    return tuple(round(r.end.get(a, 0.0), 4) for a in "XYZ")


@lru_cache(maxsize=None)
def _corpus(name: str, machine_key: str = "default"):
    return _run((CORPUS / name).read_text(encoding="utf-8"), MACHINES[machine_key](), name)


def _offsets_machine() -> Machine:
    m = default_mill()
    m.offsets = {"G55": {"X": 100.0}, "G54.1P1": {"Y": 50.0}}
    return m


def _tool_machine() -> Machine:
    m = default_mill()
    m.tools = [Tool(number=1, length=50.0, radius=2.0)]
    return m


MACHINES = {"default": default_mill, "offsets": _offsets_machine, "tool": _tool_machine}


# ------------------------------------------------------------------ the conformance programs

# program -> (machine, the end point of every move in order)
ENDS = {
    "01-structure.nc": ("default", [(0, 0, 5), (1, 1, 5), (1, 1, -1)]
                        + [(11, 1, -1), (11, 11, -1), (1, 11, -1), (1, 1, -1)] * 2 + [(1, 1, 5)]),
    "02-parameters.nc": ("default", [(14, 20, 5), (14, 20, -2), (13, 11, -2), (21, 10.5, -2), (5, -5, -2)]),
    "03-flow.nc": ("default", [(0, 0, 0), (10, 0, 0), (30, 0, 0), (30, 1, 0), (30, 2, 0), (30, 3, 0),
                               (30, 3, -6), (60, 3, -6), (60, 40, -6), (70, 40, -6), (70, 80, -6)]),
    "04-arcs.nc": ("default", [(0, 0, 0), (10, 0, 0), (0, 10, 0), (10, 20, 0), (0, 20, 0), (20, 0, 0),
                               (20, 0, -5), (0, 20, -5), (-10, 10, -5), (0, 0, -5)]),
    "05-offsets.nc": ("offsets", [(0, 0, 0), (110, 0, 0), (0, 50, 0), (5, 5, 0), (15, 5, 0), (30.4, 5, 0)]),
    "06-frames.nc": ("default", [(0, 0, 0)] + [(0, 10, 0), (0, 0, 0), (-10, 0, 0), (0, 0, 0), (0, -10, 0),
                                               (0, 0, 0), (10, 0, 0), (0, 0, 0)]
                     + [(10, 10, 0), (-5, 5, 0), (-5, -5, 0), (5, -5, 0), (5, 5, 0)]),
    "07-calls.nc": ("default", [(50, 0, 2), (50, 0, -1), (50, 0, 2), (99, 0, 2)]
                    + [p for x in (0, 10, 20) for p in ((x, 0, 2), (x, 0, -3), (x, 0, 2))]
                    + [(20, 5, 2), (7, 0, 2), (7, 0, -2), (7, 0, 2), (7, 9, 2)]),
    # tool 1: length 50 on Z from T1 M6 (D1 implied) until D0; radius 2 left of the path (G41):
    # the entry ends 2 left of the +Y segment at (-2, 0), a circular transition round the corner
    # (0, 0) to (0, 2), 2 left of the +X segment to (20, 2), G40 back on the path at (20, -10)
    "08-tools.nc": ("tool", [(0, -10, 55), (0, -10, 49), (-2, 0, 49), (0, 2, 49), (20, 2, 49),
                             (20, -10, 49), (20, -10, 5)]),
    "09-messages.nc": ("default", [(0, 0, 0), (1, 0, 0), (1, 1, 0), (2, 1, 0), (2, 2, 0), (3, 2, 0), (3, 3, 0)]),
    "10-unmodelled.nc": ("default", [(10, 10, 10), (20, 10, 10), (0, 0, 10)]),
    "11-limits.nc": ("default", [(0, 0, 0), (90, 0, 0)]),
    # V.E.DONE is unknown: the $WHILE condition is taken as false, the loop is not analysed
    "13-interface.nc": ("default", [(0, 0, 50)]),
    "12-machine-test.nc": ("default", [(0, 0, 50), (0, 0, 10), (50, 0, 10), (0, 0, 10), (100, 0, 10),
                                       (0, 0, 10), (0, 0, 50)]),
}


def test_every_conformance_program_has_its_facts():
    assert sorted(ENDS) == [p.name for p in PROGRAMS]


@pytest.mark.parametrize("name", sorted(ENDS))
def test_conformance_program_parses_clean_and_ends_where_computed(name):
    machine, ends = ENDS[name]
    res, recs, diags = _corpus(name, machine)
    syntax = [d for d in res.diagnostics + diags if d.rule.startswith("NC0") or d.severity == "error"]
    assert not syntax, "\n".join(d.format_text() for d in syntax)
    got = [_end(r) for r in _moves(recs)]
    if name == "13-interface.nc":
        assert {("NC135", 8), ("NC107", 8), ("NC103", 4)} <= {(d.rule, d.line) for d in res.diagnostics + diags}
    assert got == [tuple(float(v) for v in e) for e in ends]


def test_arc_facts():
    """04-arcs: centres and directions, worked out from the program."""
    _, recs, _ = _corpus("04-arcs.nc")
    arcs = [r for r in recs if r.kind == "arc"]
    want = [((0, 0), "ccw"), ((10, 10), "cw"), ((0, 0), "cw"), ((10, 0), "ccw"), ((0, 0), "ccw"),
            ((0, 10), "cw"), ((0, 10), "cw")]
    got = [((round(a.center["X"], 4), round(a.center["Y"], 4)), a.direction) for a in arcs]
    assert got == [((float(x), float(y)), d) for (x, y), d in want]
    helix = arcs[3]
    assert helix.start["Z"] == 0 and helix.end["Z"] == -5    # a full circle rising to Z-5


def test_tangent_and_three_point_arcs():
    _, recs, _ = _run("%T\nG00 X0 Y0 Z0\nG01 X10 F100\nG08 X20 Y10\nG09 X20 Y30 I30 J20\nX0\nM30\n")
    arcs = [r for r in recs if r.kind == "arc"]
    # G08 from (10,0) heading +X to (20,10): centre (10,10), counter-clockwise
    assert (round(arcs[0].center["X"], 6), round(arcs[0].center["Y"], 6), arcs[0].direction) == (10, 10, "ccw")
    # G09 from (20,10) through (30,20) to (20,30): centre (20,20), counter-clockwise; G01 again after
    assert (round(arcs[1].center["X"], 6), round(arcs[1].center["Y"], 6), arcs[1].direction) == (20, 20, "ccw")
    assert recs[-2].kind == "linear" and _end(recs[-2]) == (0, 30, 0)


def test_def_macros_expand_as_the_manual_shows():
    """spec §16.12: P1=800 "START" F450 with #DEF "START"="SP1 M3" is S800 M3 F450; a macro may
    name another with \\"NAME\\"; an undefined one is an error at its line."""
    text = ('%M\n#DEF "START"="SP1 M3" "GO"="G01 X10 F100 \\"START\\""\nP1=800 "START" F450\n'
            'G00 X0 Y0 Z0\n"GO"\n"NOPE"\nM30\n')
    res, recs, _ = _run(text)
    spindle = [r for r in recs if r.kind == "spindle"]
    assert spindle[0].spindle == 800 and spindle[0].spindle_dir == "cw"
    assert _end(_moves(recs)[-1]) == (10, 0, 0) and _moves(recs)[-1].feed == 100
    assert ("NC102", 6) in {(d.rule, d.line) for d in res.diagnostics}


def test_tool_facts():
    """08-tools: one tool change, three dwells of 0.5 s, 2 s and 1.5 s, the spindle at 1000 rpm."""
    _, recs, _ = _corpus("08-tools.nc", "tool")
    assert [r.tool for r in recs if r.kind == "tool_change"] == [1]
    assert [r.dwell_s for r in recs if r.kind == "dwell"] == [0.5, 2.0, 1.5]
    spindle = [r for r in recs if r.kind == "spindle"]
    assert spindle[0].spindle == 1000 and spindle[0].spindle_dir == "cw"


def test_unmodelled_constructs_are_named_at_their_line():
    res, _, _ = _corpus("10-unmodelled.nc")
    found = {(d.rule, d.line) for d in res.diagnostics}
    assert {("NC416", 5), ("NC416", 6), ("NC415", 8), ("NC415", 9), ("NC415", 10)} <= found


def test_software_limits_are_data_for_the_machine_check():
    res, _, _ = _corpus("11-limits.nc")
    limits = res.program.meta["soft_limits"]
    assert limits == [{"line": 3, "bound": "lower", "axes": {"X": -100.0, "Y": -50.0, "Z": -200.0},
                       "incremental": False},
                      {"line": 4, "bound": "upper", "axes": {"X": 100.0, "Y": 50.0, "Z": 0.0},
                       "incremental": False}]
    res = _parse("%L\nG91 G198 X-700\nM30\n")                # G91: relative to the limit in force
    assert res.program.meta["soft_limits"][0]["incremental"] is True


def test_system_variables_are_read_from_the_machine_or_reported():
    text = "%V\nP100 = V.MPA.MAXFEED.X\nG01 X10 FP100\nM30\n"
    res, recs, diags = _run(text)
    assert ("NC135", 2) in {(d.rule, d.line) for d in res.diagnostics}
    assert all(r.feed != 0 for r in _moves(recs))            # never silently 0
    machine = default_mill()
    machine.variables = {"V.MPA.MAXFEED.X": 5000.0}
    _, recs, _ = _run(text, machine)
    assert _moves(recs)[0].feed == 5000.0


# ------------------------------------------------------------------ constructs one by one

# (Fagor block after "G00 X0 Y0 Z0", end point of its last move)
CONSTRUCTS = [
    ("G01 X10 Y-5 F100", (10, -5, 0)),
    ("G1 X 10 Y -5 F100", (10, -5, 0)),                     # blanks inside words
    ("P1=4 P2=P1*2\nG01 XP2 F100", (8, 0, 0)),              # several assignments in one block
    ("P100=6\nG01 X[P100/2] F[P100*100]", (3, 0, 0)),
    ("P1=2\nP[P1+100]=7\nG01 XP102 F100", (7, 0, 0)),        # indirect parameter
    ("P1=$4A\nG01 XP1 F100", (74, 0, 0)),                    # hex constant
    ("P1=1 + 2 == 3\nG01 XP1 F100", (1, 0, 0)),              # relational below +
    ("P1=[1 == 1] + [2 == 3]\nG01 XP1 F100", (1, 0, 0)),     # + as OR on conditions
    ("P1=SQR[3]\nG01 XP1 F100", (9, 0, 0)),                  # SQR is the square
    ("P1=ARG[0,1]\nG01 XP1 F100", (90, 0, 0)),               # angle of (0, 1), degrees
    ("P1=COS[60]*10\nG01 XP1 F100", (5, 0, 0)),              # degrees
    ("P1=FRACT[2.75]*4\nG01 XP1 F100", (3, 0, 0)),
    ("P1=DEXP[2]\nG01 XP1 F100", (100, 0, 0)),
    ("P1 = 5 MOD 2 + 2 ** 3\nG01 XP1 F100", (9, 0, 0)),
    ("P1=10\nP1 -= 4\nP1 *= 2\nG01 XP1 F100", (12, 0, 0)),   # compound assignment
    ("G91 G01 X5 F100\nX5", (10, 0, 0)),
    ("G01 G91 X5 Y5 F100 NR3", (15, 15, 0)),                 # block repetition
    ("G01 R10 Q90 F100", (0, 10, 0)),                        # polar
    ("G01 X10 F100\nG03 X0 Y10 R10", (0, 10, 0)),
    ("G18 G01 X10 F100\nG02 X0 Z10 I-10 K0", (0, 0, 10)),    # ZX plane, I K
    ("G01 X10 F100\nG08 X20 Y10", (20, 10, 0)),             # tangent arc: centre (10, 10)
    ("G01 X0 F100\nG09 X20 Y0 I10 J10", (20, 0, 0)),         # through (10, 10): centre (10, 0)
    ("N10: G01 X1 F100\n$GOTO N30\nX99\nN30: X2", (2, 0, 0)),
    ("[START] G01 X1 F100\n$IF 0 $GOTO [START]\nX3", (3, 0, 0)),
    ("G01 X1 F100 ; comment\nX2 (comment) Y1 (another)", (2, 1, 0)),
    ("#MCS X5 Y6", (5, 6, 0)),                               # machine coordinates
    ("G30 I10 J10\nG01 R5 Q0 F100", (15, 10, 0)),            # polar origin G30 I J
    ("G01 X5 F100\nG30\nG01 R5 Q90", (5, 5, 0)),             # G30 alone: at the current point
    ("G158 X10\nG01 X5 F100", (15, 0, 0)),                   # incremental zero offset
    ("G158 X10\nG158 Y5\nG01 X0 Y0 F100", (10, 5, 0)),       # G158 replaces per axis
    ("G158 X10\nG158\nG01 X1 F100", (1, 0, 0)),              # G158 alone cancels
    ("G158 X10\nG53 G01 X1 F100", (1, 0, 0)),                # G53 cancels G158 too
    ("G54 G01 X5 F100", (5, 0, 0)),
    ("G159=1 G01 X5 F100", (5, 0, 0)),
]


@pytest.mark.parametrize("block,end", CONSTRUCTS, ids=[c[0].split("\n")[-1] for c in CONSTRUCTS])
def test_construct_is_read_as_the_manual_says(block, end):
    text = f"%T\nG00 X0 Y0 Z0\n{block}\nM30\n"
    res, recs, diags = _run(text)
    bad = [d for d in res.diagnostics + diags if d.severity == "error" or d.rule.startswith("NC0")]
    assert not bad, "\n".join(d.format_text() for d in bad)
    assert _end(_moves(recs)[-1]) == tuple(float(v) for v in end)


@pytest.mark.parametrize("block,end", CONSTRUCTS, ids=[c[0].split("\n")[-1] for c in CONSTRUCTS])
def test_construct_survives_emit_and_parse(block, end):
    """parse∘emit: the Fagor text nctrans writes parses clean and moves the same way."""
    text = f"%T\nG00 X0 Y0 Z0\n{block}\nM30\n"
    _assert_fagor_round_trip(text)


def _assert_fagor_round_trip(text: str, machine=None):
    assert_toolpath_round_trip("fagor", text, machine)


@pytest.mark.parametrize("name", sorted(ENDS))
def test_conformance_program_survives_emit_and_parse(name):
    machine, _ = ENDS[name]
    _assert_fagor_round_trip((CORPUS / name).read_text(encoding="utf-8"), MACHINES[machine]())


# ------------------------------------------------------------------ errors and lint

@pytest.mark.parametrize("text,rule,line", [
    ("%T\n$IF P1 == 1\nG01 X1 F100\nM30\n", "NC006", 2),            # $IF never closed
    ("%T\nP1=0\n$DO\nP1=P1+1\nM30\n", "NC006", 3),                  # $DO never closed
    ("%T\n$GOTO [NOWHERE]\nM30\n", "NC102", 2),                      # jump to a missing label
    ("%T\n$GOTO N99\nN10: G00 X1\nM30\n", "NC102", 2),
    ("%T\nG01 X10\nM30\n", "NC202", 2),                              # cutting move, no feed
    ("%T\nG01 XP5 F100\nM30\n", "NC101", 2),                          # P5 never assigned: not 0
    ("%T\n$ENDIF\nM30\n", "NC002", 2),
    ("%T\nG01 X[1+2 F100\nM30\n", "NC003", 2),
    ("%T\nG01 X10 (unclosed\nM30\n", "NC003", 2),
    ("%T\nG01 X10 F100 Y*5\nM30\n", "NC002", 2),
    ("%T\n#COMMENT BEGIN\nG00 X1\n", "NC006", 1),
])
def test_lint_reports_fagor_defects_at_their_line(text, rule, line, tmp_path, capsys):
    path = tmp_path / "p.nc"
    path.write_text(text, encoding="utf-8")
    status = cli.main(["lint", str(path), "--from", "fagor", "--format", "json"])
    import json
    report = json.loads(capsys.readouterr().out)
    found = {(d["rule"], d["line"]) for d in report["diagnostics"]}
    assert (rule, line) in found, found
    assert status == 1


def test_clean_program_lints_clean(tmp_path, capsys):
    path = tmp_path / "p.nc"
    path.write_text((CORPUS / "03-flow.nc").read_text(encoding="utf-8"), encoding="utf-8")
    assert cli.main(["lint", str(path), "--from", "fagor"]) == 0, capsys.readouterr()


@pytest.mark.parametrize("path", PROGRAMS, ids=[p.name for p in PROGRAMS])
def test_conformance_programs_are_detected_as_fagor(path):
    guess = detect.detect(path.read_text(encoding="utf-8"), path.name)
    assert guess.dialect == "fagor", guess.describe()


# ------------------------------------------------------------------ generated programs

_num = st.integers(-50, 50)


@st.composite
def _blocks(draw, depth=0):
    kind = draw(st.sampled_from(["move", "move", "arc", "param", "if", "for", "while"] if depth < 2
                                else ["move", "arc", "param"]))
    if kind == "move":
        g = draw(st.sampled_from(["G00", "G01"]))
        x, y = draw(_num), draw(_num)
        return [f"{g} X{x} Y[P1+{y}] F{draw(st.integers(50, 900))}"]
    if kind == "arc":
        r = draw(st.integers(1, 20))
        return [f"G01 X{r} Y0 F300", f"G03 X0 Y{r} I-{r} J0", f"G02 X{r} Y0 R{r}"]
    if kind == "param":
        return [f"P1 = P1 {draw(st.sampled_from(['+', '-', '*']))} {draw(st.integers(1, 3))}",
                f"P100 = SQR[P1] MOD 7"]
    body = [b for _ in range(draw(st.integers(1, 2))) for b in draw(_blocks(depth=depth + 1))]
    if kind == "if":
        els = [b for b in draw(_blocks(depth=depth + 1))]
        return [f"$IF [P1 > {draw(_num)}] * [P100 < 5]", *body, "$ELSE", *els, "$ENDIF"]
    if kind == "for":
        var = f"P{10 + depth}"
        return [f"$FOR {var} = 1, {draw(st.integers(1, 3))}, 1", *body, "$ENDFOR"]
    var = f"P{20 + depth}"
    return [f"{var} = 0", f"$WHILE {var} < {draw(st.integers(1, 3))}", f"{var} = {var} + 1", *body,
            "$ENDWHILE"]


@st.composite
def fagor_programs(draw):
    """Valid Fagor programs: moves, arcs by centre and radius, parameters, nested $IF/$FOR/$WHILE."""
    lines = ["%GEN", "P1 = 1", "P100 = 0", "G00 X0 Y0 Z0"]
    for _ in range(draw(st.integers(1, 5))):
        lines += draw(_blocks())
    return "\n".join(lines + ["M30"]) + "\n"


@settings(max_examples=40, deadline=None)
@given(fagor_programs())
def test_generated_programs_parse_clean_and_survive_emit_and_parse(text):
    res = _parse(text)
    assert not [d for d in res.diagnostics if d.rule.startswith("NC0") or d.severity == "error"], text
    _assert_fagor_round_trip(text)


@settings(max_examples=25, deadline=None)
@given(fagor_programs())
def test_generated_programs_convert_to_iso_equivalently(text):
    from nctrans.convert import convert
    from nctrans.lower.flatten import flatten
    program = _parse(text).program
    a = list(interpret(program, default_mill(), diagnostics=[]))
    conv = convert(program, get("iso-m"),
                   flatten_with=lambda d: flatten(program, default_mill(), diagnostics=d))
    assert conv.text is not None, [d.format_text() for d in conv.diagnostics]
    b = list(interpret(get("iso-m").parse(conv.text, "g.nc").program, default_mill(), diagnostics=[]))
    diff = equiv.compare(a, b)
    assert diff is None, conv.text + diff.format()


_plain_word = st.tuples(st.sampled_from("GXYZIJKFSTRQM"), st.sampled_from(["", "-"]),
                        st.one_of(st.integers(0, 999).map(str),
                                  st.decimals(0, 999, places=3).map(lambda d: f"{d}".rstrip("0"))))


@settings(max_examples=60, deadline=None)
@given(st.lists(_plain_word, min_size=1, max_size=6))
def test_plain_word_fast_path_reads_as_the_grammar(words):
    """Blocks of letter-number words skip lark (frontend._plain_items); the result must be the
    grammar's own reading of the same block."""
    from nctrans.dialects.fagor import blocks, frontend
    code = " ".join(f"{l}{s}{n if not n.endswith('.') else n + '0'}" for l, s, n in words)
    assert frontend._plain_items(code) is not None
    line = blocks.split(1, code)
    fast = frontend.Lowerer("f").items(frontend._plain_items(line.code), line)
    slow = frontend.Lowerer("f").items(frontend.parser().parse(line.code, start="start").children, line)
    assert fast == slow
