"""Fanuc/Haas macro B system variables end to end (issue 8): writes the control refuses (NC228),
timers that run on after a write, counters a program sets, the extended work offset number #4130,
and the external output words (POPEN/DPRNT/BPRNT/PCLOS, G103) through lint, toolpath and check.
Expected positions are computed by hand in the comments."""
from __future__ import annotations

import subprocess
import sys

import pytest

from nctrans import pipeline
from nctrans.source import from_text


def run(text: str):
    ld = pipeline.load_source(from_text(text, "t.nc"), "t.nc", "iso-m")
    recs = list(pipeline.toolpath_of(ld))
    return [r for r in recs if r.kind in ("rapid", "linear")], ld.diagnostics


def x_ends(moves):
    return [round(r.end["X"], 6) for r in moves]


@pytest.mark.parametrize("number", [5001, 5021, 5041, 5063, 4001, 4014, 4120, 3011])
def test_a_write_to_a_read_only_number_is_refused_at_its_line(number):
    # the write is refused: the read after it is the machine's value, not 123
    text = f"G0 X4 Y0 Z0\n#{number}=123\n#100=#{number}\nM30\n"
    _, diags = run(text)
    (d,) = [d for d in diags if d.rule == "NC228"]
    assert (d.line, d.severity) == (2, "error") and f"#{number}" in d.message


def test_position_read_after_a_refused_write_is_the_position():
    # X is at 4 when #5001=3 is refused; G1 X[#5001 + 1] goes to 4 + 1 = 5 (not 3 + 1 = 4)
    moves, diags = run("G0 X4 Y0 Z0\n#5001=3\nG1 X[#5001+1] F100\nM30\n")
    assert x_ends(moves) == [4.0, 5.0]
    assert [(d.rule, d.line) for d in diags if d.severity != "info"] == [("NC228", 2)]


def test_timer_write_leaves_it_unknown_and_counters_keep_what_is_written():
    # #3001=0 resets the millisecond timer, which runs on: the read is unknown (NC107, X ignored);
    # #3901 (parts machined) is set by the program: X#3901 after #3901=5 goes to 5
    moves, diags = run("G0 X1\n#3001=0\nG0 X#3001\n#3901=5\nG0 X#3901\nM30\n")
    assert x_ends(moves) == [1.0, 5.0]          # line 3 moves nothing
    assert [(d.rule, d.line) for d in diags] == [("NC107", 3)]


def test_4130_is_the_extended_work_offset_number():
    # G54.1 P7 -> #4130 = 7; G55 -> 0; #4014 reads 54.1 then 55
    moves, diags = run("G0 X0\nG54.1 P7\nG1 X#4130 Y#4014 F100\nG55\nG1 X#4130 Y#4014\nM30\n")
    assert [(round(r.end["X"], 6), round(r.end["Y"], 6)) for r in moves[1:]] == [(7.0, 54.1),
                                                                                  (0.0, 55.0)]
    assert [d for d in diags if d.severity != "info"] == []


@pytest.mark.parametrize("command", ["lint", "toolpath", "check"])
def test_external_output_runs_clean_and_alarm_stops_in_every_command(tmp_path, command):
    src = tmp_path / "probe.nc"
    src.write_text("G0 X1\nPOPEN\nDPRNT[X#5041[44]*Y#5042[44]]\nBPRNT[A#1[3]]\nPCLOS\n"
                   "G103 P1\nG0 X2\nM30\n")
    argv = [sys.executable, "-m", "nctrans", command, str(src), "--from", "iso-m",
            "--fail-on", "warning"]
    out = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    src.write_text("G0 X1\n#3000=12 (TOOL BROKEN)\nG0 X2\nM30\n")
    out = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    said = out.stdout + out.stderr
    assert out.returncode == 1 and ":2:1: error[NC221]" in said and "TOOL BROKEN" in said
