"""ISO turning to Fagor and back: a Fagor lathe starts in diameter programming (G151) on its
DIAMPROG axes and in G94/G17, so the conversion writes the modes an ISO lathe program relies on
(G18, G95, G151 or G152 for a flattened program in radius), G50 S as G192 S, and the Fagor front
end reads G151/G152 and G192 S back."""
from __future__ import annotations

from pathlib import Path

import pytest

import nctrans
from conftest import CORPUS
from nctrans.dialects.base import get
from nctrans.interp.interpreter import interpret
from nctrans.machine import default_lathe

REPO = Path(__file__).resolve().parent.parent

TURN = ("G18 G21 G99\nT0101\nG50 S2000\nG96 S200 M03\nG00 X40. Z2.\nG01 Z-10. F0.2\n"
        "G02 X50. Z-15. R5.\nG01 X60. Z-20.\nG00 X80. Z20.\nM30\n")


def _lines(text):
    return [ln.strip() for ln in text.splitlines()]


def test_iso_t_program_written_structurally_with_lathe_modes_and_g192():
    conv = nctrans.transpile(TURN, read="iso-t", write="fagor")
    assert conv.ok, conv.diagnostics
    lines = _lines(conv.text)
    assert "flattened" not in conv.text
    assert lines[1].startswith("(converted by nctrans")   # the header comment
    assert lines[2] == "G18 G95 G151"                   # before anything reads a word
    assert "G192 S2000" in lines and "G96 S200 M3" in lines and "G00 X40 Z2" in lines
    assert bool(nctrans.equiv(TURN, conv.text, read_a="iso-t", read_b="fagor"))
    back = nctrans.transpile(conv.text, read="fagor", write="iso-t")
    assert back.ok, back.diagnostics
    assert "G50 S2000" in _lines(back.text)
    assert bool(nctrans.equiv(TURN, back.text, read_a="iso-t", read_b="iso-t"))


def test_without_the_power_on_modes_the_fagor_program_would_differ():
    """The words alone (no G18 G95 G151) on Fagor's power-on modes: X read as a radius."""
    conv = nctrans.transpile(TURN, read="iso-t", write="fagor")
    bare = "\n".join(ln for ln in conv.text.splitlines() if ln.strip() != "G18 G95 G151") + "\n"
    assert not bool(nctrans.equiv(TURN, bare, read_a="iso-t", read_b="fagor"))


def _records(text, dialect="fagor"):
    res = get(dialect).parse(text, "f.nc")
    diags = list(res.diagnostics)
    return [r for r in interpret(res.program, default_lathe(), diagnostics=diags)
            if r.kind in ("rapid", "linear")], diags


def test_fagor_g151_g152_and_g192_speed_limit():
    """G151 X40 is radius 20; S200 m/min under G96 at radius 10 mm is 200000 / (2 pi 10) = 3183.1
    rpm, capped by G192 S1500; G152 X30 is radius 30."""
    text = ("G18 G95 G151\nT1 D1 M6\nG192 S1500\nG96 S200 M3\nG00 X40 Z2\nG01 X20 F0.1\nG152\n"
            "G01 X30\nM30\n")
    recs, diags = _records(text)
    assert not [d for d in diags if d.severity != "info"], diags
    assert [(round(r.end["X"], 6), r.line) for r in recs] == [(20.0, 5), (10.0, 6), (30.0, 8)]
    assert recs[1].spindle == 1500.0
    unlimited, _ = _records(text.replace("G192 S1500\n", ""))
    assert unlimited[1].spindle == pytest.approx(200000 / (2 * 3.141592653589793 * 10), abs=1e-3)


@pytest.mark.parametrize("path", [CORPUS / "iso-turn" / "enier-haas-valve.nc",
                                  CORPUS / "iso-turn" / "kiely-haas-L8-Ex1.nc",
                                  REPO / "corpus" / "iso-t" / "g71-type2-pockets.nc"],
                         ids=lambda p: p.name)
def test_flattened_lathe_program_says_g152_and_round_trips(path):
    src = path.read_text(encoding="utf-8")
    conv = nctrans.transpile(src, read="iso-t", write="fagor")
    assert conv.ok, conv.diagnostics
    assert _lines(conv.text)[2] == "G152" and "flattened" in conv.text   # [1]: the header
    assert bool(nctrans.equiv(src, conv.text, read_a="iso-t", read_b="fagor"))
    back = nctrans.transpile(conv.text, read="fagor", write="iso-t")
    assert back.ok, back.diagnostics
    assert bool(nctrans.equiv(src, back.text, read_a="iso-t", read_b="iso-t"))
