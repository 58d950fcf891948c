"""Cutting-edge offset data a program writes and reads by flat D number: Sinumerik `$TC_DP3[d]`
(geometry length 1) and `$TC_DP6[d]` (geometry radius), the one-index form of the "flat D number
structure" (spec sinumerik.md 8.4: flat D numbers use `$TC_DPx[d]`; seed L13488: D numbers not
assigned to tools). The machine model keeps offsets by flat number as ISO H/D does
(machine.length_offsets / radius_offsets), so a write here changes the same register an ISO
`#2001=` / `G10 L10 P1` writes, and the moves after it use the new value.

The rules table names the variables (`[options.flat_edge_data]`: spelling -> "length" / "radius").
A write whose index is not known to the analysis is NC107 and leaves the offset as it was. The
two-index form `$TC_DPx[t,d]` (tool and edge) is not handled here.
"""
from __future__ import annotations

from typing import Any

from nctrans.interp.evaluate import EvalError, UNKNOWN


def flat_edge_variables(dialect: str) -> dict[str, str]:
    """Spelling (upper case) -> "length" / "radius" from the dialect's rules table."""
    from nctrans.rules import option
    found = option(dialect, "flat_edge_data", {})
    return {str(k).upper(): str(v) for k, v in found.items() if v in ("length", "radius")}


def register(interp) -> None:
    for name, kind in flat_edge_variables(interp.program.dialect).items():
        before = interp.ev.indexed_system.get(name)
        interp.ev.indexed_system[name] = (
            lambda idx, kind=kind, before=before: _read(interp, kind, idx, before))
        edges = interp.ev.system_writers.get(name)
        if edges is not None:       # nctrans.interp.tool_edges writes the [tool, edge] form
            interp.ev.system_writers[name] = (
                lambda key, v, name=name, kind=kind, edges=edges:
                _write_flat(interp, name, kind, key[0], v) if len(key) == 1 else edges(key, v))
            continue
        interp.ev.frame_component_setters[name] = (
            lambda ix, v, name=name, kind=kind: _write(interp, name, kind, ix, v))


def _read(interp, kind: str, idx: tuple, before) -> Any:
    if len(idx) != 1:
        return before(idx) if before is not None else UNKNOWN
    number = int(idx[0])
    m = interp.machine
    value = m.length_offset(number) if kind == "length" else m.radius_offset(number)
    return value / _unit(interp)


def _write(interp, name: str, kind: str, indices: list, v: Any) -> None:
    if len(indices) != 1:
        interp.ev.system[name] = lambda: v      # tool and edge: kept as before (not analysed here)
        return
    _write_flat(interp, name, kind, interp.ev.compile(indices[0])(), v)


def _write_flat(interp, name: str, kind: str, got: Any, v: Any) -> None:
    from nctrans.interp.sysvars import _machine, _value
    if got is None or got is UNKNOWN or isinstance(got, str) or got != int(got) or got < 1:
        raise EvalError("NC107", f"{name}[..]: the D number is not known to the analysis; the "
                        "offset is kept as it was", "warning")
    value = _value(name, v) * _unit(interp)
    m = _machine(interp)
    store = m.length_offsets if kind == "length" else m.radius_offsets
    store[int(got)] = value      # read when a D selects it, as the ISO registers are


def _unit(interp) -> float:
    """mm per unit of the value: system variables are read and written in inch under G700 only
    (G70 converts geometry, not system data; seed: G700 "also feeds and system variables"); the
    interpreter's feed scale is exactly that."""
    return interp.st.feed_scale
