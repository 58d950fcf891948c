"""Thread start angles and multi-start threads (issue 8, nctrans/interp/thread_starts.py):
Sinumerik SF=, ISO G33/G32 Q (0.001 degree), CYCLE97 NUMT / CYCLE98 NUMTH starts spread from NSP.

Expected values by hand: the angle each thread move starts at (`thread_start`, absent at 0), the
cuts of a multi-start CYCLE97 (the single-start passes of test_milling_cycles, once per start)."""
from __future__ import annotations

import pytest

from nctrans import api, pipeline
from nctrans.source import from_text


def _threads(text: str, dialect: str, name: str = "t"):
    """(line, Z end, pitch, thread_start) of every thread move, and the diagnostics."""
    ld = pipeline.load_source(from_text(text, name), name, dialect)
    recs = [r for r in pipeline.toolpath_of(ld) if r.pitch]
    return [(r.line, round(r.end["Z"], 6), r.pitch, r.thread_start) for r in recs], ld.diagnostics


SINUMERIK = """G18 G90 T1 D1
S500 M3
G0 X20 Z5
G33 Z-20 K2 SF=90
G0 X30
Z5
X20
G33 Z-20 K2
G0 X30
SF=0
Z5
X20
G33 Z-20 K2
M30
"""


def test_sinumerik_sf_is_a_setting_that_holds_until_written_again():
    # SF=90 in the first thread block; the second thread (no SF) starts at 90 too (SD 42000);
    # SF=0 alone in a block: the third starts at 0 and carries no key
    threads, diags = _threads(SINUMERIK, "sinumerik", "t.mpf")
    assert threads == [(4, -20, 2.0, 90.0), (8, -20, 2.0, 90.0), (13, -20, 2.0, None)]
    assert not [d for d in diags if d.severity != "info"]


ISO = """G18 G90 G0 X20 Z5 S500 M3
G33 Z-20 F2 Q180000
G0 X30
Z5
X20
G33 Z-20 Q45500
M30
"""


def test_iso_q_is_the_start_angle_in_thousandths_of_a_degree():
    threads, diags = _threads(ISO, "iso-m", "t.nc")
    assert threads == [(2, -20, 2.0, 180.0), (6, -20, 2.0, 45.5)]
    assert not [d for d in diags if d.severity != "info"]


def test_iso_q_with_a_decimal_point_is_the_controls_alarm():
    _, diags = _threads("G18 G0 X20 Z5 S500 M3\nG33 Z-20 F2 Q180.\nM30\n", "iso-m", "t.nc")
    assert [(d.rule, d.line) for d in diags if d.severity == "error"] == [("NC121", 2)]


def _lathe(call: str) -> str:
    return f"G18 G90 G54 T1 D1\nS500 M3\nG0 X30 Z10\n{call}\nG0 X40\nM30\n"


def test_cycle97_cuts_each_start_completely_in_turn():
    # the single-start passes of test_cycle97_external_by_hand (roughing 9.5, 9.0, finishing 8.8,
    # one idle pass at 8.8, all from Z4 to Z-22) once per start; NUMT 3 from NSP 45: 45, 165, 285
    call = "CYCLE97(2, , 0, -20, 20, 20, 4, 2, 1.2, 0.2, 0, 45, 2, 1, 1, 3)"
    ld = pipeline.load_source(from_text(_lathe(call), "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear") and r.line == 4]
    got = [(r.kind, round(r.end["X"], 6), round(r.end["Z"], 6), r.pitch, r.thread_start) for r in recs]
    want = [("rapid", 11, 4, None, None)]
    for angle in (45.0, 165.0, 285.0):
        for x in (9.5, 9.0, 8.8, 8.8):
            want += [("rapid", x, 4, None, None), ("linear", x, -22, 2.0, angle),
                     ("rapid", 11, -22, None, None), ("rapid", 11, 4, None, None)]
    assert got == [(k, pytest.approx(x), pytest.approx(z), p, a) for k, x, z, p, a in want]
    assert not [d for d in ld.diagnostics if d.severity != "info"]


def test_cycle97_two_starts_from_zero_leave_the_first_without_a_key():
    call = "CYCLE97(2, , 0, -20, 20, 20, 4, 2, 1, 0, 0, 0, 1, 0, 1, 2)"
    threads, _ = _threads(_lathe(call), "sinumerik", "t.mpf")
    assert [(z, a) for _, z, _, a in threads] == [(-22, None), (-22, 180.0)]


def test_cycle97_angle_in_force_before_the_call_holds_after_it():
    text = _lathe("SF=30\nCYCLE97(2, , 0, -20, 20, 20, 4, 2, 1, 0, 0, 0, 1, 0, 1, 2)\nG0 X9 Z4\nG33 Z-20 K2")
    threads, _ = _threads(text, "sinumerik", "t.mpf")
    assert [a for *_, a in threads] == [None, 180.0, 30.0]


def test_cycle98_numth_starts():
    call = "CYCLE98(0, 20, -10, 20, -20, 24, -30, 24, 2, 2, 1, 0, 0, 90, 1, 0, 1.5, 2, 1.5, 1, 2, 0)"
    threads, diags = _threads(_lathe(call), "sinumerik", "t.mpf")
    # one cut (depth 1) through the five chain moves, then the same at the second start
    assert [a for *_, a in threads] == [90.0] * 5 + [270.0] * 5
    assert not [d for d in diags if d.severity != "info"]


@pytest.mark.parametrize("numt", ["2.5", "-1"])
def test_a_count_of_starts_that_is_not_a_whole_number_alarms(numt):
    call = f"CYCLE97(2, , 0, -20, 20, 20, 4, 2, 1, 0, 0, 0, 1, 0, 1, {numt})"
    threads, diags = _threads(_lathe(call), "sinumerik", "t.mpf")
    assert threads == [] and [d.rule for d in diags if d.line == 4] == ["NC225"]


# ------------------------------------------------------------------ conversion and equiv

def test_sinumerik_to_iso_and_back_keeps_the_start_angles():
    iso = api.transpile(SINUMERIK, "sinumerik", "iso-m")
    assert iso.text is not None
    lines = [ln for ln in iso.text.splitlines() if ln.startswith("G33")]
    # written where programmed, again on the thread that inherits it, Q0 where it returns to 0
    assert [ln.split()[-1] for ln in lines] == ["Q90000", "Q90000", "Q0"]
    assert api.equiv(SINUMERIK, iso.text, read_a="sinumerik", read_b="iso-m")
    back = api.transpile(iso.text, "iso-m", "sinumerik")
    assert back.text is not None and "SF=90" in back.text
    assert api.equiv(iso.text, back.text, read_a="iso-m", read_b="sinumerik")


def test_iso_to_sinumerik_writes_sf():
    conv = api.transpile(ISO, "iso-m", "sinumerik")
    assert conv.text is not None and "SF=180" in conv.text and "SF=45.5" in conv.text
    assert api.equiv(ISO, conv.text, read_a="iso-m", read_b="sinumerik")


def test_equiv_tells_threads_cut_at_other_angles_apart():
    other = SINUMERIK.replace("SF=90", "SF=180")
    eq = api.equiv(SINUMERIK, other, read_a="sinumerik", read_b="sinumerik")
    assert not eq and "thread start" in str(eq.difference.message)


def test_multi_start_cycle97_to_iso_turning_is_equivalent():
    text = "G18 G90 DIAMON T1 D1\nS500 M3\nG0 X30 Z10\nCYCLE97(2, , 0, -20, 20, 20, 4, 2, 1.2, 0.2, 0, 0, 2, 1, 1, 2)\nG0 X40\nM30\n"
    conv = api.transpile(text, "sinumerik", "iso-t")
    assert conv.text is not None and "CYCLE97" not in conv.text
    assert conv.text.count("Q180000") == 4               # the four cuts of the second start
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-t")
    back = api.transpile(conv.text, "iso-t", "sinumerik")
    assert back.text is not None and back.text.count("SF=180") >= 1
    assert api.equiv(conv.text, back.text, read_a="iso-t", read_b="sinumerik")


def test_flattened_sinumerik_keeps_the_angle_and_fagor_refuses_it():
    flat = api.transpile(SINUMERIK, "sinumerik", "sinumerik", flatten=True)
    assert flat.text is not None and "SF=90" in flat.text and "SF=0" in flat.text
    assert api.equiv(SINUMERIK, flat.text, read_a="sinumerik", read_b="sinumerik")
    fagor = api.transpile(SINUMERIK, "sinumerik", "fagor")
    assert fagor.text is None
    assert any(d.rule == "NC402" and "thread start angle" in d.message for d in fagor.diagnostics)


def test_flattened_iso_writes_q_for_a_fanuc_and_refuses_it_for_linuxcnc():
    fanuc = api.transpile(SINUMERIK, "sinumerik", "iso-m", flatten=True)
    assert fanuc.text is not None
    threads = [ln for ln in fanuc.text.splitlines() if "F2." in ln and ("G33" in ln or "Z-20." in ln)]
    assert [ln.split()[-1] for ln in threads] == ["Q90000", "Q90000", "Q0"]
    assert api.equiv(SINUMERIK, fanuc.text, read_a="sinumerik", read_b="iso-m")
    linuxcnc = api.transpile(SINUMERIK, "sinumerik", "iso-m", flatten=True, profile="linuxcnc")
    assert linuxcnc.text is None
    assert any(d.rule == "NC402" and d.line == 4 and "LinuxCNC" in d.message for d in linuxcnc.diagnostics)


G92 = "G18 G99 G97 S500 M3\nG0 X30 Z5\nG92 X19 Z-20 F2 Q180000\nX18\nG0 X40\n"


def test_iso_t_g92_threads_are_synchronised_and_keep_q_with_the_cycle():
    # X is a diameter: radius 9.5 then 9; the second pass (X18 alone) repeats the modal cycle with
    # its data, Q included, as F and R; a G32 after it starts at 0 (Q holds for the cycle only)
    threads, diags = _threads(G92 + "G0 X20 Z5\nG32 Z-20 F2\n", "iso-t", "t.nc")
    assert threads == [(3, -20, 2.0, 180.0), (4, -20, 2.0, 180.0), (7, -20, 2.0, None)]
    assert not [d for d in diags if d.severity != "info"]


@pytest.mark.parametrize("target", ["iso-t", "sinumerik", "iso-m"])
def test_a_g92_thread_lowered_to_plain_motion_stays_a_thread(target):
    # was written as G1 feeds per revolution: a thread cut that is not synchronised with the spindle
    text = G92 + "M30\n"
    conv = api.transpile(text, "iso-t", target, flatten=True)
    assert conv.text is not None
    lines = conv.text.splitlines()
    assert not any(ln.startswith(("G1 ", "G01 ")) for ln in lines)
    assert sum("Z-20" in ln and ("G32" in ln or "G33" in ln) for ln in lines) == 2
    assert api.equiv(text, conv.text, read_a="iso-t", read_b=target)


def test_equiv_tells_a_thread_from_a_plain_feed_per_revolution_at_the_same_speed():
    # G33 K2 at S500 and G95 F2 at S500 both move 1000 mm/min along the same line; only the
    # first is synchronised with the spindle (a thread), so the programs are not equivalent
    thread = "G54 G90 G0 X10 Z5\nS500 M3\nG33 Z-20 K2\nG0 X20\nM30\n"
    feed = "G54 G90 G0 X10 Z5\nS500 M3\nG95 G1 Z-20 F2\nG0 X20\nM30\n"
    assert api.equiv(thread, thread, read_a="sinumerik", read_b="sinumerik")
    eq = api.equiv(thread, feed, read_a="sinumerik", read_b="sinumerik")
    assert not eq and "pitch" in str(eq.difference.message)
