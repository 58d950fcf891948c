"""ISO turning emitter: the ISO emitter with the lathe's table and spelling.

X is written in diameter (an IR in radius, from a flattened program or Sinumerik DIAMOF, is doubled);
incremental X/Z are U/W; T<tt><oo> selects tool and offset at once (no M06); G50 sets the position
and the maximum spindle speed. Turning cycles are not written back as cycles: the conversion policy
expands them (nctrans.convert)."""
from __future__ import annotations

from nctrans.dialects.emit import NotExpressible
from nctrans.dialects.iso_m.emitter import NotConvertible
from nctrans.dialects.iso_m import emitter as iso
from nctrans.ir import nodes as n

_INC = {"X": "U", "Z": "W", "C": "H"}


def _fagor_d(s: n.ModeChange) -> int | None:
    """The register of a tool-length change spelt D<k> (Fagor's D selects length and radius)."""
    code = s.code.strip().upper()
    return int(code[1:]) if code[:1] == "D" and code[1:].isdigit() and int(code[1:]) < 100 else None


def _register(e) -> int | None:
    """A constant offset register 0..99, or None."""
    if type(e) is n.Num and e.value == int(e.value) and 0 <= e.value < 100:
        return int(e.value)
    return None


class TurningEmitter(iso.IsoEmitter):
    dialect = "iso-t"
    table_name = "iso-t"
    target_text = "ISO turning"
    lowered_for = "ISO"
    writes_edge_lengths = False     # a lathe's tool length is not applied along Z (tool_edges)
    drops_staying_turret = False    # its T word is the turret's own (T0111 says the offset)
    t_word_is_turret = True

    def __init__(self, program: n.Program):
        super().__init__(program)
        defaults = (program.meta or {}).get("defaults") or {}
        self.diameter = defaults.get("diameter") == "diameter"
        self.plane = defaults.get("plane", "ZX")
        # a source whose D belongs to the active tool (Sinumerik edge, Fagor corrector): its D1 is
        # the tool's own offset, the register of the tool number in the T word (T4 D1 -> T0404;
        # D2 of tool 4 -> T0402, register 2, as ISO T0402 reads back as T4 D2)
        from nctrans.rules import option
        self.tool_relative = bool(option(program.dialect, "offsets_of_active_tool", False))

    def w_ModeChange(self, s: n.ModeChange):
        if s.group == "diameter":
            self.diameter = s.value == "diameter"
            self.pos = {}
            return []
        if s.group == "distance":
            self.distance = s.value
            return []                   # system A: incremental words are U/W
        if s.group == "tool_length" and _fagor_d(s) is not None:
            # a Fagor D<k> (length and radius of register k) is the T word's register k
            self.pos = {}
            return self._select_register(_fagor_d(s), None)
        if s.group == "cutter_comp" and s.value != "off" and self.t_tool is None \
                and self.program.dialect != self.dialect:
            raise NotConvertible("cutter compensation with no tool known before it: ISO turning takes "
                                 "the nose radius from the offset register its T word names, and which "
                                 "tool and offset are in force here is not in the program", "G41/G42")
        if s.group == "tool_length" and s.value in ("plus", "off"):
            self.lowered("tool length offset on/off: a lathe applies the offset the T word names")
            return []
        return super().w_ModeChange(s)

    def w_SubCall(self, s: n.SubCall):
        """A call made under G91: the called blocks' axis words are incremental at run time, but
        system A writes an incremental word as U/W where it is written, and a subprogram is written
        once, from its own text (its plain X0 Y0 came out absolute: the motion changed, exit 0)."""
        if self.distance == "incremental":
            raise NotExpressible(f"a call of {s.name or 'a subprogram'} under G91 (ISO turning has no "
                                 "G91: the called program's incremental words would be written absolute)")
        return super().w_SubCall(s)

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

    # T<tool><offset> selects the tool and its one offset register at once: the tool and register
    # the T word in force wrote, and the registers the program chose for each kind of offset
    # (length H, radius D) since; None/empty where not known (before any T, after a place reached
    # from elsewhere)
    t_tool: "int | None" = None
    t_offset: "int | None" = None
    t_chosen: dict = {}
    chosen_register: "int | None" = None    # the last register an offset word of the source chose
    block_offset: "int | None" = None
    block_changes: bool = False

    def forget(self) -> None:
        super().forget()
        self.t_tool = self.t_offset = None
        self.t_chosen = {}
        self.chosen_register = None

    def _own(self, k: "int | None", tool: "int | None") -> "int | None":
        """Register k as the T word writes it: a tool-relative D1 is tool `tool`'s own offset."""
        return tool if self.tool_relative and k == 1 and tool is not None else k

    def statements(self, body) -> list[list[str]]:
        # a D in the block of its T goes into that T word (T1 D2 -> T0102; ISO T0102 stays T0102)
        self.block_offset = next((_register(s.index) for s in body if type(s) is n.OffsetSelect
                                  and _register(s.index) is not None), None)
        if self.block_offset is None:
            self.block_offset = next((_fagor_d(s) for s in body if type(s) is n.ModeChange
                                      and s.group == "tool_length" and _fagor_d(s) is not None), None)
        # the source's M6 changes the tool even to the one in place (its edge D1 comes in again);
        # a T of the tool in place that changes nothing (a turret that stays) keeps the edge
        # (where the source's T changes the tool, its M6 never changes the one in place)
        self.block_changes = not self.tool_timing.source_changes and any(
            type(s) is n.ToolChange and not s.turret for s in body)
        try:
            return super().statements(body)
        finally:
            self.block_offset = None
            self.block_changes = False

    def w_ToolSelect(self, s):
        t = s.tool
        if type(t) is n.Num and t.value == int(t.value) and 0 <= t.value < 100:
            new = int(t.value)
            if self.block_offset is None and self.tool_relative and new == self.t_tool \
                    and self.t_offset is not None and not self.block_changes:
                return []               # the turret stays: the T word in force says it all
            if self.block_offset is not None:
                self.t_offset = self._own(self.block_offset, new)
            elif self.tool_relative or self.chosen_register is None:
                self.t_offset = new     # the new tool's own (Sinumerik/Fagor: its D1 comes in)
            else:
                # an ISO mill's register (H/D) stays in force through the change (T0201 after
                # H1: a later G43 H2 writes T0202)
                self.t_offset = self.chosen_register
            self.t_tool = new
            self.t_chosen = {}
            return [("T", f"T{self.t_tool:02d}{self.t_offset:02d}")]
        self.t_tool = self.t_offset = None
        raise NotExpressible("a tool number that is not 0..99")

    def w_ToolChange(self, s):
        self.pos = {}
        return []

    def w_OffsetSelect(self, s):
        """An offset register (Sinumerik/Fagor D, ISO H or D) is the register of the T word: one
        naming another register than the T word in force is written as the tool's T word with it.
        Refused (NC402) where no T word can say it: no tool known before it, or an ISO mill's
        length register H and radius register D that differ (a lathe's T word has one register
        for both)."""
        self.pos = {}
        k = _register(s.index)
        if k is None:
            raise NotExpressible("an offset register that is not a number 0..99 (ISO turning writes it "
                                 "in the T word)")
        return self._select_register(k, s.kind)

    def _select_register(self, k: int, kind: "str | None") -> list:
        if self.t_tool is None:
            raise NotConvertible(f"offset register {k} with no tool known before it: ISO turning selects "
                                 "the register with its tool in one word (T<tool><offset>), and which "
                                 "tool is in the turret here is not in the program", f"D{k}")
        k = self._own(k, self.t_tool)
        if kind is not None:
            other_kind = "radius" if kind == "length" else "length"
            other = self.t_chosen.get(other_kind)
            if other is not None and other != k:
                raise NotConvertible(f"{kind} register {k} while the {other_kind} register {other} is in "
                                     "force: a lathe's T word has one register for both", f"D{k}")
            self.t_chosen[kind] = k
        self.chosen_register = k
        if k == self.t_offset:
            return []                   # the T word in force already carries it
        self.t_offset = k
        return [("T", f"T{self.t_tool:02d}{k:02d}")]

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

