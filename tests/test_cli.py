"""The command line: wiring, exit codes, output files, formats.

Two kinds of test: in-process ones against a small fake dialect (registered for the test only), so
the CLI's own behaviour is pinned whatever the state of the real front ends; and end-to-end ones
through a subprocess with the real dialects on real corpus programs.
"""
import hashlib
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import nctrans
from nctrans import cli
from nctrans.dialects import base
from nctrans.dialects.base import Dialect, EmitResult, ParseResult
from nctrans.diagnostics import Diagnostic
from nctrans.ir import nodes as n
from conftest import CORPUS

ROOT = Path(__file__).resolve().parents[1]
NCTRANS = [sys.executable, "-m", "nctrans"]
TIMEOUT = 120

TOOLPATH_KEYS = {"seq", "file", "line", "kind", "start", "end", "center", "direction", "plane", "turns",
                 "feed", "feed_mode", "spindle", "tool", "dwell_s", "spindle_dir", "coolant", "stop_kind", "pitch"}
KINDS = {"rapid", "linear", "arc", "dwell", "tool_change", "spindle", "coolant", "stop"}


# --------------------------------------------------------------------------- a fake dialect

_WORD = re.compile(r"([A-Z])\s*([-+]?\d*\.?\d+)")
_MOTION = {0: "rapid", 1: "linear", 2: "arc_cw", 3: "arc_ccw"}


def _fake_parse(text: str, file: str) -> ParseResult:
    """Words G0-G3 X Y Z I J F S T M3 M5 M6 M30; '(' comments; (LOWER)/(REFUSE) steer the emitter."""
    body, diags = [], []
    for ln, raw in enumerate(text.split("\n"), 1):
        line = raw.strip()
        if not line:
            continue
        if line.count("(") != line.count(")"):
            col = raw.index("(") + 1 if "(" in raw else 1
            diags.append(Diagnostic("NC003", "error", "comment not closed", file, ln, col))
            continue
        code = re.sub(r"\([^)]*\)", lambda m: " " * len(m.group(0)), raw)
        stmts, target, center = [], {}, {}
        pos = 0
        for m in _WORD.finditer(code):
            gap = code[pos:m.start()]
            if gap.strip():
                diags.append(Diagnostic("NC002", "error", f"unexpected {gap.strip()!r}", file, ln,
                                        pos + len(gap) - len(gap.lstrip()) + 1))
            pos = m.end()
            letter, value = m.group(1), float(m.group(2))
            if letter == "G":
                stmts.append(n.ModeChange("motion", _MOTION[int(value)], f"G{int(value)}"))
            elif letter in "XYZ":
                target[letter] = n.AxisValue(n.Num(value))
            elif letter in "IJ":
                center["X" if letter == "I" else "Y"] = n.AxisValue(n.Num(value))
            elif letter == "F":
                stmts.append(n.Feed(n.Num(value)))
            elif letter == "S":
                stmts.append(n.SpindleSpeed(n.Num(value)))
            elif letter == "T":
                stmts.append(n.ToolSelect(n.Num(value)))
            elif letter == "M":
                stmts.append({3: n.ModeChange("spindle", "cw"), 5: n.ModeChange("spindle", "off"),
                              6: n.ToolChange(), 30: n.ProgramEnd("end_rewind")}[int(value)])
        rest = code[pos:]
        if rest.strip():
            diags.append(Diagnostic("NC002", "error", f"unexpected {rest.strip()!r}", file, ln,
                                    pos + len(rest) - len(rest.lstrip()) + 1))
        if target:
            stmts.append(n.Motion(target, center or None))
        comment = raw[raw.index("(") + 1:raw.index(")")] if "(" in raw else None
        body.append(n.Block(n.Span(file, ln, 1, ln, len(raw) + 1), stmts, comment=comment))
    if not body:
        diags.append(Diagnostic("NC004", "error", "no blocks", file, 1, 1))
    return ParseResult(n.Program(file, "fake", body), diags)


def _fake_emit(program: n.Program) -> EmitResult:
    lines, diags = [], []
    for b in program.body:
        if b.comment == "LOWER":
            diags.append(Diagnostic("NC401", "info", "lowered", program.file, b.span.line, 1))
        if b.comment == "REFUSE":
            diags.append(Diagnostic("NC402", "error", "cannot express", program.file, b.span.line, 1))
        lines.append(f"N{b.span.line} ; {len(b.body)} statements")
    return EmitResult("\n".join(lines) + "\n", diags)


class Fake(Dialect, register=False):
    name = "fake"
    extensions = (".nc", ".fk")     # convert writes the first

    def parse(self, text, file="<stdin>"):
        return _fake_parse(text, file)

    def emit(self, program):
        return _fake_emit(program)

    def sniff(self, text):
        return 1.0 if text.startswith("G") else 0.0


@pytest.fixture
def fake(monkeypatch, tmp_path):
    """Register the fake dialect (alone, so detection picks it) and work in a temporary directory."""
    monkeypatch.chdir(tmp_path)
    with base.registered_only(Fake()):
        yield tmp_path


def run(capsys, *argv):
    rc = cli.main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err


PART = "T1 M6\nS1000 M3\nG0 X10 Y0\nG1 Z-1 F200\nG2 X20 Y0 I5 J0\nG1 Y10 (cut)\nM30\n"


def sha(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


# --------------------------------------------------------------------------- toolpath

def test_toolpath_jsonl_keys_follow_the_contract(fake, capsys):
    Path("p.fk").write_text(PART)
    rc, out, err = run(capsys, "toolpath", "p.fk", "--from", "fake")
    assert rc == 0, err
    recs = [json.loads(line) for line in out.splitlines()]
    assert [r["seq"] for r in recs] == list(range(1, len(recs) + 1))
    for r in recs:
        assert set(r) <= TOOLPATH_KEYS and {"seq", "file", "line", "kind"} <= set(r)
        assert r["kind"] in KINDS and r["file"] == "p.fk"
        for key in ("start", "end", "center"):
            if key in r:
                assert set(r[key]) >= {"X", "Y", "Z"}
                assert all(isinstance(v, float) and round(v, 6) == v for v in r[key].values())
    arc = next(r for r in recs if r["kind"] == "arc")
    assert arc["direction"] == "cw" and arc["plane"] == "XY" and arc["center"]["X"] == 15.0 and arc["line"] == 5
    lin = next(r for r in recs if r["kind"] == "linear")
    assert lin["feed"] == 200.0 and lin["feed_mode"] == "per_min" and "center" not in lin
    assert [r["kind"] for r in recs][:2] == ["tool_change", "spindle"]


def test_toolpath_csv_and_summary(fake, capsys):
    Path("p.fk").write_text(PART)
    rc, out, _ = run(capsys, "toolpath", "p.fk", "--format", "csv")
    rows = out.splitlines()
    assert rows[0].startswith("seq,file,line,kind,start_X") and len(rows) > 5
    rc, out, _ = run(capsys, "toolpath", "p.fk", "--summary")
    assert rc == 0
    assert "rapid" in out and "bounding box: X 0.000 .. 20.000" in out and "T1" in out
    assert "estimated cycle time" in out and "diagnostics: 0" in out
    # feed length: Z plunge 1 + half circle r5 (pi*5) + 10
    m = re.search(r"feed ([\d.]+) mm", out)
    assert abs(float(m.group(1)) - (1 + 5 * 3.141592653589793 + 10)) < 1e-3


def test_toolpath_of_a_program_with_errors_exits_1(fake, capsys):
    Path("bad.fk").write_text("G0 X1\nG1 X2 (open\n")
    rc, out, err = run(capsys, "toolpath", "bad.fk")
    assert rc == 1 and "bad.fk:2:7: error[NC003]" in err


# --------------------------------------------------------------------------- lint

def test_lint_formats_and_exit_codes(fake, capsys):
    Path("ok.fk").write_text("G0 X1\n")
    Path("bad.fk").write_text("G0 X1 F10\nG1 X2 (open\nG1 X3 Q\n")
    rc, out, _ = run(capsys, "lint", "ok.fk")
    assert (rc, out) == (0, "")
    rc, out, _ = run(capsys, "lint", "ok.fk", "bad.fk")
    assert rc == 1
    assert out.splitlines() == ["bad.fk:2:7: error[NC003] comment not closed",
                                "bad.fk:3:7: error[NC002] unexpected 'Q'"]
    rc, out, _ = run(capsys, "lint", "bad.fk", "--format", "json")
    doc = json.loads(out)
    assert doc["files"] == 1 and doc["summary"]["error"] == 2
    rc, out, _ = run(capsys, "lint", "bad.fk", "--format", "github")
    assert out.startswith("::error file=bad.fk,line=2,col=7,")
    rc, out, _ = run(capsys, "lint", "bad.fk", "--format", "sarif")
    assert json.loads(out)["version"] == "2.1.0"


def test_lint_select_ignore_and_fail_on(fake, capsys):
    Path("bad.fk").write_text("G0 X1 F10\nG1 X2 (open\nG1 X3 Q\n")
    rc, out, _ = run(capsys, "lint", "bad.fk", "--select", "NC00")
    assert rc == 1 and len(out.splitlines()) == 2
    rc, out, _ = run(capsys, "lint", "bad.fk", "--ignore", "NC003,NC002")
    assert (rc, out) == (0, "")
    rc, out, _ = run(capsys, "lint", "bad.fk", "--select", "nc003")
    assert out.count("NC003") == 1 and "NC002" not in out
    # the interpreter's NC202 (feed move without feed) is an error; a warning-only file passes by default
    Path("nofeed.fk").write_text("G1 X10\n")
    rc, out, _ = run(capsys, "lint", "nofeed.fk")
    assert rc == 1 and "NC202" in out
    assert run(capsys, "lint", "nofeed.fk", "--ignore", "NC2")[0] == 0


def test_lint_fail_on_warning_and_info(fake, capsys, monkeypatch):
    Path("w.fk").write_text("G0 X1\n")
    extra = [Diagnostic("NC501", "info", "style", "w.fk", 1, 1)]
    real_lint = cli.pipeline.lint
    monkeypatch.setattr(cli.pipeline, "lint", lambda ld, m=None: real_lint(ld, m) + extra)
    assert run(capsys, "lint", "w.fk")[0] == 0
    assert run(capsys, "lint", "w.fk", "--fail-on", "warning")[0] == 0
    assert run(capsys, "lint", "w.fk", "--fail-on", "info")[0] == 1


def test_lint_recurses_directories_and_reads_stdin(fake, capsys, monkeypatch):
    d = Path("progs")
    (d / "sub").mkdir(parents=True)
    (d / "a.fk").write_text("G0 X1\n")
    (d / "sub" / "b.fk").write_text("G0 X1 (open\n")
    (d / "README.md").write_text("# not a program (\n")
    (d / ".hidden").mkdir()
    (d / ".hidden" / "c.fk").write_text("G0 X1 (open\n")
    rc, out, _ = run(capsys, "lint", "progs", "--format", "json")
    doc = json.loads(out)
    assert rc == 1 and doc["files"] == 2
    assert {x["file"] for x in doc["diagnostics"]} == {os.path.join("progs", "sub", "b.fk")}
    import io
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(b"G0 X1\nG1 (x\n")))
    rc, out, _ = run(capsys, "lint", "-", "--from", "fake")
    assert rc == 1 and out.startswith("<stdin>:2:4: error[NC003]")


def test_lint_unreadable_and_missing_files_exit_2_but_report_the_rest(fake, capsys):
    Path("bad.fk").write_text("G1 (x\n")
    rc, out, err = run(capsys, "lint", "bad.fk", "missing.fk")
    assert rc == 2 and "missing.fk: no such file" in err and "NC003" in out


def test_internal_error_is_a_message_not_a_traceback(fake, capsys, monkeypatch):
    def boom(text, file):
        raise RuntimeError("parser bug")
    monkeypatch.setattr(base.get("fake"), "parse", boom)
    Path("a.fk").write_text("G0 X1\n")
    rc, out, err = run(capsys, "lint", "a.fk")
    assert rc == 2 and "internal error on a.fk: RuntimeError: parser bug" in err
    rc, out, err = run(capsys, "toolpath", "a.fk")
    assert rc == 2 and "internal error: RuntimeError: parser bug" in err
    monkeypatch.setenv("NCTRANS_DEBUG", "1")
    with pytest.raises(RuntimeError):
        cli.main(["toolpath", "a.fk"])


# --------------------------------------------------------------------------- convert

def test_convert_to_stdout_file_and_out_dir(fake, capsys):
    Path("a.fk").write_text("G0 X1\nG1 X2 F100\n")
    Path("b.fk").write_text("G0 X5\n")
    rc, out, _ = run(capsys, "convert", "a.fk", "--to", "fake")
    head = f"; converted by nctrans {nctrans.__version__} from fake to fake: a.fk\n"     # the header comment
    assert rc == 0 and out == head + "N1 ; 2 statements\nN2 ; 3 statements\n"
    rc, out, _ = run(capsys, "convert", "a.fk", "--to", "fake", "-o", "out/x.txt")
    assert rc == 0 and out == "" and Path("out/x.txt").read_text().startswith(head + "N1 ;")
    rc, _, _ = run(capsys, "convert", "a.fk", "b.fk", "--to", "fake", "--out-dir", "conv")
    assert rc == 0 and sorted(p.name for p in Path("conv").iterdir()) == ["a.nc", "b.nc"]
    assert not [p for p in Path("conv").iterdir() if p.name.startswith(".")]   # no temp files left


def test_convert_never_overwrites_an_input(fake, capsys):
    a = Path("a.fk")
    a.write_text("G0 X1\n")
    before = sha(a)
    rc, _, err = run(capsys, "convert", "a.fk", "--to", "fake", "-o", "a.fk")
    assert rc == 2 and "refusing to overwrite" in err
    rc, _, err = run(capsys, "convert", "a.fk", "--to", "fake", "-o", "./sub/../a.fk")
    assert rc == 2
    os.symlink("a.fk", "link.fk")
    rc, _, err = run(capsys, "convert", "a.fk", "--to", "fake", "-o", "link.fk")
    assert rc == 2
    Path("x.nc").write_text("G0 X1\n")
    rc, _, err = run(capsys, "convert", "a.fk", "x.nc", "--to", "fake", "--out-dir", ".")
    assert rc == 2 and "x.nc" in err and Path("x.nc").read_text() == "G0 X1\n"
    assert sha(a) == before


def test_convert_usage_errors(fake, capsys):
    Path("a.fk").write_text("G0 X1\n")
    Path("b.fk").write_text("G0 X1\n")
    assert run(capsys, "convert", "a.fk", "b.fk", "--to", "fake")[0] == 2
    assert run(capsys, "convert", "a.fk", "b.fk", "--to", "fake", "-o", "x")[0] == 2
    rc, _, err = run(capsys, "convert", "a.fk", "--to", "klingon")
    assert rc == 2 and "unknown dialect 'klingon'" in err



def test_convert_flatten(fake, capsys):
    Path("a.fk").write_text("G0 X1\nG1 X2 F100\n")
    rc, out, err = run(capsys, "convert", "a.fk", "--to", "fake", "--flatten")
    assert rc == 0, err
    assert out.strip()


def test_convert_lowering_strict_and_refusal(fake, capsys):
    Path("l.fk").write_text("G0 X1 (LOWER)\n")
    rc, out, err = run(capsys, "convert", "l.fk", "--to", "fake")
    assert rc == 0 and out and "info[NC401]" in err
    rc, out, err = run(capsys, "convert", "l.fk", "--to", "fake", "--strict", "-o", "l.out")
    assert rc == 1 and out == "" and "error[NC401]" in err and not Path("l.out").exists()
    # a construct the target cannot express: the program is lowered to plain motion (NC401 at the
    # construct's line), and --strict refuses instead
    Path("r.fk").write_text("G0 X1 (REFUSE)\n")
    rc, out, err = run(capsys, "convert", "r.fk", "--to", "fake")
    assert rc == 0 and out and "r.fk:1:1: info[NC401]" in err and "lowered to plain motion" in err
    rc, out, err = run(capsys, "convert", "r.fk", "--to", "fake", "--strict")
    assert rc == 1 and out == "" and "NC402" in err and "not converted" in err


def test_convert_keeps_an_old_output_when_the_write_fails(fake, capsys, monkeypatch):
    Path("a.fk").write_text("G0 X1\n")
    Path("o.nc").write_text("old\n")

    def fail(src, dst):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(cli.os, "replace", fail)
    rc, _, err = run(capsys, "convert", "a.fk", "--to", "fake", "-o", "o.nc")
    assert rc == 2 and "cannot write" in err
    assert Path("o.nc").read_text() == "old\n"
    assert sorted(p.name for p in Path(".").iterdir()) == ["a.fk", "o.nc"]


# --------------------------------------------------------------------------- equiv, detect

def test_equiv_same_and_different(fake, capsys):
    Path("a.fk").write_text("G0 X10 Y0\nG1 X20 F100\nG1 Y10\n")
    Path("b.fk").write_text("G0 X10 Y0\nG1 X15 F100\nG1 X20\nG1 Y10\n")
    Path("c.fk").write_text("G0 X10 Y0\nG1 X20 F100\nG1 Y10.5\n")
    rc, out, _ = run(capsys, "equiv", "a.fk", "b.fk")
    assert rc == 0 and out.startswith("equivalent")
    rc, out, _ = run(capsys, "equiv", "a.fk", "c.fk", "--tol", "0.01")
    assert rc == 1 and out.startswith("different: a.fk:3: c.fk:3: ")
    assert run(capsys, "equiv", "a.fk", "c.fk", "--tol", "1")[0] == 0
    assert run(capsys, "equiv", "a.fk", "c.fk", "--tol", "0")[0] == 2


def test_detect_and_ambiguity(fake, capsys, monkeypatch):
    Path("a.fk").write_text("G0 X1\n")
    rc, out, _ = run(capsys, "detect", "a.fk")
    assert rc == 0 and out.startswith("a.fk: fake (confidence 1.00)")
    monkeypatch.setattr(base.get("fake"), "sniff", lambda t: 0.0)
    Path("a.txt").write_text("hello\n")
    rc, out, _ = run(capsys, "detect", "a.txt")
    assert rc == 2 and "ambiguous" in out
    rc, out, err = run(capsys, "lint", "a.txt")
    assert rc == 2 and "use --from" in err


# --------------------------------------------------------------------------- subprocess, no dialect needed

def sh(*argv, cwd=None, stdin=None):
    proc = subprocess.run(NCTRANS + list(argv), cwd=cwd, input=stdin, capture_output=True, timeout=TIMEOUT)
    err = proc.stderr.decode("utf-8", "replace")
    assert "Traceback" not in err, err
    return proc.returncode, proc.stdout.decode("utf-8", "replace"), err


def test_rules_catalogue_and_one_rule():
    rc, out, _ = sh("rules")
    assert rc == 0 and "NC001" in out and "NC501" in out
    rc, out, _ = sh("rules", "NC202")
    assert rc == 0 and "Why:" in out and "Bad:" in out and "Good:" in out
    assert sh("rules", "NC999")[0] == 2


@pytest.mark.parametrize("cmd", cli.NOT_IMPLEMENTED)
def test_pending_commands_say_so(cmd):
    rc, out, err = sh(cmd, "whatever", "--flag")
    assert rc == 2 and "not implemented yet (issue pending)" in err


def test_usage_errors_exit_2():
    assert sh()[0] == 2
    assert sh("frobnicate")[0] == 2
    rc, _, err = sh("lint", "/nonexistent/x.nc")
    assert rc == 2 and "no such file" in err
    rc, _, err = sh("lint", "x.nc", "--from", "klingon")
    assert rc == 2 and "unknown dialect" in err
    rc, out, _ = sh("--version")
    assert rc == 0 and out.startswith("nctrans ")


def test_installed_script_and_module_agree():
    script = Path(sys.executable).with_name("nctrans")
    if not script.exists():
        pytest.skip("console script not installed")
    a = subprocess.run([str(script), "rules"], capture_output=True, timeout=TIMEOUT)
    b = subprocess.run(NCTRANS + ["rules"], capture_output=True, timeout=TIMEOUT)
    assert a.returncode == b.returncode == 0 and a.stdout == b.stdout


def test_detect_on_the_corpus():
    files = sorted(p for p in (CORPUS / "sinumerik").iterdir() if p.suffix.lower() in (".mpf", ".spf"))[:4]
    files += sorted((CORPUS / "iso-mill").glob("*.nc"))[:4]
    rc, out, _ = sh("detect", *map(str, files))
    assert rc == 0
    for f, line in zip(files, out.splitlines()):
        want = "sinumerik" if "sinumerik" in f.parts else "iso-m"
        assert line.startswith(f"{f}: {want} (confidence")


# --------------------------------------------------------------------------- end to end with real dialects



def test_e2e_iso_toolpath_contract_on_the_sample(tmp_path):
    sample = ROOT / "corpus" / "iso-m" / "sample-pocket.nc"
    rc, out, err = sh("toolpath", str(sample), "--from", "iso-m")
    assert rc == 0, err
    recs = [json.loads(line) for line in out.splitlines()]
    assert len(recs) > 20
    for r in recs:
        assert set(r) <= TOOLPATH_KEYS and r["kind"] in KINDS
        if r["kind"] in ("rapid", "linear", "arc"):
            assert "start" in r and "end" in r
        if r["kind"] == "arc":
            assert r["direction"] in ("cw", "ccw") and r["plane"] in ("XY", "ZX", "YZ") and "center" in r
        else:
            assert "center" not in r and "direction" not in r
    assert {r["tool"] for r in recs if r["kind"] == "tool_change"} == {1, 2}
    rc, out, _ = sh("toolpath", str(sample), "--summary")
    assert rc == 0 and "T1 T2" in out


def test_e2e_iso_lint_corpus_file_has_no_syntax_errors():
    f = CORPUS / "iso-mill" / "donpayne-haas-O2001-advanced-arcs.cnc"
    rc, out, err = sh("lint", str(f), "--format", "json", "--select", "NC0")
    doc = json.loads(out)
    assert doc["files"] == 1 and doc["diagnostics"] == [], doc


def test_e2e_equiv_program_with_itself_and_a_changed_copy(tmp_path):
    sample = ROOT / "corpus" / "iso-m" / "sample-pocket.nc"
    rc, out, _ = sh("equiv", str(sample), str(sample))
    assert rc == 0 and out.startswith("equivalent")
    changed = tmp_path / "changed.nc"
    changed.write_text(sample.read_text().replace("N100 G01 Y30.", "N100 G01 Y30.5"))
    rc, out, _ = sh("equiv", str(sample), str(changed))
    assert rc == 1 and f"{sample}:" in out and f"{changed}:" in out


def test_e2e_convert_iso_to_sinumerik_is_equivalent(tmp_path):
    sample = ROOT / "corpus" / "iso-m" / "sample-pocket.nc"
    out = tmp_path / "pocket.mpf"
    rc, _, err = sh("convert", str(sample), "--to", "sinumerik", "-o", str(out))
    assert rc == 0, err
    rc, text, err = sh("equiv", str(sample), str(out), "--from-a", "iso-m", "--from-b", "sinumerik")
    assert rc == 0 and text.startswith("equivalent"), text + err


# --------------------------------------------------------------------------- detection (in process)

def test_detect_every_corpus_program_with_and_without_its_name():
    from nctrans.detection import detect
    from nctrans.source import read_source
    files = [p for p in CORPUS.rglob("*") if p.is_file() and p.suffix != ".tsv"]
    assert len(files) > 50
    for p in files:
        want = "sinumerik" if "sinumerik" in p.parts else "iso-t" if "iso-turn" in p.parts else "iso-m"
        text = read_source(p).text
        assert detect(text, p.name).dialect == want, p
        assert detect(text, None).dialect == want, p


def test_detect_ignores_words_inside_iso_comments(monkeypatch):
    from nctrans import detection as det
    monkeypatch.setattr(det, "_sniff", lambda dialect, text: 0.0)     # the marker table alone
    detect = det.detect
    iso = "%\nO1000\n(T1 D=0.5 CR=0. - ZMIN=0. - MIRROR ENDIF)\n(X=10 R1=5 GOTOF)\nG0 X0 Y0\nM30\n%\n"
    g = detect(iso, None)
    assert g.dialect == "iso-m" and g.content.get("sinumerik", 0.0) <= 1.0
    sin = "DEF REAL LEN\nR1=(R2+3)*2\nIF (R1>2) GOTOF END\nCYCLE81(10, 0, 2, -5)\nEND:\nM30\n"
    g = detect(sin, None)
    assert g.dialect == "sinumerik" and g.first_marker["sinumerik"][0] == 1


def test_detect_says_ambiguous_without_evidence():
    from nctrans.detection import detect
    for text in ("", "hello\n", "  \n"):
        g = detect(text, None)
        assert g.ambiguous and g.dialect is None
    assert detect("G0 X1\n", "part.mpf").dialect == "sinumerik"
    assert detect("G0 X1\n", "part.nc").dialect == "iso-m"


def test_machine_file_is_used_and_a_broken_one_exits_2(fake, capsys):
    Path("p.fk").write_text("G0 X10 Y0 Z5\n")
    Path("m.toml").write_text('name = "vmc"\nkind = "mill"\n[offsets.G54]\nX = 100.0\nY = -50.0\nZ = 0.0\n'
                              '[axes.X]\nmin = -300.0\nmax = 300.0\nrapid = 20000.0\n')
    rc, out, _ = run(capsys, "toolpath", "p.fk", "--machine", "m.toml")
    assert rc == 0
    Path("bad.toml").write_text("name = [unclosed\n")
    rc, _, err = run(capsys, "toolpath", "p.fk", "--machine", "bad.toml")
    assert rc == 2 and "bad.toml" in err and "invalid TOML" in err
    Path("wrong.toml").write_text('kind = "submarine"\n')
    rc, _, err = run(capsys, "lint", "p.fk", "--machine", "wrong.toml")
    assert rc == 2 and "invalid machine description" in err
    rc, _, err = run(capsys, "lint", "p.fk", "--machine", "missing.toml")
    assert rc == 2 and "cannot read machine file" in err


def test_convert_a_directory_keeps_its_structure(fake, capsys):
    (Path("src") / "sub").mkdir(parents=True)
    Path("src/a.fk").write_text("G0 X1\n")
    Path("src/sub/b.fk").write_text("G0 X2\n")
    Path("src/notes.md").write_text("(\n")
    assert run(capsys, "convert", "src", "--to", "fake")[0] == 2          # a directory needs --out-dir
    rc, _, err = run(capsys, "convert", "src", "--to", "fake", "--out-dir", "dst")
    assert rc == 0, err
    assert sorted(str(p.relative_to("dst")) for p in Path("dst").rglob("*") if p.is_file()) == ["a.nc", "sub/b.nc"]


def test_e2e_flatten_is_equivalent_to_its_source(tmp_path):
    sample = ROOT / "corpus" / "iso-m" / "sample-pocket.nc"
    for target, name in (("iso-m", "flat.nc"), ("sinumerik", "flat.mpf")):
        out = tmp_path / name
        rc, _, err = sh("convert", str(sample), "--flatten", "--to", target, "-o", str(out))
        assert rc == 0, err
        rc, text, err = sh("equiv", str(sample), str(out), "--from-a", "iso-m", "--from-b", target)
        assert rc == 0, text + err
