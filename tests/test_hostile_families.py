"""Hostile input, family by family, for every dialect and every command.

Each (dialect, family) case runs in one child process held to 700 MiB of address space and 60 s of
CPU (resource limits, not timing assertions). The child runs the CLI in-process once per command
(lint, toolpath, convert, equiv, check, backplot, detect) and reports each one's exit code and
output; a run must end cleanly (exit 0) or with a located diagnostic (file:line:col), or refuse
with a usage error naming the input (exit 2): never an internal error or a traceback, never an
output file from a refused conversion. Families: deep nesting, huge numbers, NUL and control bytes,
CP1252 text, CRLF line ends, endless loops, self-recursive calls, inputs over the size limit,
symlinked and read-only outputs.
"""
from __future__ import annotations

import json
import os
import re
import resource
import subprocess
import sys
from pathlib import Path

import pytest

MEMORY_LIMIT = 700 * 1024 * 1024
CPU_SECONDS = 60
COMMANDS = ("lint", "toolpath", "convert", "equiv", "check", "backplot", "detect")
DIALECTS = ("iso-m", "iso-t", "sinumerik", "fagor")
EXT = {"iso-m": ".nc", "iso-t": ".nc", "sinumerik": ".mpf", "fagor": ".nc"}
TARGET = {"iso-m": "sinumerik", "iso-t": "sinumerik", "sinumerik": "iso-m", "fagor": "iso-m"}

# Runs the CLI in-process for each command (start-up once per case, not per command).
_DRIVER = r"""
import contextlib, io, json, resource, sys
from nctrans import cli
out = []
for argv in json.loads(sys.argv[1]):
    used = resource.getrusage(resource.RUSAGE_SELF)
    soft = int(used.ru_utime + used.ru_stime) + CPU_SECONDS       # 60 s of CPU for this command
    resource.setrlimit(resource.RLIMIT_CPU, (soft, resource.getrlimit(resource.RLIMIT_CPU)[1]))
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        try:
            rc = cli.main(argv)
        except SystemExit as x:
            rc = x.code if isinstance(x.code, int) else 2
    out.append([argv, rc, o.getvalue()[-4000:], e.getvalue()[-4000:]])
print(json.dumps(out))
""".replace("CPU_SECONDS", str(CPU_SECONDS))


def _limits() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    hard = CPU_SECONDS * (len(COMMANDS) + 1)        # the driver lowers the soft limit per command
    resource.setrlimit(resource.RLIMIT_CPU, (hard, hard))


def run_all(runs: list[list[str]], cwd: Path, env: dict | None = None) -> list:
    """[argv, exit code, stdout, stderr] of each CLI run, in one limited child process (700 MiB
    for the process, 60 s of CPU for each run)."""
    p = subprocess.run([sys.executable, "-c", _DRIVER, json.dumps(runs)], cwd=cwd, capture_output=True,
                       preexec_fn=_limits, env={**os.environ, "NCTRANS_DEBUG": "0", **(env or {})},
                       timeout=CPU_SECONDS * (len(runs) + 1) * 3)
    err = p.stderr.decode("utf-8", "replace")
    assert p.returncode == 0, f"child ended with {p.returncode}: {err[-2000:]}"
    return json.loads(p.stdout)


def commands(name: str, dialect: str) -> list[list[str]]:
    stem = Path(name).stem
    return [
        ["lint", name, "--from", dialect],
        ["toolpath", name, "--from", dialect],
        ["convert", name, "--from", dialect, "--to", TARGET[dialect], "-o", f"{stem}.out"],
        ["equiv", name, name, "--from-a", dialect, "--from-b", dialect],
        ["check", name, "--from", dialect],
        ["backplot", name, "--from", dialect, "-o", f"{stem}.svg"],
        ["detect", name],
    ]


_LOCATED = re.compile(r"^(?P<file>[^\s:][^:\n]*):(?P<line>\d+):(?P<col>\d+): (error|warning|info)\[NC\d{3}\]", re.M)


def assert_sound(results: list, cwd: Path, name: str) -> None:
    """Every run: no internal error; exit 0, or a located diagnostic in this file (exit 1), or a
    usage error naming the file (exit 2); a refused conversion leaves no output."""
    for argv, rc, out, err in results:
        text = out + "\n" + err
        what = f"{argv}: exit {rc}\n{text[-1500:]}"
        assert "internal error" not in text and "Traceback" not in text, what
        assert rc in (0, 1, 2), what
        if rc == 1 and argv[0] == "backplot" and "no moves" in err:
            assert name in err, what                # a program with nothing to draw says so
        elif rc == 1 and argv[0] != "equiv":
            here = {p.name for p in cwd.iterdir()}          # this program or a file it called
            assert any(Path(m.group("file")).name in here for m in _LOCATED.finditer(text)), what
        if rc == 2:
            assert name in text and (err.startswith("nctrans:") or argv[0] == "detect") or _LOCATED.search(text), what
        if argv[0] == "convert" and rc != 0:
            assert not (cwd / argv[-1]).exists(), what


def case(tmp_path: Path, dialect: str, text: str | bytes, env: dict | None = None) -> list:
    name = "p" + EXT[dialect]
    data = text.encode("utf-8") if isinstance(text, str) else text
    (tmp_path / name).write_bytes(data)
    results = run_all(commands(name, dialect), tmp_path, env)
    assert_sound(results, tmp_path, name)
    return results


def by_command(results: list) -> dict:
    return {argv[0]: (rc, out + "\n" + err) for argv, rc, out, err in results}


# --------------------------------------------------------------------------- programs per dialect

def nested_structures(dialect: str, depth: int = 300) -> str:
    if dialect in ("iso-m", "iso-t"):
        return ("#1=0\n" + "\n".join(f"WHILE [#1 GT 1] DO{1 + i % 3}" for i in range(depth)) + "\nG0 X1\n"
                + "\n".join(f"END{1 + i % 3}" for i in reversed(range(depth))) + "\nM30\n")
    if dialect == "sinumerik":
        return "R1=0\n" + "IF R1==0\n" * depth + "G0 X1\n" + "ENDIF\n" * depth + "M30\n"
    return "P1=0\n" + "$IF P1==0\n" * depth + "G00 X1\n" + "$ENDIF\n" * depth + "M30\n"


def nested_expression(dialect: str, depth: int = 300) -> str:
    if dialect in ("iso-m", "iso-t"):
        return "#1=" + "[" * depth + "1" + "]" * depth + "\nG0 X#1\nM30\n"
    if dialect == "sinumerik":
        return "R1=" + "(" * depth + "1" + ")" * depth + "\nG0 X=R1\nM30\n"
    return "P1=" + "[" * depth + "1" + "]" * depth + "\nG00 XP1\nM30\n"


def huge_number(dialect: str) -> str:
    big = "9" * 400
    if dialect == "sinumerik":
        return f"G0 X1\nR1={big}\nG0 X=R1*R1\nG1 Y{big}.5 F100\nM30\n"
    if dialect == "fagor":
        return f"G00 X1\nP1={big}\nG00 X[P1*P1]\nG01 Y{big}.5 F100\nM30\n"
    return f"G0 X1\n#1={big}\nG0 X[#1*#1]\nG1 Y{big}.5 F100\nM30\n"


def plain(dialect: str) -> str:
    g0, g1 = ("G00", "G01") if dialect == "fagor" else ("G0", "G1")
    return f"{g0} X0 Y0 Z5\n{g1} Z-1 F100\n{g1} X10 Y5\n{g1} X20\nM30\n"


def endless(dialect: str) -> str:
    if dialect in ("iso-m", "iso-t"):
        return "G91\nWHILE [1 EQ 1] DO1\nG1 X1 F100\nEND1\nM30\n"
    if dialect == "sinumerik":
        return "G91\nLOOP\nG1 X1 F100\nENDLOOP\nM30\n"
    return "G91\n$WHILE 1 == 1\nG01 X1 F100\n$ENDWHILE\nM30\n"


def self_recursive(dialect: str) -> str:
    if dialect in ("iso-m", "iso-t"):
        return "O1\nM98 P100\nM30\nO100\nG91 G1 X1 F100\nM98 P100\nM99\n"
    if dialect == "sinumerik":
        return "PROC SELF\nG91 G1 X1 F100\nSELF\nRET\n"     # the file calls itself by its name
    return "%L SELF\nG91 G01 X1 F100\n#CALL SELF\n#RET\n%MAIN\n#CALL SELF\nM30\n"


# --------------------------------------------------------------------------- the cases

@pytest.mark.parametrize("dialect", DIALECTS)
def test_deep_structure_nesting(tmp_path, dialect):
    results = case(tmp_path, dialect, nested_structures(dialect))
    rc, text = by_command(results)["lint"]
    assert rc == 1 and "NC008" in text


@pytest.mark.parametrize("dialect", DIALECTS)
def test_deep_expression_nesting(tmp_path, dialect):
    """NC008 in every dialect (Fagor's `[ ]` included: 32 levels, as the others)."""
    results = case(tmp_path, dialect, nested_expression(dialect))
    rc, text = by_command(results)["lint"]
    assert rc == 1 and "NC008" in text, text


@pytest.mark.parametrize("dialect", DIALECTS)
def test_huge_numbers(tmp_path, dialect):
    results = case(tmp_path, dialect, huge_number(dialect))
    rc, text = by_command(results)["toolpath"]
    assert rc == 1 and "null" not in text and re.search(r"NC108|NC107|NC002", text), text


@pytest.mark.parametrize("dialect", DIALECTS)
def test_nul_and_control_bytes(tmp_path, dialect):
    data = plain(dialect).replace("Z5\n", "Z5 \x00\x01\x1b[2J\x7f\n", 1).encode("utf-8")
    results = case(tmp_path, dialect, data)
    rc, text = by_command(results)["lint"]
    assert rc == 1 and ":1:" in text


@pytest.mark.parametrize("dialect", DIALECTS)
def test_cp1252_comments_and_crlf_line_ends(tmp_path, dialect):
    """Windows CAM output: CP1252 comments and CRLF line ends read cleanly; the moves are the same
    as the plain UTF-8 program's."""
    comment = "; Fr\xe4se \xb0 \xb1 \u20ac\r\n" if dialect in ("sinumerik", "fagor") else "(Fr\xe4se \xb0 \xb1 \u20ac)\r\n"
    data = (comment + plain(dialect).replace("\n", "\r\n")).encode("cp1252")
    results = case(tmp_path, dialect, data)
    (tmp_path / ("q" + EXT[dialect])).write_text(plain(dialect))
    ref = by_command(run_all([["toolpath", "q" + EXT[dialect], "--from", dialect]], tmp_path))["toolpath"]
    rc, text = by_command(results)["toolpath"]
    assert rc == 0 and ref[0] == 0
    moves = lambda t: re.findall(r'"end":\{[^}]*\}', t)     # noqa: E731
    assert moves(text) == moves(ref[1]) and len(moves(text)) == 4
    assert by_command(results)["convert"][0] == 0


@pytest.mark.parametrize("dialect", DIALECTS)
def test_endless_loop_stops_at_the_step_budget(tmp_path, dialect):
    """(A smaller budget than the default 2 M steps: the same stop, sooner.)"""
    results = case(tmp_path, dialect, endless(dialect), env={"NCTRANS_MAX_STEPS": "20000"})
    rc, text = by_command(results)["lint"]
    assert rc == 1 and "NC205" in text


@pytest.mark.parametrize("dialect", DIALECTS)
def test_self_recursive_call(tmp_path, dialect):
    if dialect == "sinumerik":              # SELF.spf calls itself; the main program calls it
        (tmp_path / "SELF.spf").write_text("PROC SELF\nG91 G1 X1 F100\nSELF\nRET\n")
        results = case(tmp_path, dialect, "G0 X0\nSELF\nM30\n")
    else:
        results = case(tmp_path, dialect, self_recursive(dialect))
    rc, text = by_command(results)["lint"]
    assert rc == 1 and _LOCATED.search(text), text


@pytest.mark.parametrize("dialect", DIALECTS)
def test_input_over_the_size_limit_is_refused_by_every_command(tmp_path, dialect):
    results = case(tmp_path, dialect, plain(dialect) * 40, env={"NCTRANS_MAX_INPUT_BYTES": "1000"})
    for argv, rc, out, err in results:
        if argv[0] == "detect":                     # reads only the head it needs
            continue
        assert rc == 2 and "p" + EXT[dialect] in err, (argv, rc, err)


@pytest.mark.parametrize("dialect", DIALECTS)
def test_symlinked_and_read_only_outputs(tmp_path, dialect):
    name = "p" + EXT[dialect]
    (tmp_path / name).write_text(plain(dialect))
    (tmp_path / "real.out").write_text("old\n")
    (tmp_path / "link.out").symlink_to("real.out")
    (tmp_path / "ro.out").write_text("keep\n")
    (tmp_path / "ro.out").chmod(0o444)
    (tmp_path / "rodir").mkdir()
    (tmp_path / "rodir").chmod(0o555)
    to = ["--from", dialect, "--to", TARGET[dialect]]
    results = run_all([["convert", name, *to, "-o", "link.out"],
                       ["convert", name, *to, "-o", "rodir/x.out"],
                       ["convert", name, *to, "--out-dir", "rodir"],
                       ["backplot", name, "--from", dialect, "-o", "rodir/x.svg"]], tmp_path)
    try:
        for argv, rc, out, err in results:
            assert "internal error" not in out + err and "Traceback" not in out + err, (argv, err)
        link = results[0]
        assert link[1] == 0 and (tmp_path / "link.out").is_symlink()
        assert (tmp_path / "real.out").read_text() != "old\n"          # written through the link
        for argv, rc, out, err in results[1:]:
            if os.geteuid() != 0:                                       # root writes anyway
                assert rc == 2 and err.startswith("nctrans:"), (argv, rc, err)
        if os.geteuid() != 0:
            rc = run_all([["convert", name, *to, "-o", "ro.out"]], tmp_path)[0]
            assert rc[1] == 2 and (tmp_path / "ro.out").read_text() == "keep\n", rc
    finally:
        (tmp_path / "rodir").chmod(0o755)
