"""What the cycle agreement tests share (issue 8, "Done when"): a program runs twice, once with the
built-in cycle models and once with cycle code (PROC files written in the Sinumerik language) beside
it, and the two record lists must agree move for move."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Callable

PROCS = Path(__file__).parent / "data" / "cycle-procs"

Records = Callable[[Path, str], tuple[list, list]]


def num(v) -> str:
    """A cycle argument as written in a call: left out (empty) for None."""
    return "" if v is None else f"{v:g}"


def close(a, b, tol: float = 1e-6) -> bool:
    """Records (nested tuples) equal, floats within `tol`."""
    if isinstance(a, float) or isinstance(b, float):
        return a is not None and b is not None and math.isclose(a, b, abs_tol=tol)
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(close(x, y, tol) for x, y in zip(a, b))
    return a == b


def procs(*names: str) -> dict[str, str]:
    """{file name: text} of PROC files under tests/data/cycle-procs (all of them when no name)."""
    files = [PROCS / f"{name}.SPF" for name in names] if names else sorted(PROCS.glob("*.SPF"))
    return {f.name: f.read_text() for f in files}


def both_runs(tmp_path: Path, text: str, code: dict[str, str], records: Records):
    """((records, bad diagnostics) with the built-in models, the same with `code` beside the program)."""
    runs = []
    for how, files in (("builtin", {}), ("code", code)):
        d = tmp_path / how
        d.mkdir(exist_ok=True)
        for name, body in files.items():
            (d / name).write_text(body)
        recs, bad = records(d, text)
        # NC419: a turning model's 1 mm default taken in an inch program (its unit there is not
        # documented); the PROCs here take the same 1 mm, so it is expected, not a disagreement
        runs.append((recs, [b for b in bad if "[NC419]" not in str(b)]))
    return runs[0], runs[1]


def assert_same(got: list, want: list, tol: float = 1e-6, *context: object) -> None:
    """The two record lists agree; the message shows where they part."""
    first = next((i for i, (g, w) in enumerate(zip(got, want)) if not close(g, w, tol)), None)
    assert first is None and len(got) == len(want), (*context, first, got[first or 0:][:3],
                                                     want[first or 0:][:3], len(got), len(want))


def agree(tmp_path: Path, text: str, code: dict[str, str], records: Records, tol: float = 1e-6) -> list:
    """Both runs clean (no error or warning) and the same records: the built-in run's records."""
    (want, bad_builtin), (got, bad_code) = both_runs(tmp_path, text, code, records)
    assert bad_builtin == [] and bad_code == [], (bad_builtin, bad_code)
    assert_same(got, want, tol)
    return want
