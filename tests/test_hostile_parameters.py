"""Hostile parameters of the newer features (issue 15): CYCLE95, CYCLE72 and CYCLE97 with huge,
zero, negative and not-a-number parameters (step counts towards 10^9), MCALL with thousands of
positions, G63 with S0, huge finite coordinates, and NCTRANS_* limits set to 0, negative numbers
or text. Every command runs in a child process held to 700 MiB and 60 s of CPU each
(test_hostile_families.run_all) and must end with a located diagnostic or a clean result."""
from __future__ import annotations

import re

import pytest

from test_hostile_families import run_all

LATHE = "G18 G90 DIAMON T1 D1\nS1000 M3 G95 F0.3\nG0 X60 Z10\n{call}\nG0 X100\nM30\n" \
        "ANF: G1 X20 Z0\nZ-10\nX30 Z-15\nENDE: X40\n"
MILL = "G17 G90 G54 T1 D1 M6\nS2000 M3 F500\nG0 X0 Y0 Z20\n{call}\nG0 Z50\nM30\n" \
       "ANF: G1 X10 Y10\nX50\nY30\nENDE: X10\n"
MACHINE = 'name = "t"\n[[tools]]\nnumber = 1\nradius = 3.0\nlength = 50.0\n'
C95 = 'CYCLE95("ANF:ENDE", {mid}, 0.25, {falx}, 0, 0.3, 0.1, 0.1, {vari}, , , 1)'
C72 = 'CYCLE72("ANF:ENDE", 10, 0, 2, {dp}, {mid}, 0, 0, 300, 100, 111, 41, 2, {lp1}, 400, 2, 5)'
C97 = "CYCLE97({pit}, , 0, -20, 20, 20, 4, 2, {tdep}, 0.2, 0, 0, {nrc}, 1, 1, 1)"


def located(text: str, rule: str, file: str, line: int, severity: str = "error") -> bool:
    return re.search(rf"^{re.escape(file)}:{line}:\d+: {severity}\[{rule}\]", text, re.M) is not None


CYCLES = [
    # name, program, rule at line 4, whether --machine (the tool radius CYCLE72 needs)
    ("c95-mid-tiny", LATHE.format(call=C95.format(mid="1EX-9", falx=0.5, vari=1)), "NC114", False),  # 10^10 cuts
    ("c95-mid-zero", LATHE.format(call=C95.format(mid=0, falx=0.5, vari=1)), "NC114", False),
    ("c95-mid-negative", LATHE.format(call=C95.format(mid=-2, falx=0.5, vari=1)), "NC114", False),
    ("c95-mid-nan", LATHE.format(call=C95.format(mid="SQRT(-1)", falx=0.5, vari=1)), "NC106", False),
    ("c95-vari-huge", LATHE.format(call=C95.format(mid=2, falx=0.5, vari="1EX20")), "NC114", False),
    ("c95-allowance-huge", LATHE.format(call=C95.format(mid=2, falx="1EX300", vari=9)), "NC108", False),
    ("c72-mid-tiny", MILL.format(call=C72.format(dp=-6, mid="1EX-9", lp1=5)), "NC225", True),
    ("c72-depth-huge", MILL.format(call=C72.format(dp="-1EX12", mid=3, lp1=5)), "NC225", True),
    ("c72-mid-nan", MILL.format(call=C72.format(dp=-6, mid="SQRT(-1)", lp1=5)), "NC106", True),
    ("c72-approach-huge", MILL.format(call=C72.format(dp=-6, mid=3, lp1="1EX300")), "NC108", True),
    ("c97-cuts-huge", LATHE.format(call=C97.format(pit=2, tdep=1.2, nrc=1000000000)), "NC225", False),
    ("c97-pitch-zero", LATHE.format(call=C97.format(pit=0, tdep=1.2, nrc=2)), "NC225", False),
    ("c97-depth-nan", LATHE.format(call=C97.format(pit=2, tdep="SQRT(-1)", nrc=2)), "NC106", False),
]


@pytest.mark.parametrize("name, program, rule, machine", CYCLES, ids=[c[0] for c in CYCLES])
def test_hostile_cycle_parameters_end_in_a_located_error(tmp_path, name, program, rule, machine):
    """Each command stops at the cycle's line with the rule that names the parameter's problem;
    a parameter that cannot be evaluated (SQRT(-1)) was an internal error, a 1EX300 lift-off a
    record at 1e300 that overflowed the cycle time (internal error with --machine)."""
    f = tmp_path / "c.mpf"
    f.write_text(program)
    extra = []
    if machine:
        (tmp_path / "m.toml").write_text(MACHINE)
        extra = ["--machine", "m.toml"]
    target = "iso-m" if program.startswith("G17") else "iso-t"
    runs = [["lint", "c.mpf", *extra], ["toolpath", "c.mpf", "--summary", *extra],
            ["convert", "c.mpf", "--to", target, "--flatten", "-o", "c.out", *extra],
            ["check", "c.mpf", *(extra or ["--machine", "m.toml"])]]
    if not machine:
        (tmp_path / "m.toml").write_text(MACHINE)
    for argv, rc, out, err in run_all(runs, tmp_path):
        assert rc == 1 and located(out + err, rule, "c.mpf", 4), (argv, out, err)
    assert not (tmp_path / "c.out").exists()


def test_mcall_with_thousands_of_positions(tmp_path):
    """MCALL CYCLE81 at 5,000 positions: one feed to depth per position (5,000 linear records),
    and conversions with and without --flatten end cleanly; 20,000 positions from a loop too."""
    start = "G17 G90 G54 T1 D1 M6\nS2000 M3 F500\nG0 X0 Y0 Z20\nMCALL CYCLE81(10, 0, 2, -5)\n"
    (tmp_path / "m.mpf").write_text(start + "".join(f"X{i % 100} Y{i // 100}\n" for i in range(5000))
                                    + "MCALL\nM30\n")
    (tmp_path / "l.mpf").write_text(start + "R1=0\nWHILE R1<20000\nX=R1 Y1\nR1=R1+1\nENDWHILE\nMCALL\nM30\n")
    runs = [["toolpath", "m.mpf"], ["convert", "m.mpf", "--to", "iso-m", "-o", "m.nc"],
            ["convert", "m.mpf", "--to", "fagor", "--flatten", "-o", "m.fnc"],
            ["toolpath", "l.mpf"], ["convert", "l.mpf", "--to", "iso-m", "-o", "l.nc"]]
    results = run_all(runs, tmp_path)
    for argv, rc, out, err in results:
        assert rc == 0, (argv, err)
    # (the child keeps the last 4,000 characters of each output: count from the file instead)
    assert (tmp_path / "m.nc").read_text().count("\nX") + (tmp_path / "m.nc").read_text().count("\nY") >= 4999
    assert (tmp_path / "m.fnc").exists() and (tmp_path / "l.nc").exists()


def test_g63_with_no_spindle_speed_is_a_warning_at_each_tap(tmp_path):
    (tmp_path / "t.mpf").write_text("G17 G90 G0 X10 Y20 Z5\nS0 M3 F750\nG63 Z-10 G1\nM4\nG63 Z5\nG0 X30\nM30\n")
    (tmp_path / "ok.mpf").write_text("G17 G90 G0 X10 Y20 Z5\nS500 M3 F750\nG63 Z-10 G1\nM4\nG63 Z5\nG0 X30\nM30\n")
    [(_, rc, out, _), (_, ok_rc, ok_out, _)] = run_all(
        [["lint", "t.mpf", "--from", "sinumerik"], ["lint", "ok.mpf", "--from", "sinumerik"]], tmp_path)
    assert rc == 0 and located(out, "NC209", "t.mpf", 3, "warning") and located(out, "NC209", "t.mpf", 5, "warning")
    assert ok_rc == 0 and "NC209" not in ok_out


def test_huge_finite_coordinates_are_out_of_range(tmp_path):
    """A move to X1EX300 (finite) overflowed the summary's lengths, the machine check and equiv
    (internal errors); it is NC108 at its line, and the native kernel stops at the same line as
    Python (ISO: a 201-digit X in a run of CAM lines)."""
    (tmp_path / "b.mpf").write_text("G0 X10 Y10\nG0 X1EX300 Y-1EX300\nG0 X0\nM30\n")
    cam = ["G1 F100"] + [f"X{i}.5 Y{i % 7}" for i in range(200)] + ["X1" + "0" * 200 + " Y1"] + ["X1 Y1", "M30"]
    (tmp_path / "k.nc").write_text("\n".join(cam) + "\n")
    (tmp_path / "m.toml").write_text(MACHINE)
    runs = [["lint", "b.mpf", "--from", "sinumerik", "--machine", "m.toml"],
            ["toolpath", "b.mpf", "--from", "sinumerik", "--summary"],
            ["equiv", "b.mpf", "b.mpf", "--from-a", "sinumerik", "--from-b", "sinumerik"],
            ["check", "b.mpf", "--from", "sinumerik", "--machine", "m.toml"],
            ["lint", "k.nc", "--from", "iso-m"], ["toolpath", "k.nc", "--from", "iso-m", "--summary"]]
    for argv, rc, out, err in run_all(runs, tmp_path):
        file, line = ("b.mpf", 2) if argv[1] == "b.mpf" else ("k.nc", 202)
        assert rc == 1 and located(out + err, "NC108", file, line), (argv, out, err)


LOOP = "G90 G1 F100\n#1=0\nWHILE[#1LT5]DO1\nG81 X#1 Y1 Z-2 R1\nG80\n#1=#1+1\nEND1\nG0 X1\nM30\n"


@pytest.mark.parametrize("value", ["-1", "abc", "1.5", "1e9", "\u0663"])
def test_a_limit_that_is_not_a_whole_number_is_refused(tmp_path, value):
    """A value the limits cannot read was dropped silently for the default; now every command
    refuses it (exit 2) naming the variable."""
    (tmp_path / "e.nc").write_text(LOOP)
    for name in ("MAX_STEPS", "MAX_INPUT_BYTES"):
        [(_, rc, out, err)] = run_all([["lint", "e.nc", "--from", "iso-m"]], tmp_path,
                                      env={f"NCTRANS_{name}": value})
        assert rc == 2 and f"NCTRANS_{name}=" in err and "not a whole number" in err, err


def test_limits_set_to_zero_end_in_located_diagnostics(tmp_path):
    (tmp_path / "e.nc").write_text(LOOP)
    lint = [["lint", "e.nc", "--from", "iso-m"]]
    [(_, rc, out, _)] = run_all(lint, tmp_path, env={"NCTRANS_MAX_STEPS": "0"})
    assert rc == 1 and located(out, "NC205", "e.nc", 3)          # the loop's first repeated step
    [(_, rc, out, _)] = run_all(lint, tmp_path, env={"NCTRANS_MAX_BLOCK_CHARS": "0"})
    assert rc == 1 and located(out, "NC010", "e.nc", 1)
    [(_, rc, _, err)] = run_all(lint, tmp_path, env={"NCTRANS_MAX_INPUT_BYTES": "0"})
    assert rc == 2 and "more than the 0 bytes" in err               # said the default before
    [(_, rc, _, err)] = run_all([["convert", "e.nc", "--from", "iso-m", "--to", "sinumerik", "--flatten",
                                  "-o", "e.out"]], tmp_path, env={"NCTRANS_MAX_UNROLLED": "0"})
    assert rc == 1 and located(err, "NC205", "e.nc", 4) and not (tmp_path / "e.out").exists()
    [(_, rc, out, err)] = run_all([["backplot", "e.nc", "--from", "iso-m", "-o", "e.svg"]], tmp_path,
                                  env={"NCTRANS_MAX_PLOTTED_MOVES": "0"})
    assert rc == 1 and located(err, "NC011", "e.nc", 4, "warning")
    [(_, rc, _, err)] = run_all([["convert", "e.nc", "--from", "iso-m", "--to", "fagor", "-o", "f.out"]],
                                tmp_path, env={"NCTRANS_MAX_LOWERED_BLOCKS": "0", "NCTRANS_MAX_DIAGNOSTICS": "0"})
    assert rc == 0 and "NC009" in err and (tmp_path / "f.out").exists()
