"""ISO milling front end: source text -> IR Program.

Per line: pre-lexer (prelex.py: comments, cleaning) -> word list (fastpath.py for plain blocks,
the lark grammar of record otherwise; words.py) -> lowering (this module) -> IR nodes, then the
structure pass nests WHILE/DO..END bodies and files O-subprograms under Program.subprograms.

The lowering looks every G/M code up in its dialect's rules table (rules/iso-m.toml for ISO
milling) and dispatches on its (group, value) through small handler tables, so every dialect of the
ISO family (nctrans.dialects.iso_m.IsoFamily) shares it: a subclass of `Lowering` with its own
`dialect` and `table` names, and handlers overridden where the family members differ; the context-dependent addresses (R P Q K L I J K) get their meaning
from the static modal state tracked in source order (canned-cycle mode, motion mode), as a Fanuc
block classifier does (spec §2.5 step 3). Statements are ordered as rs274ngc executes them.
"""
from __future__ import annotations

import gc
import re
from operator import itemgetter
from typing import Any, Optional

from nctrans import limits, plainrun
from nctrans.diagnostics import Diagnostic, DiagnosticList
from nctrans.ir.nodes import (
    Alarm, Assign, AxisValue, Binary, Block, CycleParams, DataSetting, Dwell, Feed, FrameOp, Goto,
    HomeReturn, If, Loop, Message, ModalCallOff, ModeChange, Motion, Num, OffsetSelect, Passthrough,
    Program, ProgramEnd, ResetSetPosition, Return, SetPosition, Span, SpindleSpeed, Stop,
    Str, SubCall, Subprogram, ToolChange, ToolSelect, TravelLimit, Var, While,
)
from nctrans.rules import CodeRule, load_table, normalise_code

from .fastpath import PLAIN, WORD
from .prelex import clean, strip_comments

DIALECT = "iso-m"
AXES = "XYZABCUVW"
AXIS_SET = frozenset(AXES)
# Plain lines in a row before the streamed parse hands them over as one PlainRun.
PLAIN_RUN_MIN = 2
# Motion modes a plain block may select (their order is the kernel's MOTION_* codes).
PLAIN_MOTIONS = plainrun.MOTIONS
CENTER_LETTERS = frozenset("IJK")

# rs274ngc order of execution (the interpreter runs Block.body as listed).
(B_ASSIGN, B_FEEDMODE, B_FEED, B_SPMODE, B_SPEED, B_TOOL, B_M6, B_SPINDLE, B_COOLANT, B_DWELL,
 B_PLANE, B_UNITS, B_COMP, B_TLC, B_WCS, B_PATH, B_DIST, B_RETRACT, B_NONMODAL, B_MOTION,
 B_END) = range(21)

# Bucket of every plain modal group (a ModeChange and nothing else).
SIMPLE_GROUPS = {
    "feed_mode": B_FEEDMODE, "spindle_mode": B_SPMODE, "spindle": B_SPINDLE, "coolant": B_COOLANT,
    "plane": B_PLANE, "units": B_UNITS, "cutter_comp": B_COMP, "tool_length": B_TLC,
    "path_mode": B_PATH, "exact_stop_once": B_PATH, "polar": B_PATH, "arc_distance": B_DIST,
    "distance": B_DIST, "cycle_retract": B_RETRACT,
}

# G65 Type I argument letter -> Fanuc local variable (spec §1.8.1); I/J/K go by set (Type II).
ARG_VARS = {"A": 1, "B": 2, "C": 3, "D": 7, "E": 8, "F": 9, "H": 11, "M": 13, "Q": 17, "R": 18,
            "S": 19, "T": 20, "U": 21, "V": 22, "W": 23, "X": 24, "Y": 25, "Z": 26}
IJK_BASE = {"I": 4, "J": 5, "K": 6}

# Addresses scaled under standard decimal notation (spec §2.3, seed L413).
LENGTH_LETTERS = frozenset("XYZUVWIJKRQ") | {",C", ",R"}
ANGLE_LETTERS = frozenset("ABC")

_G_IN_TEXT = re.compile(r"G(\d+(?:\.\d+)?)")
_LEAD_N = re.compile(r"^\s*(?:/\d?\s*)?(?:[Nn]\s*\d+)?\s*")
LOCAL_CALL = "m97"              # call kind of a control profile's local subprogram call (Haas M97)
ALARM_VARIABLE = 3000          # Fanuc macro B: #3000=n (message) raises alarm n
ALARM_OWN_BASE = 0             # ... the program's own alarm n (rules iso-m alarms.user_base)
STOP_MESSAGE_VARIABLE = 3006   # Fanuc macro B: #3006=n (message) stops as M00 and shows the message
_EXTERNAL_OUTPUT = re.compile(r"^(?:N\d+\s*)?(?:POPEN|PCLOS|[DB]PRNT\s*\[.*\])\s*$")
_O_WORDS = re.compile(r"O(\d+)(?=$|[A-Z][-+.\d#\[]|[,#\[/])")
_O_NAME = re.compile(r"O([0-9A-Z_.]*)$")
_LINUXCNC_O_WORD = re.compile(r"O\d+(?:SUB|ENDSUB|IF|ELSEIF|ELSE|ENDIF|WHILE|ENDWHILE|DO|REPEAT|"
                              r"ENDREPEAT|CALL|RETURN|BREAK|CONTINUE)(?![A-Z])")
_SKIP = re.compile(r"/(\d?)")
# "[your xy start position]": prose in brackets (a template to fill in), not a macro expression.
_PLACEHOLDER = re.compile(r"\[[^\]]*[a-z]{2}[^\]]*\]")
_ARCHIVE = re.compile(r"^\s*%?_N_\w+_(MPF|SPF)", re.I)


def _ex(v: Any):
    """Word value -> IR expression."""
    return Num(float(v), v) if type(v) is str else v


def _digits(v: Any) -> Optional[str]:
    """The digits of a plain integer-like word (N, P, O, L numbers), or None for expressions."""
    if type(v) is not str:
        return None
    t = v.lstrip("+")
    if t.endswith(".0"):
        t = t[:-2]
    elif t.endswith("."):
        t = t[:-1]
    return t if t.isdigit() else None


def _word_text(letter: str, v: Any) -> str:
    if type(v) is str:
        return letter + v
    from .emitter import format_value
    return letter + format_value(v)



def _computed(v: Any) -> Any:
    """The block number of `GOTO #2` / `GOTO [#1+10]` as an expression (None for `GOTO 30`)."""
    return None if _digits(v) is not None or type(v) is str else v


def _signed_float(text: str) -> float:
    """A word's number; repeated signs (`Z--17.352`, unary minus applied twice) fold into one."""
    try:
        return float(text)
    except ValueError:
        digits = text.lstrip("+-")
        sign = -1.0 if (len(text) - len(digits) - text[: len(text) - len(digits)].count("+")) % 2 else 1.0
        return sign * float(digits)

# frame codes that cancel and read no words (rules value -> FrameOp kind)
_WORDLESS_CLEARS = {"rot_off": "rot", "scale_off": "scale"}


class _Blk:
    """Per-block lowering context (one per non-trivial block)."""
    __slots__ = ("vals", "out", "owner", "owner_rule", "machine", "motion_g", "cycle_g",
                 "call", "args", "mcodes")

    def __init__(self, vals):
        self.vals = vals            # letter -> value, in source order (last wins)
        self.out: list = []         # (bucket, statement)
        self.owner = None           # non-modal function that consumes the axis words
        self.owner_rule = None
        self.machine = False        # G53
        self.motion_g = None        # group-01 value written in this block
        self.cycle_g = None         # cycle value written in this block
        self.call = None            # "g65" / "g66" / "m98"
        self.args = None            # G65/G66 arguments [(letter, value)]
        self.mcodes: list = []


class Lowering:
    """Word lists -> IR nodes for one file, tracking the static modal state in source order.

    dialect: the name the IR is tagged with (Program.dialect, Passthrough.dialect); table: the
    rules table it reads (rules/<table>.toml). An ISO-family dialect subclasses this with its own
    names and overrides the handler methods that differ (the tables below map to bound methods)."""
    dialect = DIALECT
    table_name = DIALECT
    code_kind = "an ISO milling code"       # NC403 wording for an unknown G code
    # Whether a streamed parse may hand runs of plain lines to the native kernel (plainrun): only
    # where a plain line means what Lowering.plain_line makes of it.
    plain_runs = True

    @classmethod
    def program_defaults(cls, table) -> dict:
        """The power-on modes the program starts from (Program.meta["defaults"])."""
        return table.defaults()

    def __init__(self, file: str, diags: list[Diagnostic]):
        self.table = load_table(self.table_name)
        opts = self.table.options
        self.file = file
        self.diags = diags
        self.raw = ""                   # the current line, comments blanked (set by the parser)
        self._dup_line = 0
        self.standard = opts.get("decimal_mode", "pocket") == "standard"
        self.corner_words = opts.get("corner_elements", {}).get("words", {})
        self.factors = opts.get("standard_factors", {}).get(opts.get("increment_system", "IS-B"), {})
        self.prog8 = bool(opts.get("prog_number_8digit", False))
        self.local_call_code = ""       # the profile's local subprogram call (Haas M97), if any
        self.local_calls: set[int] = set()      # N numbers it calls (_local_subprograms)
        self.dwell_unit = float(opts.get("dwell_p_unit", 0.001))
        self.dwell_div = round(1 / self.dwell_unit) if self.dwell_unit else 1000
        # G04 P with a decimal point counts seconds (the profile's dwell_p_point, Haas) [GK]
        self.dwell_point_seconds = False
        self.cur_line = 0
        defaults = self.table.defaults()
        self.motion = defaults.get("motion")
        self.cycle = None               # active canned-cycle kind (None = off)
        self.arc_abs = defaults.get("arc_distance") == "absolute"
        self.units = defaults.get("units", "mm")
        self.feed_mode = defaults.get("feed_mode", "per_min")
        self.in_sub = False
        self.main_ended = False         # M30/M2/M99 seen in the main program: a later O is a subprogram
        self._codes: dict[str, Any] = {}    # "G" + text as written -> rule (or None)
        self._warned: set[str] = set()
        self.g_handlers = {
            "motion": self._g_motion, "cycle": self._g_cycle, "work_offset": self._g_wcs,
            "frame": self._g_frame, "call": self._g_call, "nonmodal": self._g_nonmodal,
            "passthrough": self._g_passthrough, "travel_limit": self._g_frame,
        }
        self.nonmodal_handlers = {
            "dwell": self._nm_owner, "home": self._nm_owner, "home2": self._nm_owner,
            "set_position": self._nm_owner, "local_offset": self._nm_owner,
            "data_setting": self._nm_owner, "reset_set_position": self._nm_reset,
            "machine_coords": self._nm_machine, "macro_call": self._nm_macro,
        }
        self.m_handlers = {
            "tool_change": lambda b, r, t: b.out.append((B_M6, ToolChange())),
            "stop": lambda b, r, t: b.out.append((B_END, Stop(optional=r.value == "optional"))),
            "program_end": self._m_end,
            "call": self._m_call,
            "passthrough": lambda b, r, t: b.out.append((B_NONMODAL, self._pass(t, r.meaning))),
        }
        self.owners = {
            "dwell": self._own_dwell, "home": self._own_home, "home2": self._own_home,
            "set_position": self._own_set_position, "local_offset": self._own_local,
            "data_setting": self._own_g10, "rot": self._own_rot, "rot_off": self._own_clear,
            "scale": self._own_scale, "scale_off": self._own_clear, "mirror": self._own_mirror,
            "mirror_off": self._own_mirror, "zone_on": self._own_zone, "zone_off": self._own_zone,
        }

    # ------------------------------------------------------------------ helpers
    def code(self, letter: str, text: str):
        key = letter + text
        try:
            return self._codes[key]
        except KeyError:
            try:
                rule = self.table.lookup(normalise_code(letter, text.lstrip("+")))
            except ValueError:
                rule = None
            if rule is not None and rule.code == self.local_call_code:
                rule = CodeRule(rule.code, "call", LOCAL_CALL, modal=False,
                                meaning="local subprogram call (control profile)")
            self._codes[key] = rule
            return rule

    def warn_once(self, key: str, rule: str, severity: str, message: str, line: int, col: int = 1):
        if key in self._warned:
            return
        self._warned.add(key)
        self.diags.append(Diagnostic(rule, severity, message, self.file, line, col))

    def _pass(self, text: str, reason: str) -> Passthrough:
        return Passthrough(text, reason, self.dialect)

    def num(self, letter: str, v: Any):
        """A word value as an expression; applies standard decimal notation when the profile asks."""
        if type(v) is not str:
            return v
        value = _signed_float(v)
        if self.standard and "." not in v:
            f = self._factor(letter)
            if f != 1.0:
                return Num(value * f, v)
        return Num(value, v)

    def _factor(self, letter: str) -> float:
        fs = self.factors
        inch = self.units == "inch"
        if letter in ANGLE_LETTERS:
            return fs.get("angle", 1.0)
        if letter in LENGTH_LETTERS:
            return fs.get("length_inch" if inch else "length_mm", 1.0)
        if letter == "F":
            mode = "per_rev" if self.feed_mode == "per_rev" else "per_min"
            return fs.get(f"feed_{mode}_{'inch' if inch else 'mm'}", 1.0)
        return 1.0

    def axis_values(self, vals: dict) -> dict:
        return {k: AxisValue(self.num(k, v)) for k, v in vals.items() if k in AXIS_SET}

    def _ms(self, v: Any):
        """P in milliseconds -> seconds expression."""
        if type(v) is str:
            return Num(float(v) / self.dwell_div, None)
        return Binary("/", v, Num(float(self.dwell_div), None))

    # ------------------------------------------------------------------ G handlers
    def _g_simple(self, b: _Blk, rule, text: str) -> None:
        b.out.append((SIMPLE_GROUPS[rule.group], ModeChange(rule.group, rule.value, "G" + text)))
        if rule.group == "units":
            self.units = rule.value
        elif rule.group == "feed_mode":
            self.feed_mode = rule.value
        elif rule.group == "arc_distance":
            self.arc_abs = rule.value == "absolute"

    def _g_motion(self, b: _Blk, rule, text: str) -> None:
        b.out.append((B_MOTION, ModeChange("motion", rule.value, "G" + text)))
        b.motion_g = rule.value

    def _g_cycle(self, b: _Blk, rule, text: str) -> None:
        b.out.append((B_MOTION, ModeChange("cycle", rule.value, "G" + text)))
        b.cycle_g = rule.value

    def _g_wcs(self, b: _Blk, rule, text: str) -> None:
        value = rule.value
        p = b.vals.get("P")
        if b.args is not None:          # P belongs to G65/G66 in this block
            p = None
        if value in ("G54", "G54.1") and (p is not None or value == "G54.1"):
            d = _digits(p) if p is not None else "1"
            if d is None or int(d) == 0:
                b.out.append((B_WCS, self._pass("G" + text + _word_text("P", p), "extended/external work offset by expression or P0")))
                b.vals.pop("P", None)
                return
            value = f"G54.1P{int(d)}"
            b.vals.pop("P", None)
        b.out.append((B_WCS, ModeChange("work_offset", value, "G" + text)))

    def _g_frame(self, b: _Blk, rule, text: str) -> None:
        if rule.value in _WORDLESS_CLEARS:
            # G69 / G50 take no words: written beside another frame code (`G69 G50`, `G69 G51 P2`)
            # each must still act, so it never competes for the block's one word owner
            b.out.append((B_NONMODAL, FrameOp(_WORDLESS_CLEARS[rule.value], clear=True)))
            return
        b.owner = rule.value
        b.owner_rule = rule

    def _g_call(self, b: _Blk, rule, text: str) -> None:
        if rule.value == "g67":
            b.out.append((B_END, ModalCallOff()))
        else:                                   # g66: arguments follow, like G65
            b.call = "g66"

    def _g_nonmodal(self, b: _Blk, rule, text: str) -> None:
        self.nonmodal_handlers[rule.value](b, rule, text)

    def _g_passthrough(self, b: _Blk, rule, text: str) -> None:
        # the code's own address words (rules table `args`, e.g. G103 P) stay with it
        own = "".join(_word_text(k, b.vals.pop(k)) for k in rule.args if k in b.vals)
        b.out.append((B_NONMODAL, self._pass("G" + text + own, rule.meaning)))

    def _nm_owner(self, b: _Blk, rule, text: str) -> None:
        b.owner = rule.value
        b.owner_rule = rule

    def _nm_reset(self, b: _Blk, rule, text: str) -> None:
        b.out.append((B_NONMODAL, ResetSetPosition()))
        b.owner = "reset"           # G92.1 X0 Y0: the axis words name the axes, not a move

    def _nm_machine(self, b: _Blk, rule, text: str) -> None:
        b.machine = True

    def _nm_macro(self, b: _Blk, rule, text: str) -> None:
        b.call = "g65"

    # ------------------------------------------------------------------ axis-word owners
    def _own_dwell(self, b: _Blk) -> None:
        vals = b.vals
        if "P" in vals:
            p = vals.pop("P")
            secs = self._dwell_point(p) if type(p) is str and "." in p else self._ms(p)
        else:
            v = vals.pop("X", None)
            if v is None:
                v = vals.pop("U", None)
            if v is None:
                secs = Num(0.0, None)
            elif type(v) is str and self.standard and "." not in v:
                secs = Num(float(v) * self.factors.get("dwell_s", 0.001), v)
            else:
                secs = _ex(v)
        b.out.append((B_DWELL, Dwell(seconds=secs)))

    def _dwell_point(self, p: str):
        """G04 P written with a decimal point. The seed counts P in 0.001 s, 1 to 99999999
        (L1805-1809): no decimal point. A Haas reads `G04 P2.` as 2 s and `G04 P2000` as 2000 ms
        (Haas mill operator's manual, G04 [GK]; Renishaw's Haas macros dwell `P200.` for 200 s):
        the profile's dwell_p_point = "seconds" reads it so; any other control is read by the
        seed and said at the line (NC241), since either reading is 1000 times the other."""
        if self.dwell_point_seconds:
            return Num(float(p), p)
        secs = self._ms(p)
        self.diags.append(Diagnostic(
            "NC241", "warning", f"G04 P{p}: P with a decimal point; the ISO seed counts P in 0.001 s "
            f"(no point), so it is read as {float(p) / self.dwell_div:g} s, where a Haas reads "
            f"{float(p):g} s (a program whose header names HAAS is read so)", self.file, self.cur_line))
        return secs

    def _own_home(self, b: _Blk) -> None:
        ref = 1 if b.owner == "home" else 2
        idx = None
        if ref == 2 and "P" in b.vals:
            idx = _ex(b.vals.pop("P"))
        b.out.append((B_NONMODAL, HomeReturn(ref, self.axis_values(b.vals), idx)))
        self._drop_axes(b)

    def _own_set_position(self, b: _Blk) -> None:
        b.out.append((B_NONMODAL, SetPosition(self.axis_values(b.vals))))
        self._drop_axes(b)

    def _own_local(self, b: _Blk) -> None:
        values = {k: self.num(k, v) for k, v in b.vals.items() if k in AXIS_SET}
        b.out.append((B_NONMODAL, FrameOp("trans", values, local=True)))
        self._drop_axes(b)

    def _own_zone(self, b: _Blk) -> None:
        """G22 X Y Z I J K: a box (X/Y/Z one corner, I/J/K the other) the tool tip must not enter
        (protection zone 3; MD 22900 = 0, an internal zone), G22 alone switches it on again, G23
        off. Nothing moves."""
        code = b.owner_rule.code if b.owner_rule else "G22"
        words = [k for k in ("X", "Y", "Z", "I", "J", "K") if k in b.vals]
        text = " ".join([code] + [_word_text(k, b.vals[k]) for k in words])
        if b.owner == "zone_off":
            limit = TravelLimit("off", "zone", text=text, dialect=self.table_name)
        else:
            corner = dict(zip("IJK", "XYZ"))
            values = {k: self.num(k, b.vals.pop(k)) for k in ("X", "Y", "Z") if k in b.vals}
            other = {corner[k]: self.num(k, b.vals.pop(k)) for k in ("I", "J", "K") if k in b.vals}
            limit = (TravelLimit("box", "zone", values, other, text=text, dialect=self.table_name)
                     if values or other else TravelLimit("on", "zone", text=text, dialect=self.table_name))
        b.out.append((B_NONMODAL, limit))
        self._drop_axes(b)

    def _own_g10(self, b: _Blk) -> None:
        vals = b.vals
        lclass = _digits(vals.get("L"))
        p = vals.get("P")
        kinds = {"2": ("work_offset", False), "20": ("work_offset", True),
                 "10": ("tool_length", False), "1": ("tool_length", False),
                 "11": ("tool_length_wear", False), "12": ("tool_radius", False),
                 "13": ("tool_radius_wear", False)}
        kind = kinds.get(str(int(lclass))) if lclass else None
        if kind is None or p is None:
            text = "G10" + "".join(_word_text(k, v) for k, v in vals.items())
            b.out.append((B_NONMODAL, self._pass(text, "G10 data class without an IR equivalent")))
            vals.clear()
            return
        vals.pop("L")
        vals.pop("P")
        if kind[0] == "work_offset":
            values = {k: self.num(k, v) for k, v in vals.items() if k in AXIS_SET}
            self._drop_axes(b)
        else:
            r = vals.pop("R", None)
            values = {"value": self.num("R", r)} if r is not None else {}
        b.out.append((B_NONMODAL, DataSetting(kind[0], _ex(p), values, kind[1])))

    def _own_rot(self, b: _Blk) -> None:
        from nctrans.interp.unmodelled import FRAME_NOT_MODELLED
        vals = b.vals
        if any(k in vals for k in "IJK"):
            # G68 with a vector is the 3D rotation (seed L1483-1511: pivot at the workpiece zero,
            # R always absolute, two G68 in series); not modelled, so kept and reported at its
            # line, never turned silently in the plane
            text = "G68" + "".join(_word_text(k, v) for k, v in vals.items())
            b.out.append((B_NONMODAL, self._pass(
                text, f"{FRAME_NOT_MODELLED}: G68 with an I/J/K vector (3D rotation); the moves "
                "after it are analysed without the rotation")))
            vals.clear()
            return
        center = self.axis_values(vals)
        self._drop_axes(b)
        angle = self.num("A", vals.pop("R")) if "R" in vals else None
        values = {k: self.num(k, vals.pop(k)) for k in "IJK" if k in vals}
        # no X Y: the centre is the current position (seed L1453), and G68 replaces no other
        # frame component: an empty centre, never None (which a Sinumerik ROT has)
        b.out.append((B_NONMODAL, FrameOp("rot", values, center, angle)))

    def _own_clear(self, b: _Blk) -> None:
        op = {"rot_off": "rot", "scale_off": "scale"}[b.owner]
        b.out.append((B_NONMODAL, FrameOp(op, clear=True)))

    def _own_scale(self, b: _Blk) -> None:
        vals = b.vals
        center = self.axis_values(vals)
        self._drop_axes(b)
        values = {}
        if "P" in vals:
            f = self._scale_factor(vals.pop("P"))
            values = {"X": f, "Y": f, "Z": f}
        for letter, axis in (("I", "X"), ("J", "Y"), ("K", "Z")):
            if letter in vals:
                values[axis] = self._scale_factor(vals.pop(letter))
        # no X Y Z: about the workpiece zero (seed L1625); an empty centre, as G51 replaces no
        # other frame component (None is a Sinumerik SCALE's, which does)
        b.out.append((B_NONMODAL, FrameOp("scale", values, center)))

    def _scale_factor(self, v: Any):
        """G51 P/I/J/K: integers count 0.001 (seed L1622); a written decimal point is the factor."""
        if type(v) is str:
            return Num(float(v) if "." in v else float(v) / 1000, v)
        return v

    def _own_mirror(self, b: _Blk) -> None:
        axes = self.axis_values(b.vals)
        self._drop_axes(b)
        values = {k: Num(1.0, None) for k in axes}
        if b.owner == "mirror":
            b.out.append((B_NONMODAL, FrameOp("mirror", values, axes or None)))
        else:
            b.out.append((B_NONMODAL, FrameOp("mirror", values, clear=True)))

    @staticmethod
    def _drop_axes(b: _Blk) -> None:
        for k in [k for k in b.vals if k in AXIS_SET]:
            del b.vals[k]

    # ------------------------------------------------------------------ M handlers
    def _m_end(self, b: _Blk, rule, text: str) -> None:
        b.out.append((B_END, ProgramEnd(rule.value)))
        if not self.in_sub:
            self.main_ended = True

    def _m_call(self, b: _Blk, rule, text: str) -> None:
        if rule.value == "m98":
            b.call = "m98"
            return
        if rule.value == LOCAL_CALL:
            b.call = LOCAL_CALL
            return
        p = b.vals.pop("P", None)
        if self.in_sub:
            b.out.append((B_END, Return(_digits(p) if p is not None else None)))
        elif p is not None:
            b.out.append((B_END, Goto(_digits(p) or _word_text("", p))))
        else:
            b.out.append((B_END, ProgramEnd("restart")))
            self.main_ended = True

    # ------------------------------------------------------------------ calls
    def _subcall(self, b: _Blk, line: int) -> None:
        vals = b.vals
        p = vals.pop("P", None)
        lval = vals.pop("L", None)
        repeat = _ex(lval) if lval is not None else None
        named: dict = {}
        name = ""
        d = _digits(p)
        if d is not None:
            if b.call == "m98" and not self.prog8 and len(d) > 4:
                if repeat is None:
                    repeat = Num(float(int(d[:-4])), None)
                d = d[-4:]
            name = f"O{int(d)}"
            if b.call == LOCAL_CALL:            # Haas M97 P<n>: the blocks from N<n> (local_calls)
                name = f"N{int(d)}"
                self.local_calls.add(int(d))
        elif p is not None:
            named["P"] = _ex(p)             # program number by expression: resolved at run time
        else:
            self.diags.append(Diagnostic("NC002", "error",
                                         f"{b.call.upper()} without a program number P", self.file, line))
        bindings: dict = {}
        if b.call in ("g65", "g66"):
            sets: list[set] = []
            for letter, v in b.args or ():
                if letter in IJK_BASE:
                    order = "IJK".index(letter)
                    cur = sets[-1] if sets else None
                    if cur is None or letter in cur or any("IJK".index(x) > order for x in cur):
                        cur = set()
                        sets.append(cur)
                    cur.add(letter)
                    n = len(sets)
                    key = f"{letter}{n}"
                    if n > 10:
                        self.diags.append(Diagnostic("NC002", "error",
                                                     f"G65 argument {letter} repeated more than 10 times",
                                                     self.file, line))
                        continue
                    var = IJK_BASE[letter] + 3 * (n - 1)
                elif letter in ARG_VARS:
                    key, var = letter, ARG_VARS[letter]
                else:
                    b.out.append((B_NONMODAL, self._pass(_word_text(letter, v),
                                                         f"{letter} is not a macro argument")))
                    continue
                named.pop(key, None)
                named[key] = self.num(letter, v)
                bindings[key] = Var("num", var)
        kind = b.call
        modal = "after_move" if kind == "g66" else "none"
        b.out.append((B_END, SubCall(name, [], named, repeat, modal, kind, bindings)))

    # ------------------------------------------------------------------ block
    def hot(self, words: list) -> Optional[tuple]:
        """Lowering of the commonest CAM blocks, [N] [G0|G1] axis words [F], exactly as lower()
        would do it (tests/test_iso_fastpath.py compares them); None sends the block to lower()."""
        if self.standard:
            return None
        done = self.plain_block(words, self.motion, self.cycle, self.arc_abs)
        if done is not None and done[2] is not None:
            self.motion = done[2]
            self.cycle = None
        return done

    def plain_block(self, words: list, motion: Optional[str], cycle: Optional[str], arc_abs: bool,
                    _axes=AXIS_SET, _av=AxisValue, _num=Num, _float=float) -> Optional[tuple]:
        """(number, body, motion mode written or None) of a plain block given the static modal
        state before it, without touching the tracked state (plainrun.PlainRun expands lines with
        it after the front end has moved on); None when the block is not [N] [G0-G3] axis words
        [I J K] [F] with centre words only in arc mode, incremental (G91.1), no cycle pending."""
        number = None
        target: dict = {}
        center: dict = {}
        mode = feed = None
        for letter, text in words:
            if letter in _axes:
                if letter in target:
                    return None
                target[letter] = _av(_num(_float(text), text))
            elif letter in CENTER_LETTERS:
                if letter in center:
                    return None
                center[letter] = _av(_num(_float(text), text))
            elif letter == "G" and mode is None:
                rule = self.code("G", text)
                if rule is None or rule.group != "motion" or rule.value not in PLAIN_MOTIONS:
                    return None
                mode = ModeChange("motion", rule.value, "G" + text)
            elif letter == "F" and feed is None:
                feed = Feed(Num(float(text), text))
            elif (letter == "N" and number is None and not target and not center and mode is None
                  and feed is None):
                number = text
            else:
                return None
        if center:
            if (mode.value if mode is not None else motion) not in ("arc_cw", "arc_ccw"):
                return None
            if (mode is None and cycle is not None) or arc_abs:
                return None
        body = []
        if feed is not None:
            body.append(feed)
        if mode is not None:
            body.append(mode)
        if target or center:
            body.append(Motion(target, center or None))
        return number, body, None if mode is None else mode.value

    def plain_line(self, code: str, motion: Optional[str], cycle: Optional[str], arc_abs: bool
                   ) -> Optional[tuple]:
        """plain_block of one line of code (blanks removed): how plainrun.PlainRun expands its lines."""
        return self.plain_block(WORD.findall(code), motion, cycle, arc_abs)

    def lower(self, items: list, line: int) -> tuple[Optional[str], list, list, Optional[str]]:
        """Lower one block's word list. Returns (number, body, structure items, unknown G)."""
        self.cur_line = line
        number = None
        gs: list = []
        macro: list = []
        vals: dict = {}
        args = None
        mcodes: list = []
        first = True
        for it in items:
            letter = it[0]
            if len(it) == 3:
                macro.append(it)
                first = False
                continue
            v = it[1]
            if letter == "G":
                if type(v) is str:
                    rule = self.code("G", v)
                    if rule is None:
                        return None, [], [], "G" + v
                    gs.append((rule, v))
                    if rule.value in ("macro_call", "g66"):
                        args = []
                else:
                    mcodes.append((None, v, "G"))
            elif args is not None and letter not in "PL":
                args.append((letter, v))
            elif letter == "M":
                mcodes.append((self.code("M", v) if type(v) is str else None, v, "M"))
            elif letter == "N" and first and type(v) is str:
                number = v
            else:
                if letter in vals and letter != "N":
                    self._dup(line, f"address {letter} written twice in the block; the last one counts",
                              letter)
                vals[letter] = v
            first = False

        # Hot path: a block of axis words only (most CAM blocks).
        if not gs and not mcodes and not macro and args is None:
            if not vals:
                return number, [], [], None
            if all(k in AXIS_SET for k in vals):
                return number, [Motion(self.axis_values(vals))], [], None

        b = _Blk(vals)
        b.args = args
        out = b.out
        structure: list = []
        for it in macro:
            tag = it[0]
            if tag == "=":
                if type(it[1]) is Var and it[1].space == "num" and it[1].key == ALARM_VARIABLE:
                    out.append((B_END, Alarm(it[2], None, ALARM_OWN_BASE)))     # #3000=n (MESSAGE): the control stops
                elif _is_stop_message(it[1]):
                    out.append((B_END, Stop()))           # #3006=n (MESSAGE): M00 with a message
                else:
                    out.append((B_ASSIGN, Assign(it[1], it[2])))
            elif tag == "GOTO":
                out.append((B_END, Goto(self._target(it[1]), computed=_computed(it[1]))))
            elif tag == "IFGOTO":
                out.append((B_END, Goto(self._target(it[2]), cond=it[1], computed=_computed(it[2]))))
            else:
                structure.append(it)

        # G codes: one per group, the last wins (NC201).
        if len(gs) > 1:
            seen: dict = {}
            for i, (rule, v) in enumerate(gs):
                key = rule.dialect_group if rule.modal and rule.group not in ("nonmodal", "passthrough") else (rule.group, rule.value)
                if key in seen:
                    self._dup(line, f"G{gs[seen[key]][1]} and G{v} are in the same modal group; G{v} counts")
                    gs[seen[key]] = None
                seen[key] = i
            gs = [g for g in gs if g is not None]
        handlers = self.g_handlers
        for rule, v in gs:
            h = handlers.get(rule.group)
            if h is None:
                self._g_simple(b, rule, v)
            else:
                h(b, rule, v)

        for rule, v, letter in mcodes:
            if rule is None:
                text = _word_text(letter, v)
                if type(v) is str:
                    self.warn_once(text, "NC403", "warning",
                                   f"{text} has no meaning in the IR; kept verbatim", line)
                ps = self._pass(text, "machine-specific code")
                if type(v) is not str:            # M#501: a computed code another dialect can write
                    ps.address, ps.value = letter, v
                out.append((B_NONMODAL, ps))
            elif rule.group in SIMPLE_GROUPS:
                out.append((SIMPLE_GROUPS[rule.group], ModeChange(rule.group, rule.value, "M" + v)))
            else:
                self.m_handlers[rule.group](b, rule, "M" + v)

        # Static modal state after this block's G codes (group 01 cancels a canned cycle).
        if b.motion_g is not None:
            self.motion = b.motion_g
            self.cycle = None
        if b.cycle_g is not None:
            self.cycle = None if (b.cycle_g == "off" or b.motion_g is not None) else b.cycle_g

        if "F" in vals:
            out.append((B_FEED, Feed(self.num("F", vals.pop("F")))))
        if "S" in vals:
            out.append((B_SPEED, SpindleSpeed(_ex(vals.pop("S")))))
        if "T" in vals:
            out.append((B_TOOL, ToolSelect(_ex(vals.pop("T")))))
        if "D" in vals:
            out.append((B_COMP, OffsetSelect("radius", _ex(vals.pop("D")))))
        if "H" in vals:
            out.append((B_TLC, OffsetSelect("length", _ex(vals.pop("H")))))

        if b.owner is not None:
            own = self.owners.get(b.owner)
            if own is None:             # G92.1: axis words only name the axes
                self._drop_axes(b)
            else:
                own(b)

        if b.call is not None:
            self._subcall(b, line)

        if self.cycle is not None:
            params = {}
            if "R" in vals:
                params["r_plane"] = self.num("R", vals.pop("R"))
            if "Q" in vals:
                key = "shift" if self.cycle in ("fine_bore", "back_bore") else "peck"
                params[key] = self.num("Q", vals.pop("Q"))
            if "P" in vals:
                params["dwell"] = self._ms(vals.pop("P"))
            for rep in ("K", "L"):
                if rep in vals:
                    params["repeat"] = _ex(vals.pop(rep))
            if params:
                out.append((B_MOTION, CycleParams(params)))

        target = {}
        for k in [k for k in vals if k in AXIS_SET]:
            target[k] = AxisValue(self.num(k, vals.pop(k)))
        arc = (b.motion_g or self.motion) in ("arc_cw", "arc_ccw") and self.cycle is None
        center = radius = turns = None
        if arc:
            if vals.keys() & CENTER_LETTERS:
                mode = "abs" if self.arc_abs else None
                center = {k: AxisValue(self.num(k, vals.pop(k)), mode) for k in "IJK" if k in vals}
            if "R" in vals:
                radius = self.num("R", vals.pop("R"))
            lv = vals.pop("L", None)
            if lv is None:
                lv = vals.pop("P", None)
            if lv is not None:
                turns = Num(float(lv) - 1, None) if type(lv) is str else Binary("-", lv, Num(1.0, None))
        elif (b.motion_g or self.motion) in ("thread", "tap_return") and self.cycle is None \
                and vals.keys() & CENTER_LETTERS:
            # G33 X.. Z.. K<lead>: LinuxCNC's lead word (ISO's own is F, seed 4.5); the
            # interpreter takes an I/J/K lead before F (interp/motion.py _g33_move)
            center = {k: AxisValue(self.num(k, vals.pop(k))) for k in "IJK" if k in vals}
        start = None
        if (b.motion_g or self.motion) == "thread" and self.cycle is None and "Q" in vals:
            start = self._thread_start(vals.pop("Q"), line)
        if target or center or radius is not None or b.machine or start is not None:
            out.append((B_MOTION, Motion(target, center, radius, turns, machine_coords=b.machine,
                                         thread_start=start)))

        for k, v in vals.items():       # words nothing above gave a meaning
            text = _word_text(k, v)
            if k in self.corner_words:  # ,R / ,C: interp/corner_elements.py
                out.append((B_NONMODAL, Passthrough(text, self.corner_words[k], self.dialect,
                                                    address=k, value=self.num(k, v))))
                continue
            self.warn_once("word:" + k, "NC403", "warning",
                           f"{text}: address {k.lstrip(',')} has no meaning in this block; kept verbatim", line)
            out.append((B_NONMODAL, self._pass(text, f"address {k} without an IR meaning here")))

        if len(out) > 1:
            out.sort(key=itemgetter(0))
        return number, [s for _, s in out], structure, None

    def _thread_start(self, v: Any, line: int):
        """G33 Q<angle>: the thread's start angle, an integer in 0.001 degree (ISO seed 4.1.16:
        `Q180000` = 180 deg), as degrees; written with a decimal point it is the control's alarm."""
        if type(v) is str:
            if "." in v:
                self.diags.append(Diagnostic(
                    "NC121", "error", f"Q{v}: the thread start angle is an integer in 0.001 degree "
                    "(Q180000 = 180 deg), never written with a decimal point; the control alarms",
                    self.file, line, 1))
            return Num(_signed_float(v) / 1000.0, None)
        return Binary("/", _ex(v), Num(1000.0, None))

    def _target(self, v: Any) -> str:
        d = _digits(v)
        return d if d is not None else _word_text("", v)

    def _dup(self, line: int, message: str, letter: str = "") -> None:
        """NC201 at the repeated word: the second occurrence of its address letter in the line
        (comments blanked), so the report points at what to delete."""
        col = 1
        raw = self.raw
        if letter and raw and line != self._dup_line:     # once per line: lines can be MBs long
            self._dup_line = line
            upper = raw.upper()
            first = upper.find(letter)
            second = upper.find(letter, first + 1) if first >= 0 else -1
            col = second + 1 if second >= 0 else 1
        self.diags.append(Diagnostic("NC201", "warning", message, self.file, line, col))


# ---------------------------------------------------------------------- parse

class _Frame:
    """An open WHILE/DO loop in the structure pass."""
    __slots__ = ("node", "label", "parent", "line")

    def __init__(self, node, label, parent, line):
        self.node, self.label, self.parent, self.line = node, label, parent, line


def _hostile_block(code: str) -> Optional[tuple[str, int, str]]:
    """(rule, index into code, message) for a block no real program holds and the grammar must
    not see: stacked signs (`X1--5`), a number too large for a double, brackets or operator chains
    deep enough to exhaust the recursion of the expression walkers (nctrans/limits.py)."""
    if "--" in code or "-+" in code or "+-" in code or "++" in code:
        idx, signs = limits.stacked_signs(code)
        return ("NC002", idx, f"stacked signs {signs!r}: write one sign (X-5) or bracket the "
                "operand (X[1-[-5]])")
    huge = limits.huge_literal(code)
    if huge is not None:
        return ("NC108", huge[0], f"number of {len(huge[1])} digits is out of range (it would "
                "read as infinity)")
    deep = limits.too_complex(code, "[", "]")
    if deep is not None:
        return ("NC008", deep[0], deep[1])
    return None


def _raw_col(blanked: str, index: int) -> int:
    """1-based source column of the `index`-th (0-based) character of clean(blanked)."""
    kept = 0
    for i, ch in enumerate(blanked):
        if clean(ch):
            if kept == index:
                return i + 1
            kept += 1
    return len(blanked) + 1


def _syntax_diag(err, code: str, blanked: str, file: str, line: int, offset: int) -> Diagnostic:
    from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedToken
    if isinstance(err, UnexpectedToken):
        idx = (err.token.start_pos if err.token.start_pos is not None else len(code))
        expected = sorted(err.expected)
        got = "end of block" if err.token.type == "$END" else repr(str(err.token))
        msg = f"unexpected {got}; expected one of {', '.join(_pretty(expected))}"
    elif isinstance(err, UnexpectedCharacters):
        idx = err.pos_in_stream
        msg = f"unexpected character {code[idx]!r}; expected one of {', '.join(_pretty(sorted(err.allowed or ())))}"
    elif isinstance(err, UnexpectedEOF):
        idx = len(code)
        msg = f"block ends early; expected one of {', '.join(_pretty(sorted(err.expected)))}"
    else:
        idx = 0
        msg = str(err).splitlines()[0]
    return Diagnostic("NC002", "error", msg, file, line, _raw_col(blanked, offset + idx))


_PRETTY = {"LETTER": "an address letter", "NUMBER": "a number", "RELOP": "EQ/NE/GT/GE/LT/LE",
           "FUNC": "a function", "LSQB": "'['", "RSQB": "']'", "HASH": "'#'", "MINUS": "'-'",
           "PLUS": "'+'", "EQUAL": "'='", "COMMA": "','", "SLASH": "'/'", "STAR": "'*'",
           "$END": "end of block", "ATAN_SEP": "']/['"}


def _pretty(names) -> list[str]:
    return [_PRETTY.get(n, n.strip('"')) for n in names][:8]


def _unbalanced(code: str) -> Optional[int]:
    """Index of the first unbalanced square bracket, or None."""
    depth = 0
    opens: list[int] = []
    for i, ch in enumerate(code):
        if ch == "[":
            opens.append(i)
        elif ch == "]":
            if not opens:
                return i
            opens.pop()
    return opens[0] if opens else None


def parse_program(text: str, file: str = "<stdin>", lowering: type[Lowering] = Lowering):
    """Parse ISO text (with the `lowering` of the family member: see Lowering). The cyclic garbage
    collector is paused while the IR is built: the parse allocates ~10 objects per block and none
    of them form cycles, so collections are pure cost."""
    gc_was_enabled = gc.isenabled()
    gc.disable()
    try:
        return _parse_program(text, file, lowering)
    finally:
        if gc_was_enabled:
            gc.enable()


def _parse_program(text: str, file: str, lowering: type[Lowering]):
    from nctrans.dialects.base import ParseResult

    diags: list[Diagnostic] = DiagnosticList()
    program = Program(file, lowering.dialect, [], {}, {}, None)
    for _ in _parse_lines(text, file, program, diags, program.body, False, lowering):
        pass
    return ParseResult(program, diags)


def parse_compact(text: str, file: str = "<stdin>", lowering: type[Lowering] = Lowering, jumps: bool = False):
    """A whole parse whose main body is held compact (base.CompactBody): each run of plain lines
    at its top level is one PlainRun (a span of the text, read again when it runs) instead of its
    Blocks (~1.2 KiB each), so a CAM body of millions of lines around a few loops and calls costs
    little. The interpreter runs such a body as it runs a streamed one, batch by batch, which
    holds only where nothing jumps back into the main body: None when anything may (a GOTO or an
    M99 in it, M99 ending it (a restart), an M99 P return to one of its block numbers), or when
    nothing would be compacted
    (without the native kernel there are no runs): parse_program then. `jumps`: such a program is
    held compact too, its runs split at the blocks jumps land on (dialects/compact_jumps.py)."""
    from nctrans.dialects.base import CompactBody, ParseResult
    if plainrun.native is None:
        return None
    gc_was_enabled = gc.isenabled()
    gc.disable()
    try:
        diags: list[Diagnostic] = DiagnosticList()
        program = Program(file, lowering.dialect, [], {}, {}, None)
        for _ in _parse_lines(text, file, program, diags, program.body, False, lowering, compact=True):
            pass
    finally:
        if gc_was_enabled:
            gc.enable()
    items = program.body
    if not any(type(x) is plainrun.PlainRun for x in items):
        return None
    if _jumps_into_main(program):
        from nctrans.dialects.compact_jumps import split_at_targets
        from nctrans.lower.macro_procs import macro_file
        # a macro file (G65 arguments, M99) is written as a PROC from its whole body
        split = split_at_targets(program) if jumps and not macro_file(program) else None
        if split is None:
            return None
        program.body = CompactBody(split, jumps=True)
        return ParseResult(program, diags)
    program.body = CompactBody(items)
    return ParseResult(program, diags)


def _jumps_into_main(program: Program) -> bool:
    """Whether anything may jump to a place in the main body (see parse_compact)."""
    from nctrans.ir.walk import blocks
    from nctrans.ir import nodes as n
    main = [x for x in program.body if type(x) is not plainrun.PlainRun]
    if any(type(s) in (n.Goto, n.Return, n.SectionRepeat) or (type(s) is n.ProgramEnd and s.kind == "restart")
           for b in blocks(main) for s in b.body):
        return True
    return any(type(s) is n.Return and s.to_label for sub in program.subprograms.values()
               for b in blocks(sub.body) for s in b.body)


# What needs the main body held whole: a jump (GOTO, IF, WHILE/DO/END, M99 P), a call (M98, M97,
# G65, G66/G67, M17/M99 returns) or a macro expression (# [ ]). Matches inside comments are skipped;
# anything else that matches only costs the streaming (the full parse is always correct).
# Subprograms later in the file need no look: only a call reaches them, and calls are in the list
# (their blocks are still parsed, into Program.subprograms, so the diagnostics are the same).
_CONTROL_MARKS = (r"GOTO", r"IF", r"WHILE", r"END[ \t]*\d", r"DO[ \t]*\d", r"#", r"\[", r"G[ \t]*0*6[ \t]*[567]",
                  r"M[ \t]*0*(?:9[ \t]*[789]|1[ \t]*7)")
_CONTROL = re.compile("|".join(_CONTROL_MARKS))
# The characters the marks begin with (each mark starts with one literal character): a line
# without any of them holds no mark (the native kernel's `quiet` passes over such lines).
_CONTROL_STARTS = "".join(sorted({m.removeprefix("\\")[0] for m in _CONTROL_MARKS}))
_SCAN_CHUNK = 1 << 16


def _control_flow_at(text: str, semicolon_comment: bool) -> Optional[int]:
    """Offset of the first control-flow mark outside a comment (None: the program runs straight
    through, block after block). With the native kernel only the lines that may hold a mark are
    searched: its `quiet` passes over lines with none of the marks' first characters and over runs
    of plain words (N, G0-G3, axis, centre and F words), ~4x faster on CAM output than stepping
    over plain runs alone and ~30x faster than searching the whole text."""
    quiet = plainrun.native.quiet if plainrun.native is not None else None
    if quiet is None or "\n" not in text:
        return _control_flow_in(text, 0, len(text), semicolon_comment)
    pos, n = 0, len(text)
    while pos < n:
        pos = quiet(text, pos, "\n", _CONTROL_STARTS)
        if pos >= n:
            break
        nl = text.find("\n", pos)
        nl = n if nl < 0 else nl
        found = _control_flow_in(text, pos, nl, semicolon_comment)
        if found is not None:
            return found
        pos = nl + 1
    return None


def _control_flow_in(text: str, start: int, end: int, semicolon_comment: bool) -> Optional[int]:
    """_control_flow_at within text[start:end), searched in upper-cased chunks of whole lines (a
    case-insensitive pattern with these alternatives is ~15x slower; chunks keep the copy small)."""
    n = end
    base = start
    while base < n:
        cut = text.rfind("\n", base, base + _SCAN_CHUNK) if base + _SCAN_CHUNK < n else n
        if cut <= base:
            cut = min(n, base + _SCAN_CHUNK)
        chunk = text[base:cut].upper()
        for m in _CONTROL.finditer(chunk):
            pos = m.start()
            head = chunk[chunk.rfind("\n", 0, pos) + 1:pos]
            if head.count("(") > head.count(")") or (semicolon_comment and ";" in head):
                continue                        # inside a comment
            return base + pos
        base = cut
    return None


def parse_stream(text: str, file: str = "<stdin>", lowering: type[Lowering] = Lowering):
    """Lazy parse for programs whose main body runs straight through (the common CAM output): a
    ParseResult whose Program.body is a StreamedBody and whose diagnostics list fills as the body
    is iterated (complete once it is drained). None when the text has control flow, a macro
    variable or subprograms (see _CONTROL): those need `parse_program`, which holds the IR whole.
    Memory then stays bounded by one batch of blocks instead of growing with the file."""
    from nctrans.dialects.base import ParseResult, StreamedBody

    diags: list[Diagnostic] = DiagnosticList()
    program = Program(file, lowering.dialect, [], {}, {}, None)
    table = load_table(lowering.table_name)
    opts = table.options
    if _control_flow_at(text, opts.get("eob_semicolon", "comment") != "eob") is not None:
        return None
    # The interpreter reads the power-on modes when it starts, before the body is first iterated
    # (which is when _parse_lines fills the rest of meta): without them a streamed program ran
    # from no work offset while the full parse ran from G54.
    program.meta["defaults"] = lowering.program_defaults(table)
    program.body = StreamedBody(_parse_lines(text, file, program, diags, [], True, lowering))
    return ParseResult(program, diags)


class _Lines:
    """(line number, text) of each piece of text.split(sep), one at a time (no list of every line),
    keeping where the current line starts so that a run of plain lines can be stepped over whole."""
    __slots__ = ("text", "sep", "start", "pos", "lineno")

    def __init__(self, text: str, sep: str):
        self.text, self.sep = text, sep
        self.start = self.pos = 0
        self.lineno = 0

    def __iter__(self):
        return self

    def __next__(self) -> tuple[int, str]:
        pos, text = self.pos, self.text
        if pos > len(text):
            raise StopIteration
        i = text.find(self.sep, pos)
        if i < 0:
            i = len(text)
        self.start, self.pos = pos, i + 1
        self.lineno += 1
        return self.lineno, text[pos:i]

    def skip_to(self, pos: int, lines: int) -> None:
        """Continue after `lines` lines that end just before `pos` (the current one among them)."""
        self.pos = pos
        self.lineno += lines - 1


def _parse_lines(text: str, file: str, program: Program, diags: list, main: list, stream: bool,
                 lowering: type[Lowering] = Lowering, compact: bool = False):
    """The parse proper. Fills program.meta/name/subprograms and `main`; with `stream` the blocks
    of the main body are yielded (and dropped from `main`) line by line instead."""
    low = lowering(file, diags)
    opts = low.table.options
    semicolon_comment = opts.get("eob_semicolon", "comment") != "eob"
    max_do_nesting = int(opts.get("max_do_nesting", limits.MAX_STRUCTURE_NESTING))
    meta: dict = program.meta
    meta.update({"program_number": None, "percent": False, "defaults": low.program_defaults(low.table),
                 "options": dict(opts)})
    if "profiles" in opts and not meta.get("profile"):
        from nctrans.dialects.iso_m.profiles import detect, detect_by_block
        meta["profile"] = detect(text, opts)
        found = detect_by_block(text, opts) if not meta["profile"] else None
        if found is not None:
            profile, line, block = found
            meta["profile"] = profile
            meaning = opts["profiles"][profile].get("meaning") or profile
            diags.append(Diagnostic(
                "NC407", "info", f"{block[:40]}: read as a program for the {meaning} (control "
                f"profile {profile}): only that control accepts this block", file, line))
    if meta.get("profile"):
        chosen = (opts.get("profiles") or {}).get(meta["profile"], {})
        low.local_call_code = str(chosen.get("local_call", "")).upper()
        low.dwell_point_seconds = chosen.get("dwell_p_point") == "seconds"
    name = None
    subprograms: dict[str, Subprogram] = program.subprograms
    cur = main
    main_seen = False
    stack: list[_Frame] = []
    seen_block = False
    lowercase_noted = False

    if "\x00" in text:
        diags.append(Diagnostic("NC001", "error", "NUL bytes: not NC program text (UTF-16 or binary?)",
                                file, 1))
        text = text.replace("\x00", "")
    sep = "\n" if "\n" in text else "\r"
    lines = _Lines(text, sep) if stream or compact else enumerate(text.split(sep), 1)
    # Streamed and with the native kernel: runs of plain lines become one PlainRun each.
    # Compact (parse_compact): runs at the top of the main body become PlainRuns too, held.
    plain_scan = plainrun.native.scan if (stream or compact) and plainrun.native is not None \
        and not low.standard and low.plain_runs else None
    plain_line = low.plain_line
    fast_plain = PLAIN.fullmatch
    fast_words = WORD.findall
    lower = low.lower
    words_of = None

    def close_loops(upto: int) -> None:
        while stack:
            fr = stack[-1]
            if len(stack) <= upto:
                break
            stack.pop()
            diags.append(Diagnostic("NC006", "error",
                                    f"DO{fr.label} (line {fr.line}) has no END{fr.label}", file, fr.line))

    hot = low.hot
    _block = Block
    _span = Span
    max_block = limits.setting("MAX_BLOCK_CHARS", limits.MAX_BLOCK_CHARS)
    for lineno, raw in lines:
        if len(raw) > max_block:
            diags.append(Diagnostic("NC010", "error", f"block of {len(raw)} characters: longer than "
                                    f"the {max_block} nctrans reads; not analysed", file, lineno))
            continue
        if stream and main:
            main_seen = True
            yield from main
            main.clear()
        if plain_scan is not None and cur is main and not stack:
            # A run starts here when its first PLAIN_RUN_MIN lines are plain. Where it ends the
            # kernel finds as it runs it (one pass over the lines), before the body is iterated
            # on; else extent() finds it with scan().
            if plain_scan(text, lines.start, sep, plainrun.motion_code(low.motion), low.cycle is None,
                          low.arc_abs, False, max_block, PLAIN_RUN_MIN)[2] >= PLAIN_RUN_MIN:
                run = plainrun.PlainRun.open(file, text, lines.start, lineno, sep, plain_line, low.motion,
                                             low.cycle, low.arc_abs, False, max_block)
                main_seen = True
                if stream:
                    yield run
                else:
                    main.append(run)
                ends = run.extent()
                lines.skip_to(ends.pos, ends.line - lineno)
                low.motion, low.cycle = ends.motion, ends.cycle
                seen_block = True
                continue
        # Hot path: a comment-free line of plain axis words (most of CAM output).
        if not ("(" in raw or ";" in raw or ")" in raw):
            code = raw.replace(" ", "")
            if code[-1:] == "\r":
                code = code[:-1]
            if code and code[0] != "O" and len(code) < 309 and fast_plain(code) is not None:
                words = fast_words(code)
                done = hot(words)
                if done is not None:
                    cur.append(_block(_span(file, lineno, 1, lineno, len(raw) + 1), done[1], done[0]))
                    seen_block = True
                    continue
        if "(" in raw or ";" in raw or ")" in raw:
            scan = strip_comments(raw, semicolon_comment)
            blanked = scan.code
            comments = scan.comments
            if scan.open_col is not None:
                diags.append(Diagnostic("NC003", "error", "comment '(' is not closed before the end of the line",
                                        file, lineno, scan.open_col))
            if scan.stray_col is not None:
                diags.append(Diagnostic("NC003", "error", "')' without an opening '('",
                                        file, lineno, scan.stray_col))
        else:
            blanked = raw
            comments = None
        code = blanked.translate(_DROP_TABLE)
        if not code:
            if not comments:
                continue
            comment = " ".join(comments)
            span = Span(file, lineno, 1, lineno, len(raw) + 1)
            cur.append(Block(span, [], comment=comment))
            continue
        if not lowercase_noted and not code.isupper() and code.upper() != code:
            lowercase_noted = True
            diags.append(Diagnostic("NC501", "info", "lowercase address letters", file, lineno))
        code = code.upper()
        comment = " ".join(comments) if comments else None
        span = Span(file, lineno, 1, lineno, len(raw) + 1)
        hostile = _hostile_block(code)
        if hostile is not None:
            rule, idx, message = hostile
            diags.append(Diagnostic(rule, "error", message, file, lineno, _raw_col(blanked, idx)))
            cur.append(_passthrough_block(raw, span, None, None, low, lineno))
            seen_block = True
            continue

        if code[0] != "O" and fast_plain(code) is not None:
            segments = ((None, code),)
        else:
            c0 = code[0]
            if c0 == "%":
                meta["percent"] = True
                if seen_block:
                    break                       # text after the closing % is not program text
                continue
            if c0 == "$" or (c0 == "#" and len(code) > 1 and code[1].isalpha()) or _ARCHIVE.match(raw):
                if _ARCHIVE.match(raw):
                    meta["archive_header"] = raw.strip()
                    continue
                low.warn_once("directive", "NC403", "warning",
                              "controller/simulator directive kept verbatim", lineno)
                cur.append(Block(span, [Passthrough(raw.strip(), "directive", low.dialect)]))
                seen_block = True
                continue
            if _EXTERNAL_OUTPUT.match(code):
                # Fanuc macro B external output (Renishaw probing macros): a port, not motion
                cur.append(Block(span, [Passthrough(raw.strip(), "no motion effect (external output)",
                                                    low.dialect)]))
                seen_block = True
                continue
            if c0 == "O" and _LINUXCNC_O_WORD.match(code):
                # LinuxCNC's o-word subroutines and control flow are not Fanuc syntax: read as a
                # program number, the rest of the file would silently become subprograms
                diags.append(Diagnostic("NC002", "error", "LinuxCNC o-word control flow (o<n> "
                                        "sub/if/while/call ...) is not read by the ISO front end",
                                        file, lineno, 1))
                cur.append(_passthrough_block(raw, span, None, None, low, lineno))
                seen_block = True
                continue
            if c0 in "O:" and not code.startswith("OR"):
                m = _O_WORDS.match("O" + code[1:])
                if m is not None:
                    prog = m.group(1)
                    rest = code[m.end():]
                else:
                    m2 = _O_NAME.match("O" + code[1:])
                    prog = m2.group(1) if m2 is not None else code[1:]
                    rest = ""
                if not prog:                    # a bare ":" / "O": no program number
                    if rest or comment is not None:
                        cur.append(Block(span, [], comment=comment))
                    continue
                key = f"O{int(prog)}" if prog.isdigit() else f"O{prog}"
                if name is None and not low.main_ended and cur is main:
                    name = key
                    program.name = name
                    meta["program_number"] = int(prog) if prog.isdigit() else prog
                    if comment is not None:
                        meta["title"] = comment
                else:
                    close_loops(0)
                    sub = Subprogram(key, span, [])
                    subprograms[key] = sub
                    cur = sub.body
                    low.in_sub = True
                if not rest:
                    if comment is not None and cur is not main:
                        cur.append(Block(span, [], comment=comment))
                    continue
                code = rest
            segments = _split_skips(code)

        seen_block = True
        for skip, seg in segments:
            if not seg:                             # "/" alone (perhaps with a comment)
                if comment is not None or skip is not None:
                    cur.append(Block(span, [], None, None, skip, comment))
                comment = None
                continue
            items = None
            if fast_plain(seg) is not None:
                items = fast_words(seg)
            else:
                if words_of is None:
                    from .words import lark_words as words_of
                bad = _unbalanced(seg)
                unknown = _unknown_g(low, seg)
                if unknown is None and bad is not None:
                    other = "]" if seg[bad] == "[" else "["
                    diags.append(Diagnostic("NC003", "error", f"'{seg[bad]}' has no matching '{other}'",
                                            file, lineno,
                                            _raw_col(blanked, max(0, clean(blanked).find(seg)) + bad)))
                elif unknown is None:
                    try:
                        items = words_of(seg)
                    except Exception as err:    # lark's UnexpectedInput family
                        from lark.exceptions import UnexpectedInput
                        if not isinstance(err, UnexpectedInput):
                            raise
                        if _PLACEHOLDER.search(blanked):
                            low.warn_once("placeholder", "NC403", "warning",
                                          "template placeholder text in [ ] kept verbatim", lineno)
                        else:
                            diags.append(_syntax_diag(err, seg, blanked, file, lineno,
                                                      max(0, clean(blanked).find(seg))))
                if items is None:
                    cur.append(_passthrough_block(raw, span, skip, unknown, low, lineno))
                    comment = None
                    continue
            low.raw = blanked                   # for the columns of NC201 duplicates
            number, body, structure, unknown = lower(items, lineno)
            if unknown is not None:
                cur.append(_passthrough_block(raw, span, skip, unknown, low, lineno))
                comment = None
                continue
            for it in structure:
                if it[0] == "IFTHEN" and comment and any(_is_alarm(a[1]) for a in it[2]):
                    it[2].append(("comment", comment))      # IF[..]THEN#3000=n (MESSAGE)
                    comment = None
            if body or number is not None or comment is not None or not structure:
                for st in body:
                    if type(st) is Alarm and st.text is None and comment:
                        st.text = Str(comment)      # the alarm message is the block's comment
                        comment = None
                if comment and any(type(st) is Stop for st in body) and any(
                        _is_stop_message(it[1]) for it in items if it[0] == "=" and len(it) > 2):
                    body.insert(0, Message(Str(comment)))   # #3006=n (MESSAGE): shown, then the stop
                    comment = None
                cur.append(Block(span, body, number, None, skip, comment))
            comment = None
            for it in structure:
                tag = it[0]
                if tag == "IFTHEN":
                    # #3000=n after THEN raises the alarm as it does alone on a line
                    message = next((Str(a[1]) for a in it[2] if a[0] == "comment"), None)
                    then = [Alarm(a[2], message, ALARM_OWN_BASE) if _is_alarm(a[1]) else
                            Stop() if _is_stop_message(a[1]) else Assign(a[1], a[2])
                            for a in it[2] if a[0] != "comment"]
                    cur.append(If(span, it[1], [Block(span, then, skip=skip)]))
                elif tag in ("WHILE", "DO"):
                    node = While(span, it[1], [], it[2]) if tag == "WHILE" else Loop(span, [])
                    if tag == "DO":
                        node_label = it[1]
                    else:
                        node_label = it[2]
                    if len(stack) >= max_do_nesting:
                        # the controller's limit; kept out of the IR so no walker recurses deeper
                        diags.append(Diagnostic(
                            "NC008", "error", f"DO{node_label} nested {len(stack) + 1} levels deep: "
                            f"nesting too deep (at most {max_do_nesting} DO levels)",
                            file, lineno))
                        stack.append(_Frame(node, node_label, cur, lineno))
                        continue
                    cur.append(node)
                    stack.append(_Frame(node, node_label, cur, lineno))
                    cur = node.body
                else:                           # END m
                    label = it[1]
                    if stack and stack[-1].label == label:
                        fr = stack.pop()
                        cur = fr.parent
                    elif any(fr.label == label for fr in stack):
                        while stack[-1].label != label:
                            fr = stack.pop()
                            diags.append(Diagnostic("NC002", "error",
                                                    f"END{label} closes DO{label} across an open DO{fr.label}",
                                                    file, lineno))
                        cur = stack.pop().parent
                    else:
                        diags.append(Diagnostic("NC002", "error", f"END{label} without WHILE [...] DO{label}",
                                                file, lineno))
    while stack:
        fr = stack.pop()
        diags.append(Diagnostic("NC006", "error",
                                f"DO{fr.label} (line {fr.line}) has no END{fr.label}: the program is truncated",
                                file, fr.line))
    if not main and not main_seen and not subprograms:
        diags.append(Diagnostic("NC004", "error", "the file holds no NC blocks", file, 1))
    if low.local_calls:
        _local_subprograms(main, subprograms, low.local_calls, diags, file)
    if stream and main:
        yield from main
        main.clear()


_DROP_TABLE = {c: None for c in list(range(0x00, 0x21)) + [0x7F, 0x85, 0xA0, 0xFEFF]}


def _unknown_g(low: Lowering, code: str) -> Optional[str]:
    for m in _G_IN_TEXT.finditer(code):
        start = m.start()
        if start and code[start - 1] in "#[":      # inside an expression, not a G word
            continue
        if low.code("G", m.group(1)) is None:
            return "G" + m.group(1)
    return None


def _local_subprograms(main: list, subprograms: dict, numbers: set[int], diags: list,
                       file: str) -> None:
    """Haas M97 P<n>: the blocks of the main program from the one numbered n up to the first M99
    (a restart in a main program, a return here) become subprogram "N<n>". Blocks after the
    program end belong to the local subprograms only; one before it stays in the main body too."""
    def end_index(i: int) -> Optional[int]:
        for j in range(i, len(main)):
            node = main[j]
            if type(node) is Block and any(type(s) is ProgramEnd and s.kind == "restart"
                                           for s in node.body):
                return j
        return None
    ended = next((i for i, node in enumerate(main) if type(node) is Block and any(
        type(s) is ProgramEnd and s.kind != "restart" for s in node.body)), len(main))
    taken: list[tuple[int, int]] = []
    for num in sorted(numbers):
        start = next((i for i, node in enumerate(main) if type(node) is Block
                      and node.number is not None and node.number.isdigit()
                      and int(node.number) == num), None)
        stop = end_index(start) if start is not None else None
        if start is None or stop is None:
            continue          # the call stays unresolved: NC103 at the M97
        body = []
        for node in main[start:stop + 1]:
            if type(node) is Block and any(type(s) is ProgramEnd and s.kind == "restart"
                                           for s in node.body):
                node = Block(node.span, [Return(None) if type(s) is ProgramEnd else s
                                         for s in node.body], node.number, node.label, node.skip,
                             node.comment)
            body.append(node)
        subprograms[f"N{num}"] = Subprogram(f"N{num}", main[start].span, body)
        if start > ended:
            taken.append((start, stop))
    for start, stop in sorted(taken, reverse=True):
        del main[start:stop + 1]


def _is_stop_message(target) -> bool:
    """An assignment to #3006 (Fanuc macro B: stop with a message, as M00)."""
    return type(target) is Var and target.space == "num" and target.key == STOP_MESSAGE_VARIABLE


def _is_alarm(target) -> bool:
    """An assignment to #3000 (Fanuc macro B: raise alarm n)."""
    return type(target) is Var and target.space == "num" and target.key == ALARM_VARIABLE


def _passthrough_block(raw: str, span: Span, skip, unknown: Optional[str], low: Lowering,
                       line: int) -> Block:
    """A block kept verbatim: an unknown G code (with all its words, which belong to it) or a
    block that does not parse."""
    m = _LEAD_N.match(raw)
    head = raw[:m.end()]
    number = None
    nm = re.search(r"[Nn]\s*(\d+)", head)
    if nm:
        number = nm.group(1)
    text = raw[m.end():].strip()
    if unknown is not None:
        low.warn_once(unknown, "NC403", "warning",
                      f"{unknown} is not {low.code_kind} nctrans knows; the block is kept verbatim", line)
        reason = f"unknown code {unknown}"
    else:
        reason = "syntax error"
    return Block(span, [Passthrough(text, reason, low.dialect)] if text else [], number, None, skip)


def _split_skips(code: str) -> list:
    """Block-skip marks: a leading `/` or `/n` makes the block optional; in a block without macro
    expressions a `/` later in the block starts an optional tail (spec §1.5), kept as a block of
    its own with that skip level."""
    skip = None
    if code[0] == "/":
        m = _SKIP.match(code)
        skip = int(m.group(1) or 0)
        code = code[m.end():]
        if not code:
            return [(skip, "")]
    if "/" not in code or "#" in code or "[" in code:
        return [(skip, code)]
    parts = code.split("/")
    out = [(skip, parts[0])] if parts[0] else []
    for part in parts[1:]:
        level = 0
        if part[:1].isdigit():
            level = int(part[0])
            part = part[1:]
        if part:
            out.append((level, part))
    return out
