"""`flatten` (convert --flatten): plain motion that drives the same toolpath, proven three ways.

For hand-written ISO macro programs (WHILE loops, G65/M98 calls, G68/G52/G92/mirror/scale, canned
cycles, cutter compensation, inch input) run on a machine with nonzero work offsets, tool lengths
and radii, and for every Sinumerik conformance program (corpus/sinumerik/*.mpf, default machine):
- the flattened IR holds plain motion only: Blocks of modal codes, literal-number moves, feeds,
  tools, spindle, coolant, dwells, stops, program end; no control flow, calls, cycles, frames,
  expressions, compensation or subprograms (walked node by node);
- nctrans's toolpath of the flattened program equals the source's record by record (machine mm,
  1e-6), comes from the same source lines, and `nctrans.equivalence` finds no difference;
- its iso-m emission runs in LinuxCNC's rs274 to PROGRAM_END with the same moves as nctrans's
  toolpath of the source (harness tests/rs274.py; the machine's work offsets are loaded into rs274
  with G10 L2 lines ahead of the program and the tool table is written from the machine model);
- its sinumerik emission parses back to the same toolpath (default machine: the sinumerik emitter
  leaves tool length to the D edge, see KNOWN_SINUMERIK).
Plus the reporting: one NC401 per kind of lowering, NC402 for what cannot be flattened, and
`nctrans convert --flatten` through the CLI.
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

import rs274 as h
from conftest import TextSink
from nctrans import equivalence as equiv
from nctrans.dialects.base import get
from nctrans.interp import interpret
from nctrans.ir import nodes as n
from nctrans.lower.flatten import flatten
from nctrans.machine import Machine, Tool, default_mill

REPO = Path(__file__).resolve().parents[1]
CONFORMANCE = sorted((REPO / "corpus" / "sinumerik").glob("*.mpf"))
TOL = 1e-6
MOTION = ("rapid", "linear", "arc")

MACHINE = Machine(
    tools=[Tool(number=i, length=10.0 * i, radius=0.5 * i) for i in range(1, 6)],
    offsets={"G54": {"X": 100.0, "Y": 50.0, "Z": -200.0}, "G55": {"X": -20.0, "Y": 30.0, "Z": -150.0},
             "G56": {"X": 5.0, "Y": -5.0, "Z": -100.0}})

ISO_PROGRAMS = {
    "while_loops": ("""%
O0100 (WHILE loops, IF GOTO, expressions, arcs by radius)
G21 G90 G17 G54
T1 M6
S2000 M3
M8
G43 H1 G0 X0 Y0 Z10.
#1 = 0
WHILE [#1 LT 3] DO1
#2 = #1 * 15.
G0 X#2 Y0
G1 Z-1. F200.
#3 = 0
WHILE [#3 LT 2] DO2
G91 G1 Y[5. + #3] F[300. + #3 * 10]
G90
#3 = #3 + 1
END2
G2 X[#2 + 10.] Y0 R10.
G0 Z5.
#1 = #1 + 1
END1
IF [#1 NE 3] GOTO 900
G4 P500
G0 X[SQRT[2.] * 10] Y[SIN[30.] * 20]
N900 M9
M5
G49 G0 Z50.
M30
%
""", {"loop", "branch", "expr", "arcform"}),
    "g65_calls": ("""%
O0200 (G65 macro call with arguments, M98 with repeat count)
G21 G90 G17 G55
T2 M6
S1500 M3
G0 X0 Y0 Z5.
G65 P9010 X10. Y10. R4. Z-2. F150.
G65 P9010 X30. Y10. R3. Z-1. F150.
G0 X50. Y0
M98 P9020 L3
G90 G0 Z20.
M5
M30
O9010 (circular pocket: X Y centre, R radius, Z depth, F feed)
G90 G0 X#24 Y#25
G1 Z#26 F#9
G91 G1 X#18
G3 I-#18 J0
G90 G1 X#24 Y#25
G0 Z5.
M99
O9020 (step along X)
G91 G1 X5. F100.
G1 Y2.
G90
M99
%
""", {"call", "expr"}),
    "frames": ("""%
O0300 (G68 rotation, G52 local offset, G92 shift, G51.1 mirror, G51 scale)
G21 G90 G17 G54
T1 M6
S1000 M3
G0 X0 Y0 Z5.
G1 F300.
G68 X10. Y10. R30.
G1 X20. Y10.
G2 X30. Y10. I5. J0
G3 X20. Y10. R5.
G69
G52 X40. Y5.
G0 X0 Y0
G1 X10. Y5.
G2 X15. Y10. R5.
G52 X0 Y0
G0 X60. Y60.
G92 X0 Y0
G1 X5. Y5.
G3 X10. Y0 I5. J0
G92.1
G51.1 X30.
G0 X35. Y20.
G2 X40. Y25. I5. J0
G50.1 X0
G51 X0 Y0 P2.
G1 X10. Y10.
G50
G0 Z50.
M30
%
""", {"frame", "arcform"}),
    "canned_cycles": ("""%
O0400 (canned cycles: G81 G82 G83 G73 G85, G98/G99, G91 with K repeat)
G21 G90 G17 G54
T3 M6
S1200 M3
G43 H3 G0 X0 Y0 Z20.
G98 G81 X10. Y10. Z-5. R2. F100.
X20.
G99 G82 X30. Y10. Z-4. R1. P300
G83 X40. Y10. Z-12. R2. Q3.
G73 X50. Y10. Z-6. R2. Q2.
G85 X60. Y10. Z-5. R2.
G80
G91 G98 G81 X5. Y5. Z-3. R-18. K3
G80 G90
G0 Z30.
M30
%
""", {"cycle"}),
    "cutter_comp": ("""%
O0500 (cutter radius compensation, G56 offset, tool length, G28)
G21 G90 G17 G56
T4 M6
S3000 M3
G43 H4 G0 X-10. Y-10. Z5.
G1 Z-2. F250.
G41 D4 G1 X0 Y0
G1 Y20.
G2 X10. Y30. R10.
G1 X30.
G1 Y0
G1 X0
G40 G1 X-10. Y-10.
G0 Z20.
G28 G91 Z0
G90
M30
%
""", {"comp", "frame"}),
    "inch_units": ("""%
O0600 (inch input, G53 machine move, feed per revolution)
G20 G90 G17 G54
T1 M6
S1000 M3
G0 X1. Y1. Z0.5
G1 Z-0.1 F20.
G2 X2. Y2. I1. J0
G95 G1 X3. F0.01
G94 F15.
G53 G0 Z0
M30
%
""", {"units", "frame"}),
}

# (program, what) -> a bug in someone else's module that makes the property fail (xfail, not strict)
KNOWN_RS274: dict[str, str] = {}   # (flattened tapping: G33 K, LinuxCNC's lead word)
KNOWN_SINUMERIK: dict[str, str] = {}

ALLOWED_STATEMENTS = (n.ModeChange, n.Motion, n.Feed, n.SpindleSpeed, n.ToolSelect, n.ToolChange,
                      n.OffsetSelect, n.Dwell, n.Stop, n.ProgramEnd)
ALLOWED_MODES = {"units": {"mm"}, "distance": {"absolute"}, "cutter_comp": {"off"},
                 "tool_length": {"off", "plus"},
                 # thread: tapping and threads keep their lead as G33 (README, "Sinumerik and ISO cycles")
                 "motion": {"rapid", "linear", "arc_cw", "arc_ccw", "thread"},
                 "plane": {"XY", "ZX", "YZ"}, "feed_mode": {"per_min", "per_rev", "inverse_time"},
                 "spindle": {"cw", "ccw", "off", "orient"}, "coolant": {"mist", "flood", "off"},
                 "work_offset": None}


# ------------------------------------------------------------------ helpers

def parse(dialect: str, text: str, file: str) -> n.Program:
    res = get(dialect).parse(text, file)
    return res.program


def toolpath(program: n.Program, machine=None, resolver=None) -> tuple[list, list]:
    diags: list = []
    recs = list(interpret(program, machine, diagnostics=diags, resolver=resolver))
    return recs, diags


def plain_motion_problems(program: n.Program) -> list[str]:
    """Why `program` is not plain motion (empty when it is)."""
    problems = []
    if program.subprograms:
        problems.append(f"subprograms {list(program.subprograms)}")

    def literal(obj, where):
        if isinstance(obj, n.AxisValue):
            literal(obj.value, where)
        elif isinstance(obj, dict):
            for v in obj.values():
                literal(v, where)
        elif isinstance(obj, (n.Var, n.Unary, n.Binary, n.Func, n.Str)):
            problems.append(f"{where}: expression {obj}")
        elif isinstance(obj, n.Num) and not math.isfinite(obj.value):
            problems.append(f"{where}: non-finite number")

    for node in program.body:
        if type(node) is not n.Block:
            problems.append(f"line {node.span.line}: {type(node).__name__}")
            continue
        where = f"line {node.span.line}"
        if node.label or node.number:
            problems.append(f"{where}: label/number kept ({node.label or node.number})")
        for s in node.body:
            if not isinstance(s, ALLOWED_STATEMENTS):
                problems.append(f"{where}: {type(s).__name__}")
                continue
            if isinstance(s, n.ModeChange):
                allowed = ALLOWED_MODES.get(s.group, set())
                if allowed is not None and s.value not in allowed:
                    problems.append(f"{where}: mode {s.group}={s.value}")
            if isinstance(s, n.Motion):
                if s.radius is not None or s.via or s.polar or s.machine_coords or s.aperture is not None:
                    problems.append(f"{where}: non-plain motion words")
                if any(av.mode is not None for av in s.target.values()):
                    problems.append(f"{where}: per-word distance mode")
            for f in dataclasses.fields(s):
                literal(getattr(s, f.name), where)
    return problems


def record_differences(a: list, b: list, tol: float = TOL, lines: bool = True) -> str | None:
    """First difference between two record streams' motions (kind, end, centre, direction, turns,
    feed, tool, source line), zero-length rapid/linear moves dropped on both sides."""
    def keep(r):
        if r.kind not in MOTION:
            return False
        if r.kind == "arc":
            return True
        return any(abs(r.end.get(k, 0.0) - r.start.get(k, 0.0)) > tol for k in set(r.end) | set(r.start))
    ma = [r for r in a if keep(r)]
    mb = [r for r in b if keep(r)]
    if len(ma) != len(mb):
        return f"{len(ma)} motions in the source, {len(mb)} in the flattened program"
    for i, (x, y) in enumerate(zip(ma, mb)):
        where = f"motion #{i} (source {x.file}:{x.line}, flattened {y.file}:{y.line})"
        if x.kind != y.kind:
            return f"{where}: kind {x.kind} vs {y.kind}"
        for k in set(x.end) | set(y.end):
            if abs(x.end.get(k, 0.0) - y.end.get(k, 0.0)) > tol:
                return f"{where}: end {k} {x.end.get(k)} vs {y.end.get(k)}"
        if x.kind == "arc":
            if (x.direction, x.plane, x.turns or 0) != (y.direction, y.plane, y.turns or 0):
                return f"{where}: arc {x.direction} {x.plane} {x.turns} vs {y.direction} {y.plane} {y.turns}"
            for k in x.center:
                if k in y.center and abs(x.center[k] - y.center[k]) > tol:
                    return f"{where}: centre {k} {x.center[k]} vs {y.center[k]}"
        if x.kind != "rapid" and (x.feed is None) != (y.feed is None) or (
                x.feed is not None and y.feed is not None and abs(x.feed - y.feed) > tol * max(1, x.feed)):
            return f"{where}: feed {x.feed} vs {y.feed}"
        if x.kind != "rapid" and x.feed_mode != y.feed_mode:
            return f"{where}: feed mode {x.feed_mode} vs {y.feed_mode}"
        if x.tool != y.tool:
            return f"{where}: tool {x.tool} vs {y.tool}"
        if lines and (x.file, x.line) != (y.file, y.line):
            return f"{where}: comes from another source line"
    return None


def offsets_prelude(machine: Machine) -> str:
    """G10 L2 lines that load the machine model's work offsets into rs274 (its registers start at 0)."""
    lines = []
    for i, name in enumerate(("G54", "G55", "G56", "G57", "G58", "G59"), start=1):
        off = machine.offsets.get(name)
        if off:
            words = " ".join(f"{a}{v:.6f}" for a, v in off.items())
            lines.append(f"G21 G10 L2 P{i} {words}")
    return "\n".join(lines) + ("\n" if lines else "")


def rs274_run(text: str, name: str, machine: Machine, cache: Path) -> h.Run:
    program = cache / f"flat--{name}.ngc"
    body = text.replace("%\n", "", 1) if text.startswith("%\n") else text
    program.write_text("%\n" + offsets_prelude(machine) + body, encoding="utf-8")
    table = cache / f"flat--{name}.tbl"
    h.write_tool_table(table, [(t.number, t.length, t.radius) for t in machine.tools]
                       or [(i, 0.0, 0.0) for i in range(1, 100)])
    out = cache / f"flat--{name}.out"
    if out.exists():
        out.unlink()
    return h.run_rs274(program, table, out)


class Case:
    """One program flattened once per session: source toolpath, flattened IR, diagnostics."""

    def __init__(self, name: str, dialect: str, text: str, machine: Machine):
        self.name, self.machine = name, machine
        self.source = parse(dialect, text, name)
        self.records, self.source_diags = toolpath(self.source, machine)
        self.diags: list = []
        with h.linuxcnc():                  # the iso-m emission runs in rs274
            self.flat = flatten(self.source, machine, diagnostics=self.diags)
        self.flat_records, self.flat_diags = toolpath(self.flat, machine)


_cases: dict[str, Case] = {}


def case(key: str) -> Case:
    if key not in _cases:
        if key in ISO_PROGRAMS:
            _cases[key] = Case(key + ".nc", "iso-m", ISO_PROGRAMS[key][0], MACHINE)
        else:
            path = REPO / "corpus" / "sinumerik" / key
            _cases[key] = Case(key, "sinumerik", path.read_text(encoding="utf-8"), default_mill())
    return _cases[key]


def _split(records):
    """flatten writes an arc's extra full turns as one full circle per turn (its declared
    lowering): the record-by-record comparisons apply that to the source side; equiv checks
    the geometry without it."""
    from nctrans.lower.flatten import _split_turns
    return [p for r in records for p in (_split_turns(r) if r.kind == "arc" and r.turns else [r])]


ALL = list(ISO_PROGRAMS) + [p.name for p in CONFORMANCE]


def _rs274_params():
    return [pytest.param(k, marks=[pytest.mark.xfail(reason=KNOWN_RS274[k], strict=False)]
                         if k in KNOWN_RS274 else []) for k in ALL]


# ------------------------------------------------------------------ properties

def test_conformance_programs_found():
    assert len(CONFORMANCE) >= 10, CONFORMANCE


@pytest.mark.parametrize("key", ALL)
def test_flattened_program_is_plain_motion(key):
    c = case(key)
    problems = plain_motion_problems(c.flat)
    assert not problems, "\n".join(problems[:10])
    assert type(c.flat.body[-1].body[-1]) is n.ProgramEnd


@pytest.mark.parametrize("key", ALL)
def test_flattened_toolpath_equals_source(key):
    c = case(key)
    assert any(r.kind in MOTION for r in c.records), "the source has no motion: nothing proven"
    # flatten writes an arc's extra full turns as one full circle per turn (the declared
    # lowering); the record comparison applies it to the source, equiv below checks geometry
    problem = record_differences(_split(c.records), c.flat_records)
    assert problem is None, problem
    # an unresolved call (NC402 for --flatten) is an event of the source only
    diff = equiv.compare([r for r in c.records if r.kind != "call"], c.flat_records)
    assert diff is None, diff.format()
    # nothing new goes wrong in the flattened program
    assert not [d for d in c.flat_diags if d.severity == "error"], c.flat_diags


@pytest.mark.parametrize("key", list(ISO_PROGRAMS))
def test_iso_sources_are_clean_and_report_their_lowerings(key):
    """The hand-written programs are valid (else the comparison would prove little) and each kind
    of lowering they need is reported once as NC401 at a source line."""
    c = case(key)
    assert not [d for d in c.source_diags if d.severity != "info"], c.source_diags
    assert not [d for d in c.diags if d.severity != "info"], [d.format_text() for d in c.diags]
    from nctrans.lower.flatten import LOWERINGS
    reported = {kind for kind, msg in LOWERINGS.items()
                if any(d.rule == "NC401" and msg in d.message for d in c.diags)}
    expected = ISO_PROGRAMS[key][1]
    assert expected <= reported, f"missing NC401 for {expected - reported}"
    for d in c.diags:
        assert d.file == c.name and d.line >= 1
    messages = [d.message for d in c.diags if d.rule == "NC401"]
    assert len(messages) == len(set(messages)), "an NC401 kind reported twice"


@pytest.mark.rs274
@pytest.mark.parametrize("key", _rs274_params())
def test_flattened_iso_runs_in_rs274_with_the_same_moves(key, rs274, rs274_cache):
    c = case(key)
    with h.linuxcnc():
        res = get("iso-m").emit(c.flat)
    assert not [d for d in res.diagnostics if d.severity == "error"], res.diagnostics
    run = rs274_run(res.text, key, c.machine, rs274_cache)
    assert run.completed, f"rs274 stops: {run.message}"
    source = [h.Motion.of(r) for r in _split(c.records) if r.kind in MOTION]
    problem = h.compare(run.moves, source, key)
    assert problem is None, problem


@pytest.mark.parametrize("key", ALL)
def test_flattened_sinumerik_emission_parses_back_to_the_same_toolpath(key):
    c = case(key)
    if c.machine is not MACHINE:
        program, records = c.flat, c.records
    else:
        # the sinumerik emitter leaves tool length to the D edge: compare on the default machine
        program = flatten(c.source, default_mill(), diagnostics=[])
        records, _ = toolpath(c.source, default_mill())
    res = get("sinumerik").emit(program)
    assert not [d for d in res.diagnostics if d.severity == "error"], res.diagnostics
    back = parse("sinumerik", res.text, c.name)
    got, diags = toolpath(back, default_mill())
    assert not [d for d in diags if d.severity == "error"], diags
    problem = record_differences(_split(records), got, lines=False)   # the text has its own line numbers
    assert problem is None, problem + "\n" + res.text[:2000]


# ------------------------------------------------------------------ modal state kept for the target

def test_work_offset_and_tool_length_kept_as_modal_codes():
    c = case("g65_calls")
    modes = [(s.group, s.value) for b in c.flat.body for s in b.body if isinstance(s, n.ModeChange)]
    assert ("work_offset", "G55") in modes
    c = case("cutter_comp")
    stmts = [s for b in c.flat.body for s in b.body]
    assert n.ModeChange("work_offset", "G56") in stmts
    i = stmts.index(n.ModeChange("tool_length", "plus"))
    assert stmts[i + 1] == n.OffsetSelect("length", n.Num(4.0))
    # the written coordinates are program coordinates of that offset and tool: the first move
    first = next(s for s in stmts if isinstance(s, n.Motion))
    assert first.target["X"].value.value == pytest.approx(-10.0)
    assert first.target["Z"].value.value == pytest.approx(5.0)


def test_cutter_compensation_is_folded_and_reported():
    c = case("cutter_comp")
    comp = [d for d in c.diags if d.rule == "NC401" and "compensation" in d.message]
    assert len(comp) == 1 and comp[0].line == 8
    # the tool-centre path is written: tool 4 has radius 2, left of the contour X0 -> X-2
    xs = [s.target["X"].value.value for b in c.flat.body for s in b.body
          if isinstance(s, n.Motion) and "X" in s.target]
    assert any(abs(x + 2.0) < 1e-9 for x in xs)


def test_spans_point_at_the_source_lines_that_moved():
    c = case("g65_calls")
    lines = {b.span.line for b in c.flat.body if any(isinstance(s, n.Motion) for s in b.body)}
    # the macro body O9010 (lines 15..20) and the M98 body O9020 (lines 23..24) drive the motion
    assert {15, 16, 17, 18, 19, 20, 23, 24} <= lines
    assert all(b.span.file == c.name for b in c.flat.body)


def test_no_settable_offset_is_written_under_g54_relative_to_the_machine():
    text = "G0 X10 Y20 Z30\nG1 X15 F100\nM30\n"
    prog = parse("sinumerik", text, "nooff.mpf")
    diags: list = []
    flat = flatten(prog, MACHINE, diagnostics=diags)
    assert any(d.rule == "NC401" and "G54" in d.message for d in diags)
    first = next(s for b in flat.body for s in b.body if isinstance(s, n.Motion))
    assert first.target["X"].value.value == pytest.approx(10.0 - 100.0)
    a, _ = toolpath(prog, MACHINE)
    b, _ = toolpath(flat, MACHINE)
    assert record_differences(a, b) is None


# ------------------------------------------------------------------ what cannot be flattened

def test_unmodelled_constructs_are_reported_not_dropped():
    text = ("N10 G0 X0 Y0 Z5\nN20 ID=1 WHEN $AA_IM[X]>5 DO M8\nN30 M77\nN40 STOPRE\n"
            "N50 G1 X10 F100\nN60 NOSUCHPROG\nN70 M30\n")
    prog = parse("sinumerik", text, "drop.mpf")
    diags: list = []
    flatten(prog, default_mill(), diagnostics=diags)
    by_line = {(d.rule, d.line) for d in diags}
    assert ("NC402", 2) in by_line, diags          # synchronized action: motion-relevant, refused
    assert ("NC403", 3) in by_line, diags          # an M function: dropped with a warning
    assert ("NC401", 4) in by_line, diags          # preprocessing stop: no effect on motion
    assert ("NC402", 6) in by_line, diags          # unresolved call: the output would be incomplete


def test_resolved_files_are_walked_for_lowerings(tmp_path):
    (tmp_path / "SUB1.spf").write_text("PROC SUB1\nR1=R1+1\nG1 X=R1*10 F100\nRET\n", encoding="utf-8")
    main = tmp_path / "MAIN.mpf"
    main.write_text("G0 X0 Y0 Z0\nSUB1\nSUB1\nM30\n", encoding="utf-8")
    from nctrans import pipeline
    prog = parse("sinumerik", main.read_text(), str(main))
    diags: list = []
    flat = flatten(prog, default_mill(), diagnostics=diags,
                   resolver=pipeline.make_resolver(str(tmp_path), "sinumerik"))
    assert not [d for d in diags if d.severity == "error"], diags
    xs = [s.target["X"].value.value for b in flat.body for s in b.body
          if isinstance(s, n.Motion) and "X" in s.target]
    assert xs[-2:] == [10.0, 20.0]
    assert any(d.rule == "NC401" and "expressions" in d.message for d in diags)


def test_cli_convert_flatten(tmp_path, capsys):
    from nctrans import cli
    src = REPO / "corpus" / "sinumerik" / "frames.mpf"
    out = tmp_path / "frames.nc"
    code = cli.main(["convert", str(src), "--to", "iso-m", "--flatten", "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "NC401" in err and "frames" in err
    text = out.read_text()
    assert "G68" not in text and "G52" not in text and "ROT" not in text
    back = parse("iso-m", text, "frames.nc")
    recs, diags = toolpath(back)
    src_recs, _ = toolpath(parse("sinumerik", src.read_text(), "frames.mpf"))
    assert equiv.compare(src_recs, recs) is None


# --------------------------------------------------------------------------- streamed (issue 15)


def test_flattened_blocks_come_as_the_program_runs():
    """An endless loop gives its first blocks at once: the flattened program is produced as the
    interpreter runs, never collected whole first (islice would wait for the step budget)."""
    from itertools import islice

    from nctrans.lower.flatten import flatten_blocks
    prog = get("sinumerik").parse("G0 X0 Y0\nLOOP\nG91 G1 X1 F100\nENDLOOP\nM30\n", "e.mpf").program
    first = list(islice(flatten_blocks(prog, default_mill(), diagnostics=[]), 6))
    moves = [s for b in first for s in b.body if type(s) is n.Motion]
    assert len(moves) >= 4


@pytest.mark.parametrize("source, dialect, target", [
    ("corpus/sinumerik/control_flow.mpf", "sinumerik", "iso-m"),
    ("corpus/sinumerik/cycles.mpf", "sinumerik", "sinumerik"),
    ("corpus/iso-m/sample-pocket.nc", "iso-m", "iso-m"),
    ("corpus/iso-m/sample-pocket.nc", "iso-m", "sinumerik"),
])
def test_streamed_flatten_writes_what_the_whole_one_does(source, dialect, target):
    """convert --flatten with an output writes as it goes (several pieces): the same text and
    the same diagnostics, in the same order, as flattening the whole program first."""
    from nctrans import api
    text = (Path(__file__).resolve().parents[1] / source).read_text()
    whole = api.transpile(text, dialect, target, flatten=True)
    sink = TextSink()
    streamed = api.transpile(text, dialect, target, flatten=True, out=sink)
    assert whole.text is not None and streamed.text == "" and len(sink.parts) > 1
    assert "".join(sink.parts) == whole.text
    assert [d.format_text() for d in streamed.diagnostics] == [d.format_text() for d in whole.diagnostics]


def test_streamed_flatten_keeps_notes_of_a_straight_program_in_order():
    """A straight ISO program is flattened from its streamed parse: the unmodelled M code and
    the radius arc are reported as the whole walk reports them, the block after M30 included."""
    from nctrans import api
    text = "G21 G90\nG0 X0 Y0\nG1 X10 F100\nM123\nG2 X20 R5\nM30\nG0 X5\nM456\n"
    whole = api.transpile(text, "iso-m", "iso-m", flatten=True)
    sink = TextSink()
    streamed = api.transpile(text, "iso-m", "iso-m", flatten=True, out=sink)
    got = [d.format_text() for d in streamed.diagnostics]
    assert got == [d.format_text() for d in whole.diagnostics]
    assert any("M123" in g and "NC403" in g for g in got) and any("M456" in g for g in got)
    assert "".join(sink.parts) == whole.text
