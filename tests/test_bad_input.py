"""Bad input through the real command line: a located diagnostic or a message, exit 1 or 2,
never a traceback, never a hang, and the input files never modified."""
import hashlib
import json
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from nctrans import pipeline
from nctrans.source import decode

NCTRANS = [sys.executable, "-m", "nctrans"]
TIMEOUT = 120
LOC = r"^(?P<file>[^:]+):(?P<line>\d+):(?P<col>\d+): (?P<sev>error|warning|info)\[(?P<rule>NC\d{3})\]"




def digest(paths):
    return {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in paths if p.is_file()}


def nctrans(*argv, cwd, stdin=b""):
    """Run the CLI; the files in cwd must be unchanged afterwards and stderr free of tracebacks."""
    files = [p for p in Path(cwd).rglob("*") if p.is_file()]
    before = digest(files)
    proc = subprocess.run(NCTRANS + list(argv), cwd=cwd, input=stdin, capture_output=True, timeout=TIMEOUT)
    err = proc.stderr.decode("utf-8", "replace")
    assert "Traceback" not in err, err
    assert digest(files) == before, "an input file was modified"
    return proc.returncode, proc.stdout.decode("utf-8", "replace"), err


def lint_json(tmp_path, *argv):
    rc, out, err = nctrans("lint", "--format", "json", *argv, cwd=tmp_path)
    return rc, (json.loads(out) if out.strip() else None), err


def only(doc, rule):
    return [d for d in doc["diagnostics"] if d["rule"] == rule]


# --------------------------------------------------------------------------- not text at all

@pytest.mark.parametrize("name,data,words", [
    ("image.nc", b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(range(256)) * 8, "binary"),
    ("wide.nc", "%\nO1000\nG0 X10\nM30\n%\n".encode("utf-16"), "UTF-16"),
    ("wide-nobom.mpf", "G0 X10\nM30\n".encode("utf-16-le"), "UTF-16"),
])
def test_not_text_is_nc001(tmp_path, name, data, words):
    (tmp_path / name).write_bytes(data)
    for extra in ([], ["--from", "iso-m"]):
        rc, doc, _ = lint_json(tmp_path, name, *extra)
        assert rc == 1
        [d] = doc["diagnostics"]
        assert (d["rule"], d["severity"], d["file"], d["line"], d["column"]) == ("NC001", "error", name, 1, 1)
        assert words in d["message"]
    rc, out, err = nctrans("toolpath", name, cwd=tmp_path)
    assert rc == 1 and out == "" and f"{name}:1:1: error[NC001]" in err


@pytest.mark.parametrize("data", [b"", b"\n\n  \n", b"\xef\xbb\xbf\r\n"])
def test_empty_file_is_nc004(tmp_path, data):
    (tmp_path / "empty.nc").write_bytes(data)
    rc, out, _ = nctrans("lint", "empty.nc", cwd=tmp_path)
    assert rc == 1 and out.startswith("empty.nc:1:1: error[NC004]")


def test_missing_unreadable_and_directory_inputs_exit_2(tmp_path):
    rc, _, err = nctrans("toolpath", "nope.nc", cwd=tmp_path)
    assert rc == 2 and "nope.nc: no such file" in err
    (tmp_path / "d").mkdir()
    rc, _, err = nctrans("toolpath", "d", cwd=tmp_path)
    assert rc == 2 and "is a directory" in err
    rc, _, err = nctrans("lint", "x.nc", "--from", "fanuc-ish", cwd=tmp_path)
    assert rc == 2 and "unknown dialect" in err


# --------------------------------------------------------------------------- malformed programs (real front ends)

@pytest.mark.parametrize("text,rule,line,col", [
    ("G0 X10\nG1 X[1+2 Y3 F100\nM30\n", "NC003", 2, 5),          # expression bracket not closed
    ("G0 X10 (comment\nM30\n", "NC003", 1, 8),                     # comment not closed
    ("%\nO1000\nG0 X10\nWHILE [#1 LT 3] DO1\nG1 X#1 F100\n#1=#1+1\n", "NC006", 4, 1),   # loop cut off
    ("G0 X1\nG1 X2 Y*5 F100\nM30\n", "NC002", 2, 8),
])
def test_iso_malformed_blocks_are_located(tmp_path, text, rule, line, col):
    (tmp_path / "p.nc").write_text(text)
    rc, doc, _ = lint_json(tmp_path, "p.nc", "--from", "iso-m")
    assert rc == 1
    hits = only(doc, rule)
    assert hits, doc
    assert (hits[0]["file"], hits[0]["line"], hits[0]["column"]) == ("p.nc", line, col)


def test_file_cut_in_the_middle_of_a_block(tmp_path):
    full = (Path(__file__).resolve().parents[1] / "corpus" / "iso-m" / "sample-pocket.nc").read_bytes()
    cut = full[: full.index(b"N230 G00 X[15.") + len(b"N230 G00 X[15.")]
    (tmp_path / "cut.nc").write_bytes(cut)
    rc, doc, _ = lint_json(tmp_path, "cut.nc", "--from", "iso-m")
    assert rc == 1
    last = cut.count(b"\n") + 1
    errors = [d for d in doc["diagnostics"] if d["severity"] == "error" and d["rule"].startswith("NC0")]
    assert errors and all(1 <= d["line"] <= last for d in errors)
    assert any(d["line"] == last for d in errors) or only(doc, "NC006")


def test_wrong_dialect_is_nc005(tmp_path):
    (tmp_path / "part.nc").write_text("DEF REAL LEN=5\nR1=2\nG1 X=LEN F100\nIF R1>1 GOTOF END\nEND:\nM30\n")
    rc, doc, _ = lint_json(tmp_path, "part.nc", "--from", "iso-m")
    assert rc == 1
    [d] = only(doc, "NC005")
    assert d["line"] == 1 and "sinumerik" in d["message"]
    rc, doc, _ = lint_json(tmp_path, "part.nc", "--from", "sinumerik", "--select", "NC0")
    assert rc == 0 and doc["diagnostics"] == []
    rc, out, _ = nctrans("detect", "part.nc", cwd=tmp_path)
    assert rc == 0 and "sinumerik" in out


def test_cp1252_comments_and_crlf_read_like_utf8_lf(tmp_path):
    text = "%\nO0001 (WÜRFEL Ø10 – Späne)\nG21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F100 (naß)\nG2 X10 Y0 R5\nM30\n%\n"
    (tmp_path / "utf8.nc").write_bytes(text.encode("utf-8"))
    (tmp_path / "ansi.nc").write_bytes(text.replace("\n", "\r\n").encode("cp1252"))
    (tmp_path / "mac.nc").write_bytes(text.replace("\n", "\r").encode("cp1252"))
    outs = []
    for name in ("utf8.nc", "ansi.nc", "mac.nc"):
        rc, doc, _ = lint_json(tmp_path, name, "--from", "iso-m", "--select", "NC0")
        assert rc == 0 and doc["diagnostics"] == [], doc
        rc, out, err = nctrans("toolpath", name, "--from", "iso-m", cwd=tmp_path)
        assert rc == 0, err
        recs = [json.loads(x) for x in out.splitlines()]
        outs.append([(r["line"], r["kind"], r.get("end")) for r in recs])
        assert any(r["kind"] == "arc" and r["line"] == 6 for r in recs)
    assert outs[0] == outs[1] == outs[2]


def test_directory_with_mixed_files(tmp_path):
    d = tmp_path / "shop"
    (d / "sub").mkdir(parents=True)
    (d / "good.nc").write_text("G0 X1 Y1\nG1 X2 F100\nM30\n")
    (d / "unbalanced.nc").write_text("G0 X1 (oops\nM30\n")
    (d / "binary.nc").write_bytes(bytes(range(256)) * 4)
    (d / "utf16.tap").write_bytes("G0 X1\n".encode("utf-16"))
    (d / "empty.cnc").write_bytes(b"")
    (d / "README.txt").write_text("notes (not a program\n")
    (d / "photo.jpg").write_bytes(b"\xff\xd8\xff\xe0" + bytes(300))
    (d / "sub" / "crlf.nc").write_bytes(b"G0 X1\r\nG1 X2 F100\r\nM30\r\n")
    rc, doc, err = lint_json(tmp_path, "shop", "--from", "iso-m")
    assert rc == 1, err
    assert doc["files"] == 6
    by_file = {}
    for x in doc["diagnostics"]:
        by_file.setdefault(Path(x["file"]).name, set()).add(x["rule"])
    assert by_file.get("unbalanced.nc") == {"NC003"}
    assert by_file.get("binary.nc") == {"NC001"} and by_file.get("utf16.tap") == {"NC001"}
    assert by_file.get("empty.cnc") == {"NC004"}
    assert "good.nc" not in by_file and "crlf.nc" not in by_file
    assert "README.txt" not in by_file and "photo.jpg" not in by_file
    # the same directory as SARIF and text: one located line per diagnostic
    rc, out, _ = nctrans("lint", "shop", "--from", "iso-m", cwd=tmp_path)
    import re
    assert rc == 1 and all(re.match(LOC, line) for line in out.splitlines())
    rc, out, _ = nctrans("lint", "shop", "--from", "iso-m", "--format", "sarif", cwd=tmp_path)
    assert rc == 1 and len(json.loads(out)["runs"][0]["results"]) == len(doc["diagnostics"])


def test_stdin_and_endless_loop_finish(tmp_path):
    prog = b"#1=0\nWHILE [1 EQ 1] DO1\n#1=#1+1\nEND1\nM30\n"
    rc, out, _ = nctrans("lint", "-", "--from", "iso-m", cwd=tmp_path, stdin=prog)
    assert "<stdin>:" in out and "NC205" in out
    assert rc == 1    # running out of the step budget is an error: the analysis is incomplete


def test_convert_refuses_to_overwrite_its_input(tmp_path):
    (tmp_path / "a.nc").write_text("G0 X1\nG1 X2 F100\nM30\n")
    rc, _, err = nctrans("convert", "a.nc", "--from", "iso-m", "--to", "iso-m", "-o", "a.nc", cwd=tmp_path)
    assert rc == 2 and "refusing to overwrite" in err
    rc, _, err = nctrans("convert", "a.nc", "--from", "iso-m", "--to", "iso-m", "--out-dir", ".", cwd=tmp_path)
    assert rc == 2 and "refusing to overwrite" in err


# --------------------------------------------------------------------------- robustness properties (in process)

nc_alphabet = st.sampled_from(list("GXYZIJKFSTMNORPQ0123456789.-+ ()[]#=;%\n\t/*") +
                              ["DEF ", "WHILE ", "IF ", "GOTO", "DO1", "END1", "R1=", "\r\n", "é", "\x00"])


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(nc_alphabet, max_size=80).map("".join), st.sampled_from(["iso-m", "sinumerik"]))
def test_any_text_gives_located_diagnostics_not_exceptions(text, dialect):
    src = decode(text.encode("utf-8"), "fz.nc")
    ld = pipeline.load_source(src, "fz.nc", dialect)
    diags = pipeline.lint(ld)
    lines = max(1, src.line_count)
    for d in diags:
        assert d.file in ("fz.nc",) or d.file.endswith(".nc")
        assert 1 <= d.line <= lines + 1 and d.column >= 1
        assert d.severity in ("error", "warning", "info")


def test_sinumerik_non_ascii_code_is_a_diagnostic_not_a_crash():
    for text in ("é", "G1 X10 é\n"):
        ld = pipeline.load_source(decode(text.encode("utf-8"), "fz.mpf"), "fz.mpf", "sinumerik")
        diags = pipeline.lint(ld)
        assert any(d.rule.startswith("NC0") and d.severity == "error" for d in diags)
