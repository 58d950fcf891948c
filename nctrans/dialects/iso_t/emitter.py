"""ISO turning emitter: the ISO emitter with the lathe's table and spelling.

X is written in diameter (an IR in radius, from a flattened program or Sinumerik DIAMOF, is doubled);
incremental X/Z are U/W; T<tt><oo> selects tool and offset at once (no M06); G50 sets the position
and the maximum spindle speed. Turning cycles are not written back as cycles: the conversion policy
expands them (nctrans.convert)."""
from __future__ import annotations

from nctrans.dialects.emit import NotExpressible
from nctrans.dialects.iso_m import emitter as iso
from nctrans.ir import nodes as n

_INC = {"X": "U", "Z": "W", "C": "H"}


class TurningEmitter(iso.IsoEmitter):
    dialect = "iso-t"
    table_name = "iso-t"
    target_text = "ISO turning"
    lowered_for = "ISO"
    writes_edge_lengths = False     # a lathe's tool length is not applied along Z (tool_edges)

    def __init__(self, program: n.Program):
        super().__init__(program)
        defaults = (program.meta or {}).get("defaults") or {}
        self.diameter = defaults.get("diameter") == "diameter"
        self.plane = defaults.get("plane", "ZX")

    def w_ModeChange(self, s: n.ModeChange):
        if s.group == "diameter":
            self.diameter = s.value == "diameter"
            self.pos = {}
            return []
        if s.group == "distance":
            self.distance = s.value
            return []                   # system A: incremental words are U/W
        if s.group == "tool_length" and s.value in ("plus", "off"):
            self.lowered("tool length offset on/off: a lathe applies the offset the T word names")
            return []
        return super().w_ModeChange(s)

    def _axes(self, target: dict) -> list:
        words = []
        for k, av in target.items():
            if k not in iso.AXES or len(k) != 1:
                # a machine's own axis name (XV, C1): which ISO letter drives it is the machine's
                raise iso.NotConvertible(f"the axis {k} (ISO axes are the letters {iso.AXES})", f"axis {k}")
            value = av.value
            if k == "X" and not self.diameter:
                value = n.Num(2 * value.value) if type(value) is n.Num else n.Binary("*", value, n.Num(2.0))
            inc = av.mode == "inc" or (av.mode is None and self.distance == "incremental")
            if inc and k not in _INC:
                # system A has no G91: only X, Z and C have incremental addresses (U, W, H)
                raise NotExpressible(f"an incremental {k} (ISO turning has incremental addresses "
                                     f"U, W, H for X, Z, C only)")
            letter = _INC.get(k, k) if inc else k
            if av.mode not in (None, "inc", "abs"):
                raise NotExpressible(f"per-word {av.mode} coordinate on {k}")
            words.append((letter, self.addr(letter, value)))
        return words

    def _cip(self, s: n.Motion):
        """The mill's three-point arc, computed in the IR's units: X is a radius there unless the
        program is in diameter mode, and the X word of a lathe is a diameter (I stays a radius)."""
        words = super()._cip(s)
        if self.diameter:
            return words
        return [(k, "X" + iso.format_number(2 * float(w[1:]), True)) if k == "X" else (k, w)
                for k, w in words]

    def w_ToolSelect(self, s):
        t = s.tool
        if type(t) is n.Num and t.value == int(t.value) and 0 <= t.value < 100:
            return [("T", f"T{int(t.value):02d}{int(t.value):02d}")]
        raise NotExpressible("a tool number that is not 0..99")

    def w_ToolChange(self, s):
        self.pos = {}
        return []

    def w_OffsetSelect(self, s):
        self.pos = {}
        return []                       # the T word carries the offset

    def w_SetPosition(self, s):
        self.pos = {}
        return [self.code_word("nonmodal", "coordinate_setting")] + self._axes(s.target)

    def w_HomeReturn(self, s):
        """G28 U0 W0: an incremental via point is written with U/W (system A has no G91); a
        zero incremental Y (a mill's G74 X1=0 Y1=0 Z1=0) names no lathe axis and is left out."""
        self.pos = {}
        via = {k: av for k, av in s.via.items()
               if not (k == "Y" and av.mode == "inc" and type(av.value) is n.Num and av.value.value == 0)}
        if any(k not in _INC and av.mode == "inc" for k, av in via.items()):
            raise NotExpressible("an incremental reference-point via point on an axis without "
                                     "an incremental address")
        return [self.code_word("nonmodal", "home" if s.ref == 1 else "home2")] + self._ref_index(s) + self._axes(via)

    def w_SpindleLimit(self, s):
        return [self.code_word("nonmodal", "coordinate_setting"), ("S", self.addr("S", s.value))]

