"""ISO G84/G74 end each hole as the Siemens ISO seed says (rules/cycles.toml [tapping] "stopped",
sinumerik-iso-milling 4.1.11 L3179 / 4.1.12 L3269): tap to the bottom, spindle stopped, dwell P,
reversed, feed out to R, dwell P at R, spindle stopped, G0 to the initial level under G98. The
next hole's rigid tap turns the spindle itself; with no M03/M04 in force every hole is NC209 (the
control's CYCLE384M alarms 61102, seed L6362). `--profile linuxcnc` keeps rs274's tap (out to the
clear level, spindle forward again). Expected records by hand from the seed's text."""
from __future__ import annotations

import nctrans
from nctrans import api

HEAD = "G90 G17 G94 G54\nS1000 M3\nG0 X0 Y0 Z50\n"      # lines 1-3


def steps(text: str, profile=None) -> list[tuple]:
    """(kind, Z end or dwell s or spindle direction) of the records from the first hole on."""
    out = []
    for r in nctrans.toolpath(text, "iso-m", profile=profile):
        if r.kind == "spindle":
            out.append(("spindle", r.spindle_dir))
        elif r.kind == "dwell":
            out.append(("dwell", r.dwell_s))
        elif r.kind in ("rapid", "linear"):
            out.append((r.kind, r.end["X"], r.end["Z"]))
    return out


def nc209(text: str) -> list[int]:
    return [d.line for d in api.lint(text, "iso-m") if d.rule == "NC209"]


def test_g98_two_holes_stop_the_spindle_and_the_second_tap_turns_it():
    # line 4: G98 (initial level Z50), R2, bottom Z-10, P500 = 0.5 s; line 5: second hole X20
    text = HEAD + "G98 G84 X10 Y10 Z-10 R2 P500 F1000\nX20\nG80\nM30\n"
    hole1 = [("rapid", 10.0, 50.0), ("rapid", 10.0, 2.0),
             ("linear", 10.0, -10.0), ("spindle", "off"), ("dwell", 0.5), ("spindle", "ccw"),
             ("linear", 10.0, 2.0), ("dwell", 0.5), ("spindle", "off"), ("rapid", 10.0, 50.0)]
    # hole 2: positioned at the initial level, R, then the rigid tap turns the spindle cw first
    hole2 = [("rapid", 20.0, 50.0), ("rapid", 20.0, 2.0), ("spindle", "cw"),
             ("linear", 20.0, -10.0), ("spindle", "off"), ("dwell", 0.5), ("spindle", "ccw"),
             ("linear", 20.0, 2.0), ("dwell", 0.5), ("spindle", "off"), ("rapid", 20.0, 50.0)]
    got = steps(text)
    assert got[got.index(("rapid", 10.0, 50.0)):] == hole1 + hole2
    assert nc209(text) == []


def test_g74_under_m4_turns_ccw_again_at_the_next_hole_and_feeds_out_to_r_only():
    text = "G90 G17 G94 G54\nS1000 M4\nG0 X0 Y0 Z50\nG99 G74 X10 Y10 Z-10 R2 F1000\nX20\nG80\nM30\n"
    got = steps(text)
    # G99: out to R (Z2) and stays there; no P: 0 s dwells; the second hole is turned ccw first
    assert got[got.index(("linear", 10.0, -10.0)):] == [
        ("linear", 10.0, -10.0), ("spindle", "off"), ("dwell", 0.0), ("spindle", "cw"),
        ("linear", 10.0, 2.0), ("dwell", 0.0), ("spindle", "off"),
        ("rapid", 20.0, 2.0), ("spindle", "ccw"),
        ("linear", 20.0, -10.0), ("spindle", "off"), ("dwell", 0.0), ("spindle", "cw"),
        ("linear", 20.0, 2.0), ("dwell", 0.0), ("spindle", "off")]
    assert nc209(text) == []


def test_k_repeats_turn_the_spindle_from_the_second_hole():
    # K2 at one position (G90): the M3 turns it for the first, the cycle for the second
    text = HEAD + "G99 G84 X10 Y10 Z-10 R2 K2 F1000\nG80\nM30\n"
    spindle = [s[1] for s in steps(text) if s[0] == "spindle"]
    assert spindle == ["cw", "off", "ccw", "off", "cw", "off", "ccw", "off"]


def test_no_direction_in_force_is_said_at_every_hole_with_the_controls_alarm():
    # M5 at line 4: no M03/M04 in force; each call alarms on the control (61102): both holes said
    text = HEAD + "M5\nG99 G84 X10 Y10 Z-10 R2 F1000\nX20\nG80\nM30\n"
    diags = [d for d in api.lint(text, "iso-m") if d.rule == "NC209"]
    assert [d.line for d in diags] == [5, 6]
    assert all("61102" in d.message and d.severity == "warning" for d in diags)
    taps = [s for s in steps(text) if s[0] == "spindle"]
    assert ("spindle", "cw") not in taps[1:]     # the cycle never turns it forward after M5


def test_m3_after_the_taps_starts_again_and_a_cut_without_it_is_said():
    # the spindle stays stopped after the tapping (seed): a feed move after G80 with no M3 is
    # NC209 at its line (7); with M3 first it is not
    tail = "G99 G84 X10 Y10 Z-10 R2 F1000\nG80\n{m}G1 X30 Z0 F200\nM30\n"
    assert nc209(HEAD + tail.format(m="G0 Z5\n")) == [7]
    assert nc209(HEAD + tail.format(m="M3\n")) == []


def test_linuxcnc_profile_keeps_rs274s_tap():
    text = HEAD + "G98 G84 X10 Y10 Z-10 R2 P500 F1000\nG80\nM30\n"
    got = steps(text, profile="linuxcnc")
    # rs274 2.9: stop, reverse, dwell, feed out to the clear level Z50, stop, forward
    assert got[got.index(("linear", 10.0, -10.0)):] == [
        ("linear", 10.0, -10.0), ("spindle", "off"), ("spindle", "ccw"), ("dwell", 0.5),
        ("linear", 10.0, 50.0), ("spindle", "off"), ("spindle", "cw")]


def test_flattened_seed_taps_read_back_equivalent():
    text = HEAD + "G98 G84 X10 Y10 Z-10 R2 P500 F1000\nX20\nG80\nG0 Z60\nM30\n"
    conv = api.transpile(text, "iso-m", "iso-m", flatten=True)
    lines = conv.text.splitlines()
    # each hole its G99 G84 (P in ms) then G80 and the rapid to Z50 (the G98 level); M3 before the
    # second, which the control's cycle turned
    assert lines.count("F1000. G99 G84 R2. P500 X10. Y10. Z-10.") == 1
    assert "F1000. G99 G84 R2. P500 X20. Y10. Z-10." in lines
    assert lines[lines.index("F1000. G99 G84 R2. P500 X20. Y10. Z-10.") - 2] == "M3"
    assert api.equiv(text, conv.text, read_a="iso-m", read_b="iso-m")
