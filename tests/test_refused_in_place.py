"""A Sinumerik subprogram file converted to ISO keeps its structure when one construct has no ISO
counterpart (an interrupt, a synchronized action, a system variable with no ISO number, a machine's
own axis name): that construct alone becomes an alarm at its place (NC412), since a subprogram file
cannot be lowered to plain motion and leaving it out would change what the machine does. The ISO
alarm after THEN (`IF[..]THEN#3000=n`) stops the control as it does alone on a line."""
from __future__ import annotations

from nctrans import api
from nctrans.dialects.base import get
from nctrans.dialects.iso_m.plan import NOT_CONVERTED_ALARM, stable_number
from nctrans.interp import interpret
from nctrans.machine import default_mill

PROBE = "PROC PROBE(REAL DEPTH)\nG1 Z=-DEPTH F100\nSETINT(3) PRIO=1 RETRACT\nG1 Z0\nRET\n"


def _run_iso(text: str):
    found: list = []
    records = list(interpret(get("iso-m").parse(text, "t.nc").program, default_mill(), diagnostics=found))
    return records, found


def test_alarm_after_then_stops_the_iso_control():
    text = "%\nO1\n#1=3\nIF[#1GT2]THEN#3000=5(TOO DEEP)\nG0 X1.\nM30\n%\n"
    records, found = _run_iso(text)
    assert not [r for r in records if r.kind == "rapid"]
    assert [(d.rule, d.line) for d in found if d.severity == "error"] == [("NC221", 4)]
    assert "alarm 5: TOO DEEP" in found[0].message
    records, found = _run_iso(text.replace("#1=3", "#1=2"))
    assert [r.end["X"] for r in records if r.kind == "rapid"] == [1.0] and not found
    # written back the same way
    out = api.transpile(text, read="iso-m", write="iso-m")
    assert "IF[#1GT2]THEN#3000=5 (TOO DEEP)" in out.text.splitlines()


def test_interrupt_in_a_proc_file_is_an_alarm_at_its_place():
    conv = api.transpile(PROBE, read="sinumerik", write="iso-m")
    assert conv.ok
    number = stable_number("PROBE", set())
    lines = conv.text.splitlines()
    body = lines[lines.index("G1 F100. Z[-#1]"):]
    assert body[:4] == ["G1 F100. Z[-#1]", f"#3000={NOT_CONVERTED_ALARM} (NOT CONVERTED: SETINT[3] PRIO=1 RETRACT)",
                        "G1 Z0.", "M99"]
    warn = [d for d in conv.diagnostics if d.rule == "NC412"]
    assert [(d.line, d.severity) for d in warn] == [(3, "warning")]
    assert "SETINT" in warn[0].message and f"#3000={NOT_CONVERTED_ALARM}" in warn[0].message
    # called: the ISO subprogram runs as the source up to the interrupt, then stops there
    main = f"%\nO1\nG0 Z50.\nG65 P{number} A5.\nG0 Z60.\nM30\n"
    sub = "\n".join(x for x in lines if x != "%")
    records, found = _run_iso(main.replace("M30\n%\n", "M30\n") + sub + "\n%\n")
    assert [(r.kind, r.end["Z"]) for r in records if r.kind in ("rapid", "linear")] == [("rapid", 50.0), ("linear", -5.0)]
    assert [d.rule for d in found if d.severity == "error"] == ["NC221"]
    assert f"alarm {NOT_CONVERTED_ALARM}" in found[0].message


def test_strict_refuses_a_construct_refused_in_place():
    conv = api.transpile(PROBE, read="sinumerik", write="iso-m", strict=True)
    assert conv.text is None
    assert [d.severity for d in conv.diagnostics if d.rule == "NC412"] == ["error"]


def test_the_same_construct_in_a_main_program_is_not_refused_in_place():
    # a main program has a toolpath of its own: the construct goes to per-construct lowering,
    # which cannot carry an interrupt, so the conversion is refused as before
    conv = api.transpile("G0 X0\nSETINT(3) PRIO=1 RETRACT\nG1 X10 F100\nM30\n", read="sinumerik", write="iso-m")
    assert conv.text is None
    assert [d.line for d in conv.diagnostics if d.rule == "NC402"] == [2]
    assert not [d for d in conv.diagnostics if d.rule == "NC412"]


def test_a_machine_axis_name_is_never_written_as_an_iso_word():
    # XV (a following axis) was written as 'XV5', which no ISO control reads as that axis
    conv = api.transpile("G0 X0\nG1 X10 XV=5 F100\nM30\n", read="sinumerik", write="iso-m")
    assert conv.text is None
    refused = [d for d in conv.diagnostics if d.rule == "NC402" and "XV" in d.message]
    assert refused and refused[0].line == 2
    proc = api.transpile("PROC SLIDE(REAL DIST)\nG1 X=DIST XV=DIST F100\nG1 X0\nRET\n", read="sinumerik", write="iso-m")
    assert proc.ok
    assert f"#3000={NOT_CONVERTED_ALARM} (NOT CONVERTED: axis XV)" in proc.text.splitlines()
    assert not [x for x in proc.text.splitlines() if x.startswith("G1") and "V" in x]


def test_licence_check_on_a_machine_serial_number_is_refused_whole_at_its_if():
    src = ('PROC P(REAL DIST)\nG1 X=DIST F100\nIF $MN_HW_SERIAL_NUMBER <> "SN-1"\nMSG("no licence")\n'
           'G4 F99999\nRET\nENDIF\nG1 X0\nRET\n')
    conv = api.transpile(src, read="sinumerik", write="iso-m")
    assert conv.ok
    lines = conv.text.splitlines()
    at = lines.index(f"#3000={NOT_CONVERTED_ALARM} (NOT CONVERTED: $MN_HW_SERIAL_NUMBER)")
    assert lines[at - 1] == "G1 F100. X#1" and lines[at + 1] == "G1 X0."
    assert not [x for x in lines if "G4" in x or "MSG" in x]
    assert [d.line for d in conv.diagnostics if d.rule == "NC412"] == [3]
    back = get("iso-m").parse(conv.text, "p.nc")
    assert not [d for d in back.diagnostics if d.severity == "error"]
