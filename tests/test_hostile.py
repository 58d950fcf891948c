"""Hostile input: each case runs the real CLI in a child process held to 700 MiB of address space
and 60 s of CPU (resource limits, not timing assertions). It must end with a located diagnostic
or a clean result: never an internal error, a traceback, a crash or a silently wrong output.

Families (issue 15): unbounded strings, diagnostic floods, devices and FIFOs, stacked signs, deep
nesting, infinity and out-of-range numbers, long straight programs, corrupt caches.
"""
from __future__ import annotations

import os
import re
import resource
import subprocess
import sys
from pathlib import Path

import pytest

MEMORY_LIMIT = 700 * 1024 * 1024
CPU_SECONDS = 60
NCTRANS = [sys.executable, "-m", "nctrans"]


def _limits() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    resource.setrlimit(resource.RLIMIT_CPU, (CPU_SECONDS, CPU_SECONDS))


def run(*args, cwd=None, stdin=None, env=None) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of one nctrans run under the limits."""
    p = subprocess.run([*NCTRANS, *map(str, args)], cwd=cwd, input=stdin, capture_output=True,
                       preexec_fn=_limits, env={**os.environ, "NCTRANS_DEBUG": "0", **(env or {})},
                       timeout=CPU_SECONDS * 3)
    out, err = p.stdout.decode("utf-8", "replace"), p.stderr.decode("utf-8", "replace")
    assert p.returncode >= 0, f"killed by signal {-p.returncode}: {err[-2000:]}"
    assert "internal error" not in err and "Traceback" not in err, err[-2000:]
    return p.returncode, out, err


def located(text: str, rule: str, file: str, line: int, column: int | None = None) -> bool:
    """Whether `text` holds a gcc-style diagnostic of `rule` at file:line(:column)."""
    col = r"\d+" if column is None else str(column)
    return re.search(rf"^{re.escape(file)}:{line}:{col}: (error|warning|info)\[{rule}\]", text,
                     re.M) is not None


def write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


# --------------------------------------------------------------------------- strings (item 1)

@pytest.mark.parametrize("program, line", [
    # doubling a declared STRING forty times: ~1 TB of text without a cap
    ("DEF STRING[200] TXT\nDEF INT I\nTXT=\"AB\"\nFOR I=1 TO 40\nTXT=TXT<<TXT\nENDFOR\nG0 X1\nM30\n", 5),
    # an undeclared growth: concatenation into an R parameter-free string expression in a loop
    ("DEF STRING[10] TXT\nDEF INT I\nFOR I=1 TO 10000\nTXT=TXT<<\"ABCDEFGHIJ\"\nENDFOR\nM30\n", 4),
])
def test_string_growth_is_capped_with_nc109(tmp_path, program, line):
    f = write(tmp_path, "s.mpf", program)
    rc, out, _ = run("lint", f.name, cwd=tmp_path)
    assert rc == 1 and located(out, "NC109", "s.mpf", line)


def test_a_literal_too_long_is_said_once(tmp_path):
    """A literal too long for its STRING[5]: NC110 at its line, and not also the run's NC109 for
    the same assignment (it was both)."""
    f = write(tmp_path, "s.mpf", "DEF STRING[5] TXT\nTXT=\"ABCDEFGH\"\nM30\n")
    rc, out, _ = run("lint", f.name, cwd=tmp_path)
    assert rc == 1 and located(out, "NC110", "s.mpf", 2)
    assert "NC109" not in out and out.count("s.mpf:2:") == 1 and "cut to 5 characters" in out


def test_declared_length_cuts_the_string(tmp_path):
    """STRING[5] holds five characters: what the program reads back is cut, not the whole."""
    from nctrans import pipeline
    f = write(tmp_path, "s.mpf", 'DEF STRING[5] TXT\nTXT="ABCDEFGH"\nIF TXT=="ABCDE"\nG0 X1\nENDIF\nM30\n')
    ld = pipeline.load(str(f))
    recs = list(pipeline.toolpath_of(ld))
    assert [r.kind for r in recs] == ["rapid", "stop"]
    assert [d.rule for d in ld.diagnostics] == ["NC109"]


def test_huge_array_declaration_is_refused(tmp_path):
    f = write(tmp_path, "a.mpf", "DEF REAL ARR[100000,100000]\nARR[0,0]=REP(1)\nM30\n")
    rc, out, _ = run("lint", f.name, cwd=tmp_path)
    assert rc == 1 and located(out, "NC109", "a.mpf", 1)


# --------------------------------------------------------------------------- stacked signs (5)

@pytest.mark.parametrize("block, column", [
    ("G0 X1--+5", 6), ("G0 X1+-+5", 6), ("#1=1--+5", 5), ("G0 X[1--+5]", 7), ("G0 X1--5", 6),
    ("G0 X--5", 5), ("G1 X1 Y2 F++100", 11),
])
def test_stacked_signs_are_located_syntax_errors(tmp_path, block, column):
    f = write(tmp_path, "s.nc", f"{block}\nM30\n")
    rc, out, _ = run("lint", f.name, "--from", "iso-m", cwd=tmp_path)
    assert rc == 1 and located(out, "NC002", "s.nc", 1, column), out
    rc, _, err = run("convert", f.name, "--from", "iso-m", "--to", "sinumerik", cwd=tmp_path)
    assert rc == 1 and "not converted" in err


def test_one_sign_and_bracketed_negation_stay_valid(tmp_path):
    f = write(tmp_path, "ok.nc", "#1=1-[-5]\nG0 X-5 Y+2\nG0 X#1\nM30\n")
    rc, out, _ = run("toolpath", f.name, "--from", "iso-m", cwd=tmp_path)
    assert rc == 0 and '"X":-5.0' in out and '"X":6.0' in out


# --------------------------------------------------------------------------- nesting (6)

def test_five_hundred_nested_sinumerik_parentheses(tmp_path):
    f = write(tmp_path, "p.mpf", "R1=" + "(" * 500 + "1" + ")" * 500 + "\nG0 X=R1\nM30\n")
    rc, out, _ = run("lint", f.name, cwd=tmp_path)
    assert rc == 1 and located(out, "NC008", "p.mpf", 1)


def test_long_operator_chain(tmp_path):
    f = write(tmp_path, "c.nc", "#1=" + "+".join(["1"] * 5000) + "\nG0 X#1\nM30\n")
    rc, out, _ = run("lint", f.name, "--from", "iso-m", cwd=tmp_path)
    assert rc == 1 and located(out, "NC008", "c.nc", 1)


@pytest.mark.parametrize("opener, closer", [("IF R1==0", "ENDIF"), ("WHILE R1>1", "ENDWHILE"),
                                            ("REPEAT", "UNTIL R1==0"), ("FOR R2=1 TO 1", "ENDFOR")])
def test_ten_thousand_nested_sinumerik_structures(tmp_path, opener, closer):
    text = "\n".join([opener] * 10000) + "\nG0 X1\n" + "\n".join([closer] * 10000) + "\nM30\n"
    f = write(tmp_path, "n.mpf", text)
    rc, out, _ = run("lint", f.name, cwd=tmp_path)
    assert rc == 1 and located(out, "NC008", "n.mpf", 17)     # the 17th level
    assert "NC205" not in out


def test_ten_thousand_nested_iso_loops(tmp_path):
    """Fanuc allows three nested DO levels: the fourth is the error, at its own line."""
    n = 10000
    text = ("\n".join(f"WHILE [#1 GT 1] DO{1 + i % 3}" for i in range(n)) + "\nG0 X1\n"
            + "\n".join(f"END{1 + i % 3}" for i in reversed(range(n))) + "\nM30\n")
    f = write(tmp_path, "n.nc", text)
    rc, out, _ = run("lint", f.name, "--from", "iso-m", cwd=tmp_path)
    assert rc == 1 and located(out, "NC008", "n.nc", 4)


def test_three_nested_iso_loops_are_fine(tmp_path):
    text = ("#1=0\nWHILE [#1 LT 2] DO1\n#2=0\nWHILE [#2 LT 2] DO2\n#3=0\nWHILE [#3 LT 2] DO3\n"
            "G91 G0 X1\n#3=#3+1\nEND3\n#2=#2+1\nEND2\n#1=#1+1\nEND1\nM30\n")
    f = write(tmp_path, "ok.nc", text)
    rc, out, err = run("toolpath", f.name, "--from", "iso-m", cwd=tmp_path)
    assert rc == 0 and out.count('"rapid"') == 8, err


@pytest.mark.parametrize("code, column", [
    ("P1=" + "[" * 2000 + "1" + "]" * 2000, 2003),          # where the 2000th level opens
    ("P1=" + "+".join(["1"] * 5000), 403),                  # the 201st operator
    ("P1=" + "-" * 3000 + "1", 203),                        # stacked unary signs
    ("P1=" + "SIN[" * 500 + "1" + "]" * 500, 2003),
])
def test_fagor_brackets_and_operator_chains_have_a_depth_limit(tmp_path, code, column):
    """Were RecursionErrors (internal error) or read silently at any depth: now NC008, as in the
    ISO and Sinumerik front ends; text in quotes is not counted."""
    f = write(tmp_path, "d.nc", f"{code}\nG00 XP1\nM30\n")
    rc, out, _ = run("lint", f.name, "--from", "fagor", cwd=tmp_path)
    assert rc == 1 and located(out, "NC008", "d.nc", 1, column), out
    f = write(tmp_path, "m.nc", '#MSG ["' + "-" * 300 + '"]\nG00 X1\nM30\n')
    rc, out, _ = run("lint", f.name, "--from", "fagor", cwd=tmp_path)
    assert rc == 0 and "NC008" not in out, out


def test_fagor_block_repetition_is_bounded(tmp_path):
    """#RPT copies its range into the program: a hundred million copies were a hang. Beyond the
    blocks nctrans expands it is NC205 at the #RPT line; the corpus's #RPT of 2 still runs."""
    f = write(tmp_path, "r.nc", "%RP\nN10: G91 G01 X1 F100\nN20: Y1\n#RPT [N10, N20, 100000000]\nM30\n")
    rc, out, _ = run("lint", f.name, "--from", "fagor", cwd=tmp_path)
    assert rc == 1 and located(out, "NC205", "r.nc", 4, 1), out
    f = write(tmp_path, "r2.nc", "%RP\nN10: G91 G01 X1 F100\nN20: Y1\n#RPT [N10, N20, 2]\nM30\n")
    rc, out, err = run("toolpath", f.name, "--from", "fagor", cwd=tmp_path)
    assert rc == 0 and out.count('"linear"') == 6, err


def test_sinumerik_define_macros_expand_within_the_block_limit(tmp_path):
    """A 51 KB DEFINE used 15,000 times in one line expanded to 765 MB (a hang): the expansion is
    a block, NC010 past 64 KiB at the line that uses it; a short macro still reads."""
    f = write(tmp_path, "m.mpf", "DEFINE BIG AS " + "G1 X1 Y2 Z3 F100 " * 3000 + "\n" + "BIG " * 15000
              + "\nM30\n")
    rc, out, _ = run("lint", f.name, cwd=tmp_path)
    assert rc == 1 and located(out, "NC010", "m.mpf", 2, 1), out
    f = write(tmp_path, "ok.mpf", "DEFINE SHORT AS G1 X1 F100\nSHORT\nM30\n")
    rc, out, err = run("toolpath", f.name, cwd=tmp_path)
    assert rc == 0 and '"X":1.0' in out, err


def test_fagor_macros_that_expand_exponentially_stop_at_the_block_limit(tmp_path):
    """Eleven #DEF macros, each naming the next ten times: 10^10 characters (a hang, then memory
    exhaustion). The expansion is a block: beyond 64 KiB it is NC010 at the line that uses it."""
    names = "ABCDEFGHIJKL"
    lines = [f'#DEF "{a}"="' + f'\\"{b}\\" ' * 10 + '"' for a, b in zip(names, names[1:])]
    lines += ['#DEF "L"="G01 X1 F100"', '"A"', "M30"]
    f = write(tmp_path, "mac.nc", "\n".join(lines) + "\n")
    rc, out, _ = run("lint", f.name, "--from", "fagor", cwd=tmp_path)
    assert rc == 1 and located(out, "NC010", "mac.nc", 13, 1), out


# --------------------------------------------------------------------------- infinity (7)

@pytest.mark.parametrize("name, text, rule, line", [
    ("big.nc", "G0 X1" + "0" * 400 + "\nM30\n", "NC108", 1),
    ("big2.nc", "G1 X1 F1" + "0" * 400 + "\nM30\n", "NC108", 1),
    ("over.nc", "#1=9" + "9" * 300 + "\n#2=#1*#1\nG0 X#2\nM30\n", "NC108", 3),
    ("nan.nc", "#1=9" + "9" * 300 + "\n#2=#1*#1-#1*#1\nG0 Y#2\nM30\n", "NC108", 3),
    # the first move, to 1e308 (finite), is already beyond limits.MAX_COORDINATE (1e12)
    ("inc.nc", "#1=9" + "9" * 307 + "\nG91 G0 X#1\nG0 X#1\nG0 X#1\nM30\n", "NC108", 2),
    ("ex.mpf", "G0 X1EX400\nM30\n", "NC108", 1),
    ("ex2.mpf", "R1=1EX400\nG0 X=R1\nM30\n", "NC108", 1),
    ("e.mpf", "G0 Y=1E400\nM30\n", "NC002", 1),
    ("big.mpf", "G0 X1" + "0" * 400 + "\nM30\n", "NC108", 1),
    ("mul.mpf", "R1=1EX300\nR2=R1*R1\nG0 X=R2\nM30\n", "NC108", 3),
])
def test_non_finite_values_are_errors_and_never_reach_a_record(tmp_path, name, text, rule, line):
    f = write(tmp_path, name, text)
    dialect = "sinumerik" if name.endswith(".mpf") else "iso-m"
    rc, out, err = run("toolpath", f.name, "--from", dialect, cwd=tmp_path)
    assert rc == 1 and located(err, rule, name, line), err
    assert not re.search(r"null|Infinity|NaN|:-?inf", out), out
    rc, out, err = run("convert", f.name, "--from", dialect, "--to",
                       "iso-m" if dialect == "sinumerik" else "sinumerik", "--flatten", cwd=tmp_path)
    assert rc == 1 and out == ""


def test_sinumerik_exponent_still_reads(tmp_path):
    f = write(tmp_path, "ok.mpf", "R1=1.5EX2\nG0 X=R1\nM30\n")
    rc, out, _ = run("toolpath", f.name, cwd=tmp_path)
    assert rc == 0 and '"X":150.0' in out


# --------------------------------------------------------------------------- floods (2)

def test_one_huge_line_is_one_located_error(tmp_path):
    """A 5 MB line of repeated X1 words: one NC010, not 1.75 M warnings; SARIF stays small."""
    f = tmp_path / "flood.nc"
    f.write_text("G1 F100 " + "X1" * (5 * 1024 * 1024 // 2) + "\nM30\n")
    rc, out, _ = run("lint", f.name, "--from", "iso-m", cwd=tmp_path)
    assert rc == 1 and out.count("\n") == 1 and located(out, "NC010", "flood.nc", 1, 1)
    rc, out, _ = run("lint", f.name, "--from", "iso-m", "--format", "sarif", cwd=tmp_path)
    assert rc == 1 and len(out) < 200_000 and out.count('"ruleId"') == 1


def test_repeats_in_a_block_are_one_diagnostic_with_a_count_at_the_repeat(tmp_path):
    f = write(tmp_path, "d.nc", "G1 F100 X1 X2 X3 X4\nM30\n")
    rc, out, _ = run("lint", f.name, "--from", "iso-m", cwd=tmp_path)
    assert out.count("NC201") == 1 and located(out, "NC201", "d.nc", 1, 12) and "+2 more" in out


def test_diagnostics_per_file_are_capped_with_a_closing_note(tmp_path):
    f = tmp_path / "many.nc"
    f.write_text("G1 F100\n" + "G1 X1 X2\n" * 3000 + "M30\n")
    rc, out, _ = run("lint", f.name, "--from", "iso-m", cwd=tmp_path)
    assert out.count("[NC201]") == 1000 and "[NC009] 2000 more diagnostics" in out


# --------------------------------------------------------------------------- reads (3)

def test_devices_and_fifos_by_name_are_refused(tmp_path):
    for args in (["lint", "/dev/zero"], ["detect", "/dev/urandom"], ["toolpath", "/dev/zero"],
                 ["convert", "/dev/zero", "--to", "sinumerik"]):
        rc, _, err = run(*args, cwd=tmp_path)
        assert rc == 2 and "not a regular file" in err
    os.mkfifo(tmp_path / "pipe.nc")
    rc, _, err = run("lint", "pipe.nc", cwd=tmp_path)
    assert rc == 2 and "FIFO" in err


def test_directory_walks_take_regular_files_only(tmp_path):
    (tmp_path / "shop").mkdir()
    os.mkfifo(tmp_path / "shop" / "a-pipe.nc")
    (tmp_path / "shop" / "part.nc").write_text("G0 X1\nM30\n")
    rc, out, err = run("lint", "shop", "--from", "iso-m", "--format", "json", cwd=tmp_path)
    assert rc == 0 and '"files": 1' in out, err


def test_input_size_limit(tmp_path):
    f = write(tmp_path, "p.nc", "G0 X1\n" * 100)
    rc, _, err = run("lint", f.name, cwd=tmp_path, env={"NCTRANS_MAX_INPUT_BYTES": "100"})
    assert rc == 2 and "NCTRANS_MAX_INPUT_BYTES" in err
    rc, _, err = run("lint", "-", "--from", "iso-m", cwd=tmp_path, stdin=b"G0 X1\n" * 100,
                     env={"NCTRANS_MAX_INPUT_BYTES": "100"})
    assert rc == 2 and "more than the" in err


def test_detect_reads_only_the_head(tmp_path):
    f = tmp_path / "big.nc"
    with f.open("w") as fh:
        fh.write("%\nO1000\nG21 G90\n")
        fh.write("G1 X1.5 Y2.5 F100\n" * 300_000)
    rc, out, _ = run("detect", f.name, cwd=tmp_path, env={"NCTRANS_MAX_INPUT_BYTES": "100000"})
    assert rc == 0 and "iso-m" in out        # the 5 MB file is over the limit: only the head is read


# --------------------------------------------------------------------------- writes (4)

def test_convert_writes_through_a_device_and_never_replaces_it(tmp_path):
    f = write(tmp_path, "p.nc", "G0 X1\nM30\n")
    before = os.stat("/dev/null")
    rc, _, err = run("convert", f.name, "--to", "sinumerik", "-o", "/dev/null", cwd=tmp_path)
    after = os.stat("/dev/null")
    assert rc == 0, err
    assert (before.st_ino, before.st_rdev) == (after.st_ino, after.st_rdev)
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_convert_through_a_symlink_writes_its_target(tmp_path):
    f = write(tmp_path, "p.nc", "G0 X1\nM30\n")
    (tmp_path / "real.mpf").write_text("old\n")
    os.symlink("real.mpf", tmp_path / "link.mpf")
    rc, _, err = run("convert", f.name, "--to", "sinumerik", "-o", "link.mpf", cwd=tmp_path)
    assert rc == 0, err
    assert (tmp_path / "link.mpf").is_symlink() and "X1" in (tmp_path / "real.mpf").read_text()


def test_out_dir_never_replaces_a_file_that_is_not_an_output(tmp_path):
    f = write(tmp_path, "p.nc", "G0 X1\nM30\n")
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "p.mpf").write_text("hand-edited\n")
    rc, _, err = run("convert", f.name, "--to", "sinumerik", "--out-dir", "out", cwd=tmp_path)
    assert rc == 2 and "--overwrite" in err and (tmp_path / "out" / "p.mpf").read_text() == "hand-edited\n"
    rc, _, err = run("convert", f.name, "--to", "sinumerik", "--out-dir", "out", "--overwrite", cwd=tmp_path)
    assert rc == 0 and "X1" in (tmp_path / "out" / "p.mpf").read_text()


def test_sigterm_leaves_no_temporary_file(tmp_path):
    """A long conversion killed with SIGTERM: exit 143, no output, no temporary file."""
    import signal
    import time
    f = tmp_path / "long.nc"
    f.write_text("G1 F100\n" + "".join(f"G1 X{i % 97}.5 Y{i % 89}.25\n" for i in range(1_000_000)) + "M30\n")
    p = subprocess.Popen([*NCTRANS, "convert", f.name, "--to", "sinumerik", "-o", "out.mpf"],
                         cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=_limits)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not any(x.name.endswith(".tmp") for x in tmp_path.iterdir()):
        time.sleep(0.05)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 143, (p.returncode, err.decode()[-2000:])
    assert not (tmp_path / "out.mpf").exists()
    assert not [x for x in tmp_path.iterdir() if x.name.endswith(".tmp")]


# --------------------------------------------------------------------------- scale (8)

ENDLESS_AROUND_A_CYCLE = ("%\nO1\nG90 G54 G17\nT1 M6\nG43 H1 Z50.\nWHILE[1LT2]DO1\n"
                          "G99 {cycle} X1. Y1. Z-5. R1. Q0.5 K2\nG80\nEND1\nM30\n%\n")


@pytest.mark.parametrize("cycle, target", [("G73", "sinumerik"), ("G83", "fagor"), ("G83", "iso-m")])
def test_endless_loop_around_a_lowered_cycle_is_refused_at_the_held_limit(tmp_path, cycle, target):
    """An endless WHILE around a cycle the target lacks: lowering that loop alone to plain motion
    would hold every record until the step budget (19 GB seen). It stops at the documented limit
    of blocks held in memory, with NC402 at the cycle's line, default limits, and writes nothing."""
    f = write(tmp_path, "e.nc", ENDLESS_AROUND_A_CYCLE.format(cycle=cycle))
    rc, out, err = run("convert", f.name, "--from", "iso-m", "--to", target, "-o", "e.out", cwd=tmp_path)
    if target == "iso-m":                   # the target writes the cycle: nothing to lower
        assert rc == 0 and "WHILE" in (tmp_path / "e.out").read_text(), err
        return
    assert rc == 1 and located(err, "NC402", "e.nc", 7, 1), err
    assert "NCTRANS_MAX_LOWERED_BLOCKS" in err and "--flatten" in err
    assert not (tmp_path / "e.out").exists()


def test_the_whole_program_fallback_of_an_endless_loop_streams_to_the_step_budget(tmp_path):
    """The loop sets #1, which the rest reads, so it cannot be lowered alone; the whole program
    lowered (the last resort) is written as it runs, so memory stays flat until the step budget
    ends it (refused, nothing written). Smaller limits than the defaults: the same stop, sooner
    (2 M steps of this loop take minutes, as `toolpath` of it does); written as it runs, the
    plain motion passes the held limit without it being reported."""
    text = ENDLESS_AROUND_A_CYCLE.format(cycle="G73").replace("G80\n", "G80\n#1=#1+1\n").replace(
        "END1\n", "END1\nG0 X#1\n")
    f = write(tmp_path, "e.nc", text)
    rc, out, err = run("convert", f.name, "--from", "iso-m", "--to", "sinumerik", "-o", "e.out",
                       cwd=tmp_path, env={"NCTRANS_MAX_STEPS": "5000", "NCTRANS_MAX_LOWERED_BLOCKS": "1000"})
    assert rc == 1 and located(err, "NC402", "e.nc", 7, 1), err
    assert "NCTRANS_MAX_LOWERED_BLOCKS" not in err
    assert not (tmp_path / "e.out").exists()


@pytest.mark.parametrize("flatten", [True, False])
def test_lowering_an_endless_loop_stops_at_the_unrolled_budget(tmp_path, flatten):
    """--flatten of an endless loop around a cycle, and the whole-program fallback of one that
    cannot be lowered alone (it sets #1, which the rest reads): each cycle writes ~12 moves per
    step, so the step budget let them write 24 M moves (> 200 s). The budget of moves written by
    repeated execution stops the run at the cycle's line and nothing is written (a tenth of the
    default budget: the same stop, sooner; the default takes ~10 s of CPU)."""
    text = ENDLESS_AROUND_A_CYCLE.format(cycle="G73")
    if not flatten:
        text = text.replace("G80\n", "G80\n#1=#1+1\n").replace("END1\n", "END1\nG0 X#1\n")
    f = write(tmp_path, "e.nc", text)
    rc, out, err = run("convert", f.name, "--from", "iso-m", "--to", "sinumerik", "-o", "e.out",
                       *(["--flatten"] if flatten else []), cwd=tmp_path,
                       env={"NCTRANS_MAX_UNROLLED": "50000"})
    assert rc == 1 and located(err, "NC402", "e.nc", 7, 1), err
    assert "50,000 moves written by repeated execution" in err and "NCTRANS_MAX_UNROLLED" in err
    assert not (tmp_path / "e.out").exists()


def test_the_unrolled_budget_counts_repeated_execution_only(tmp_path):
    """A straight program's cycles and a loop's first pass are free; the loop's later passes count
    every move they write: per pass G0 Z5 and 4 holes of G81 (rapid over the hole, rapid to R,
    feed to Z, rapid back to the initial Z5) = 17 moves, so the two repeated passes write 34; with
    33 the third pass stops at its fourth hole (X4, line 8)."""
    holes = "G0 Z5\nG81 X1 Y1 Z-2 R1 F100\nX2\nX3\nX4\nG80\n"
    straight = write(tmp_path, "s.nc", "G21 G90 G17\n" + holes * 10 + "M30\n")
    rc, _, err = run("convert", straight.name, "--from", "iso-m", "--to", "iso-m", "--flatten", "-o", "s.out",
                     cwd=tmp_path, env={"NCTRANS_MAX_UNROLLED": "20"})
    assert rc == 0 and "NC205" not in err, err
    looped = write(tmp_path, "l.nc", "G21 G90 G17\n#1=0\nWHILE[#1LT3]DO1\n" + holes + "#1=#1+1\nEND1\nM30\n")
    for budget, ok in (("34", True), ("33", False)):
        rc, _, err = run("convert", looped.name, "--from", "iso-m", "--to", "iso-m", "--flatten", "-o", "l.out",
                         cwd=tmp_path, env={"NCTRANS_MAX_UNROLLED": budget})
        assert (rc == 0) == ok, err
        if not ok:
            assert located(err, "NC205", "l.nc", 8) and located(err, "NC402", "l.nc", 8), err


def test_long_straight_program_gives_all_its_moves_and_converts_streamed(tmp_path):
    """3 M straight blocks: every move comes out (the step budget counts repetition only), and the
    streamed conversion gives the text the whole-program conversion gives."""
    n = 3_000_000
    f = tmp_path / "long.nc"
    with f.open("w") as fh:
        fh.write("G21 G90 G1 F500\n")
        for i in range(0, n, 10_000):
            fh.write("".join(f"X{j % 1000}.5 Y{j % 7}\n" for j in range(i, i + 10_000)))
        fh.write("M30\n")
    p = subprocess.Popen([*NCTRANS, "toolpath", f.name, "--from", "iso-m"], cwd=tmp_path,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=_limits)
    lines = sum(1 for _ in p.stdout)
    err = p.stderr.read().decode()
    assert p.wait() == 0 and "NC205" not in err, err
    assert lines == n + 1                     # every move, and the stop


@pytest.mark.parametrize("target", ["sinumerik", "iso-m", "fagor"])
def test_streamed_conversion_equals_the_whole_one(tmp_path, target):
    from nctrans import api
    text = "%\nO1\nG21 G90 G17\nT1 M6\nS8000 M3\nG0 X0 Y0 Z5.\nG1 Z-1. F500.\n" + "".join(
        f"G1 X{i % 97}.5 Y{i % 89}.25\n" + (f"G2 X{i % 97}.5 Y{i % 89}.25 I1. J0\n" if i % 50 == 0 else "")
        for i in range(9000)) + "M30\n%\n"
    whole = api.transpile(text, "iso-m", target)

    class Sink:
        def __init__(self):
            self.parts = []

        def write(self, s):
            self.parts.append(s)

        def reset(self):
            self.parts = []
    sink = Sink()
    streamed = api.transpile(text, "iso-m", target, out=sink)
    assert streamed.text == "" and len(sink.parts) > 2          # written in several pieces
    assert "".join(sink.parts) == whole.text
    assert [d.format_text() for d in streamed.diagnostics] == [d.format_text() for d in whole.diagnostics]


def test_backplot_of_an_endless_loop_draws_a_bounded_number_of_moves(tmp_path):
    """A scene holds each move it draws: 24 M moves of an endless loop needed gigabytes. Past
    250,000 moves (the default) the plot shows the first ones and says so (NC011 at the first move
    left out, and a note in the plot); the run still ends at the step budget (600,000 steps here:
    360,000 moves)."""
    f = write(tmp_path, "loop.nc", "G90 G1 F1000\nWHILE [1 EQ 1] DO1\nX1 Y1\nX0 Y0\nX1 Y0\nEND1\nM30\n")
    rc, out, err = run("backplot", f.name, "--from", "iso-m", "-o", "loop.svg", cwd=tmp_path,
                       env={"NCTRANS_MAX_STEPS": "600000"})
    assert rc == 1 and located(err, "NC205", "loop.nc", 5) and located(err, "NC011", "loop.nc", 4, 1), err
    assert "250000 moves" in out and "first 250,000 moves of 360,002" in (tmp_path / "loop.svg").read_text()


# --------------------------------------------------------------------------- wrong dialect (11)

@pytest.mark.parametrize("text, column, marked", [
    ("G0 X=5\nM30\n", 4, "X=5"),                          # a Sinumerik axis assignment
    ("G0 X10\nG1 Y=R1+2 F100\nM30\n", 4, "Y=R1"),
])
def test_syntax_error_on_another_dialects_line_is_a_located_nc005(tmp_path, text, column, marked):
    f = write(tmp_path, "w.nc", text)
    line = text[:text.index(marked)].count("\n") + 1
    rc, out, _ = run("lint", f.name, "--from", "iso-m", cwd=tmp_path)
    assert rc == 1 and located(out, "NC005", "w.nc", line, column), out
    assert "use --from sinumerik" in out and located(out, "NC002", "w.nc", line)
    rc, _, err = run("convert", f.name, "--from", "iso-m", "--to", "sinumerik", "-o", "out.mpf", cwd=tmp_path)
    assert rc == 1 and located(err, "NC005", "w.nc", line, column) and not (tmp_path / "out.mpf").exists()


def test_an_iso_syntax_error_is_not_blamed_on_the_dialect(tmp_path):
    f = write(tmp_path, "s.nc", "G0 X1--5\nM30\n")
    rc, out, _ = run("lint", f.name, "--from", "iso-m", cwd=tmp_path)
    assert rc == 1 and "NC002" in out and "NC005" not in out


def test_plain_mpf_calling_a_subprogram_by_name_is_sinumerik(tmp_path):
    """`RECSUB` alone on a line calls a subprogram by name: with the .mpf ending that settles it."""
    write(tmp_path, "RECSUB.spf", "PROC RECSUB\nG1 X5 F100\nRET\n")
    f = write(tmp_path, "main.mpf", "G0 X10\nRECSUB\nM30\n")
    rc, out, err = run("detect", f.name, cwd=tmp_path)
    assert rc == 0 and "sinumerik" in out and "ambiguous" not in out + err
    rc, out, _ = run("toolpath", f.name, cwd=tmp_path)
    assert rc == 0 and '"X":5.0' in out


def _structured_program(path: Path, cam_lines: int) -> None:
    """An ISO macro program: `cam_lines` CAM moves (lines 4..) around a subprogram called twice,
    a G28 and a WHILE loop of peck drilling (G73), the subprogram after M30."""
    half = cam_lines // 2
    with path.open("w") as fh:
        fh.write("%\nO1000\nG21 G90 G17 G40 G49 G80 G1 F500\n")
        for lo, hi in ((0, half), (half, cam_lines)):
            for i in range(lo, hi, 10_000):
                fh.write("".join(f"G1 X{j % 997}.125 Y{j % 389}.25 Z-{j % 7}.5\n" for j in range(i, min(i + 10_000, hi))))
            if lo == 0:
                fh.write("M98 P2000 L2\nG28 G91 Z0\nG90\n#1=0\nWHILE[#1LT3]DO1\nG0 X[#1*10] Y0 Z5.\n"
                         "G99 G73 X1. Y1. Z-5. R1. Q0.5 F100.\nG80\n#1=#1+1\nEND1\nG1 F500\n")
        fh.write("M30\nO2000\nG91 G1 X1. F100.\nY1.\nG90\nM99\n%\n")


def test_thirty_megabyte_macro_program_runs_in_bounded_memory(tmp_path):
    """30 MB of ISO macro program (1.2 M CAM moves around calls and a loop) is parsed whole, its
    plain stretches held as spans of the text (Dialect.parse_compact): the whole IR took ~1.2 KiB
    per block (1.4 GiB here). Every CAM line gives its one move, and the run reaches M30."""
    n = 1_200_000
    f = tmp_path / "macro.nc"
    _structured_program(f, n)
    assert f.stat().st_size > 30_000_000
    end_line = n + 15                                   # 3 header lines, 11 of structure, then M30
    p = subprocess.Popen([*NCTRANS, "toolpath", f.name, "--from", "iso-m"], cwd=tmp_path,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=_limits)
    cam = 0
    last = b""
    for rec in p.stdout:
        m = re.search(rb'"line":(\d+)', rec)
        line = int(m.group(1))
        if 4 <= line < 4 + n // 2 or 4 + n // 2 + 11 <= line < end_line:
            cam += 1
        last = rec
    err = p.stderr.read().decode()
    assert p.wait() == 0 and "NC205" not in err, err
    assert cam == n and b'"kind":"stop"' in last and f'"line":{end_line},'.encode() in last


@pytest.mark.parametrize("command", ["convert-flatten", "equiv"])
def test_structured_program_flattens_and_compares_in_bounded_memory(tmp_path, command):
    """A 6 MB macro program converted with --flatten (to Fagor, which lacks G73) and compared
    with itself: run compact, not held whole (~300 MiB held whole at this size)."""
    f = tmp_path / "macro.nc"
    _structured_program(f, 240_000)
    if command == "equiv":
        rc, out, err = run("equiv", f.name, f.name, "--from-a", "iso-m", "--from-b", "iso-m", cwd=tmp_path)
        assert rc == 0 and "equivalent" in out, err
        return
    rc, _, err = run("convert", f.name, "--from", "iso-m", "--to", "fagor", "--flatten", "-o", "m.out", cwd=tmp_path)
    text = (tmp_path / "m.out").read_text()
    assert rc == 0 and "G73" not in text and text.count("\n") > 240_000, err
