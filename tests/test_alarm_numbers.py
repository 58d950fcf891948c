"""A program's own alarm keeps its meaning across controls (nctrans.alarm_numbers, NC408).

ISO `#3000=n (TEXT)` raises the program's own alarm n; Sinumerik SETAL takes cycle alarm numbers
only (60000..69999), so `SETAL(86, ..)` is another alarm. The own alarm n is SETAL(66000+n) (rules
sinumerik.toml alarms.user_base, the seed's own user alarm 66000 at L1898) and back. A number of a
control's own list (a Sinumerik cycle alarm 61000, a Fagor error-list number) has no place in
another control: it is raised as the target's "foreign" alarm (Sinumerik 65003, ISO 103) with the
number in the text. Every side stops at the alarm: equiv compares the moves before it."""
from __future__ import annotations

from nctrans import api

ISO = "O1000\nG0 X0 Y0 Z10.\n#1=5\nIF[#1GT2]THEN#3000=86(PROBE FAIL)\nG1 X10. F100.\nM30\n"
SIN = 'G0 X0 Y0 Z10\nSETAL(66086, "PROBE FAIL")\nSETAL(61000)\nG1 X10 F100\nM30\n'
FAGOR = 'G0 X0 Y0 Z10\n#ERROR [100]\n#ERROR ["PROBE FAIL"]\nG01 X10 F100\nM30\n'


def _nc408(conv):
    return [(d.line, d.severity) for d in conv.diagnostics if d.rule == "NC408"]


def test_iso_own_alarm_goes_into_sinumerik_user_band():
    conv = api.transpile(ISO, read="iso-m", write="sinumerik")
    # 66000 + 86 = 66086; the text is kept; the mapping said at line 4, as info
    assert '  SETAL(66086, "PROBE FAIL")' in conv.text.splitlines()
    assert "SETAL(86" not in conv.text
    assert _nc408(conv) == [(4, "info")]
    assert "86 raised as 66086" in next(d.message for d in conv.diagnostics if d.rule == "NC408")


def test_sinumerik_user_band_comes_back_as_the_iso_number():
    conv = api.transpile(SIN, read="sinumerik", write="iso-m")
    lines = conv.text.splitlines()
    assert "#3000=86 (PROBE FAIL)" in lines          # 66086 - 66000 = 86
    # 61000 is a cycle alarm of the Sinumerik list, ISO has no such number: #3000=103 with it in text
    assert "#3000=103 (ALARM 61000)" in lines
    assert _nc408(conv) == [(2, "info"), (3, "info")]


def test_round_trip_keeps_the_number():
    sin = api.transpile(ISO, read="iso-m", write="sinumerik").text
    back = api.transpile(sin, read="sinumerik", write="iso-m")
    assert "IF[#501GT2]THEN#3000=86 (PROBE FAIL)" in back.text or "THEN#3000=86 (PROBE FAIL)" in back.text


def test_sinumerik_to_sinumerik_keeps_its_own_numbers():
    conv = api.transpile(SIN, read="sinumerik", write="sinumerik")
    assert 'SETAL(66086, "PROBE FAIL")' in conv.text and "SETAL(61000)" in conv.text
    assert _nc408(conv) == []


def test_computed_own_alarm_is_shifted_by_the_band():
    conv = api.transpile("#1=7\n#3000=#1(BAD)\nM30\n", read="iso-m", write="sinumerik")
    # the control computes 66000 + R1 = 66007 at run time
    assert 'SETAL(R1+66000, "BAD")' in conv.text


def test_fagor_error_numbers_and_texts():
    to_sin = api.transpile(FAGOR, read="fagor", write="sinumerik")
    lines = to_sin.text.splitlines()
    # Fagor error 100 is of the Fagor list (not SETAL(0, 100) as before)
    assert 'SETAL(65003, "ALARM 100")' in lines and 'SETAL(65003, "PROBE FAIL")' in lines
    assert "SETAL(0" not in to_sin.text
    to_iso = api.transpile(FAGOR, read="fagor", write="iso-m")
    assert "#3000=103 (ALARM 100)" in to_iso.text.splitlines()
    assert "#3000=0" not in to_iso.text
    same = api.transpile(FAGOR, read="fagor", write="fagor")
    assert "#ERROR [100]" in same.text and '#ERROR ["PROBE FAIL"]' in same.text


def test_iso_alarm_to_fagor_is_its_text():
    conv = api.transpile(ISO, read="iso-m", write="fagor")
    assert '#ERROR ["PROBE FAIL"]' in conv.text
    plain = api.transpile("G0 X0 Y0 Z10.\n#3000=7\nM30\n", read="iso-m", write="fagor")
    assert '#ERROR ["ALARM 7"]' in plain.text


def test_every_side_stops_at_the_alarm(tmp_path):
    src = tmp_path / "a.nc"
    src.write_text(ISO)
    for target, ext in (("sinumerik", "mpf"), ("fagor", "pim")):
        out = tmp_path / f"a.{ext}"
        out.write_text(api.transpile(src, read="iso-m", write=target).text)
        # #1=5 > 2: the alarm at line 4 stops before G1 X10: one rapid to (0,0,10) and no feed move
        moves = [r for r in api.toolpath(out) if r.kind in ("rapid", "linear")]
        assert [(r.kind, r.end) for r in moves] == [("rapid", {"X": 0.0, "Y": 0.0, "Z": 10.0})]
        assert api.equiv(src, out).equivalent
        alarms = [d for d in api.lint(out) if d.rule == "NC221"]
        assert len(alarms) == 1


def test_equiv_sees_an_alarm_left_out():
    # without the alarm the run goes on to X10: the paths differ after (0,0,10)
    assert not api.equiv(ISO, ISO.replace("THEN#3000=86(PROBE FAIL)", "THEN#2=1"),
                         read_a="iso-m", read_b="iso-m").equivalent
