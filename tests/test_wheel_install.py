"""The package as users install it: a regular wheel in a fresh virtual environment, outside the checkout.

`pip install .`, pipx and pre-commit all build a wheel and install it; an editable install (what
`make test` uses) hides every file the wheel forgets, because the checkout is still beside the
package. So this test builds the wheel, installs it into a new venv in a temporary directory and
runs the CLI from another directory on corpus files copied there.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import pytest

from conftest import CORPUS

# One xdist worker runs this module (make test passes --dist loadgroup), so the wheel is built once.
pytestmark = pytest.mark.xdist_group("wheel")

ROOT = Path(__file__).resolve().parents[1]
DATA_DIRS = ("rules", "grammars", "backplot")


def _run(cmd, cwd, env=None, timeout=300):
    return subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def outside():
    """A temporary directory outside the checkout (make test's --basetemp is inside it)."""
    d = Path(tempfile.mkdtemp(prefix="nctrans-wheel-"))
    assert not d.resolve().is_relative_to(ROOT)
    yield d
    shutil.rmtree(d, ignore_errors=True)


@pytest.fixture(scope="module")
def installed(outside):
    """(venv bin directory, wheel path, clean environment) with nctrans installed from its wheel."""
    base = outside
    dist = base / "dist"
    # Built from a copy: pip builds in the source tree's build/ folder, which a concurrent or an
    # interrupted build in the checkout would leave half-written.
    source = base / "source"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(
        ".git", ".venv", ".pytest-tmp", "build", "dist", "out", "*.egg-info", "__pycache__", "*.so"))
    build = _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(dist), str(source)], cwd=base)
    assert build.returncode == 0, build.stderr
    (wheel,) = dist.glob("nctrans-*.whl")
    venv = base / "venv"
    made = _run([sys.executable, "-m", "venv", str(venv)], cwd=base)
    assert made.returncode == 0, made.stderr
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}
    env["NCTRANS_CACHE_DIR"] = str(base / "cache")
    inst = _run([str(venv / "bin" / "python"), "-m", "pip", "install", "-q", str(wheel)], cwd=base, env=env)
    assert inst.returncode == 0, inst.stderr
    return venv / "bin", wheel, env


def test_one_worker_runs_this_module(request):
    """Under make test (--dist loadgroup) the group mark reaches xdist, so the wheel is built and
    installed once; a pytest or xdist whose node ids lose the group would build it on each worker."""
    if getattr(request.config.option, "loadgroup", False):
        assert request.node.nodeid.endswith("@wheel"), request.node.nodeid


def test_wheel_carries_every_data_file_and_the_kernel(installed):
    _, wheel, _ = installed
    names = set(zipfile.ZipFile(wheel).namelist())
    for kind in DATA_DIRS:
        files = [p for p in (ROOT / kind).rglob("*") if p.is_file() and "__pycache__" not in p.parts]
        assert files, f"{kind}/ is empty in the checkout"
        for p in files:
            assert f"nctrans/_data/{p.relative_to(ROOT).as_posix()}" in names, f"{p} missing from the wheel"
    if list((ROOT / "nctrans").glob("_plainrun*.so")):       # this machine compiles the kernel
        assert any(n.startswith("nctrans/_plainrun") and n.endswith(".so") for n in names)


def test_installed_cli_runs_outside_the_checkout(installed, outside):
    bin_dir, _, env = installed
    work = outside / "shop"
    work.mkdir()
    iso = work / "part.nc"
    shutil.copy(CORPUS / "iso-mill" / "kiely-haas-step-part.nc", iso)
    siemens = work / "slot.mpf"
    shutil.copy(CORPUS / "sinumerik" / "dubovikov-slot.mpf", siemens)
    nctrans = str(bin_dir / "nctrans")

    where = _run([str(bin_dir / "python"), "-c", "import nctrans, nctrans.resources as r;"
                  "print(nctrans.__file__); print(r.root('rules')); print(r.root('backplot'))"],
                 cwd=work, env=env)
    assert where.returncode == 0, where.stderr
    for line in where.stdout.split():
        assert Path(line).is_relative_to(bin_dir.parent), f"the installed CLI reads {line}, not the wheel"

    lint = _run([nctrans, "lint", "--format", "json", str(iso), str(siemens)], cwd=work, env=env)
    assert lint.returncode in (0, 1), lint.stderr
    doc = json.loads(lint.stdout)
    assert doc["files"] == 2
    assert not any(d["rule"].startswith("NC0") for d in doc["diagnostics"]), doc["diagnostics"]

    for native in ("1", "0"):           # with the kernel and on the pure-Python fallback
        tp = _run([nctrans, "toolpath", "part.nc"], cwd=work, env={**env, "NCTRANS_NATIVE": native})
        assert tp.returncode == 0, tp.stderr
        records = [json.loads(line) for line in tp.stdout.splitlines()]
        assert sum(r["kind"] == "linear" for r in records) > 10

    conv = _run([nctrans, "convert", "part.nc", "--to", "sinumerik", "-o", "part.mpf"], cwd=work, env=env)
    assert conv.returncode == 0, conv.stderr
    back = _run([nctrans, "equiv", "part.nc", "part.mpf"], cwd=work, env=env)
    assert back.returncode == 0, back.stdout + back.stderr

    listing = _run([nctrans, "rules"], cwd=work, env=env)
    assert listing.returncode == 0 and "NC002" in listing.stdout
    one = _run([nctrans, "rules", "NC002"], cwd=work, env=env)
    assert one.returncode == 0 and one.stdout.startswith("NC002")


# Runs the installed CLI as if the wheel had no compiled kernel (a platform pip serves no binary
# wheel for, built where no C compiler was found): importing nctrans._plainrun fails as it would.
NO_KERNEL = r'''
import sys
from importlib.abc import MetaPathFinder

class NoKernel(MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name == "nctrans._plainrun":
            raise ImportError("no compiled kernel in this install")
        return None

sys.meta_path.insert(0, NoKernel())
from nctrans import cli, plainrun
assert plainrun.native is None
sys.exit(cli.main(sys.argv[1:]))
'''


def test_installed_wheel_without_its_kernel(installed, outside):
    """The pure-Python fallback of the installed package: the same toolpath and lint findings as
    with the kernel, from outside the checkout."""
    bin_dir, _, env = installed
    work = outside / "no-kernel"
    work.mkdir()
    part = work / "part.nc"
    shutil.copy(CORPUS / "iso-mill" / "mheaton-fusion-adaptive-1001.nc", part)
    script = work / "no_kernel.py"
    script.write_text(NO_KERNEL, encoding="utf-8")
    python, nctrans = str(bin_dir / "python"), str(bin_dir / "nctrans")
    out = {}
    for args in (["toolpath", "part.nc"], ["lint", "--format", "json", "part.nc"]):
        with_kernel = _run([nctrans, *args], cwd=work, env=env)
        without = _run([python, str(script), *args], cwd=work, env=env)
        assert with_kernel.returncode == without.returncode and without.returncode in (0, 1), without.stderr
        assert without.stdout == with_kernel.stdout, args
        out[args[0]] = without.stdout
    assert out["toolpath"].count("\n") > 20_000 and json.loads(out["lint"])["files"] == 1


API_SCRIPT = r'''
import pathlib, sys, tracemalloc
import nctrans

corpus = pathlib.Path(sys.argv[1])
part = corpus / "iso-mill" / "kiely-haas-step-part.nc"
there = nctrans.transpile(part, read="iso-m", write="sinumerik")
back = nctrans.transpile(there.text, read="sinumerik", write="iso-m")
assert there.ok and back.ok, there.diagnostics + back.diagnostics
assert nctrans.equiv(part, there.text, read_b="sinumerik"), "conversion changed the toolpath"
assert nctrans.equiv(part, back.text, read_b="iso-m"), "round trip changed the toolpath"

cam = corpus / "iso-mill" / "mheaton-fusion-adaptive-1001.nc"
tracemalloc.start()
moves = sum(1 for r in nctrans.toolpath(cam) if r.kind in ("linear", "arc"))
peak = tracemalloc.get_traced_memory()[1]
tracemalloc.stop()

found = nctrans.lint(corpus / "iso-mill", dialect="iso-m")
print(moves, peak, len(found), len({d.file for d in found}))
'''


def test_installed_python_api_from_a_script(installed, outside):
    """Issue 16's promise: in a fresh venv with the wheel, a script importing only nctrans can
    transpile both ways, stream a 22k-line toolpath with flat memory, lint a directory, prove equiv."""
    bin_dir, wheel, env = installed
    assert "nctrans/py.typed" in zipfile.ZipFile(wheel).namelist()
    script = outside / "api_user.py"
    script.write_text(API_SCRIPT, encoding="utf-8")
    run = _run([str(bin_dir / "python"), str(script), str(CORPUS)], cwd=outside, env=env)
    assert run.returncode == 0, run.stdout + run.stderr
    moves, peak, diags, files = (int(x) for x in run.stdout.split())
    assert moves > 20_000
    # the whole IR of this program is ~60 MiB; a streamed run holds a bounded window of it
    assert peak < 16 * 2**20, f"streamed toolpath peaked at {peak / 2**20:.1f} MiB"
    assert diags > 0 and files > 5
