"""Every ISO milling corpus program against LinuxCNC's rs274: the project's correctness judge.

Each program in corpus/iso-mill runs through rs274 and through nctrans (iso-m front end +
interpreter). Programs rs274 runs to PROGRAM_END are compared; the rest are skipped with rs274's own
error (LinuxCNC rejects Fanuc macros, subprogram calls and the like), and a separate test insists at
least MIN_REFERENCE programs complete, so a broken rs274 set-up cannot pass by skipping everything.

Two set-ups: "zero" (the built-in mill, every tool of zero size) and "geometry"
(tests/data/rs274-geometry-machine.toml: nonzero length and radius for tools 1..99, so G43 and
G41/G42 are compared too). The rs274 tool table is written from the same machine model.

What is compared: the ordered sequence of rapid/linear/arc records, in machine mm.
- end point (and start point) on every axis; arcs also plane, direction, extra full turns and the
  centre's two in-plane coordinates.
- Tolerance: 1 µm, or the rounding rs274's 4-decimal output allows if that is larger: half a printed
  digit of the point plus half a digit of each nonzero printed offset, in the units they were printed
  in. For an inch program without offsets that is 0.00005 in = 1.27 µm.
- Zero-length rapid/linear moves (every axis within 1e-6 mm of the start) are dropped on BOTH sides
  before pairing: rs274 emits them for repeated positions and cutter-comp bookkeeping, and whether an
  interpreter emits a no-op move is not behaviour. Arcs are never dropped (equal ends = full circle).
On a mismatch the failure shows the first differing pair: rs274's output line (sequence number,
N word, canonical call) and the nctrans record's file:line, plus the last pair that agreed.

KNOWN_DIFFERENCES lists cases where nctrans deliberately follows the ISO/Fanuc specification
(shared/specs/iso.md) where LinuxCNC behaves otherwise; each entry is a strict xfail carrying the
spec reference, so it turns into a failure once the behaviours agree. Keep it small and honest.
"""
from __future__ import annotations

from pathlib import Path

import pytest

import rs274 as h
from conftest import CORPUS, DATA

ISO_MILL = CORPUS / "iso-mill"
PROGRAMS = sorted(p for p in ISO_MILL.iterdir() if p.is_file()) if ISO_MILL.is_dir() else []
SETUPS = ("zero", "geometry")
GEOMETRY_MACHINE = DATA / "rs274-geometry-machine.toml"
MIN_REFERENCE = 10
MOTION_KINDS = ("rapid", "linear", "arc")

# (setup, file name) -> why nctrans differs from rs274 on purpose, with the iso.md line reference.
KNOWN_DIFFERENCES: dict[tuple[str, str], str] = {}


def _machine(setup: str):
    from nctrans.machine import default_mill, load
    return default_mill() if setup == "zero" else load(GEOMETRY_MACHINE)


def _tool_table(setup: str, where: Path) -> Path:
    path = where / f"{setup}.tbl"
    if not path.exists():
        if setup == "zero":
            tools = [(n, 0.0, 0.0) for n in range(1, 100)]
        else:
            tools = [(t.number, t.length, t.radius) for t in _machine(setup).tools]
        h.write_tool_table(path, tools)
    return path


@pytest.fixture(scope="session")
def reference(rs274, rs274_cache):
    """reference(setup, program) -> rs274 Run, each computed once per session."""
    def run(setup: str, program: Path) -> h.Run:
        return h.run_rs274(program, _tool_table(setup, rs274_cache),
                           rs274_cache / f"{setup}--{program.name}.out")
    return run


def _read(program: Path) -> str:
    from nctrans import source
    return source.decode(program.read_bytes(), program.name).text


def nctrans_motions(program: Path, setup: str) -> tuple[list[h.Motion], list]:
    """Parse and interpret with nctrans; the motion records plus every diagnostic (for the report)."""
    from nctrans.dialects.base import get
    from nctrans.interp import interpret
    result = get("iso-m").parse(_read(program), program.name)
    diagnostics = list(result.diagnostics)
    records = interpret(result.program, _machine(setup), diagnostics=diagnostics)
    motions = [h.Motion.of(r) for r in records if r.kind in MOTION_KINDS]
    return motions, diagnostics


def _params():
    out = []
    for setup in SETUPS:
        for p in PROGRAMS:
            reason = KNOWN_DIFFERENCES.get((setup, p.name))
            marks = [pytest.mark.xfail(reason=reason, strict=True)] if reason else []
            out.append(pytest.param(setup, p, marks=marks, id=f"{setup}-{p.name}"))
    return out


@pytest.mark.rs274
@pytest.mark.parametrize("setup", SETUPS)
def test_reference_completes_enough_programs(setup, reference, corpus_dir):
    done = [p.name for p in PROGRAMS if reference(setup, p).completed]
    print(f"\nrs274 ({setup} tools) runs {len(done)}/{len(PROGRAMS)} iso-mill programs to PROGRAM_END: "
          + ", ".join(done))
    assert len(done) >= MIN_REFERENCE, f"only {len(done)} programs complete in rs274: {done}"


@pytest.mark.rs274
@pytest.mark.parametrize("setup,program", _params())
def test_toolpath_matches_rs274(setup, program, reference):
    ref = reference(setup, program)
    if not ref.completed:
        pytest.skip(f"rs274 stops before PROGRAM_END: {ref.message.splitlines()[0] if ref.message else '?'}")
    if not ref.moves:
        pytest.skip("rs274 runs the program without any motion: nothing to compare")
    motions, diagnostics = nctrans_motions(program, setup)
    problem = h.compare(ref.moves, motions, f"{program.name} [{setup} tools]")
    if problem:
        errors = [f"  {d.rule} {d.severity} {d.file}:{d.line}: {d.message}"
                  for d in diagnostics if d.severity == "error"][:5]
        if errors:
            problem += "\n  nctrans errors:\n" + "\n".join(errors)
    assert problem is None, problem
