"""Frame components a program writes that move the work coordinate system: the external zero
offset `<frame>[X,TR]=v`, where <frame> is the rules table's `external_frame_variable` (the frame
ISO G10 L2 P0 writes). It is the machine's external work offset ("EXT", as ISO #5201..), applied under every
work system at once (nctrans.interp.offsets._work_offset). A component the analysis does not model
(rotation RT, scale SC, mirror MI, or an index computed at run time) is NC107, never kept silently."""
from __future__ import annotations

from typing import Any

from nctrans.interp.evaluate import EvalError, UNKNOWN
from nctrans.interp.state import LINEAR_AXES
from nctrans.ir import nodes as n



def external_frame_variable(dialect: str) -> str:
    """The dialect's external-offset frame variable (upper case), or "" when it has none."""
    try:
        from nctrans.rules import load_table
        return str(load_table(dialect).options.get("external_frame_variable", "")).upper()
    except Exception:           # a dialect without a table of its own
        return ""


def register(interp) -> None:
    name = external_frame_variable(interp.program.dialect)
    if name:
        interp.ev.frame_component_setters[name] = lambda ix, v: _write_external(interp, name, ix, v)


def _axis_translation(name: str, indices: list) -> str:
    """The axis of `[X,TR]` written with names; EvalError for any other component."""
    if (len(indices) == 2 and all(type(i) is n.Var and i.space == "name" and not i.indices
                                  for i in indices)
            and str(indices[1].key).upper() == "TR" and str(indices[0].key).upper() in "XYZABC"
            and len(str(indices[0].key)) == 1):
        return str(indices[0].key).upper()
    raise EvalError("NC107", f"{name}[..] component other than an axis translation [X,TR] is "
                    "not analysed; the external offset is kept as it was")


def _write_external(interp, name: str, indices: list, v: Any) -> None:
    from nctrans.interp.sysvars import _machine, _value
    axis = _axis_translation(name, indices)
    value = _value(name, v) * (interp.st.scale if axis in LINEAR_AXES else 1.0)
    m = _machine(interp)
    m.offsets["EXT"] = {**m.offsets.get("EXT", {}), axis: value}
    interp._work_offset_changed("EXT")
