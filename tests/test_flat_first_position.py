"""Plain motion writes an axis at the first position the source programs for it, even where the
analysis' start point (machine zero) has the tool there already: on the machine the tool starts
anywhere (at the tool change position, say). `G0 X0 Y0 Z10` then `G1 Z-1` was flattened to
`G0 Z10` and `G1 Z-1`: the plunge at whatever XY the machine stood at. An axis the source never
programs is never written (no position invented either)."""
from __future__ import annotations

from nctrans import api

PLUNGE = {"sinumerik": "G17 G90 G54\nT1 D1 M6\nG0 X0 Y0 Z10\nG1 Z-1 F100\nG0 Z10\nM30\n",
          "iso-m": "G17 G90 G54\nT1 M6\nG0 X0 Y0\nG43 H1 Z10.\nG1 Z-1. F100.\nG0 Z10.\nM30\n"}


def motion_lines(text):
    return [ln.split("(")[0].split() for ln in text.splitlines()
            if any(w in ln.split() for w in ("G0", "G1"))]


def first_with(lines, word):
    return next(i for i, ws in enumerate(lines) if any(w.startswith(word) for w in ws))


def test_first_programmed_position_is_written_before_the_plunge():
    for source, text in PLUNGE.items():
        conv = api.transpile(text, source, "iso-m", flatten=True)
        lines = motion_lines(conv.text)
        plunge = next(i for i, ws in enumerate(lines) if "Z-1." in ws)
        # X0 and Y0 are written, and before the feed to Z-1
        assert first_with(lines, "X0.") < plunge and first_with(lines, "Y0.") < plunge, lines
        assert api.equiv(text, conv.text, read_a=source, read_b="iso-m")


def test_an_axis_the_source_never_programs_is_not_written():
    text = "G17 G90 G54\nT1 D1 M6\nG0 X5 Z10\nG1 Z-1 F100\nG0 Z10\nM30\n"
    conv = api.transpile(text, "sinumerik", "iso-m", flatten=True)
    words = [w for ws in motion_lines(conv.text) for w in ws]
    assert "X5." in words and not [w for w in words if w.startswith("Y")]
