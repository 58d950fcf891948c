"""Constructs that real Sinumerik and ISO programs from outside the corpus showed wrong or silent
(issue 8, wave 12), each reproduced by a hand-written minimal program with hand-computed values:

- a Sinumerik main program starts in G1: `G54 Z10 F600` with no motion code is a feed move, so
  its ISO and Fagor conversions (which start in G0) must say G1/G01 at that first move; a
  subprogram file's first move runs in its caller's mode and is left as written;
- `equiv` of a subprogram file and its conversion runs each once (the converted M99 is the
  return the file's M17 was), where a main program's M99 loops;
- NC240: a construct nctrans does not model, in a block the analysis never ran (a PROC file or
  macro file linted on its own, a branch not taken), is said at its line.
"""
from __future__ import annotations

import nctrans


def _lines(conv) -> list[str]:
    assert conv.text is not None, [d.message for d in conv.diagnostics if d.severity == "error"]
    return [x for x in conv.text.splitlines()
            if x and x != "%" and not x.startswith(("(converted", "%PROGRAM"))]


def _kinds(text: str, dialect: str) -> list[str]:
    return [r.kind for r in nctrans.toolpath(text, dialect)]


def _codes(diags, code: str) -> list[int]:
    return [d.line for d in diags if d.rule == code]


# ------------------------------------------------------------- power-on motion mode (G1 vs G0)

MAIN = "G54 Z10 F600\nZ5 F1\nM30\n"


def test_sinumerik_main_program_first_move_is_a_feed_move():
    # Sinumerik powers on in G1 (rules/sinumerik.toml: G1 default): Z0 -> Z10 at 600 mm/min,
    # then Z10 -> Z5 at 1 mm/min; nothing rapid
    assert _kinds(MAIN, "sinumerik") == ["linear", "linear", "stop"]


def test_iso_conversion_writes_g1_at_the_first_move():
    conv = nctrans.transpile(MAIN, read="sinumerik", write="iso-m")
    assert _lines(conv) == ["G54 F600. G1 Z10.", "F1. Z5.", "M30"]
    assert _kinds(conv.text, "iso-m") == ["linear", "linear", "stop"]     # was rapid, rapid
    assert nctrans.equiv(MAIN, conv.text, read_a="sinumerik", read_b="iso-m")


def test_fagor_conversion_writes_g01_at_the_first_move():
    conv = nctrans.transpile(MAIN, read="sinumerik", write="fagor")
    assert _lines(conv)[0] == "G54 G01 Z10 F600"                           # was G00
    assert nctrans.equiv(MAIN, conv.text, read_a="sinumerik", read_b="fagor")


def test_an_explicit_motion_code_is_not_doubled():
    src = "G0 X5\nX10 F100\nM30\n"              # both moves rapid: G0 is modal
    conv = nctrans.transpile(src, read="sinumerik", write="iso-m")
    assert _lines(conv) == ["G0 X5.", "F100. X10.", "M30"]
    assert _kinds(conv.text, "iso-m") == ["rapid", "rapid", "stop"]


def test_a_subprogram_file_keeps_its_callers_motion_mode():
    # an .SPF runs from its caller's modes: no motion code is invented at its first move
    spf = "%_N_LIFT_SPF\nZ10 F600\nM17\n"
    conv = nctrans.transpile(spf, read="sinumerik", write="iso-m")
    assert not any(" G1 " in f" {x} " for x in _lines(conv)), _lines(conv)


# ------------------------------------------------------------- equiv of a subprogram file

def test_equiv_runs_a_subprogram_file_and_its_conversion_once():
    spf = "%_N_LIFT_SPF\nG1 Z10 F600\nG4 F4\nM17\n"
    conv = nctrans.transpile(spf, read="sinumerik", write="iso-m")
    assert _lines(conv)[-1] == "M99"             # the return, as an ISO subprogram ends
    # A: Z0 -> Z10 at 600, dwell 4 s, end; B the same once (a main program's M99 would loop
    # until the step budget and B would never end where A does)
    result = nctrans.equiv(spf, conv.text, read_a="sinumerik", read_b="iso-m")
    assert result, result.difference
    assert result.records == (3, 3)


def test_equiv_starts_the_conversion_of_a_subprogram_file_in_the_same_callers_modes():
    # `Z10 F600` with no motion code: from a caller in G1 both run Z0 -> Z10 at 600 mm/min; the ISO
    # side alone would start in its power-on G0 (a rapid) and differ for no reason of its own
    spf = "%_N_LIFT_SPF\nZ10 F600\nM17\n"
    conv = nctrans.transpile(spf, read="sinumerik", write="iso-m")
    assert _lines(conv) == ["F600. Z10.", "M99"]          # no G1 invented: the caller's mode
    result = nctrans.equiv(spf, conv.text, read_a="sinumerik", read_b="iso-m")
    assert result, result.difference
    assert result.records == (2, 2)


# ------------------------------------------------------------- NC240: not modelled, not run

PROC_FILE = "PROC OSC_ON\nOSP1[Z]=10 OSP2[Z]=50\nOS[Z]=1\nG1 Z5 F100\nM17\n"


def test_proc_file_linted_alone_says_what_is_not_modelled():
    diags = nctrans.lint(PROC_FILE, "sinumerik")
    assert _codes(diags, "NC240") == [2, 3]     # oscillation points, oscillation on
    assert _codes(diags, "NC220") == []         # the body does not run on its own
    assert all(d.severity == "warning" for d in diags if d.rule == "NC240")


def test_a_block_that_runs_is_nc220_not_nc240():
    diags = nctrans.lint("G1 X10 F100\nOS[Z]=1\nM30\n", "sinumerik")
    assert _codes(diags, "NC220") == [2]
    assert _codes(diags, "NC240") == []


def test_a_branch_not_taken_is_nc240():
    # R1 = 0: the IF body never runs, its fixed-stop word is said at line 3
    src = "R1=0\nIF R1==1\nFXS[Z]=1 FXST[Z]=20 Z-5\nENDIF\nG1 X10 F100\nM30\n"
    diags = nctrans.lint(src, "sinumerik")
    assert _codes(diags, "NC240") == [3]
    assert _codes(diags, "NC220") == []


def test_iso_subprogram_nothing_calls_is_said():
    # a probing macro stored after an empty O-number (as Renishaw's listings are): O9100 runs only
    # when called, and its G31 (skip move) at line 4 is not modelled
    src = "%\nO0002()\nO9100 (PROBE)\nG31 X10. F100.\nM99\n%\n"
    diags = nctrans.lint(src, "iso-m")
    assert _codes(diags, "NC240") == [4]


# ------------------------------------------------------------- NC241: G04 P with a point

def _dwells(text: str) -> list[float]:
    return [r.dwell_s for r in nctrans.toolpath(text, "iso-m") if r.kind == "dwell"]


def test_dwell_p_with_a_point_is_said_and_read_as_milliseconds():
    # seed Table 3-8: P counts 0.001 s; P200. read so is 200 * 0.001 = 0.2 s, said at line 2
    src = "G0 X0\nG04 P200.\nG04 P500\nM30\n"
    assert _dwells(src) == [0.2, 0.5]
    assert _codes(nctrans.lint(src, "iso-m"), "NC241") == [2]


def test_haas_program_reads_dwell_p_with_a_point_as_seconds():
    # header names HAAS: P200. is 200 s, P500 (no point) still 500 ms = 0.5 s; nothing to say
    src = "%\nO9220 (HAAS WARM-UP)\nG04 P200.\nG04 P500\nM30\n%\n"
    assert _dwells(src) == [200.0, 0.5]
    assert _codes(nctrans.lint(src, "iso-m"), "NC241") == []
    conv = nctrans.transpile(src, read="iso-m", write="sinumerik")
    assert "G4 F200" in conv.text and "G4 F0.5" in conv.text, conv.text


# ------------------------------------------------------------- Fagor: a machine's own M function

def test_fagor_keeps_a_machine_m_function_as_written():
    # M27 (a clamp, a PLC output) is the machine builder's number on either control: kept as the
    # ISO and Sinumerik emitters keep it (NC403), where it refused the whole conversion
    src = "G1 X10 F100\nM27\nm12\nX20\nM30\n"
    conv = nctrans.transpile(src, read="sinumerik", write="fagor")
    assert _lines(conv) == ["G01 X10 F100", "M27", "M12", "X20", "M30"]
    assert _codes(conv.diagnostics, "NC403") == [2, 3]
    assert not [d for d in conv.diagnostics if d.severity == "error"]
    assert nctrans.equiv(src, conv.text, read_a="sinumerik", read_b="fagor")


# ------------------------------------------------------------- NC202 in a subprogram file

def test_feed_move_without_f_in_a_subprogram_file_is_the_callers_feed():
    # an .SPF moves at the F its caller set: alone, the feed is unknown, not an error of the file
    spf = "%_N_CONTOUR_SPF\nG2 X80 Y0 CR=80\nRET\n"
    diags = [d for d in nctrans.lint(spf, "sinumerik") if d.rule == "NC202"]
    assert [(d.line, d.severity) for d in diags] == [(2, "warning")]
    # the same move in a main program is the program's own error
    main = [d for d in nctrans.lint("G2 X80 Y0 CR=80\nM30\n", "sinumerik") if d.rule == "NC202"]
    assert [(d.line, d.severity) for d in main] == [(1, "error")]


# ------------------------------------------------------------- NC237: an ISO system number write

def test_write_to_an_unmodelled_iso_system_number_is_said():
    # #12029: a Haas NGC output (Renishaw's air blast), a Fanuc's tool memory: nothing models it;
    # the two writes at lines 2 and 3 were silent, the program linted clean
    src = "G0 X0\n#12029=1\n#12029=0\nM30\n"
    diags = nctrans.lint(src, "iso-m")
    assert _codes(diags, "NC237") == [2, 3]
    assert all(d.severity == "warning" for d in diags if d.rule == "NC237")


def test_common_variables_and_haas_macro_variables_are_not_system_writes():
    # #100/#500 are common variables; under a HAAS header #10110 is one too (profile haas)
    assert _codes(nctrans.lint("#100=1\n#500=2\nG0 X#100\nM30\n", "iso-m"), "NC237") == []
    haas = "%\nO1 (HAAS VF2)\n#10110=-.125\nG1 Z#10110 F10.\nM30\n%\n"
    assert _codes(nctrans.lint(haas, "iso-m"), "NC237") == []
    assert [r.end["Z"] for r in nctrans.toolpath(haas, "iso-m") if r.kind == "linear"] == [-0.125]


def test_fagor_conversion_of_a_subprogram_file_keeps_its_callers_motion_mode():
    # the .SPF's first move runs in its caller's mode: no G00 invented (it made `Z10 F600` a rapid)
    spf = "%_N_LIFT_SPF\nZ10 F600\nM17\n"
    conv = nctrans.transpile(spf, read="sinumerik", write="fagor")
    assert _lines(conv) == ["%LIFT", "Z10 F600", "M30"]          # was `G00 Z10 F600`
    result = nctrans.equiv(spf, conv.text, read_a="sinumerik", read_b="fagor")
    assert result, result.difference
