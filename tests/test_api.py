"""The Python API (nctrans/api.py): the README's examples, the promises of each function, and the
public names staying what they are."""
from __future__ import annotations

import doctest
import importlib
import os
import pkgutil
import re
import shutil
import subprocess
import sys
import tracemalloc
from pathlib import Path

import pytest

import nctrans
from nctrans import api
from conftest import CORPUS

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "corpus" / "iso-m" / "sample-pocket.nc"


# --------------------------------------------------------------------------- README examples

def _readme_python_section() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## From Python", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert blocks, "README's 'From Python' section has no python example"
    return "\n".join(blocks)


def test_readme_examples_run(monkeypatch):
    monkeypatch.chdir(ROOT)
    parser = doctest.DocTestParser()
    test = parser.get_doctest(_readme_python_section(), {}, "README.md#from-python", "README.md", 0)
    assert len(test.examples) >= 10
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, "README 'From Python' examples failed (output above)"


# --------------------------------------------------------------------------- public names

def test_public_names_survive_importing_every_submodule():
    """`nctrans.toolpath` is the API function although nctrans/toolpath.py is the record module:
    a submodule loaded late would rebind the package attribute, so load them all and look."""
    for mod in pkgutil.walk_packages(nctrans.__path__, "nctrans."):
        if mod.name != "nctrans.__main__":
            importlib.import_module(mod.name)
    for name in nctrans.__all__:
        if name == "__version__":
            continue
        value = getattr(nctrans, name)
        assert not isinstance(value, type(sys)), f"nctrans.{name} is a module, not the API name"
    assert nctrans.toolpath is api.toolpath and nctrans.equiv is api.equiv and nctrans.detect is api.detect


def test_every_public_name_has_a_docstring():
    for name in nctrans.__all__:
        if name == "__version__":
            continue
        assert (getattr(nctrans, name).__doc__ or "").strip(), f"nctrans.{name} has no docstring"


# --------------------------------------------------------------------------- transpile and equiv

def _corpus_iso_programs() -> list[Path]:
    d = CORPUS / "iso-mill"
    return [d / n for n in (
        # slot-assembly: its G73 peck cycle becomes plain motion on its own, the rest stays
        "kiely-haas-step-part.nc", "lmhdpro-JPM-abs-handwritten.nc", "enier-haas-slot-assembly-12.nc",
        "camotics-scorpion.nc")]


@pytest.mark.parametrize("path", _corpus_iso_programs(), ids=lambda p: p.name)
def test_corpus_program_round_trips_through_sinumerik(path):
    if not path.is_file():
        pytest.skip(f"{path} not in the shared corpus")
    there = nctrans.transpile(path, read="iso-m", write="sinumerik")
    assert there.ok, [d.format_text() for d in there.diagnostics]
    assert nctrans.equiv(path, there.text, read_a="iso-m", read_b="sinumerik"), "conversion changed the toolpath"
    back = nctrans.transpile(there.text, read="sinumerik", write="iso-m")
    assert back.ok, [d.format_text() for d in back.diagnostics]
    same = nctrans.equiv(path, back.text, read_a="iso-m", read_b="iso-m")
    assert same, same.message


def test_equiv_names_the_first_difference_and_where():
    a = "G0 X0 Y0\nG1 X10 F100\nG1 Y10\nM30\n"
    b = "G0 X0 Y0\nG1 X10 F100\nG1 Y11\nM30\n"
    result = nctrans.equiv(a, b, read_a="iso-m", read_b="iso-m")
    assert not result
    assert result.difference is not None
    assert ":3" in result.message               # line 3 of each program
    assert nctrans.equiv(a, b, tol=2.0, read_a="iso-m", read_b="iso-m")


def test_equiv_keeps_the_diagnostics_of_both_programs():
    result = nctrans.equiv("G0 X1\nG0 Y[1+\n", "G0 X1\n", read_a="iso-m", read_b="iso-m")
    assert any(d.rule == "NC003" and d.file == "<a>" and d.line == 2 for d in result.diagnostics)


@pytest.mark.parametrize("tol", [0, -1, float("inf"), float("nan"), "0.1", True])
def test_equiv_rejects_a_tolerance_that_is_not_a_positive_finite_number(tol):
    with pytest.raises(nctrans.NCInputError):
        nctrans.equiv("G0 X1\n", "G0 X1\n", tol=tol, read_a="iso-m", read_b="iso-m")


def test_transpile_reports_lowered_constructs_and_strict_refuses_them():
    conv = nctrans.transpile("G0 X1\nM30\n", read="iso-m", write="sinumerik")
    assert conv.ok and conv.lowered and all(d.rule == "NC401" for d in conv.lowered)
    strict = nctrans.transpile("G0 X1\nM30\n", read="iso-m", write="sinumerik", strict=True)
    assert strict.text is None and not strict.ok
    assert any(d.severity == "error" for d in strict.diagnostics)


def test_transpile_flatten_writes_plain_motion_with_the_same_toolpath():
    src = "#1=0\nWHILE[#1LT3]DO1\nG1 X#1 Y[#1*2] F100\n#1=#1+1\nEND1\nM30\n"
    flat = nctrans.transpile(src, read="iso-m", write="iso-m", flatten=True)
    assert flat.ok and "WHILE" not in flat.text and "#" not in flat.text
    assert nctrans.equiv(src, flat.text, read_a="iso-m", read_b="iso-m")


def test_error_level_raise_carries_the_diagnostics():
    with pytest.raises(nctrans.NCProgramError) as info:
        nctrans.lint("G1 X10\nM30\n", dialect="iso-m", error_level=nctrans.ErrorLevel.RAISE)
    assert [d.rule for d in info.value.diagnostics] == ["NC202"]
    # warnings and infos alone do not raise
    assert nctrans.lint("G1 X10 F100\nM30\n", dialect="iso-m", error_level=nctrans.ErrorLevel.RAISE) == []


# --------------------------------------------------------------------------- toolpath

def test_toolpath_of_text_path_and_program_agree():
    text = SAMPLE.read_text(encoding="utf-8")
    from_path = [r.to_dict() for r in nctrans.toolpath(SAMPLE)]
    from_text = [r.to_dict() for r in nctrans.toolpath(text, "iso-m")]
    program = nctrans.parse(text, "iso-m")
    from_program = [r.to_dict() for r in nctrans.toolpath(program)]
    strip = lambda recs: [{k: v for k, v in r.items() if k != "file"} for r in recs]   # noqa: E731
    assert len(from_path) > 30
    assert strip(from_path) == strip(from_text) == strip(from_program)


def test_toolpath_states_and_diagnostics():
    tp = nctrans.toolpath("G0 X1\nG1 X2 F100\nG1 Y1 F-5\nM30\n", "iso-m")
    assert "not started" in repr(tp)
    records = list(tp)
    assert [r.kind for r in records][:2] == ["rapid", "linear"] and records[-1].kind == "stop"
    assert "complete" in repr(tp) and f"{len(records)} records" in repr(tp)
    assert [(d.severity, d.line) for d in tp.diagnostics] == [("error", 3)]      # negative feed


def _cam_program(blocks: int) -> str:
    lines = ["G21 G90 G17", "G0 Z5", "G1 Z-1 F300"]
    for i in range(blocks):
        lines.append(f"X{(i % 97) * 0.5:.3f} Y{(i % 89) * 0.25:.3f}")
    lines.append("M30")
    return "\n".join(lines) + "\n"


def _peak_bytes(text: str) -> int:
    tracemalloc.start()
    try:
        n = sum(1 for _ in nctrans.toolpath(text, "iso-m"))
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
        assert n > 0


def test_toolpath_streams_with_memory_flat_in_program_length():
    """The full IR of a CAM block costs ~3 KB; a streamed run keeps a bounded window of them, so
    four times the blocks may add little more than the extra text itself (~25 bytes a block)."""
    small, large = _cam_program(5_000), _cam_program(20_000)
    growth = _peak_bytes(large) - _peak_bytes(small)
    added_blocks = 15_000
    assert growth < 300 * added_blocks, f"peak grew by {growth / added_blocks:.0f} bytes per block"


# --------------------------------------------------------------------------- lint

def test_lint_a_directory_equals_linting_each_file(tmp_path):
    for name in ("stcline-maze-G91-incremental.nc", "kiely-haas-step-part.nc"):
        shutil.copy(CORPUS / "iso-mill" / name, tmp_path / name)
    (tmp_path / "bad.nc").write_text("G1 X10\nM30\n", encoding="utf-8")
    (tmp_path / "notes.txt").write_text("G1 X10\n", encoding="utf-8")      # not an NC file ending
    together = nctrans.lint(tmp_path, dialect="iso-m")
    one_by_one = [d for f in sorted(tmp_path.glob("*.nc")) for d in nctrans.lint(f, dialect="iso-m")]
    assert [d.to_dict() for d in together] == [d.to_dict() for d in one_by_one]
    assert any(d.rule == "NC202" and d.file.endswith("bad.nc") for d in together)
    assert not any(d.file.endswith("notes.txt") for d in together)


def test_lint_select_and_ignore_take_rule_prefixes():
    text = "G1 X10\nG99.9\nM30\n"
    everything = {d.rule for d in nctrans.lint(text, "iso-m")}
    assert {"NC202", "NC403"} <= everything
    assert {d.rule for d in nctrans.lint(text, "iso-m", select=["NC4"])} == {"NC403"}
    assert "NC202" not in {d.rule for d in nctrans.lint(text, "iso-m", ignore=["NC20"])}


# --------------------------------------------------------------------------- misuse

def test_unknown_dialect_is_an_nc_error_and_a_value_error():
    for call in (lambda: nctrans.parse("G0 X1", "nope"),
                 lambda: nctrans.transpile("G0 X1", "iso-m", "nope"),
                 lambda: nctrans.lint("G0 X1", "nope"),
                 lambda: nctrans.toolpath("G0 X1", "nope")):
        with pytest.raises(nctrans.UnknownDialectError) as info:
            call()
        assert isinstance(info.value, nctrans.NCError) and isinstance(info.value, ValueError)


def test_a_string_is_program_text_never_a_file_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "G0").write_text("G1 X99 F10\n", encoding="utf-8")
    records = list(nctrans.toolpath("G0", "iso-m"))
    assert all(r.end is None or r.end.get("X", 0) != 99 for r in records)


def test_bad_arguments_raise_nc_input_error(tmp_path):
    with pytest.raises(nctrans.NCInputError):
        nctrans.toolpath(tmp_path / "missing.nc", "iso-m")
    with pytest.raises(nctrans.NCInputError):
        nctrans.parse(42, "iso-m")                                   # type: ignore[arg-type]
    bad = tmp_path / "m.toml"
    bad.write_text("[axes.X]\nmin = 'low'\n", encoding="utf-8")
    with pytest.raises(nctrans.NCInputError) as info:
        nctrans.toolpath("G0 X1\n", "iso-m", machine=bad)
    assert "axes" in str(info.value)
    with pytest.raises(nctrans.NCInputError):
        nctrans.transpile("G0 X1\n", "iso-m", "sinumerik", search_path=[tmp_path / "nowhere"])


def test_machine_from_toml(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text('name = "vmc"\n[axes.X]\nmin = -10.0\nmax = 10.0\n', encoding="utf-8")
    m = nctrans.Machine.from_toml(path)
    assert m.name == "vmc" and m.axes["X"].max == 10.0


# --------------------------------------------------------------------------- types

def test_the_api_type_checks_with_mypy_strict(tmp_path):
    """A user's script, and the API module itself, under `mypy --strict`."""
    pytest.importorskip("mypy")
    script = tmp_path / "user.py"
    script.write_text(
        "import pathlib\nimport nctrans\n\n"
        "def convert(path: pathlib.Path) -> str:\n"
        "    conv: nctrans.Conversion = nctrans.transpile(path, read='iso-m', write='sinumerik')\n"
        "    ok: bool = bool(nctrans.equiv(path, conv.text or '', read_b='sinumerik'))\n"
        "    moves: int = sum(1 for r in nctrans.toolpath(path) if r.kind in ('linear', 'arc'))\n"
        "    errors: list[nctrans.Diagnostic] = nctrans.lint(path.parent, select=['NC2'])\n"
        "    return f'{ok} {moves} {len(errors)} {nctrans.detect(conv.text or \"\").dialect}'\n",
        encoding="utf-8")
    cmd = [sys.executable, "-m", "mypy", "--strict", "--follow-imports=silent", "--no-error-summary",
           "--cache-dir", str(tmp_path / "cache"), str(ROOT / "nctrans" / "api.py"), str(script)]
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, env={**os.environ, "MYPYPATH": str(ROOT)})
    assert out.returncode == 0, out.stdout + out.stderr


def test_toolpath_plots_inline_for_notebooks():
    """`Toolpath._repr_html_` (Jupyter) draws the program: one SVG element per move."""
    tp = nctrans.toolpath(SAMPLE)
    svg = tp._repr_html_()
    moves = sum(1 for r in nctrans.toolpath(SAMPLE) if r.kind in ("rapid", "linear", "arc"))
    assert svg.startswith("<svg") and f'data-moves="{moves}"' in svg
    assert tp.done and "complete" in tp._repr_html_()      # consumed: the summary, not a replay
