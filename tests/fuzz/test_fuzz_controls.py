"""Property fuzzing of the newer control features with hostile values (issue 15): contour corner
elements (Sinumerik RND/RNDM/CHF/CHR/FRC, ISO `,R`/`,C`) on degenerate geometry (zero-length
moves, reversals, tiny and huge radii, values made infinite or not-a-number through variables),
SPOS/SPOSA/M19, the CYCLE93/94/96 grooves and undercuts and the thread cycles and G33 with extreme
parameters. Every program must run to a finite toolpath or stop with located diagnostics: no
exception, no non-finite coordinate in a record, no non-finite number in a conversion's text.
`make test` runs each property briefly, `make fuzz` long (tests/conftest.py profiles)."""
from __future__ import annotations

import io
import math
import os
import re

from hypothesis import given, settings, strategies as st

import nctrans
from nctrans import api, toolpath_io
from nctrans.machine import Tool, default_lathe

# a few examples each in `make test` (every one converts twice); `make fuzz` sets the count
BRIEF = settings() if os.environ.get("NCTRANS_FUZZ_PROFILE_SET") else settings(max_examples=20)
RULE = re.compile(r"^NC\d{3}$")
NON_FINITE = re.compile(r"\b(nan|inf|infinity)\b|e\+?\d{3}", re.IGNORECASE)

# values a parameter or a coordinate takes: ordinary, zero, signs, tiny, huge, and (Sinumerik
# expressions) infinity and not-a-number reached through arithmetic
# (an overflowing expression stops the run at its line: written in place, not set before the moves)
SIN_VALUES = ["0", "1", "2", "-2", "10", "0.001", "1EX-9", "1EX6", "1EX300", "-1EX300",
              "1EX300*1EX300", "-1EX300*1EX300", "SQRT(-1)", "1/3", "R9"]
SIN_PRELUDE = "R9=1EX-300\n"
_E200 = "1" + "0" * 200 + "."
ISO_VALUES = ["0", "1.", "2.", "-2.", "10.", "0.001", "1000000.", f"[{_E200}*{_E200}]", f"[-{_E200}*{_E200}]",
              "[1/3]", "#100", "#9", "1" + "0" * 300 + "."]
ISO_PRELUDE = "#9=0.000000001\n"


def _numbers(text: str) -> None:
    assert not NON_FINITE.search(text.replace("G0", "")), text


def _sound(text: str, dialect: str, target: str, machine=None) -> None:
    """The program's toolpath and both conversions: finite where produced, diagnostics located."""
    lines = text.count("\n") + 1
    tp = nctrans.toolpath(text, dialect, machine)
    records = list(tp)
    for rec in records:
        for where in (rec.start, rec.end, rec.center):
            for v in (where or {}).values():
                assert v is not None and math.isfinite(v), rec
        for v in (rec.feed, rec.spindle, rec.dwell_s, rec.pitch):
            assert v is None or math.isfinite(v), rec
    sink = io.StringIO()
    toolpath_io.write_jsonl(iter(records), sink)        # an unknown spindle angle (NaN) is left out
    assert not re.search(r"null|NaN|Infinity", sink.getvalue()), sink.getvalue()
    for d in tp.diagnostics:
        assert RULE.match(d.rule) and 1 <= d.line <= lines + 1 and d.column >= 1, d
    for flatten in (False, True):
        conv = api.transpile(text, dialect, target, flatten=flatten, machine=machine)
        for d in conv.diagnostics:
            assert RULE.match(d.rule) and d.line >= 1 and d.column >= 1, d
        if conv.text is not None:
            _numbers("\n".join(l for l in conv.text.splitlines() if not l.lstrip().startswith((";", "("))))


def _sin_move(draw) -> str:
    kind = draw(st.sampled_from(["G1", "G1", "G2", "G3", "G0", "G91 G1", "G90 G1", "Z", "same", "same"]))
    x, y = draw(st.sampled_from(SIN_VALUES)), draw(st.sampled_from(SIN_VALUES))
    if kind == "same":                  # a move of no length
        return "G1 X=$P_EP[X] Y=$P_EP[Y]" if draw(st.booleans()) else "G91 G1 X0 Y0\nG90"
    if kind == "Z":
        return f"G1 Z={draw(st.sampled_from(SIN_VALUES))}"
    if kind in ("G2", "G3"):
        centre = f"CR={draw(st.sampled_from(SIN_VALUES))}" if draw(st.booleans()) else \
            f"I={draw(st.sampled_from(SIN_VALUES))} J={draw(st.sampled_from(SIN_VALUES))}"
        return f"{kind} X={x} Y={y} {centre}"
    return f"{kind} X={x} Y={y}"


def _with_word(line: str, word: str) -> str:
    """`word` in the first block of `line` (a move of no length is two blocks: G91 ... and G90)."""
    head, _, rest = line.partition("\n")
    return f"{head} {word}" + (f"\n{rest}" if rest else "")


@st.composite
def sinumerik_corners(draw) -> str:
    """Corners: a move carrying an element word, maybe blocks between, the next move."""
    body = []
    for _ in range(draw(st.integers(1, 3))):
        word = draw(st.sampled_from(["RND", "RND", "CHF", "CHR", "RNDM", "FRC", "FRCM"]))
        value = draw(st.sampled_from(["2", "0.5", "2", *SIN_VALUES]))
        body.append(_with_word(_sin_move(draw), f"{word}={value}"))
        if draw(st.integers(0, 3)) == 0:
            body.append(draw(st.sampled_from(["M8", "R2=R2+1", "G18", "G17", "G41 D1", "G40", "TRANS X=1",
                                              "G64", "F0", "FRC=0"])))
        body.append(_sin_move(draw))
    return "G17 G90 G71 T1 D1 M6\nS1000 M3 F500\n" + SIN_PRELUDE + "G0 X0 Y0 Z0\n" + "\n".join(body) + "\nM30\n"


def _iso_move(draw) -> str:
    kind = draw(st.sampled_from(["G1", "G1", "G2", "G3", "G0", "G91 G1", "G90 G1", "same", "same"]))
    if kind == "same":                  # a move of no length
        return "G91 G1 X0 Y0\nG90"
    x, y = draw(st.sampled_from(ISO_VALUES)), draw(st.sampled_from(ISO_VALUES))
    return f"{kind} X{x} Y{y}" + (f" R{draw(st.sampled_from(ISO_VALUES))}" if kind in ("G2", "G3") else "")


@st.composite
def iso_corners(draw) -> str:
    body = []
    for _ in range(draw(st.integers(1, 3))):
        value = draw(st.sampled_from(["2.", "0.5", *ISO_VALUES]))
        body.append(_with_word(_iso_move(draw), f",{draw(st.sampled_from(['R', 'C']))}{value}"))
        if draw(st.integers(0, 4)) == 0:
            body.append(draw(st.sampled_from(["M8", "#2=#2+1", "G18", "G17", "G41 D1", "G40"])))
        body.append(_iso_move(draw))
    return "G17 G90 G21 T1 M6\nS1000 M3 F500.\n" + ISO_PRELUDE + "G0 X0 Y0 Z0\n" + "\n".join(body) + "\nM30\n"


@st.composite
def spindle_positions(draw) -> str:
    lines = []
    for _ in range(draw(st.integers(1, 4))):
        v = draw(st.sampled_from(SIN_VALUES))
        form = draw(st.sampled_from(["SPOS={v}", "SPOSA={v}", "SPOS=IC({v})", "SPOS=DC({v})", "SPOS=ACP({v})",
                                     "SPOS=ACN({v})", "SPOS[1]={v}", "SPOS[2]={v}", "M19", "M3", "M5"]))
        lines.append(form.format(v=v))
        lines.append(draw(st.sampled_from(["G1 X10", "G0 Y5", "M3", "G4 F1"])))
    return "G17 G90 T1 D1 M6\nS1000 M3 F500\n" + SIN_PRELUDE + "\n".join(lines) + "\nM30\n"


@st.composite
def lathe_cycles(draw) -> str:
    v = lambda: draw(st.sampled_from(SIN_VALUES))        # noqa: E731
    form = lambda: draw(st.sampled_from(['"E"', '"F"', '"A"', '"B"', '"C"', '""', "5", '"X"']))   # noqa: E731
    call = draw(st.sampled_from([
        lambda: f"CYCLE94({v()}, {v()}, {form()}, {v()})",
        lambda: f"CYCLE96({v()}, {v()}, {form()}, {v()})",
        lambda: f"CYCLE93({v()}, {v()}, {v()}, {v()}, 0, 0, 0, {v()}, 0, 0, 0, {v()}, {v()}, {v()}, {v()}, 5, 1)",
        lambda: f"CYCLE97({v()}, , 0, {v()}, 20, 20, 4, 2, {v()}, 0.2, {v()}, 0, {v()}, 1, {v()}, 1)",
        lambda: f"CYCLE98(0, 20, {v()}, 25, -20, 30, -30, 30, 2, 2, 1, 1, {v()}, {v()}, 2, 0.2, 0, 0, {v()}, 1, 1, 1)",
        lambda: f"G33 Z={v()} K={v()}",
        lambda: f"G33 X={v()} Z={v()} K={v()} SF={v()}",
        lambda: f"G331 Z={v()} K={v()}",
    ]))()
    return "G18 G90 DIAMON T1 D1\nS800 M3 G95 F0.1\n" + SIN_PRELUDE + "G0 X40 Z5\n" + call + "\nG0 X60\nM30\n"


@st.composite
def turning_contours(draw) -> str:
    """A CYCLE95 contour with roundings and chamfers on its elements (zero-length ones too)."""
    lines = ["ANF: G1 X20 Z0"]
    for _ in range(draw(st.integers(1, 5))):
        x, z = draw(st.sampled_from(["20", "20", "40", "X", "1EX-9"])), draw(st.sampled_from(["0", "0", "-20", "Z"]))
        line = "G1" + ("" if x == "X" else f" X{x}") + ("" if z == "Z" else f" Z{z}")
        if draw(st.booleans()):
            line += f" {draw(st.sampled_from(['RND', 'CHR', 'CHF']))}={draw(st.sampled_from(SIN_VALUES))}"
        lines.append(line)
    lines.append("ENDE: X50")
    return ("G18 G90 DIAMON T1 D1\nS1000 M3 G95 F0.3\n" + SIN_PRELUDE + "G0 X60 Z10\n"
            'CYCLE95("ANF:ENDE", 2, 0.25, 0.5, 0, 0.3, 0.1, 0.1, 1, , , 1)\nG0 X100\nM30\n' + "\n".join(lines) + "\n")


@BRIEF
@given(sinumerik_corners())
def test_sinumerik_corner_elements_end_finite_or_located(text):
    _sound(text, "sinumerik", "iso-m")


@BRIEF
@given(iso_corners())
def test_iso_corner_elements_end_finite_or_located(text):
    _sound(text, "iso-m", "sinumerik")


@BRIEF
@given(spindle_positions())
def test_spindle_positions_end_finite_or_located(text):
    _sound(text, "sinumerik", "iso-m")


@BRIEF
@given(lathe_cycles())
def test_grooves_undercuts_and_threads_end_finite_or_located(text):
    machine = default_lathe()
    machine.tools = [Tool(1, tip=3, width=3.0)]
    _sound(text, "sinumerik", "iso-t", machine)


@BRIEF
@given(turning_contours())
def test_turning_contour_corners_end_finite_or_located(text):
    _sound(text, "sinumerik", "iso-t")
