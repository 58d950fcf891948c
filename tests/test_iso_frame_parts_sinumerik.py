"""ISO frame components are cancelled one by one (G69, G50, G92.1, G52 X0); in Sinumerik they are
one programmable frame, and the TRANS written for a cancel or a G52 clears all of it. With another
component in force the conversion wrote that TRANS anyway and moved elsewhere with exit 0:
`G52 X50 Y25 / G68 R30 / G69 / G0 X10 Y0` went to (10, 0) instead of (60, 25). Such a stretch is
now lowered to plain motion (or refused at its line), never written as a TRANS that drops a
component. Ends computed by hand."""
from __future__ import annotations

from nctrans import api


def ends(text, dialect):
    return [(round(r.end["X"], 6), round(r.end["Y"], 6))
            for r in api.toolpath(text, dialect) if r.kind in ("rapid", "linear")]


def test_rotation_cancel_keeps_the_local_offset():
    text = ("G21 G17 G90\nG54 G0 X0 Y0 Z20\nG52 X50. Y25.\nG68 X0 Y0 R30.\nG0 X10. Y0\nG69\n"
            "G0 X10. Y0\nG52 X0 Y0\nG0 X1 Y1\nM30\n")
    # rotated: (10 cos30, 10 sin30) + (50, 25) = (58.660254, 30); after G69 (10, 0) + (50, 25)
    expected = [(0, 0), (58.660254, 30.0), (60.0, 25.0), (1.0, 1.0)]
    assert ends(text, "iso-m") == expected
    conv = api.transpile(text, "iso-m", "sinumerik")
    assert conv.text
    assert ends(conv.text, "sinumerik") == expected
    assert api.equiv(text, conv.text, read_a="iso-m", read_b="sinumerik")


def test_local_offset_under_rotation_keeps_the_rotation():
    # G68 R90 about the origin, then G52 X5 (a local offset stacked under the rotation): ISO keeps
    # the rotation; a Sinumerik TRANS X5 alone would drop it
    text = ("G21 G17 G90\nG0 X0 Y0 Z5\nG68 X0 Y0 R90.\nG0 X10. Y0\nG52 X5. Y0\nG0 X10. Y0\nG52 X0 Y0\n"
            "G69\nM30\n")
    src = ends(text, "iso-m")
    conv = api.transpile(text, "iso-m", "sinumerik")
    assert conv.text
    assert ends(conv.text, "sinumerik") == src
    assert api.equiv(text, conv.text, read_a="iso-m", read_b="sinumerik")


def test_a_cancel_with_nothing_else_in_force_stays_a_trans():
    text = "G21 G17 G90\nG0 X0 Y0 Z5\nG68 X0 Y0 R90.\nG0 X10. Y0\nG69\nG0 X10. Y0\nM30\n"
    conv = api.transpile(text, "iso-m", "sinumerik")
    body = [ln.strip() for ln in conv.text.splitlines()]
    assert "TRANS" in body and not [d for d in conv.diagnostics if "stays in force" in d.message]
    assert ends(conv.text, "sinumerik") == ends(text, "iso-m") == [(0, 0), (0.0, 10.0), (10.0, 0.0)]
