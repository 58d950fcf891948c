"""Frames a program writes as data: the external zero offset and the settable frames.

- The external zero offset `<frame>[X,TR]=v`, where <frame> is the rules table's
  `external_frame_variable` (the frame ISO G10 L2 P0 writes). It is the machine's external work offset
  ("EXT", as ISO #5201..), applied under every work system at once (nctrans.interp.offsets._work_offset).
  A component other than a translation (or an index computed at run time) is NC107.
- The settable frames (neutral meaning "settable_frame_data", Sinumerik $P_UIFR[n]): frame n is the
  work offset the table's `settable_frame_offsets` names (G500, G54..G57, then the extended offsets
  from `settable_frame_extended_from` on). Written whole (`$P_UIFR[1]=CTRANS(X,10):CROT(Z,30)`) or by
  component (`$P_UIFR[1,X,TR]=10`, components TR FI RT SC MI). Its translation TR (+ fine FI) is the
  machine's work offset of that name; rotation, scale and mirror are kept here. Writing the data
  activates nothing: the next selection of the work offset does (spec 7.4: "writing $P_UIFR[n] does not
  activate; the next G500/G54..G599 does").
- The active settable frame ("settable_frame", $P_IFRAME): read, written whole or by component, it
  acts at once. Its translation is the active work offset; rotation R (RPY: Rz(c)·Ry(b)·Rx(a)),
  scale S and mirror Mi act as x_parent = TR + R·S·Mi·x about the work origin, after the
  programmable frame (ProgrammableFrame.settable holds R·S·Mi).
- The number of the active settable frame ("settable_frame_number", $P_UIFRNUM).
"""
from __future__ import annotations

from typing import Any, Optional

from nctrans.interp.evaluate import EvalError, FrameValue, UNKNOWN
from nctrans.interp.frames import IDENT, RPY_ORDER, Matrix, compose, mat_mul, rotation, rpy_ordered
from nctrans.interp.state import LINEAR_AXES
from nctrans.ir import nodes as n

COMPONENTS = ("TR", "FI", "RT", "SC", "MI")
GEOMETRY = ("X", "Y", "Z")


def _table(dialect: str):
    try:
        from nctrans.rules import load_table
        return load_table(dialect)
    except Exception:           # a dialect without a table of its own
        return None


def external_frame_variable(dialect: str) -> str:
    """The dialect's external-offset frame variable (upper case), or "" when it has none."""
    t = _table(dialect)
    return str(t.options.get("external_frame_variable", "")).upper() if t is not None else ""


def register(interp) -> None:
    name = external_frame_variable(interp.program.dialect)
    if name:
        interp.ev.frame_component_setters[name] = lambda ix, v: _write_external(interp, name, ix, v)
    t = _table(interp.program.dialect)
    if t is None or not t.options.get("settable_frame_offsets"):
        return
    store = SettableFrames(interp, list(t.options["settable_frame_offsets"]),
                           int(t.options.get("settable_frame_extended_from", 0) or 0))
    interp.settable = store
    ev = interp.ev
    for spelling, meaning in t.system_variables.items():
        key = spelling.upper()
        if meaning == "settable_frame_data":
            ev.system_writers[key] = store.write_data
            ev.indexed_system[key] = store.read_data
        elif meaning == "settable_frame":
            ev.system_writers[key] = store.write_active
            ev.indexed_system[key] = store.read_active_component
    ev.meanings["settable_frame"] = store.active_value
    ev.meaning_setters["settable_frame"] = lambda v: store.write_active((), v)
    ev.meanings["settable_frame_number"] = store.active_number


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


# ------------------------------------------------------------------------------ frame algebra

def linear_part(comps: dict) -> Optional[Matrix]:
    """R·S·Mi of a settable frame's components (None when it is the identity)."""
    m: Matrix = IDENT
    rt = comps.get("RT", {})
    for a in RPY_ORDER:
        if rt.get(a):
            m = mat_mul(m, rotation(a, rt[a]))
    sc, mi = comps.get("SC", {}), comps.get("MI", {})
    diag = [1.0, 1.0, 1.0]
    for i, a in enumerate(GEOMETRY):
        diag[i] = float(sc.get(a, 1.0)) * (-1.0 if mi.get(a) else 1.0)
    if diag != [1.0, 1.0, 1.0]:
        m = mat_mul(m, ((diag[0], 0.0, 0.0), (0.0, diag[1], 0.0), (0.0, 0.0, diag[2])))
    return None if m == IDENT else m


def decompose(value: Any, what: str) -> tuple[dict[str, float], dict]:
    """A FRAME value -> (translation per axis in mm of the parent system, components RT SC MI).
    The translation is that of the whole chain (CROT(Z,90):CTRANS(X,10) translates by (0, 10));
    rotations about one axis add, scales multiply, mirrors toggle."""
    if value is UNKNOWN:
        raise EvalError("NC107", f"{what} is assigned a value unknown at analysis time; the "
                        "frame is kept as it was", "warning")
    if not isinstance(value, FrameValue):
        raise EvalError("NC104", f"{what} needs a frame value (a frame expression or variable)")
    aff = (IDENT, (0.0, 0.0, 0.0))
    other: dict[str, float] = {}
    comps: dict[str, dict[str, float]] = {"RT": {}, "SC": {}, "MI": {}}
    for op, vals in value.steps:
        if op == "state":
            raise EvalError("NC237", f"{what} assigned the programmable frame: not modelled, the "
                            "frame is kept as it was", "warning")
        vals = tuple(vals)
        if op == "trans":
            t = tuple(dict(vals).get(a, 0.0) for a in GEOMETRY)
            aff = compose(aff, (IDENT, t))
            for a, v in vals:
                if a not in GEOMETRY:
                    other[a] = other.get(a, 0.0) + v
        elif op == "rot":
            for a, v in rpy_ordered(vals):
                if a not in GEOMETRY:
                    raise EvalError("NC104", f"{what}: rotation about {a}, not a geometry axis")
                aff = compose(aff, (rotation(a, v), (0.0, 0.0, 0.0)))
                comps["RT"][a] = comps["RT"].get(a, 0.0) + v
        elif op == "scale":
            for a, v in vals:
                comps["SC"][a] = comps["SC"].get(a, 1.0) * v
        elif op == "mirror":
            for a, _ in vals:
                comps["MI"][a] = 0.0 if comps["MI"].get(a) else 1.0
    if sum(1 for v in comps["RT"].values() if v) > 1:
        raise EvalError("NC237", f"{what}: rotation about more than one axis in a frame chain is "
                        "not modelled; the frame is kept as it was", "warning")
    trans = {a: aff[1][i] for i, a in enumerate(GEOMETRY) if aff[1][i]}
    trans.update(other)
    return trans, comps


def frame_value(trans: dict[str, float], comps: dict) -> FrameValue:
    """Components -> a FRAME value (steps in the frame's own order: TR, RT, SC, MI)."""
    steps: list = []
    if any(trans.values()):
        steps.append(("trans", tuple((a, v) for a, v in trans.items() if v)))
    rt = comps.get("RT", {})
    if any(rt.get(a) for a in RPY_ORDER):
        steps.append(("rot", tuple((a, rt[a]) for a in RPY_ORDER if rt.get(a))))
    sc = {a: v for a, v in comps.get("SC", {}).items() if v != 1.0}
    if sc:
        steps.append(("scale", tuple(sc.items())))
    mi = [a for a, v in comps.get("MI", {}).items() if v]
    if mi:
        steps.append(("mirror", tuple((a, 0.0) for a in mi)))
    return FrameValue(tuple(steps))


class SettableFrames:
    """The settable frames' data and the active settable frame of one interpreter run."""

    def __init__(self, interp, names: list[str], extended_from: int) -> None:
        self.it = interp
        self.names = [str(x).upper() for x in names]
        self.extended_from = extended_from
        self.comps: dict[int, dict] = {}          # index -> {"FI"|"RT"|"SC"|"MI": {axis: v}}
        self.active_comps: dict = {}             # of the active settable frame

    # -------------------------------------------------------------- names and numbers
    def offset_name(self, index: int) -> str:
        if 0 <= index < len(self.names):
            return self.names[index]
        if self.extended_from and index >= self.extended_from:
            return f"G54.1P{index - self.extended_from + 1}"
        raise EvalError("NC105", f"settable frame {index} does not exist")

    def index_of(self, offset: Optional[str]) -> Optional[int]:
        up = (offset or "").upper()
        if up in self.names:
            return self.names.index(up)
        if up.startswith("G54.1P") and self.extended_from:
            try:
                return self.extended_from + int(up[len("G54.1P"):]) - 1
            except ValueError:
                return None
        return None

    def active_number(self) -> Any:
        i = self.index_of(self.it.st.work_offset)
        return float(i) if i is not None else UNKNOWN

    # -------------------------------------------------------------- helpers
    def _lin(self, axis: str) -> float:
        return self.it.st.scale if axis in LINEAR_AXES else 1.0

    def _number(self, v: Any, what: str) -> float:
        if v is UNKNOWN:
            raise EvalError("NC107", f"{what} is written with a value the analysis cannot know: "
                            "the frame keeps its old value", "warning")
        if v is None:
            return 0.0
        if isinstance(v, (str, FrameValue)):
            raise EvalError("NC104", f"{what} needs a number")
        return float(v)

    def _set_component(self, trans: dict, comps: dict, axis: str, comp: str, value: float) -> bool:
        """One component write into (translation per axis, components): TR replaces the coarse
        translation and FI the fine one (the axis's translation is coarse + fine); RT, SC and MI
        are kept as components. True when the translation changed."""
        if comp not in ("TR", "FI"):
            comps.setdefault(comp, {})[axis] = value
            return False
        fine = comps.setdefault("FI", {})
        coarse = trans.get(axis, 0.0) - fine.get(axis, 0.0) * self._lin(axis)
        if comp == "TR":
            coarse = value * self._lin(axis)
        else:
            fine[axis] = value
        trans[axis] = coarse + fine.get(axis, 0.0) * self._lin(axis)
        return True

    def _split(self, key: tuple, what: str) -> tuple[str, str]:
        if len(key) != 2 or not all(isinstance(k, str) for k in key) or key[1] not in COMPONENTS:
            raise EvalError("NC104", f"{what}[..]: a component is [axis, TR|FI|RT|SC|MI]")
        axis, comp = key
        if comp == "RT" and axis not in GEOMETRY:
            raise EvalError("NC104", f"{what}[{axis},RT]: only geometry axes rotate")
        return axis, comp

    def _translation(self, index: int) -> dict[str, float]:
        """TR + FI of frame `index` in mm (the machine's work offset of its name)."""
        name = self.offset_name(index)
        return dict(self.it.machine.work_offset(name)) if name != "G53" else dict(
            self.it.machine.offsets.get("G53", {}))

    # -------------------------------------------------------------- data: $P_UIFR
    def read_data(self, key: tuple) -> Any:
        index = self._index(key[0] if key else None)
        comps = self.comps.get(index, {})
        trans = self._translation(index)
        if len(key) == 1:
            return frame_value({a: v / self._lin(a) for a, v in trans.items()}, comps)
        axis, comp = self._split(key[1:], "settable frame")
        return self._component(trans, comps, axis, comp)

    def _component(self, trans: dict, comps: dict, axis: str, comp: str) -> float:
        if comp == "TR":
            return (trans.get(axis, 0.0) / self._lin(axis)) - comps.get("FI", {}).get(axis, 0.0)
        default = 1.0 if comp == "SC" else 0.0
        return float(comps.get(comp, {}).get(axis, default))

    def _index(self, v: Any) -> int:
        if not isinstance(v, int):
            raise EvalError("NC104", "settable frame number is not a number")
        self.offset_name(v)          # NC105 past the frames
        return v

    def write_data(self, key: tuple, v: Any) -> None:
        """$P_UIFR[n]=frame or $P_UIFR[n,axis,comp]=value: data only, active at the next selection."""
        from nctrans.interp.sysvars import _machine
        index = self._index(key[0] if key else None)
        name = self.offset_name(index)
        m = _machine(self.it)
        if len(key) == 1:
            trans, comps = decompose(v, f"settable frame {index}")
            m.offsets[name] = {a: t * self._lin(a) for a, t in trans.items()}
            self.comps[index] = comps
        else:
            axis, comp = self._split(key[1:], "settable frame")
            value = self._number(v, f"settable frame {index} [{axis},{comp}]")
            comps = self.comps.setdefault(index, {})
            cur = dict(m.offsets.get(name, {}))
            if self._set_component(cur, comps, axis, comp, value):
                m.offsets[name] = cur
        if name == "G53" and (any(m.offsets.get(name, {}).values())
                              or linear_part(self.comps.get(index, {})) is not None):
            raise EvalError("NC237", "settable frame 0 (G500) written with a non-zero value: not "
                            "modelled, G500 stays the zero frame", "warning")

    # -------------------------------------------------------------- the active one: $P_IFRAME
    def selected(self, offset: Optional[str]) -> None:
        """G500/G54..: the settable frame `offset` becomes active (its translation is the work
        offset the interpreter just set; its rotation, scale and mirror go into the frame)."""
        index = self.index_of(offset)
        self.active_comps = {k: dict(v) for k, v in self.comps.get(index, {}).items()} \
            if index is not None else {}
        self.it.frame.set_settable(linear_part(self.active_comps))
        self.it._resync()

    def _active_translation(self) -> dict[str, float]:
        ext = self.it.machine.work_offset("EXT")
        return {a: v - ext.get(a, 0.0) for a, v in self.it.off.work.items()}

    def active_value(self) -> Any:
        trans = self._active_translation()
        return frame_value({a: v / self._lin(a) for a, v in trans.items()}, self.active_comps)

    def read_active_component(self, key: tuple) -> Any:
        axis, comp = self._split(key, "active settable frame")
        return self._component(self._active_translation(), self.active_comps, axis, comp)

    def write_active(self, key: tuple, v: Any) -> None:
        """$P_IFRAME=frame or $P_IFRAME[axis,comp]=value: acts at once (spec 7.4)."""
        trans = self._active_translation()
        if not key:
            t, comps = decompose(v, "active settable frame")
            trans = {a: x * (self.it.st.scale if a in LINEAR_AXES else 1.0) for a, x in t.items()}
            self.active_comps = comps
        else:
            axis, comp = self._split(key, "active settable frame")
            value = self._number(v, f"active settable frame [{axis},{comp}]")
            self._set_component(trans, self.active_comps, axis, comp, value)
        ext = self.it.machine.work_offset("EXT")
        self.it.off.set_work({a: trans.get(a, 0.0) + ext.get(a, 0.0) for a in {**trans, **ext}})
        self.it.frame.set_settable(linear_part(self.active_comps))
        self.it._resync()
