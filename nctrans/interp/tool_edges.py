"""Cutting edges: where a D number selects an edge of the active tool (rules table option
`edge_offsets`, Sinumerik), not an offset register.

Edge (t, d) has a length along the tool axis and a radius, plus their wear (neutral meanings
"edge_length", "edge_radius", "edge_length_wear", "edge_radius_wear"; Sinumerik $TC_DP3, $TC_DP6,
$TC_DP12, $TC_DP15 [t,d]). A program may write them; otherwise edge 1 of a tool is the machine
file's tool (length, radius) and any other edge D<d> the machine file's offset register d
(radius_offsets / length_offsets, else tool d). D0 switches length and radius off.

When they act (general knowledge of the Siemens Fundamentals manual [GK]): the edge applies its
length and radius from its selection by D, or by the tool change, which brings edge D1
(`default_cutting_edge`) unless the same block programs a D. Data written for the active edge acts
at the next D or tool change, as on the control. Length is applied along Z (the tool axis of a
3-axis mill under G17; under G18/G19 the control applies it along Y/X, which the model does not:
said at the selection); on a lathe it is not applied (said, NC220), as ISO lathe geometry offsets.
"""
from __future__ import annotations

from typing import Any

from nctrans.interp.evaluate import EvalError, FrameValue, UNKNOWN

FIELDS = {"edge_length": "length", "edge_radius": "radius",
          "edge_length_wear": "length_wear", "edge_radius_wear": "radius_wear"}


def register(interp) -> None:
    """Edge data for a dialect whose table sets `edge_offsets`."""
    try:
        from nctrans.rules import load_table
        t = load_table(interp.program.dialect)
    except Exception:           # a dialect without a table of its own
        return
    if not t.options.get("edge_offsets"):
        return
    edges = ToolEdges(interp)
    interp.edges = edges
    for spelling, meaning in t.system_variables.items():
        field = FIELDS.get(meaning)
        if field is not None:
            interp.ev.system_writers[spelling.upper()] = (
                lambda key, v, f=field, s=spelling.upper(): edges.write(s, f, key, v))
            interp.ev.indexed_system[spelling.upper()] = (
                lambda key, f=field, s=spelling.upper(): edges.read(s, f, key))


class ToolEdges:
    """Edge data of one run (mm) and the selection of the active edge."""

    def __init__(self, interp) -> None:
        self.it = interp
        self.data: dict[tuple[int, int], dict[str, float]] = {}
        self.d_span = None              # the block whose D word selected the active edge

    def _value(self, t: int, d: int, field: str) -> float:
        own = self.data.get((t, d), {})
        if field in own:
            return own[field]
        if field.endswith("_wear"):
            return 0.0
        m = self.it.machine
        registers = m.length_offsets if field == "length" else m.radius_offsets
        if d in registers:          # a flat D number's data ($TC_DP3[d], nctrans.interp.edge_data)
            return float(registers[d])
        tool = m.tool(t) if t else None
        if d == 1 and tool is not None:
            return float(getattr(tool, field) or 0.0)
        # no data of its own: the machine file's offset register of the D number (radius_offsets /
        # length_offsets, else tool d), as every D read before edges were modelled; conversions
        # between ISO offset numbers and D numbers rely on it (ISO T0102 -> T1 D2)
        return float(m.length_offset(d) if field == "length" else m.radius_offset(d))

    def length(self, t: int, d: int) -> float:
        return self._value(t, d, "length") + self._value(t, d, "length_wear")

    def radius(self, t: int, d: int) -> float:
        return self._value(t, d, "radius") + self._value(t, d, "radius_wear")

    # -------------------------------------------------------------- selection
    def active(self) -> tuple[int, int]:
        st = self.it.st
        return int(st.tool or 0), int(st.radius_index or 0)

    def select(self, d: int) -> None:
        """D word: edge d of the active tool gives length and radius (D0: none)."""
        it = self.it
        it.st.radius_index = d
        self.d_span = it.span
        self._apply()

    def tool_changed(self) -> None:
        """A tool change brings the default edge unless this block programs a D."""
        it = self.it
        if self.d_span is not it.span or it.span is None:
            it.st.radius_index = it.default_edge
        self._apply()

    def _apply(self) -> None:
        it = self.it
        t, d = self.active()
        it.comp_radius = self.radius(t, d) if d else 0.0      # a flat D number needs no tool
        it._apply_length()

    def active_length(self) -> float:
        t, d = self.active()
        z = self.length(t, d) if d else 0.0
        if z and getattr(self.it.machine, "kind", "mill") == "lathe":
            # a turning tool's lengths act in X and Z by its type (not modelled, as ISO lathe
            # geometry offsets): the tip path is analysed as programmed
            self.it.diag("NC220", "warning", f"tool length {z:g} mm of a lathe tool is not modelled: "
                         "the analysed toolpath is the programmed tip path")
            return 0.0
        if z and self.it.st.plane != "XY":
            self.it.diag("NC220", "warning", f"tool length {z:g} mm under plane {self.it.st.plane}: "
                         "the control applies it along the axis normal to the plane, the analysis "
                         "along Z")
        return z

    # -------------------------------------------------------------- data
    def _key(self, name: str, key: tuple) -> tuple[int, int]:
        if len(key) != 2 or not all(isinstance(k, int) for k in key):
            raise EvalError("NC104", f"{name}[tool, edge]: two numbers")
        return key[0], key[1]

    def read(self, name: str, field: str, key: tuple) -> Any:
        t, d = self._key(name, key)
        return self._value(t, d, field) / self.it.st.scale

    def write(self, name: str, field: str, key: tuple, v: Any) -> None:
        t, d = self._key(name, key)
        if v is UNKNOWN:
            raise EvalError("NC107", f"{name}[{t},{d}] is written with a value the analysis cannot "
                            "know: the edge keeps its old value", "warning")
        if isinstance(v, (str, FrameValue)):
            raise EvalError("NC104", f"{name} needs a number")
        self.data.setdefault((t, d), {})[field] = (0.0 if v is None else float(v)) * self.it.st.scale
