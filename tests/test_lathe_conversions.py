"""Conversions to and from the ISO lathe (iso-t) drive the same toolpath or are refused at their line
(issue #9): X programmed as a diameter, the lathe's power-on plane ZX, incremental words that
system A has no address for. Expected values are computed by hand in the comments."""
from __future__ import annotations

import pytest

import nctrans
from nctrans import api


def _convert(text: str, read: str, write: str) -> nctrans.Conversion:
    conv = nctrans.transpile(text, read=read, write=write)
    assert conv.ok, [d.format_text() for d in conv.diagnostics]
    return conv


def _moves(text: str, dialect: str) -> list:
    return [r for r in nctrans.toolpath(text, dialect) if r.kind in ("rapid", "linear", "arc")]


def _end(text: str, dialect: str, axes: str = "XZ") -> tuple:
    last = _moves(text, dialect)[-1]
    return tuple(round(last.end[a], 6) for a in axes)


def _code_lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line and not line.startswith(("(", ";", "%"))]


# --------------------------------------------------------- G50 / G92 set position in diameter

# From machine X0 Z0: G50 X100. (a diameter: radius 50) Z50. makes the current point work X50 Z50,
# so the work zero sits at machine X-50 Z-50; G0 X60. (radius 30) Z20. ends at machine X-20 Z-30.
G50_LATHE = "G50 X100. Z50.\nG0 X60. Z20.\nM30\n"


def test_iso_turning_g50_diameter_is_a_radius_offset_on_sinumerik():
    assert _end(G50_LATHE, "iso-t") == (-20.0, -30.0)
    out = _convert(G50_LATHE, "iso-t", "sinumerik").text
    assert "ATRANS X=$P_EP[X]-(100.)/2 Z=$P_EP[Z]-(50.)" in out.splitlines()
    assert _end(out, "sinumerik") == (-20.0, -30.0)
    assert nctrans.equiv(G50_LATHE, out, read_a="iso-t", read_b="sinumerik")


def test_iso_turning_g50_diameter_is_a_radius_g92_on_iso_milling():
    out = _convert(G50_LATHE, "iso-t", "iso-m").text
    assert "G92 X50. Z50." in out.splitlines()
    assert _end(out, "iso-m") == (-20.0, -30.0)
    assert nctrans.equiv(G50_LATHE, out, read_a="iso-t", read_b="iso-m")


def test_sinumerik_diamon_set_position_round_trip_through_iso_turning():
    # the Sinumerik program written from G50_LATHE, converted back to the lathe: still X-20 Z-30
    sin = _convert(G50_LATHE, "iso-t", "sinumerik").text
    back = nctrans.transpile(sin, read="sinumerik", write="iso-t")
    if back.text is not None:
        assert _end(back.text, "iso-t") == (-20.0, -30.0)
        assert nctrans.equiv(sin, back.text, read_a="sinumerik", read_b="iso-t")
    else:
        assert any(d.severity == "error" and d.line >= 1 for d in back.diagnostics)


def test_iso_milling_g92_is_written_in_diameter_on_the_lathe():
    # a mill's G92 X50. (radius) is G50 X100. on iso-t; from machine 0: work zero at X-50 Z-50
    mill = "G92 X50. Z50.\nG0 X30. Z20.\nM30\n"
    out = _convert(mill, "iso-m", "iso-t").text
    assert any(line.startswith("G50 X100.") for line in out.splitlines()), out
    assert _end(out, "iso-t") == (-20.0, -30.0)
    assert nctrans.equiv(mill, out, read_a="iso-m", read_b="iso-t")


def test_corpus_g50_and_constant_surface_speed_on_sinumerik(corpus_dir):
    # corpus/iso-t/u-w-g50-css.nc: G50 X100. Z50. at machine 0, then G0 U-20. W-10.: diameter 80,
    # radius 40; G96 S200 there: 200000 / (2 pi 40) = 795.774715 rev/min
    from conftest import TESTS
    path = TESTS.parent / "corpus" / "iso-t" / "u-w-g50-css.nc"
    out = nctrans.transpile(path, read="iso-t", write="sinumerik").text
    speeds = [r.spindle for r in nctrans.toolpath(out, "sinumerik") if r.kind == "spindle"]
    assert speeds[0] == pytest.approx(795.774715, abs=1e-5)
    assert nctrans.equiv(path, out, read_a="iso-t", read_b="sinumerik")


# ----------------------------------------------------------------- diameter X to a milling X

def test_iso_turning_diameter_x_is_a_radius_on_iso_milling():
    # X60. is radius 30, U-20. a radius step of -10: X20 Z-10 at the end
    lathe = "G98\nG0 X60. Z5.\nG1 X40. Z-10. F100.\nM30\n"
    out = _convert(lathe, "iso-t", "iso-m").text
    assert "X30." in out and "X20." in out
    assert _end(out, "iso-m") == (20.0, -10.0)
    assert nctrans.equiv(lathe, out, read_a="iso-t", read_b="iso-m")


# ------------------------------------------------------------------ power-on plane

# ZX arc on the lathe: from X0 Z0 to radius 10 (X20. as a diameter) Z-10 with R10, centre
# (Z-10, X0) or (Z0, X10): G2 in ZX; both programs must agree on the plane the arc lies in
LATHE_ARC = "G98\nG0 X0. Z0.\nG2 X20. Z-10. R10. F100.\nM30\n"


@pytest.mark.parametrize("target", ["iso-m", "fagor", "sinumerik"])
def test_iso_turning_power_on_plane_zx_is_written_for_mills(target):
    out = _convert(LATHE_ARC, "iso-t", target).text
    arcs = [r for r in _moves(out, target) if r.kind == "arc"]
    assert [r.plane for r in arcs] == ["ZX"]
    assert (round(arcs[0].end["X"], 6), round(arcs[0].end["Z"], 6)) == (10.0, -10.0)
    assert nctrans.equiv(LATHE_ARC, out, read_a="iso-t", read_b=target)


MILL_ARC = "G0 X0 Y0 Z0\nG2 X10. Y10. I10. J0 F100.\nM30\n"


@pytest.mark.parametrize("source", ["iso-m", "fagor"])
def test_a_mill_arc_in_xy_stays_in_xy_on_the_lathe(source):
    # G17 is the mill's power-on plane: the lathe (power-on G18) must be told; centre X10 Y0
    mill = MILL_ARC if source == "iso-m" else "%ARC\n" + MILL_ARC
    out = _convert(mill, source, "iso-t").text
    first = _code_lines(out)[0].split()
    assert "G17" in first, out
    arcs = [r for r in _moves(out, "iso-t") if r.kind == "arc"]
    assert [r.plane for r in arcs] == ["XY"]
    assert (arcs[0].center["X"], arcs[0].center["Y"]) == (10.0, 0.0)
    assert (arcs[0].end["X"], arcs[0].end["Y"]) == (10.0, 10.0)
    assert nctrans.equiv(mill, out, read_a=source, read_b="iso-t")


def test_no_plane_is_added_between_two_lathe_programs():
    out = _convert(LATHE_ARC, "iso-t", "iso-t").text
    assert not any(w in ("G17", "G18", "G19") for w in out.split())


# --------------------------------------------------- incremental words system A cannot write

def test_an_incremental_y_is_not_written_as_an_absolute_y_on_the_lathe():
    # G91 from X0 Y0: X+10 then Y+10 twice: X10 Y20 at the end. System A has U/W/H only; an
    # incremental Y written as `Y10.` would be read as absolute (the second move would not move)
    mill = "G0 X0 Y0 Z0\nG91 G1 X10. F100.\nY10.\nY10.\nG90\nM30\n"
    conv = _convert(mill, "iso-m", "iso-t")
    ends = [(round(r.end["X"], 6), round(r.end["Y"], 6)) for r in _moves(conv.text, "iso-t")]
    assert ends[-1] == (10.0, 20.0)
    assert nctrans.equiv(mill, conv.text, read_a="iso-m", read_b="iso-t")
    # the lowering is said at the line of a Y move
    assert any(d.rule == "NC401" and d.line in (3, 4) for d in conv.diagnostics)


def test_api_load_reads_converted_lathe_programs_clean():
    out = _convert(MILL_ARC, "iso-m", "iso-t").text
    ld = api._load(out, "iso-t", file="<converted>")
    assert not [d for d in ld.diagnostics if d.rule.startswith("NC0")]
