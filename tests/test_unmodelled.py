"""Nothing unmodelled passes silently (issue 8): the Sinumerik pole, NC220 for every word, code or
function the interpreter does not model, and a walk over every code and function of every rules
table. Expected positions are computed by hand in the comments."""
from __future__ import annotations

import math
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from nctrans import pipeline
from nctrans.dialects import base
from nctrans.interp import spindle_position
from nctrans.interp.unmodelled import modelled, no_motion_effect
from nctrans.ir import nodes as n
from nctrans.ir.vocabulary import MODAL_GROUPS, UNMODELLED_MODES
from nctrans.source import from_text

ROOT = Path(__file__).resolve().parents[1]
RULES = ROOT / "rules"


def run(text: str, dialect: str = "sinumerik"):
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", dialect)
    recs = list(pipeline.toolpath_of(ld))
    return recs, ld.diagnostics


def moves(recs):
    return [r for r in recs if r.kind in ("rapid", "linear", "arc")]


def xy(r):
    return (round(r.end["X"], 6), round(r.end["Y"], 6))


def nc220(diags):
    return [d for d in diags if d.rule == "NC220"]


# --------------------------------------------------------------------------- the pole

def test_g111_sets_the_pole_and_moves_nothing():
    # pole (10,10); AP=90 RP=5 -> (10 + 5 cos 90, 10 + 5 sin 90) = (10, 15)
    recs, diags = run("G17 G90\nG111 X10 Y10\nG0 AP=90 RP=5\nM30\n")
    assert [xy(r) for r in moves(recs)] == [(10.0, 15.0)]
    assert moves(recs)[0].line == 3
    assert nc220(diags) == []


def test_g110_g112_are_relative_to_last_point_and_last_pole():
    text = ("G17 G90\nG0 X5 Y5\nG111 X10 Y10\nG0 AP=90 RP=5\n"   # (10,15)
            "G1 AP=180 F100\n"           # RP stays 5: (10-5, 10) = (5,10)
            "G110 X2\n"                  # pole = last point (5,10) + (2,0) = (7,10)
            "G1 RP=1 AP=0\n"             # (8,10)
            "G112 AP=90 RP=10\n"         # pole = (7,10) + 10*(cos 90, sin 90) = (7,20)
            "G0 AP=0 RP=0\n"             # the pole itself: (7,20)
            "G91 G111 X1 Y1\n"           # absolute to the work zero whatever G91: (1,1)
            "G90 G0 AP=-90 RP=2\n"       # (1, 1-2) = (1,-1)
            "M30\n")
    recs, _ = run(text)
    assert [xy(r) for r in moves(recs)] == [(5.0, 5.0), (10.0, 15.0), (5.0, 10.0), (8.0, 10.0),
                                            (7.0, 20.0), (1.0, -1.0)]


def test_pole_in_the_zx_plane():
    # G18: plane axes Z (first) and X (second); pole Z=10 X=0; AP=90 RP=4 -> Z 10, X 4
    recs, _ = run("G18 G90\nG111 Z10 X0\nG0 AP=90 RP=4\nM30\n")
    end = moves(recs)[0].end
    assert (round(end["Z"], 6), round(end["X"], 6)) == (10.0, 4.0)


def test_pole_round_trips_through_sinumerik_and_flattens_for_iso(tmp_path):
    src = tmp_path / "pole.mpf"
    src.write_text("G17 G90\nG111 X10 Y10\nG0 AP=90 RP=5\nM30\n")
    out = subprocess.run([sys.executable, "-m", "nctrans", "convert", str(src), "--from", "sinumerik",
                          "--to", "sinumerik"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and "G111 X10 Y10" in out.stdout
    out = subprocess.run([sys.executable, "-m", "nctrans", "convert", str(src), "--from", "sinumerik",
                          "--to", "iso-m"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "X10. Y15." in out.stdout


# --------------------------------------------------------------------------- the general rule

def test_unmodelled_motion_code_moves_nothing_until_the_next_motion_code():
    text = "G0 X1 Y2 Z3\nG35 Z-10 K1.5 F=0.1\nZ-20\nG1 Z5 F100\nM30\n"
    recs, diags = run(text)
    # G35 (thread with decreasing lead) and the Z-20 after it move nothing; G1 Z5 starts from (1,2,3)
    assert [(r.line, r.end["Z"]) for r in moves(recs)] == [(1, 3.0), (4, 5.0)]
    lines = [(d.line, d.severity) for d in nc220(diags)]
    assert lines == [(2, "warning"), (3, "warning")]
    assert "G35" in nc220(diags)[0].message and "G35" in nc220(diags)[1].message


def test_unmodelled_word_in_a_modelled_block_is_named_at_its_line():
    recs, diags = run("G1 X5 Y0 F100\nG1 X10 ANG=30\nG1 Y5\nM30\n")
    assert len(moves(recs)) == 3
    (d,) = nc220(diags)
    assert d.line == 2 and "ANG=30" in d.message


def test_known_no_effect_vocabulary_is_silent():
    text = ("FNORM\nTRAFOOF\nSETMS(1)\nNEWCONF\nCHANDATA(1)\nDIAM90\nSTOPRE\nMSG(\"hello\")\n"
            "G0 X1\nM30\n")
    recs, diags = run(text)
    assert [xy(r) for r in moves(recs)] == [(1.0, 0.0)]
    assert [d for d in diags if d.severity in ("warning", "error")] == []


def test_diameter_programming_is_no_effect_on_a_mill_only():
    from nctrans.machine import default_lathe
    ld = pipeline.load_source(from_text("DIAM90\nG0 X1\nM30\n", "t.mpf"), "t.mpf", "sinumerik")
    list(pipeline.toolpath_of(ld, default_lathe()))
    assert [d.line for d in nc220(ld.diagnostics)] == [1]


def test_iso_unmodelled_modes_and_thread_are_reported():
    recs, diags = run("G0 X1\nG34 X10 K1 F1\nX20\nG16\nG1 X5 Y0 F100\nM30\n", "iso-m")
    # G34 X10 and X20 move nothing; G1 X5 starts from X1; G16 is modelled (polar_input.py): X5 Y0
    # is radius 5 at 0 deg about the zero, (5, 0)
    assert [(r.line, r.end["X"]) for r in moves(recs)] == [(1, 1.0), (5, 5.0)]
    msgs = {}
    for d in nc220(diags):
        msgs[d.line] = msgs.get(d.line, "") + d.message
    assert "G34" in msgs[2] and "G34" in msgs[3] and 4 not in msgs


@pytest.mark.parametrize("command", ["toolpath", "lint"])
def test_fail_on_warning_exits_1(tmp_path, command):
    src = tmp_path / "p.mpf"
    src.write_text("G0 X0 Y0\nTRAORI\nG1 X1 F100\nM30\n")
    argv = [sys.executable, "-m", "nctrans", command, str(src), "--from", "sinumerik"]
    clean = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    assert "NC220" in clean.stderr + clean.stdout and "TRAORI" in clean.stderr + clean.stdout
    strict = subprocess.run(argv + ["--fail-on", "warning"], capture_output=True, text=True,
                            timeout=120)
    assert strict.returncode == 1


# --------------------------------------------------------------------------- every code of every table
#
# Every entry of every rules table (G/M codes, machine commands, words, address letters, predefined
# functions, system variables, numbered variables, the cycles of rules/cycles.toml) is run on a line
# of its own. Each must be modelled (it parses to IR the interpreter knows, a system variable reads a
# number) or said at its line; and every construct said only by a warning must also be said by
# `lint`, `toolpath` and `check` at its line, with exit 1 under --fail-on warning.

_TWO_ARGS = ("ATAN2", "MINVAL", "MAXVAL", "POW", "ATAN")
_SET_UP = {"sinumerik": "T1 D1 S1000 F100", "iso-m": "T1 D1 H1 S1000 F100",
           "iso-t": "T0101 S1000 F1", "fagor": "T1 D1 S1000 F100"}


def _tables():
    for path in sorted(RULES.glob("*.toml")):
        data = tomllib.loads(path.read_text())
        if "dialect" in data and "codes" in data:
            yield path.stem, data


def _function_line(dialect: str, f: str) -> str:
    args = "1,1" if f.upper() in _TWO_ARGS else "1"
    if dialect == "sinumerik":
        return f"R1={f}({args})"
    if dialect == "fagor":
        return f"P1={f}({args})"
    return f"#1={f}[{args.replace(',', ',')}]"


def _variable_line(dialect: str, var: str) -> str:
    """The variable drives an axis word: its value is seen in the move (or said unknown)."""
    if dialect == "sinumerik":
        indexed = var.upper() in ("$AA_IW", "$AA_IM", "$AA_MW", "$AA_MM", "$P_EP")
        return f"G1 X={var}[X]" if indexed else f"G1 X={var}"
    if dialect == "fagor":
        return f"P1={var} G1 XP1"
    return f"G1 X[{var}]"


def _constructs(dialect: str, data: dict) -> list[tuple[str, str]]:
    """(kind, line) per entry of the table: kind "code" for words and codes, "function",
    "variable"."""
    out = [("code", c["code"].split(":")[-1]) for c in data["codes"]]
    opts = data.get("options", {})
    for section in ("machine_commands", "unsupported_functions"):
        out += [("code", w) for w in opts.get(section, {})]
    nme = opts.get("no_motion_effect", {})
    out += [("code", w) for w in nme.get("words", []) + nme.get("mill_only", [])]
    out += [("code", w) for w in opts.get("unmodelled_motion", {}).get("codes", [])]
    for codes in opts.get("g_group_index", {}).values():
        out += [("code", c) for c in codes if c]
    out += [("code", f"{w}=1" if dialect == "sinumerik" else f"{w}1")
            for w in opts.get("passthrough_words", {}) if w.isalpha()]
    out += [("code", f"{w}1") for w in data.get("addresses", {})]
    funcs = list(opts.get("functions", {})) + list(data.get("expressions", {}).get("functions",
                                                                                  {}).values())
    out += [("function", _function_line(dialect, f)) for f in dict.fromkeys(funcs)]
    variables = list(data.get("system_variables", {}))
    for nv in opts.get("numbered_variables", []):
        variables += [f"#{nv['first']}", f"#{nv.get('last', nv['first'])}"]
    out += [("variable", _variable_line(dialect, v)) for v in dict.fromkeys(variables)]
    # corner elements of the table (ISO ,R / ,C): in a contour block followed by another
    corner = opts.get("corner_elements", {}).get("words", {})
    out += [("code", f"G1 X1 {w}0.5" if w.startswith(",") else f"G1 X1 {w}=0.5")
            for w in corner if dialect != "sinumerik"]
    if dialect == "sinumerik":
        # the string and axis functions of the language (interp/strings.py), not a table:
        # AXNAME's axis drives an axis word
        from nctrans.interp.strings import FUNCTIONS
        out += [("variable", 'G1 AX[AXNAME("X")]=1')]
        out += [("function", f'R1={f}("1")') for f in FUNCTIONS if f not in ("AXNAME", "AXSTRING")]
        cycles = tomllib.loads((RULES / "cycles.toml").read_text())
        for section in ("cycle", "pattern", "milling", "swivel", "unmodelled"):
            out += [("code", f"{c['name']}()") for c in cycles.get(section, [])]
    return list(dict.fromkeys(out))


def _line_statements(program: n.Program, line: int) -> list:
    out = []

    def walk(nodes_):
        for node in nodes_:
            if isinstance(node, n.Block):
                if node.span.line == line:
                    out.extend(node.body)
            else:
                for attr in ("then", "orelse", "body"):
                    walk(getattr(node, attr, None) or [])
    walk(program.body)
    return out


def _run_line(dialect: str, line: str):
    text = f"G0 X0 Y0 Z0 {_SET_UP[dialect]}\n{line}\nM30\n"
    ld = pipeline.load_source(from_text(text, "all.nc"), "all.nc", dialect)
    recs = list(pipeline.toolpath_of(ld)) if ld.program is not None else []
    return ld, recs


def _silently_unmodelled(dialect: str, kind: str, construct: str) -> str | None:
    ld, recs = _run_line(dialect, construct)
    if ld.program is None:
        return None
    said = [d for d in ld.diagnostics if d.line == 2 and d.severity in ("warning", "error")]
    if said:
        return None
    if kind == "variable":
        moved = [r for r in recs if r.line == 2 and r.kind == "linear"]
        unknown = [d for d in ld.diagnostics if d.line == 2 and d.rule == "NC107"]
        if not unknown and not (moved and math.isfinite(moved[0].end["X"])):
            return f"{construct}: read no value and said nothing"
        return None
    stmts = _line_statements(ld.program, 2)
    # corner elements (RND, RNDM, FRC ...) and OFFN are modelled (unmodelled.modelled): a modal
    # one alone changes nothing and rightly says nothing
    unmodelled = [s for s in stmts if isinstance(s, n.Passthrough)
                  and not no_motion_effect(s.reason) and not modelled(s)
                  and not spindle_position.is_modelled(s)]
    unmodelled += [s for s in stmts if isinstance(s, n.ModeChange)
                   and (s.group, s.value) in UNMODELLED_MODES]
    # a ModeChange outside the neutral vocabulary is a mode the interpreter cannot know
    unmodelled += [s for s in stmts if isinstance(s, n.ModeChange)
                   and s.group not in MODAL_GROUPS]
    unmodelled += [s for s in stmts if isinstance(s, n.ModeChange) and MODAL_GROUPS.get(s.group)
                   and s.value not in MODAL_GROUPS[s.group]]
    if unmodelled:
        return f"{construct}: {unmodelled} with no warning"
    if not stmts and not any(d.line == 2 for d in ld.diagnostics):
        if construct[0] in "GM" or construct.isalpha():
            # a one-shot modifier of axis words (G53, ATRANS): it must act on them
            if " " not in construct:
                return _silently_unmodelled(dialect, kind, construct + " X1")
        if construct[0] not in "NO":        # block number, program number
            return f"{construct}: parsed to nothing and said nothing"
    return None


def _dialect_tables():
    return [(t, d) for t, d in _tables() if d["dialect"] in base.names()]


@pytest.mark.parametrize("table", [t for t, _ in _tables()])
def test_no_entry_of_any_table_is_silently_unmodelled(table):
    data = dict(_tables())[table]
    dialect = data["dialect"]
    if dialect not in base.names():
        pytest.skip(f"no front end for {dialect} yet")
    constructs = _constructs(dialect, data)
    kinds = {k for k, _ in constructs}
    assert len(constructs) > 50 and "code" in kinds
    bad = [msg for k, c in constructs if (msg := _silently_unmodelled(dialect, k, c))]
    assert bad == [], "\n".join(bad)


def _warned_only(dialect: str, construct: str) -> bool:
    """Said at its line by warnings only, and nothing said elsewhere (it changes no other line)."""
    ld, _ = _run_line(dialect, construct)
    at = [d for d in ld.diagnostics if d.line == 2]
    return (ld.program is not None and any(d.severity == "warning" for d in at)
            and all(d.severity != "error" and d.rule != "NC205" for d in at)
            and all(d.line == 2 or d.severity == "info" for d in ld.diagnostics))


@pytest.mark.parametrize("table", [t for t, d in _dialect_tables()])
def test_every_warned_entry_is_said_by_lint_toolpath_and_check(tmp_path, table):
    data = dict(_tables())[table]
    dialect = data["dialect"]
    warned = [c for k, c in _constructs(dialect, data) if k == "code" and _warned_only(dialect, c)]
    assert len(warned) > 10
    # one program: each construct on a line of its own, a plain move between them
    lines = [f"G0 X0 Y0 Z0 {_SET_UP[dialect]}"]
    where = {}
    for c in warned:
        where[len(lines) + 1] = c
        lines += [c, "G1 X1 Y1"]
    src = tmp_path / ("all" + {"sinumerik": ".mpf", "fagor": ".pim"}.get(dialect, ".nc"))
    src.write_text("\n".join(lines + ["M30", ""]))
    for command in ("lint", "toolpath", "check"):
        argv = [sys.executable, "-m", "nctrans", command, str(src), "--from", dialect,
                "--fail-on", "warning"]
        if command == "toolpath":
            argv += ["--summary"]
        out = subprocess.run(argv, capture_output=True, text=True, timeout=300)
        said = out.stdout + out.stderr
        assert out.returncode == 1, (command, said[-2000:])
        missing = [f"{line}: {c}" for line, c in where.items()
                   if not re.search(rf":{line}:\d+: warning", said)]
        assert missing == [], f"{command} --from {dialect} says nothing at: {missing}"


def test_a_frame_read_as_an_axis_word_is_a_type_error_not_a_crash():
    # $P_PFRAME is a FRAME: as X= it was a TypeError out of the interpreter
    recs, diags = run("G0 X0\nG1 X=$P_PFRAME F100\nG1 X2\nM30\n")
    (d,) = [d for d in diags if d.rule == "NC104"]
    assert d.line == 2 and d.severity == "error" and "frame" in d.message
    assert all(r.line != 2 for r in moves(recs))


def test_fagor_direct_compensation_start_is_said():
    # G138 sends the tool straight to the perpendicular of the next path (no corner, seed
    # L10965-10981); the interpreter models G139, the default: G138 must be named at its line
    recs, diags = run("G0 X0 Y0\nG138\nG1 X1 F100\nM30\n", "fagor")
    assert {d.rule for d in diags if d.line == 2 and d.severity == "warning"} >= {"NC415"}
    assert "G138" in " ".join(d.message for d in diags if d.line == 2)
    recs, diags = run("G0 X0 Y0\nG139\nG1 X1 F100\nM30\n", "fagor")
    assert [d for d in diags if d.severity != "info"] == []


def test_check_names_what_it_did_not_model(tmp_path):
    src = tmp_path / "p.mpf"
    src.write_text("G0 X0 Y0\nTRAORI\nG1 X1 F100\nM30\n")
    argv = [sys.executable, "-m", "nctrans", "check", str(src), "--from", "sinumerik"]
    out = subprocess.run(argv + ["--fail-on", "error"], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0 and ":2:1: warning[NC220]" in out.stdout and "TRAORI" in out.stdout
    out = subprocess.run(argv + ["--fail-on", "warning"], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 1


def test_an_unknown_g_code_moves_nothing_until_the_next_motion_code():
    # LinuxCNC NURBS: G5.2 and its control points were unknown to the table, and the points after
    # it ran as G1 moves (warned only for their P words). Lines 3-5 move nothing now; G1 X1 (line
    # 6) starts from where line 2 left the tool: (0, 0, 0) -> (1, 0, 0).
    text = "G0 X0 Y0 Z1\nG1 Z0 F300\nG5.2 X3 Y-1 P2\nX5 Y-11 P1\nG5.3\nG1 X1\nM30\n"
    recs, diags = run(text, "iso-m")
    assert [(r.line, xy(r)) for r in moves(recs)] == [(1, (0.0, 0.0)), (2, (0.0, 0.0)),
                                                     (6, (1.0, 0.0))]
    assert sorted({d.line for d in nc220(diags)}) == [3, 4, 5]
    # Sinumerik: G123 is no G function; its X1 does not move the tool
    recs, diags = run("G0 X0\nG123 X1\nG1 X2 F100\nM30\n")
    assert [(r.line, xy(r)) for r in moves(recs)] == [(1, (0.0, 0.0)), (3, (2.0, 0.0))]
    assert [d.line for d in nc220(diags)] == [2]
