"""A tapping cycle fed with the spindle standing is NC209 at the line that taps (wave 12):
CYCLE840 (compensating chuck: it never turns the spindle itself) at an MCALL position after an
earlier hole's SDAC 5, ISO G84/G74 after M5. CYCLE84 taps with G331, which turns the spindle
first (rigid_tap): never reported. Expected lines and records by hand."""
from __future__ import annotations

import pytest

import nctrans
from nctrans import api, cli

HEAD = "G17 G90 G54 T1 D1 M6\nS500 M3 F100\nG0 X0 Y0 Z50\n"


def mcall(call: str) -> str:
    # lines 1-3 HEAD, 4 MCALL, 5 first position, 6 second position, 7 MCALL off, 8 M30
    return HEAD + f"MCALL {call}\nX10 Y10\nX20 Y10\nMCALL\nM30\n"


# CYCLE840(RTP, RFP, SDIS, DP, DPR, DTB, SDR, SDAC, ENC, MPIT, PIT): SDR 3, ENC 0, pitch 1 mm
CYCLE840 = "CYCLE840(10, 0, 2, -10, , 0, 3, {sdac}, 0, , 1.0)"
# CYCLE84(RTP, RFP, SDIS, DP, DPR, DTB, SDAC, MPIT, PIT, POSS, SST, SST1)
CYCLE84 = "CYCLE84(10, 0, 2, -10, , 0, {sdac}, , 1.0, 0, 500, 500)"


def nc209(text: str, dialect: str = "sinumerik") -> list[tuple]:
    return [(d.line, d.severity) for d in api.lint(text, dialect) if d.rule == "NC209"]


def spindle_at_taps(text: str, dialect: str = "sinumerik") -> list[str]:
    """The spindle direction in force at each feed move into a hole (end below the start)."""
    now, out = None, []
    for r in nctrans.toolpath(text, dialect):
        if r.kind == "spindle":
            now = r.spindle_dir
        elif r.kind == "linear" and r.end["Z"] < r.start["Z"]:
            out.append(now)
    return out


def test_cycle840_sdac5_under_mcall_second_position_taps_standing():
    text = mcall(CYCLE840.format(sdac=5))
    # hole 1 taps under M3; its SDAC 5 stops the spindle; CYCLE840 does not start it again
    assert spindle_at_taps(text) == ["cw", "off"]
    assert nc209(text) == [(6, "warning")]     # the second position's line, not the first


def test_cycle840_sdac5_each_standing_position_is_said():
    # positions at lines 5, 6, 7, (M3 at 8), 9, 10: every hole turns the spindle back (SDR 3: M4
    # at the bottom) and stops it again (SDAC 5), a fresh stop each time, so 6, 7 and 10 tap
    # standing and each is said at its own line; 9 taps under the M3 of line 8
    text = (HEAD + f"MCALL {CYCLE840.format(sdac=5)}\nX10 Y10\nX20 Y10\nX30 Y10\nM3\nX40 Y10\n"
            "X50 Y10\nMCALL\nM30\n")
    assert spindle_at_taps(text) == ["cw", "off", "off", "cw", "off"]
    assert nc209(text) == [(6, "warning"), (7, "warning"), (10, "warning")]


def test_cycle840_sdac3_not_reported():
    text = mcall(CYCLE840.format(sdac=3))
    assert spindle_at_taps(text) == ["cw", "cw"]
    assert nc209(text) == []


def test_cycle84_sdac5_turns_the_spindle_itself():
    # G331 turns the spindle the thread's way before the second hole's tap (rigid_tap)
    text = mcall(CYCLE84.format(sdac=5))
    assert spindle_at_taps(text) == ["cw", "cw"]
    assert nc209(text) == []


ISO_HEAD = "O1000\nG17 G90 G54 G21\nT1 M6\nS500 M3\nG0 X0 Y0 Z50\n"


@pytest.mark.parametrize("code", ["G84", "G74"])
def test_iso_tap_after_m5_reported_at_the_cycle_line(code):
    # line 6 M5, line 7 the cycle: G84/G74 stop and reverse the spindle, never start it
    text = ISO_HEAD + f"M5\nG99 {code} X10 Y10 Z-10 R2 F500\nG80\nM30\n"
    assert spindle_at_taps(text, "iso-m") == ["off"]
    assert nc209(text, "iso-m") == [(7, "warning")]


def test_iso_tap_turning_not_reported_and_m5_between_positions_is():
    text = ISO_HEAD + "G99 G84 X10 Y10 Z-10 R2 F500\nM5\nX20\nG80\nM30\n"
    assert spindle_at_taps(text, "iso-m") == ["cw", "off"]
    assert nc209(text, "iso-m") == [(8, "warning")]


def test_drilling_cycle_after_m5_is_said_too():
    # CYCLE81 feeds to the depth: the general cycle text, at the call's line 5
    text = HEAD + "M5\nCYCLE81(10, 0, 2, -5)\nM30\n"
    said = [d for d in api.lint(text, "sinumerik") if d.rule == "NC209"]
    assert [(d.line, d.severity) for d in said] == [(5, "warning")]
    assert "cycle feed move" in said[0].message


def test_fail_on_warning_exit_1_lint_and_toolpath(tmp_path, capsys):
    bad, good = tmp_path / "bad.mpf", tmp_path / "good.mpf"
    bad.write_text(mcall(CYCLE840.format(sdac=5)))
    good.write_text(mcall(CYCLE840.format(sdac=3)))
    for cmd in ("lint", "toolpath"):
        assert cli.main([cmd, str(bad), "--fail-on", "warning"]) == 1
        assert cli.main([cmd, str(good), "--fail-on", "warning"]) == 0
    capsys.readouterr()


def test_check_keeps_to_its_documented_codes_and_lint_says_it(tmp_path, capsys):
    # README "Machine check": check prints the machine findings (NC3xx), the program's errors and
    # what the toolpath leaves out (not-analysed rules); NC209 is none of those, so check is clean
    # on this program (exit 0) while lint says the second position (line 6)
    bad = tmp_path / "bad.mpf"
    bad.write_text(mcall(CYCLE840.format(sdac=5)))
    assert cli.main(["check", str(bad)]) == 0
    assert "NC209" not in capsys.readouterr().out
    assert cli.main(["lint", str(bad), "--fail-on", "warning"]) == 1
    out = capsys.readouterr().out
    assert "bad.mpf:6:1: warning[NC209]" in out and ":5:1: warning[NC209]" not in out
