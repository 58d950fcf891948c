"""The ISO external work offset (EXOFS: `G10 L2 P0`, `#5201..#5206`) shifts every work coordinate
system alike (seed sinumerik-iso-milling L1177-1204: "the workpiece coordinate systems determined
through G54 to G59 as well as G54 P.. are changed"). It was stored but never applied: every move
after it ran unshifted, silently wrong.

The oracle is LinuxCNC's rs274: it has no EXOFS (its `G10 L2 P0` means the active system), but its
G52 is one shift common to all G54..G59 systems, the same behaviour; so the ISO program with EXOFS
and the rs274 program with `G52` in its place must give the same machine moves."""
from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

import nctrans
import rs274 as harness
from nctrans import api
from nctrans.interp import interpret


def _moves(src: str):
    return [r for r in nctrans.toolpath(src, dialect="iso-m") if r.kind in ("linear", "rapid")]


def _ends(src: str):
    return [tuple(round(m.end[a], 6) for a in "XYZ") for m in _moves(src)]


def test_external_offset_moves_every_work_system():
    src = ("G21 G90 G17\nG10 L2 P1 X100 Y50\nG10 L2 P2 X-10 Y5\nG10 L2 P0 X1 Y2 Z3\n"
           "G54 G0 X0 Y0 Z0\nG55 X0 Y0\nG53 X0 Y0\nM30\n")
    # hand-computed: G54 = 100/50 + 1/2/3, G55 = -10/5 + 1/2/3, G53 machine X0 Y0 with
    # no offset at all (Z not programmed: stays at machine 3)
    assert _ends(src) == [(101.0, 52.0, 3.0), (-9.0, 7.0, 3.0), (0.0, 0.0, 3.0)]


def test_external_offset_written_while_a_system_is_active_moves_it_at_once():
    src = "G21 G90 G55\nG0 X0 Y0\n#5201=4.\n#5202=-1.\nG0 X1 Y1\n#100=#5201\nG0 X#100\nM30\n"
    # the read gives the external value alone (4), not the sum
    assert _ends(src) == [(0.0, 0.0, 0.0), (5.0, 0.0, 0.0), (8.0, 0.0, 0.0)]


def test_incremental_g10_adds_to_the_external_offset():
    src = "G21 G90 G54\nG10 L2 P0 X2\nG91 G10 L2 P0 X3\nG90 G0 X0\nM30\n"
    assert _ends(src) == [(5.0, 0.0, 0.0)]


@settings(max_examples=25, deadline=None)
@given(value=st.integers(-500, 500).map(lambda v: v / 100), axis=st.sampled_from("XYZ"))
def test_external_write_by_variable_and_by_g10_move_the_same(value, axis):
    number = 5201 + "XYZ".index(axis)
    by_var = _ends(f"G90 G21 G56\n#{number}={value}\nG0 X1 Y2 Z3\nM30\n")
    by_g10 = _ends(f"G90 G21 G56\nG10 L2 P0 {axis}{value}\nG0 X1 Y2 Z3\nM30\n")
    assert by_var == by_g10
    assert by_var[0]["XYZ".index(axis)] == pytest.approx((1, 2, 3)["XYZ".index(axis)] + value)


PROGRAM = """G21 G90 G17
G10 L2 P1 X100 Y50 Z-20
G10 L2 P2 X-10 Y5 Z0
{ext}
G54 G0 X10 Y10 Z5
G1 F100 X20 Y20 Z-1
G2 X30 Y20 I5 J0
G55 G0 X0 Y0
G1 X5 Y-5
M2
"""


def test_external_offset_matches_rs274_common_shift(rs274, rs274_cache):
    iso = PROGRAM.format(ext="G10 L2 P0 X7 Y-3 Z2")
    ngc = PROGRAM.format(ext="G52 X7 Y-3 Z2")
    src = rs274_cache / "ext_offset.ngc"
    src.write_text(ngc)
    table = harness.write_tool_table(rs274_cache / "ext_offset.tbl", [(1, 0.0, 0.0)])
    ref = harness.run_rs274(src, table, rs274_cache / "ext_offset.out")
    assert ref.completed, ref.message
    from nctrans.dialects import base
    program = base.get("iso-m").parse(iso, "ext.nc").program
    diags: list = []
    got = [harness.Motion.of(r) for r in interpret(program, diagnostics=diags)
           if r.kind in ("rapid", "linear", "arc")]
    assert not [d for d in diags if d.severity == "error"], diags
    assert harness.compare(ref.moves, got, "ext_offset") is None


# ---------------------------------------------------------------- conversion to Sinumerik

def _convert(src: str, tmp_path):
    path = tmp_path / "p.nc"
    path.write_text(src)
    return nctrans.transpile(path, read="iso-m", write="sinumerik")


@pytest.mark.parametrize("g10", ["G10 L2 P1 X100 Y50", "G10 L2 P0 X7 Y-3", "#5201=7.",
                                 "G91 G10 L2 P0 X7 Y-3 G90"])
def test_offset_data_is_never_dropped_by_a_conversion(g10, tmp_path):
    # G10 L2 P1 was "lowered to plain motion" alone: nothing, and the G54 move after it ran
    # without the offset in the Sinumerik output (equiv: X110 Y60 vs X10 Y10)
    src = f"G21 G90 G17\n{g10}\nG54 G0 X10 Y10\nG1 X20 F100\nM30\n"
    conv = _convert(src, tmp_path)
    assert conv.text is not None
    out = tmp_path / "p.mpf"
    out.write_text(conv.text)
    a = [tuple(round(r.end[k], 6) for k in "XY") for r in nctrans.toolpath(src, dialect="iso-m")
         if r.kind in ("rapid", "linear")]
    b = [tuple(round(r.end[k], 6) for k in "XY") for r in nctrans.toolpath(conv.text, dialect="sinumerik")
         if r.kind in ("rapid", "linear")]
    assert a == b
    shift = {"G10 L2 P1 X100 Y50": (100, 50), "G10 L2 P0 X7 Y-3": (7, -3), "#5201=7.": (7, 0),
             "G91 G10 L2 P0 X7 Y-3 G90": (7, -3)}[g10]
    assert a[0] == (10 + shift[0], 10 + shift[1])       # hand-computed


# ---------------------------------------------------------------- G68 with a vector

def test_g68_with_a_vector_is_reported_not_turned_in_the_plane():
    src = "G21 G90 G17\nG0 X0 Y0\nG68 X0 Y0 I1 J0 K0 R90\nG1 X10 F100\nG69\nM30\n"
    diags: list = []
    from nctrans.dialects import base
    program = base.get("iso-m").parse(src, "g68.nc").program
    moves = [r for r in interpret(program, diagnostics=diags) if r.kind == "linear"]
    # not rotated about Z (that gave Y10) and said so at the G68 line
    assert [round(m.end["Y"], 6) for m in moves] == [0.0]
    assert any(d.rule == "NC220" and d.line == 3 and "3D rotation" in d.message for d in diags)


def test_g68_with_a_vector_is_refused_by_the_sinumerik_conversion(tmp_path):
    # never written as a rotation in the plane: refused at its line, in place (the alarm stands
    # where it was; the control stops there), or whole with --strict
    src = "G21 G90 G17\nG68 X0 Y0 I0 J0 K1 R90\nG1 X10 F100\nG69\nM30\n"
    conv = _convert(src, tmp_path)
    assert any(d.rule == "NC412" and d.line == 2 and "G68" in d.message for d in conv.diagnostics)
    assert 'SETAL(65002, "NOT CONVERTED: SOURCE LINE 2")' in conv.text.splitlines()
    assert "ROT" not in conv.text
    strict = nctrans.transpile(src, read="iso-m", write="sinumerik", strict=True)
    assert strict.text is None and any(d.line == 2 for d in strict.diagnostics if d.severity == "error")


def test_g68_in_the_plane_still_rotates():
    moves = [m for m in _moves("G21 G90 G17\nG0 X0 Y0\nG68 X0 Y0 R90\nG1 X10 F100\nG69\nM30\n")
             if m.kind == "linear"]
    assert (round(moves[0].end["X"], 6), round(moves[0].end["Y"], 6)) == (0.0, 10.0)


@settings(max_examples=15, deadline=None)
@given(x=st.integers(-5000, 5000).map(lambda v: v / 100), y=st.integers(-5000, 5000).map(lambda v: v / 100),
       by_var=st.booleans(), work=st.sampled_from(["G54", "G55", "G57"]))
def test_external_offset_is_kept_as_the_sinumerik_external_frame(x, y, by_var, work, tmp_path_factory):
    ext = f"#5201={x}\n#5202={y}" if by_var else f"G10 L2 P0 X{x} Y{y}"
    # (a G10 L2 P1..6 would make the whole conversion plain motion: $P_UIFR is not written yet)
    src = f"G21 G90 G17\n{work} G0 X1 Y1\n{ext}\nG1 X10 Y2 F100\nG55 X-10 Y5\nM30\n"
    conv = _convert(src, tmp_path_factory.mktemp("ext"))
    assert conv.text is not None
    assert "$P_EXTFRAME[X,TR]=" in conv.text and "flattened" not in conv.text
    assert api.equiv(src, conv.text, read_a="iso-m", read_b="sinumerik")
    last = [r for r in nctrans.toolpath(conv.text, dialect="sinumerik") if r.kind == "linear"][-1]
    assert (round(last.end["X"], 6), round(last.end["Y"], 6)) == (round(-10 + x, 6), round(5 + y, 6))
    assert [round(m.end["X"], 6) for m in [r for r in nctrans.toolpath(src, dialect="iso-m")
                                            if r.kind == "linear"]] == [round(10 + x, 6), round(-10 + x, 6)]


def test_sinumerik_external_frame_components_other_than_tr_are_reported():
    from nctrans.dialects import base
    program = base.get("sinumerik").parse("G54 G0 X0\n$P_EXTFRAME[X,TR]=5\nG0 X10\n"
                                          "$P_EXTFRAME[Z,RT]=30\nG0 X0\nM30\n", "e.mpf").program
    diags: list = []
    moves = [r for r in interpret(program, diagnostics=diags) if r.kind == "rapid"]
    assert [m.end["X"] for m in moves] == [0.0, 15.0, 5.0]
    assert any(d.rule == "NC107" and d.line == 4 for d in diags)


def test_external_frame_round_trips_iso_sinumerik_iso(tmp_path):
    src = "G21 G90 G17\nG10 L2 P0 X7 Y-3\nG54 G0 X10 Y10\n#5201=4.\nG0 X1\nG55 X2\nM30\n"
    sin = _convert(src, tmp_path).text
    path = tmp_path / "p.mpf"
    path.write_text(sin)
    back = nctrans.transpile(path, read="sinumerik", write="iso-m").text
    assert "#5201=7" in back and "#5202=-3" in back and "#5201=4" in back
    assert api.equiv(src, back, read_a="iso-m", read_b="iso-m")
    # hand-computed ends: G54 + (7, -3); then X 1 + 4; G55 X 2 + 4
    assert _ends(back) == [(17.0, 7.0, 0.0), (5.0, 7.0, 0.0), (6.0, 7.0, 0.0)]


def test_offset_data_is_never_dropped_by_a_streamed_conversion(tmp_path, capsys):
    # convert -o - streams with per-construct lowering: the G10 was lowered alone there too
    from nctrans import cli
    src = tmp_path / "p.nc"
    src.write_text("G21 G90 G17\nG10 L2 P1 X100 Y50\nG54 G0 X10 Y10\nM30\n")
    assert cli.main(["convert", str(src), "--to", "sinumerik", "-o", "-"]) == 0
    out = capsys.readouterr().out
    moves = [r for r in nctrans.toolpath(out, dialect="sinumerik") if r.kind == "rapid"]
    assert (moves[-1].end["X"], moves[-1].end["Y"]) == (110.0, 60.0)      # hand-computed
