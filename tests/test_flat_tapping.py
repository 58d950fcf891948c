"""Taps in plain motion in the target control's form (issue 8, nctrans/lower/flat_tapping.py):
a Fanuc's rigid tapping cycle `M29 S..` / `G84`/`G74` (ISO seed 4.1.11, the iso-m default), and
LinuxCNC's `G33.1` (`--profile linuxcnc`); taps of another shape and threads stay G33 moves.

Each output is read back and compared with the source (`equiv`): the form is only written where it
runs exactly the records the source's tap has. Expected texts by hand from the seed's format."""
from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from nctrans import api

import rs274 as h


def _flat(text: str, read: str, profile=None):
    conv = api.transpile(text, read, "iso-m", flatten=True, profile=profile)
    assert conv.text is not None, [d.format_text() for d in conv.diagnostics]
    return conv


def test_g74_under_m4_with_a_dwell_at_two_holes_in_two_work_offsets():
    text = ("G17 G90 G94 G54\nT1 M6\nS400 M4\nG0 X10 Y10 Z20\nG99 G74 Z-10 R5 F600 P300\nG55 X20\n"
            "G80\nG0 Z30\nM30\n")
    conv = _flat(text, "iso-m")
    lines = conv.text.splitlines()
    # each hole: rigid tapping mode with the speed, the cycle from R = the level the tap starts
    # at (Z5), P in ms, cancelled after its hole; the second under G55 as the source
    assert lines.count("S400 M29") == 2 and lines.count("G80") == 2
    assert "F600. G99 G74 R5. P300 X10. Y10. Z-10." in lines
    assert "F600. G99 G74 R5. P300 X20. Y10. Z-10." in lines
    assert lines[lines.index("F600. G99 G74 R5. P300 X10. Y10. Z-10.") + 2].startswith("G55")
    assert not any(ln.startswith("G33") for ln in lines)
    assert api.equiv(text, conv.text, read_a="iso-m", read_b="iso-m")


def test_a_thread_that_is_no_tap_stays_a_g33_move_with_its_lead_as_f():
    text = "G17 G90 G94 G54\nS500 M3\nG0 X0 Y0 Z5\nG33 Z-5 F1\nG0 Z20\nM30\n"
    conv = _flat(text, "iso-m")
    assert "G33 Z-5. F1." in conv.text.splitlines() and "M29" not in conv.text
    assert api.equiv(text, conv.text, read_a="iso-m", read_b="iso-m")


def test_g98_tap_of_the_seed_is_a_g99_cycle_then_a_rapid_and_linuxcncs_is_not():
    text = "G17 G90 G94 G54\nS500 M3\nG0 X10 Y10 Z20\nG98 G84 Z-10 R5 F750\nG80\nM30\n"
    # iso-m (the seed, L3179): G98 taps out to R (Z5), stops the spindle, rapids to Z20: the tap
    # is the G99 form, the rapid after it a move of its own; the spindle stays stopped
    conv = _flat(text, "iso-m")
    lines = conv.text.splitlines()
    assert "F750. G99 G84 R5. X10. Y10. Z-10." in lines
    assert lines[lines.index("F750. G99 G84 R5. X10. Y10. Z-10.") + 2] == "G0 Z20."
    assert api.equiv(text, conv.text, read_a="iso-m", read_b="iso-m")
    # LinuxCNC's G98 tap feeds out to the initial level Z20, not to where it began (Z5): that is
    # no G33.1 (which returns to where it began), so it stays G33 moves (LinuxCNC's lead word K)
    conv = _flat(text, "iso-m", "linuxcnc")
    assert "G33 Z-10. K1.5" in conv.text.splitlines() and "G84" not in conv.text


CYCLE84 = "G17 G90 G0 X10 Y10 Z20 S500 M3\nCYCLE84(10, 0, 2, -10, , , 3, , 1.5)\nG0 X30\nM30\n"


def test_cycle84_for_a_fanuc_stays_g33_and_for_linuxcnc_is_g33_1():
    fanuc = _flat(CYCLE84, "sinumerik")
    assert "G33 Z-10. F1.5" in fanuc.text.splitlines() and "G84" not in fanuc.text
    assert api.equiv(CYCLE84, fanuc.text, read_a="sinumerik", read_b="iso-m")
    linuxcnc = _flat(CYCLE84, "sinumerik", "linuxcnc")
    assert "G33.1 Z-10. K1.5" in linuxcnc.text.splitlines()
    assert api.equiv(CYCLE84, linuxcnc.text, read_a="sinumerik", read_b="iso-m")


@pytest.mark.rs274
def test_g33_1_runs_in_rs274_with_the_source_moves(rs274, tmp_path):
    from nctrans import pipeline
    from nctrans.source import from_text
    conv = _flat(CYCLE84, "sinumerik", "linuxcnc")
    prog = tmp_path / "tap.ngc"
    prog.write_text(conv.text, encoding="utf-8")
    table = h.write_tool_table(tmp_path / "tools.tbl", [])
    run = h.run_rs274(prog, table, tmp_path / "tap.out")
    assert run.completed, run.message
    ld = pipeline.load_source(from_text(CYCLE84, "t.mpf"), "t.mpf", "sinumerik")
    source = [h.Motion.of(r) for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear", "arc")]
    assert h.compare(run.moves, source, "tap") is None


@settings(max_examples=40, deadline=None)
@given(st.floats(-30, -1), st.floats(0.5, 10), st.integers(100, 2000), st.sampled_from([0.5, 1.0, 1.25, 1.5, 2.0]),
       st.sampled_from(["M3", "M4"]), st.sampled_from([None, 100, 1500]), st.integers(1, 3))
def test_any_g99_tap_written_as_the_cycle_reads_back_the_same(bottom, r, speed, lead, hand, dwell, holes):
    cycle = "G84" if hand == "M3" else "G74"
    p = f" P{dwell}" if dwell else ""
    moves = "".join(f"X{10 * k}\n" for k in range(2, holes + 1))
    text = (f"G17 G90 G94 G54\nS{speed} {hand}\nG0 X10 Y0 Z20\n"
            f"G99 {cycle} Z{bottom:.3f} R{r:.3f} F{lead * speed:.3f}{p}\n{moves}G80\nG0 Z50\nM30\n")
    conv = _flat(text, "iso-m")
    assert conv.text.count(f"G99 {cycle}") == holes and "G33" not in conv.text
    eq = api.equiv(text, conv.text, read_a="iso-m", read_b="iso-m")
    assert eq, eq.difference
