"""Per-word absolute/incremental coordinates written for ISO milling
(nctrans.dialects.iso_m.per_word): Sinumerik `X=AC(..)` / `X=IC(..)` and ISO turning `U`/`W` are
plain words where the G90/G91 in force means the same, and a move whose every axis word asks for
the other mode is written under G91 (G90) with the mode in force written again after it; mixed
words, and places the mode is not known on every path, stay refused (lowered alone). Hand-written
expected outputs, equiv against the source, rs274 on the ISO output, and a hypothesis property."""
from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from nctrans import api

import rs274 as h


def _body(text: str) -> list[str]:
    return [x for x in text.splitlines() if x and not x.startswith(("%", "("))]


def _iso(text: str, read: str):
    conv = api.transpile(text, read=read, write="iso-m")
    assert conv.ok, [d.format_text() for d in conv.diagnostics if d.severity == "error"]
    return conv


SIN = "G0 X0 Y0 Z5\nG1 X=IC(5) Y=IC(2) F100\nX=AC(1)\nG91 X=AC(2)\nY=IC(3)\nG90\nM30\n"


def test_sinumerik_ac_ic_as_plain_words_or_one_block_switch(tmp_path):
    conv = _iso(SIN, "sinumerik")
    assert _body(conv.text) == [
        "G0 X0. Y0. Z5.",
        "G1 F100. G91 X5. Y2.", "G90",          # both words incremental under G90: one switch
        "X1.",                                  # AC under G90: the plain word
        "G91", "G90 X2.", "G91",                # AC under G91: G90 for the block, G91 again
        "Y3.",                                  # IC under G91: the plain word
        "G90", "M30"]
    assert not [d for d in conv.diagnostics if "lowered to plain motion" in d.message]
    src, out = tmp_path / "ac.mpf", tmp_path / "ac.nc"
    src.write_text(SIN)
    out.write_text(conv.text)
    # hand-computed: (5,2) then X1, X2, then Y up by 3
    assert [r.end for r in api.toolpath(out, "iso-m") if r.kind == "linear"] == [
        {"X": 5.0, "Y": 2.0, "Z": 5.0}, {"X": 1.0, "Y": 2.0, "Z": 5.0},
        {"X": 2.0, "Y": 2.0, "Z": 5.0}, {"X": 2.0, "Y": 5.0, "Z": 5.0}]
    assert api.equiv(src, out, read_a="sinumerik", read_b="iso-m").equivalent


@pytest.mark.rs274
def test_the_switch_runs_the_same_in_rs274(rs274, tmp_path):
    prog = tmp_path / "ac.ngc"
    prog.write_text(_iso(SIN, "sinumerik").text)
    run = h.run_rs274(prog, h.write_tool_table(tmp_path / "t.tbl", [(1, 0.0, 0.0)]), tmp_path / "o.out")
    assert run.completed, run.message
    ends = [(m.end["X"], m.end["Y"]) for m in run.moves if not h.is_zero_move(m) and m.kind == "linear"]
    assert [tuple(round(v, 3) for v in e) for e in ends] == [(5.0, 2.0), (1.0, 2.0), (2.0, 2.0), (2.0, 5.0)]


def test_iso_turning_u_w_written_under_g91(tmp_path):
    text = "G0 X20. Z5.\nG1 U-2. F0.1\nG0 U2. W1.\nM30\n"
    conv = _iso(text, "iso-t")
    body = _body(conv.text)
    # U is a diameter increment: the radius X moves by half of it
    assert body[body.index("G0 X10. Z5."):] == ["G0 X10. Z5.", "F0.1 G1 G91 X-1.", "G90",
                                                 "G0 G91 X1. Z1.", "G90", "M30"]
    src, out = tmp_path / "u.nc", tmp_path / "u.ngc"
    src.write_text(text)
    out.write_text(conv.text)
    assert api.equiv(src, out, read_a="iso-t", read_b="iso-m").equivalent


def test_mixed_words_and_unknown_modes_are_not_written_plain():
    # X incremental and Y absolute in one block under G90: one block cannot hold both modes
    mixed = _iso("G0 X0 Y0 Z5\nG1 X=IC(5) Y10 F100\nM30\n", "sinumerik")
    assert any("per-word inc coordinate on X" in d.message for d in mixed.diagnostics)
    # a label reached from a G91 path: the mode at X=AC(5) is not known, so it is not a plain X5.
    jump = _iso("G0 X0 Y0 Z5\nG91\nIF R1==0 GOTOF L1\nG90\nL1: G1 X=AC(5) F100\nG90\nM30\n", "sinumerik")
    assert "plain motion of a construct the target lacks" in jump.text      # lowered, with its G90
    assert not [d for d in jump.diagnostics if "written as plain words" in d.message]
    # a subprogram file (M17) runs in its caller's mode
    sub = api.transpile("G1 X=AC(5) F100\nM17\n", read="sinumerik", write="iso-m")
    assert any("per-word abs coordinate on X" in d.message for d in sub.diagnostics)
    assert not [d for d in sub.diagnostics if "written as plain words" in d.message]


def test_equiv_after_jump_target_lowering(tmp_path):
    text = "G0 X0 Y0 Z5\nG91\nR1=0\nIF R1==0 GOTOF L1\nG90\nL1: G1 X=AC(5) F100\nG90\nM30\n"
    conv = _iso(text, "sinumerik")
    src, out = tmp_path / "j.mpf", tmp_path / "j.nc"
    src.write_text(text)
    out.write_text(conv.text)
    assert api.equiv(src, out, read_a="sinumerik", read_b="iso-m").equivalent
    assert [r.end["X"] for r in api.toolpath(out, "iso-m") if r.kind == "linear"] == [5.0]


# A straight program of G90/G91 switches and single moves with per-word modes: the conversion
# to ISO milling is equivalent to the source whatever the mix.
WORD = st.tuples(st.sampled_from("XY"), st.sampled_from(["", "AC", "IC"]),
                 st.integers(-20, 20))
LINE = st.one_of(st.sampled_from(["G90", "G91"]), st.lists(WORD, min_size=1, max_size=2,
                                                           unique_by=lambda w: w[0]))


@settings(max_examples=30, deadline=None)
@given(st.lists(LINE, min_size=1, max_size=8))
def test_any_mix_converts_equivalent(tmp_path_factory, lines):
    out_lines = ["G0 X0 Y0 Z5", "G1 F100"]
    modal, mixed = "AC", False
    for line in lines:
        if isinstance(line, str):
            out_lines.append(line)
            modal = "AC" if line == "G90" else "IC"
        else:
            out_lines.append(" ".join(f"{a}={m}({v})" if m else f"{a}{v}" for a, m, v in line))
            mixed |= len({m or modal for _, m, _ in line}) > 1
    text = "\n".join(out_lines + ["G90", "M30"]) + "\n"
    conv = api.transpile(text, read="sinumerik", write="iso-m")
    assert conv.ok
    d = tmp_path_factory.mktemp("mix")
    (d / "a.mpf").write_text(text)
    (d / "a.nc").write_text(conv.text)
    assert api.equiv(d / "a.mpf", d / "a.nc", read_a="sinumerik", read_b="iso-m").equivalent, \
        (text, conv.text)
    # one mode per block: every block written structurally (plain words or a one-block switch)
    lowered = [d for d in conv.diagnostics if "plain motion" in d.message]
    assert mixed or not lowered, (text, [d.message for d in lowered])
