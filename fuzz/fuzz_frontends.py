"""Coverage-guided fuzzing of every front end with atheris (`make fuzz`).

For each registered dialect, libFuzzer mutates NC programs (seeded with the shared corpus) and
runs what a user runs: decode, parse, lint (the interpreter to its end) and convert to every other
dialect. A run that raises anything but a diagnostic is a crash: its input is kept in
tests/data/fuzz-crashes/<dialect>/ (tests/test_fuzz_crashes.py runs each one in `make test` from
then on) and fuzzing goes on. Usage: python fuzz/fuzz_frontends.py [SECONDS per dialect].
"""
from __future__ import annotations

import contextlib
import hashlib
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CRASHES = ROOT / "tests" / "data" / "fuzz-crashes"
CORPUS = ROOT.parent / "shared" / "corpus"
# Seed programs of each front end: the shared corpus where it has the dialect, else the repository's.
SEEDS = {"iso-m": CORPUS / "iso-mill", "iso-t": CORPUS / "iso-turn", "sinumerik": CORPUS / "sinumerik",
         "fagor": ROOT / "corpus" / "fagor"}
RUNS_PER_DIALECT = 5        # fuzzing restarts after each crash kept, at most this often


# Fuzzing looks for crashes, not for scale: with the default budgets one mutant that loops
# forever runs 2 M steps four times over (minutes), and a seed with a real 100k-move loop
# (dubovikov-konus.mpf) took 3.5 min per input. Smaller budgets give the same stops sooner;
# tests/test_hostile*.py hold the defaults to their bounds.
FUZZ_LIMITS = {"NCTRANS_MAX_STEPS": "5000", "NCTRANS_MAX_LOWERED_BLOCKS": "5000", "NCTRANS_MAX_UNROLLED": "5000"}


@contextlib.contextmanager
def fuzz_limits():
    saved = {k: os.environ.get(k) for k in FUZZ_LIMITS}
    os.environ.update(FUZZ_LIMITS)
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def one_input(dialect: str, data: bytes) -> None:
    """Everything a user can run on `data` as `dialect`; only bugs raise."""
    with fuzz_limits():
        _run_all(dialect, data)


def _run_all(dialect: str, data: bytes) -> None:
    from nctrans import api, pipeline, source
    src = source.decode(data[:16 * 1024], "fuzz")
    if not src.ok:
        return
    ld = pipeline.load_source(src, source.STDIN, dialect)
    if ld.program is None:
        return
    for _ in pipeline.toolpath_of(ld):
        pass
    for target in api.dialects():
        api.transpile(src.text, dialect, target)


def fuzz(dialect: str) -> None:
    try:
        import atheris
    except ImportError:
        sys.exit("atheris is not installed: `pip install -e '.[fuzz]'` installs its wheel (Linux "
                 "x86_64/aarch64, CPython 3.8-3.12); elsewhere pip builds it from source, which needs "
                 "clang with libFuzzer (Debian: apt-get install clang libfuzzer-dev; CLANG_BIN=clang)")
    with atheris.instrument_imports():
        import nctrans.api  # noqa: F401  (instrumented: coverage guides the mutations)
        import nctrans.interp.interpreter  # noqa: F401
        import nctrans.lower.flatten  # noqa: F401

    def test_one(data: bytes) -> None:
        try:
            one_input(dialect, data)
        except Exception:
            keep(dialect, data)
            raise
    atheris.Setup(sys.argv, test_one)        # sys.argv: the script, then libFuzzer's options
    atheris.Fuzz()


def keep(dialect: str, data: bytes) -> Path:
    """Store a crashing input as a regression case (named by its content)."""
    d = CRASHES / dialect
    d.mkdir(parents=True, exist_ok=True)
    path = d / f"crash-{hashlib.sha1(data).hexdigest()[:16]}.bin"
    path.write_bytes(data)
    return path


def main() -> int:
    seconds = int(sys.argv[1]) if len(sys.argv) > 1 else 60
    status = 0
    for dialect, sub in SEEDS.items():
        runs = 0
        with tempfile.TemporaryDirectory() as work:
            seeds = Path(work) / "seeds"
            seeds.mkdir()
            for p in sorted(sub.glob("*"))[:60]:     # heads: short seeds mutate fast
                (seeds / p.name).write_bytes(p.read_bytes()[:4096])
            # each dialect in its own process: libFuzzer stops at the first crash, the loop goes on
            while True:
                r = subprocess.run([sys.executable, __file__, "--child", dialect,
                                    f"-max_total_time={seconds}", "-rss_limit_mb=700", "-timeout=60",
                                    f"-artifact_prefix={work}/", str(seeds)], cwd=work)
                print(f"fuzz {dialect}: exit {r.returncode}", flush=True)
                for art in Path(work).glob("*-*"):   # libFuzzer's crash-/timeout-/oom- artifacts
                    if art.is_file() and art.name.split("-")[0] in ("crash", "timeout", "oom"):
                        print(f"kept {keep(dialect, art.read_bytes())} ({art.name})", flush=True)
                        art.unlink()
                runs += 1
                if r.returncode == 0 or runs >= RUNS_PER_DIALECT:
                    break
                status = 1                      # a crash was kept; fuzz on from the seeds
                seconds = max(10, seconds // 2)
    print(f"kept crashes: {sorted(str(p.relative_to(ROOT)) for p in CRASHES.rglob('crash-*'))}")
    return status


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--child":
        dialect = sys.argv.pop(2)
        sys.argv.pop(1)
        fuzz(dialect)
    else:
        sys.exit(main())
