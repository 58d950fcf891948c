"""Fagor 8060/8065 front end: source text -> IR Program.

Per line: the block splitter (blocks.py: headers, comments, skip, N/label, paths) -> the lark
grammar of record (grammars/fagor.lark, LALR) -> lowering (this module) -> IR statements; then the
structure pass nests `$IF/$WHILE/$DO/$FOR/$SWITCH` bodies and files `%L` local subroutines under
Program.subprograms. Codes come from rules/fagor.toml, looked up by their neutral (group, value).

How Fagor meets the IR (spec §20.2):
- Local parameters P0..P99 live in the call frame (Var "local" `P<n>`: LL / L / #CALL share the
  caller's frame, #PCALL / #MCALL / G180.. open a new one with A..Z = P0..P25); global P100.. are
  Var "R" n. `V.` variables: the neutral ones (positions, tool, feed, speed) read what the
  interpreter publishes; `V.P.` / `V.S.` user variables are names; anything else is read from the
  machine model's `variables` table or is unknown, reported NC135 at its line, never taken as 0.
- `$SWITCH` becomes an IR Case with jumps to generated labels; `$BREAK` / `$CONTINUE` become jumps
  to labels generated after / at the end of the loop; `$DO .. $ENDDO c` is a RepeatUntil(not c).
- D<n> selects offset n of the active tool: tool length compensation on (ModeChange tool_length),
  radius from offset n; D0 cancels both; M06 implies D1 (spec §8.9, §12.3). There is no G43/G44.
- Polar R/Q about the G30 origin are modelled (interp/polar_words.py, incremental under G91).
- What changes the path but is not modelled (G36-G39, mirror G14 by axis, canned
  cycles whose parameters the programming manual does not define, #CS, #RTCP ...) is kept verbatim
  as Passthrough with NC415/NC416 at its line: never silently skipped.
"""
from __future__ import annotations

import copy
import re
from functools import lru_cache
from typing import Any, Optional

from nctrans import limits, resources
from nctrans.diagnostics import Diagnostic
from nctrans.dialects.base import ParseResult
from nctrans.ir import nodes as ir
from nctrans.ir import walk as ir_walk
from nctrans.rules import load_table, normalise_code

from . import blocks

DIALECT = "fagor"
GRAMMAR = resources.path("grammars", "fagor.lark")
STARTS = ["start", "call_tail", "msg_tail", "value_tail", "words_tail", "rpt_tail"]
AXES = "XYZUVWABC"
LOCAL_PARAMS = 100
PARAM_LETTERS = "ABCDEFGHIJKLMNOPQRSTUVWXYZ"

# rs274-style order of execution inside a block (the interpreter runs Block.body as listed)
(B_ASSIGN, B_FEEDMODE, B_FEED, B_SPMODE, B_SPEED, B_TOOL, B_M6, B_SPINDLE, B_COOLANT, B_DWELL,
 B_PLANE, B_UNITS, B_COMP, B_TLC, B_WCS, B_PATH, B_DIST, B_RETRACT, B_NONMODAL, B_MOTION,
 B_CALL, B_END) = range(22)
SIMPLE_GROUPS = {
    "feed_mode": B_FEEDMODE, "spindle_mode": B_SPMODE, "spindle": B_SPINDLE, "coolant": B_COOLANT,
    "plane": B_PLANE, "units": B_UNITS, "cutter_comp": B_COMP, "path_mode": B_PATH,
    "exact_stop_once": B_PATH, "arc_distance": B_DIST, "distance": B_DIST,
    "cycle_retract": B_RETRACT, "work_offset": B_WCS, "corner": B_PATH, "diameter": B_UNITS,
}
# functions: Fagor name -> neutral IR name (SQR is the square, spec §6.6)
FUNCS = {"SIN": "sin", "COS": "cos", "TAN": "tan", "ASIN": "asin", "ACOS": "acos", "ATAN": "atan",
         "ARG": "atan2", "ABS": "abs", "SQRT": "sqrt", "LOG": "log10", "LN": "ln", "EXP": "exp",
         "DEXP": "dexp", "INT": "trunc", "FRACT": "fract", "ROUND": "round", "FUP": "fup",
         "EXIST": "exist", "INV": "bnot"}
# instructions by what the front end does with them
MESSAGES = {"#MSG": "message", "#WARNING": "warning", "#WARNINGSTOP": "warning", "#ERROR": "error"}
NO_EFFECT = frozenset((  # no effect on the programmed path: kept verbatim, no diagnostic
    "#FLUSH", "#ESBLK", "#DSBLK", "#ESTOP", "#DSTOP", "#EFHOLD", "#DFHOLD", "#DGWZ", "#SLOPE",
    "#ROUNDPAR", "#HSC", "#SYNC", "#UNSYNC", "#TSYNC", "#SERVO", "#CD", "#MEET", "#WAIT", "#SIGNAL",
    "#CLEAR", "#SWTOUT", "#PWMOUT", "#DELETE", "#INIT", "#ABORT", "#SELECT", "#MASTER", "#TANGFEED",
    "#CONTJOG", "#INCJOG", "#MPG", "#AXIS", "#KIN", "#ROTATEMZ", "#DEF", "#INIT"))
# Passthrough reason of constructs with no effect on the programmed path (dynamics, look-ahead,
# software limits, search folders): the word the shared passes read as "no motion effect"
NO_PATH_EFFECT = "directive"
NUMBERED_AXIS = re.compile(r"^([XYZUVWABC])([1-9])$")


class _LarkNotLoaded(Exception):
    """What lark's names below stand for until _load_lark(): nothing is an instance of it."""


# lark (~15 ms of start-up, and ~10 ms more for the cached tables) is imported when the first block
# needs the grammar: blocks of letter-number words (_plain_items, the kernel's runs) never do, so a
# CAM program runs without it. Until then its names are the placeholder above.
Lark = Token = Tree = _LarkNotLoaded
LarkError = UnexpectedCharacters = UnexpectedInput = UnexpectedToken = _LarkNotLoaded


def _load_lark() -> None:
    global Lark, Token, Tree, LarkError, UnexpectedCharacters, UnexpectedInput, UnexpectedToken
    from lark import Lark, Token, Tree
    from lark.exceptions import LarkError, UnexpectedCharacters, UnexpectedInput, UnexpectedToken


@lru_cache(maxsize=1)
def parser():
    """The LALR parser of grammars/fagor.lark (tables cached on disk, see lark_cache)."""
    from nctrans.lark_cache import cache_option
    _load_lark()
    return Lark(GRAMMAR.read_text(encoding="utf-8"), parser="lalr", lexer="basic", start=STARTS,
                propagate_positions=False, maybe_placeholders=False, cache=cache_option("fagor"))


@lru_cache(maxsize=1)
def table():
    return load_table(DIALECT)


# ------------------------------------------------------------------ expressions

class _Expr:
    """Tree -> IR expression. Reports V. variables it cannot read (NC135) through `note`."""

    def __init__(self, note):
        self.note = note
        self.writing = False

    def __call__(self, t) -> ir.Expr:
        if type(t) is ir.Num:           # a word read without the grammar (_plain_items)
            return t
        if isinstance(t, Token):
            if t.type == "NUMBER":
                return ir.Num(float(t), str(t))
            raise ValueError(f"unexpected token {t!r}")
        d = t.data
        ch = t.children
        if d == "num":
            return ir.Num(float(ch[0]), str(ch[0]))
        if d == "hex":
            return ir.Num(float(int(str(ch[0])[1:], 16)), str(ch[0]))
        if d == "true":
            return ir.Num(1.0, "TRUE")
        if d == "false":
            return ir.Num(0.0, "FALSE")
        if d == "param":
            return param_var(int(str(ch[0]).lstrip("P")))
        if d == "param_ind":
            self.note("NC136", "info", "P[expr] is read and written as a global parameter; an index "
                      "below 100 (a local parameter) is not followed")
            return ir.Var("R", None, [self(ch[0])])
        if d == "var":
            return self.var(t)
        if d == "neg":
            inner = self(ch[0])
            if isinstance(inner, ir.Num):
                return ir.Num(-inner.value, "-" + (inner.text or ""))
            return ir.Unary("-", inner)
        if d in _BINOPS:
            return ir.Binary(_BINOPS[d], self(ch[0]), self(ch[1]))
        if d == "compare":
            return ir.Binary(str(ch[1]), self(ch[0]), self(ch[2]))
        if d == "func":
            name = str(ch[0])
            args = [self(a) for a in ch[1:]]
            if name == "SQR":
                return ir.Binary("pow", args[0], ir.Num(2.0, "2"))
            if name == "ARG":            # ARG[x,y]: angle of the vector (x, y), 0..360
                return ir.Func("atan2", [args[1], args[0]] if len(args) == 2 else args)
            if name == "DEXP":
                return ir.Binary("pow", ir.Num(10.0, "10"), args[0])
            if name == "LOG":
                return ir.Binary("/", ir.Func("ln", args), ir.Func("ln", [ir.Num(10.0, "10")]))
            if name == "FRACT":
                return ir.Binary("-", args[0], ir.Func("trunc", args))
            if name == "INT":
                return ir.Func("trunc", args)
            if name == "EXIST":
                self.note("NC415", "warning", "EXIST[..] depends on the controller's variable table; "
                          "analysed as unknown")
                return ir.Var("system", "EXIST")
            return ir.Func(FUNCS[name], args)
        if d == "assign":
            raise ValueError("assignment inside an expression")
        # a transparent rule (value, atom ...) with one child
        if len(ch) == 1:
            return self(ch[0])
        raise ValueError(f"unknown expression node {d}")

    def var(self, t: Tree) -> ir.Var:
        ch = t.children
        name = str(ch[0])
        idx = [self(c.children[0]) for c in ch[1:] if isinstance(c, Tree) and c.data == "index"]
        tail = "".join(str(c) for c in ch[1:] if isinstance(c, Token) and c.type == "VTAIL")
        return v_variable(name, idx, tail, (lambda *a, **k: None) if self.writing else self.note)


_BINOPS = {"add": "+", "sub": "-", "mul": "*", "div": "/", "pow": "pow", "mod": "mod",
           "band": "band", "bor": "bor", "bxor": "bxor"}


def param_var(n: int) -> ir.Var:
    """P<n>: local parameters (P0..P99) in the call frame (a call binds them, an LL / L / #CALL
    shares them; reading one before it is assigned is NC101), global ones by number."""
    if n < LOCAL_PARAMS:
        return ir.Var("local", f"P{n}")
    return ir.Var("R", n)


def v_variable(name: str, idx: list, tail: str, note) -> ir.Var:
    """A V. variable as an IR variable: V.P./V.S. user variables are local names; system variables
    keep their Fagor spelling (the evaluator finds their neutral meaning through rules/fagor.toml
    [system_variables]); one the table does not know is reported (NC135)."""
    full = name + tail
    parts = name.split(".")
    if len(parts) >= 3 and parts[1] in ("P", "S") and not idx:
        # user variables live with the local parameters (created by their first assignment);
        # V.S globals are analysed in the program's frame too (shared by LL, L and #CALL)
        return ir.Var("local", full.upper())
    spelling = re.sub(r"^V\.\[\d+\]\.", "V.", full.upper())   # the channel selector does not change it
    if idx or spelling not in table().system_variables:
        note("NC135", "warning", f"{full} is not in the neutral system-variable vocabulary: it is read "
             "from the machine model's `variables` table, else it is unknown (never taken as 0)")
    return ir.Var("system", spelling, idx or None)


# ------------------------------------------------------------------ lowering of one block

class _Words:
    def __init__(self):
        self.out: list[tuple[int, Any]] = []
        self.vals: dict[str, ir.Expr] = {}
        self.gs: list[tuple[Any, str, Optional[ir.Expr]]] = []   # (rule, code, "=" value)
        self.ms: list[tuple[Any, str]] = []
        self.numbered: dict[str, ir.Expr] = {}
        self.extra: list[ir.Expr] = []        # bare number after G04 / G131 / G133
        self.call: Optional[ir.SubCall] = None
        self.call_params: dict[str, ir.Expr] = {}


class Lowerer:
    def __init__(self, file: str):
        self.file = file
        self.diags: list[Diagnostic] = []
        self.motion = "rapid"            # static modal motion (decides what R means)
        self.s_negative = False          # the last S was negative: G63 taps counterclockwise
        self.cycle = False               # a Fagor canned cycle is modal
        self.line = 0
        self.col = 1
        self._once: set = set()
        self.expr = _Expr(self.note)
        self.soft_limits: list[dict] = []
        self.mirror: set[str] = set()     # axes mirrored by G11-G14, in source order
        self.offset: ir.Expr = ir.Num(1.0, "1")   # the D in force (D1 is the default)
        self.distance = "absolute"                 # G90/G91 in source order (for G198/G199)
        self.plane = "XY"                          # G17-G19 in source order (G30 I J letters)
        self.local_shift: dict[str, ir.Expr] = {}  # G158 per axis, in source order

    def note(self, rule: str, severity: str, message: str, col: Optional[int] = None) -> None:
        self.diags.append(Diagnostic(rule, severity, message, self.file, self.line, col or self.col))

    def once(self, key, rule, severity, message) -> None:
        if key not in self._once:
            self._once.add(key)
            self.note(rule, severity, message)

    def code(self, letter: str, value: ir.Expr) -> Optional[str]:
        if isinstance(value, ir.Num):
            text = value.text or repr(value.value)
            try:
                return normalise_code(letter, text.lstrip("+"))
            except ValueError:
                return None
        return None

    # ---------------------------------------------------------------- items
    def items(self, items: list, line: blocks.Line) -> list:
        """Lower the items of one block (ISO words, assignments, calls) to ordered statements."""
        w = _Words()
        out = w.out
        param_mode = False
        for it in items:
            d = it.data
            ch = it.children
            if param_mode:
                self._param(w, it)
                continue
            if d in ("word", "gword"):
                letter = "G" if d == "gword" else str(ch[0])
                value = self.expr(ch[1])
                if letter == "G":
                    if len(ch) > 2:
                        w.extra.append(ir.Num(float(ch[2]), str(ch[2])))
                    code = self.code("G", value)
                    rule = table().lookup(code) if code else None
                    if code is None:
                        self.note("NC415", "warning", "G code given by an expression: its effect is "
                                  "not analysed; kept verbatim")
                        out.append((B_NONMODAL, ir.Passthrough("G" + _text(ch[1]), "computed G code",
                                                               DIALECT)))
                        continue
                    if rule is None:
                        self.note("NC415", "warning", f"{code} is not a Fagor 8060/8065 G function "
                                  "known here; kept verbatim, its effect is not analysed")
                        out.append((B_NONMODAL, ir.Passthrough(code, "unknown G code", DIALECT)))
                        continue
                    w.gs.append((rule, code, None))
                    if rule.group == "call":
                        w.call = ir.SubCall(code, kind="pcall")
                        param_mode = True
                elif letter == "M":
                    code = self.code("M", value)
                    rule = table().lookup(code) if code else None
                    w.ms.append((rule, code or "M" + _text(ch[1])))
                else:
                    if letter in w.vals:
                        self.note("NC201", "warning", f"address {letter} written twice in the block; "
                                  "the last one counts")
                    w.vals[letter] = value
            elif d == "nr_word":
                w.vals["NR"] = self.expr(ch[0])
            elif d == "mg_call":
                code = "G" + str(ch[0])[2:]
                w.call = ir.SubCall(code, kind="pcall", modal="after_move")
                param_mode = True
            elif d == "numbered":
                name = str(ch[0])
                value = self.expr(ch[1])
                if name in ("G159", "G263"):
                    rule = table().lookup(name)
                    w.gs.append((rule, name, value))
                else:
                    w.numbered[name] = value
            elif d == "spos":
                self.once("spos", "NC415", "info", "spindle positioning speed S.POS= has no effect on "
                          "the path; kept verbatim")
                out.append((B_NONMODAL, ir.Passthrough(f"{ch[0]}={_text(ch[1])}", NO_PATH_EFFECT,
                                                       DIALECT)))
            elif d == "assign":
                self.expr.writing = True          # a write is not a read of an unknown value
                try:
                    target = self.expr(ch[0])
                finally:
                    self.expr.writing = False
                op = next((str(c) for c in ch[1:-1] if isinstance(c, Token)), "=")
                value = self.expr(ch[-1])
                if op != "=":
                    value = ir.Binary(op[0], target, value)
                if target.space == "system":
                    self.note("NC415", "warning", f"writing {target.key} is kept for later reads; its "
                              "effect on the machine (offsets, limits, tables) is not modelled")
                out.append((B_ASSIGN, ir.Assign(target, value)))
            elif d == "ll_call":
                out.append((B_CALL, ir.SubCall(_unquote(ch[0]), kind="shared")))
            elif d == "l_call":
                out.append((B_CALL, ir.SubCall(_program_name(_unquote(ch[0])), kind="shared")))
            elif d == "macro_ref":
                self.note("NC102", "error", f"macro {ch[0]} is not defined by a #DEF before it")
                out.append((B_NONMODAL, ir.Passthrough(str(ch[0]), "macro call", DIALECT)))
        return self._words(w, line)

    def _param(self, w: _Words, it: Tree) -> None:
        """A word after a G180../MG.. call code: a call parameter (spec §13.2)."""
        d, ch = it.data, it.children
        if d in ("word", "gword"):
            letter = "G" if d == "gword" else str(ch[0])
            w.call_params[letter] = self.expr(ch[1])
        elif d == "assign" and ch[0].data == "param":
            w.call_params["P" + str(ch[0].children[0]).lstrip("P")] = self.expr(ch[-1])
        else:
            self.note("NC002", "error", "only parameters (A..Z, P<n>=) may follow a subroutine call "
                      "code in its block")

    def _words(self, w: _Words, line: blocks.Line) -> list:
        out = w.out
        vals = w.vals
        motion_g = None
        arc_once = None
        frame = None
        home = setpos = dwell = soft = pole = shift = limit = False
        unmodelled = []
        for rule, code, eq in w.gs:
            g, v = rule.group, rule.value
            if g == "motion":
                motion_g = v
                out.append((B_MOTION - 1, ir.ModeChange("motion", v, code)))
            elif g == "work_offset" and code == "G159":
                n = _const(eq)
                if n is None or n < 1 or n > 99 or n != int(n):
                    self.note("NC105", "error", "G159=<n> needs a constant offset number 1..99")
                    continue
                name = f"G{53 + int(n)}" if n <= 6 else f"G54.1P{int(n) - 6}"
                out.append((B_WCS, ir.ModeChange("work_offset", name, f"G159={int(n)}")))
            elif g in SIMPLE_GROUPS:
                out.append((SIMPLE_GROUPS[g], ir.ModeChange(g, v, code)))
                if g == "distance":
                    self.distance = v
                elif g == "plane":
                    self.plane = v
                elif g == "work_offset" and v == "G53" and self.local_shift:
                    self.local_shift = {}            # G53 cancels G158 too (spec §7.15)
                    out.append((B_WCS + 1, ir.FrameOp("trans", clear=True, local=True)))
            elif g == "cycle":
                if v == "off":
                    self.cycle = False
                    out.append((B_NONMODAL, ir.ModeChange("cycle", "off", code)))
                else:
                    self.cycle = True
                    self.note("NC416", "warning", f"canned cycle {code}: its parameters are defined in "
                              "Fagor's cycles manual, not the programming manual; kept as a structured "
                              "node, its motion is not analysed")
            elif g == "probe":
                self.note("NC416", "warning", f"probing move {code}: described in Fagor's probing "
                          "manual; its motion is not analysed")
                unmodelled.append(code)
            elif g == "dwell":
                dwell = True
            elif g == "home":
                home = True
            elif g == "set_position":
                setpos = True
            elif g == "frame":
                frame = (code, v)
            elif g == "arc_once":
                arc_once = v
            elif g == "arc_radius":
                self.note("NC415", "warning", "G263= modal arc radius is not modelled; program R on "
                          "the arc")
                unmodelled.append(f"G263={_text_expr(eq)}")
            elif g == "soft_limit":
                soft = True
            elif g == "polar_pole":
                pole = True
            elif g == "incremental_offset":
                shift = True
            elif g == "call":
                pass
            elif g == "spindle_limit":
                limit = True                      # G192 S<rpm>: the S word is the limit
            elif g == "dynamics":
                out.append((B_NONMODAL, ir.Passthrough(code, NO_PATH_EFFECT, DIALECT)))
            else:        # unmodelled
                self.note("NC415", "warning", f"{code} ({rule.meaning}) changes the path in a way the "
                          "interpreter does not model; kept verbatim")
                unmodelled.append(code)

        if w.extra and not dwell and not any(c in ("G131", "G133") for _, c, _ in w.gs):
            self.note("NC002", "error", "a bare number follows a G function that takes none")

        for rule, code in w.ms:
            if rule is None:
                self.note("NC415", "warning", f"{code} is not in the M table known here (an OEM "
                          "function); kept verbatim")
                out.append((B_NONMODAL, ir.Passthrough(code, "machine-specific M function", DIALECT)))
                continue
            g, v = rule.group, rule.value
            if g in SIMPLE_GROUPS:
                out.append((SIMPLE_GROUPS[g], ir.ModeChange(g, v, code)))
            elif g == "stop":
                out.append((B_END, ir.Stop(optional=v == "optional")))
            elif g == "program_end":
                out.append((B_END, ir.ProgramEnd(v)))
            elif g == "return":
                out.append((B_END, ir.Return()))
            elif g == "tool_change":
                out.append((B_M6, ir.ToolChange()))
                if "D" not in vals:       # after a tool change D1 is implicit (spec §8.9)
                    out.append((B_M6, ir.ModeChange("tool_length", "plus", "D1")))
                    self.offset = ir.Num(1.0, "1")
            else:
                out.append((B_NONMODAL, ir.Passthrough(code, NO_PATH_EFFECT, DIALECT)))
        for q_m, q in line.qualifiers:
            if re.search(r"\.S[2-9]", q):
                self.note("NC415", "warning", f"M{q_m}{q} addresses another spindle than the first; "
                          "only spindle S/S1 is modelled")

        if motion_g is None and self.motion == "tap_interp" and any(
                r is not None and r.group == "spindle" for r, _ in w.ms):
            # M3/M4/M5/M19 cancel G63 (spec 9.8, L8556-8780): back to the power-on motion the
            # reader assumes at the start of a program
            motion_g = "rapid"
            out.append((B_MOTION - 1, ir.ModeChange("motion", "rapid", "")))
        if motion_g is not None:
            self.motion = motion_g
            self.cycle = False

        if "F" in vals:
            out.append((B_FEED, ir.Feed(vals.pop("F"))))
        if frame is not None and frame[1] == "scale" and "S" in vals:
            pass                                  # G72 S<f>: S is the factor
        elif limit and "S" in vals:
            out.append((B_SPEED, ir.SpindleLimit(vals.pop("S"))))
        elif "S" in vals:
            speed = vals.pop("S")
            value = ir_walk.literal(speed)
            if value is not None:
                self.s_negative = value < 0
                if self.motion == "tap_interp":
                    speed = ir.Num(abs(value), format(abs(value), "g"))
            elif self.motion == "tap_interp":
                self.note("NC415", "warning", "G63 with a computed S: the sign of S is the spindle "
                          "direction, read here as the sign of the last constant S")
            if self.motion == "tap_interp":  # G63: the sign of S turns the spindle, M3/M4 do not
                out.append((B_SPEED, ir.ModeChange("spindle", "ccw" if self.s_negative else "cw", "")))
            out.append((B_SPEED, ir.SpindleSpeed(speed)))
        elif self.motion == "tap_interp":
            out.append((B_SPEED, ir.ModeChange("spindle", "ccw" if self.s_negative else "cw", "")))
        for name in list(w.numbered):
            if name in ("S1",):
                out.append((B_SPEED, ir.SpindleSpeed(w.numbered.pop(name))))
        if "T" in vals:
            out.append((B_TOOL, ir.ToolSelect(vals.pop("T"))))
        if "D" in vals:
            # D: offset of the active tool; its length applies at once, its radius is what the next
            # G41/G42 uses (so it is handed to the IR with the compensation that reads it)
            d = vals.pop("D")
            zero = _const(d) == 0
            out.append((B_TLC, ir.ModeChange("tool_length", "off" if zero else "plus",
                                             "D" + _text_expr(d))))
            self.offset = d
        if any(r.group == "cutter_comp" and r.value != "off" for r, _, _ in w.gs):
            out.append((B_COMP, ir.OffsetSelect("radius", self.offset)))
        if "H" in vals:
            out.append((B_NONMODAL, ir.Passthrough("H" + _text_expr(vals.pop("H")), "H function to "
                                                   "the PLC", DIALECT)))

        if dwell:
            t = vals.pop("K", None)
            if t is None and w.extra:
                t = w.extra[0]
            if t is None:
                self.note("NC105", "error", "G04 needs a time: G04 K<s> or G04 <s>")
            else:
                out.append((B_DWELL, ir.Dwell(seconds=t)))
        if soft:
            self._soft_limits(w, vals, out)
        if home:
            axes = {a: vals.pop(a) for a in list(vals) if a in AXES}
            self.note("NC415", "warning", "G74 home search: the machine reference point is not in the "
                      "machine model; the position after it is not analysed")
            out.append((B_NONMODAL, ir.Passthrough("G74 " + " ".join(f"{a}{_text_expr(e)}"
                                                                      for a, e in axes.items()),
                                                   "home search", DIALECT)))
        if setpos:
            target = {a: ir.AxisValue(vals.pop(a)) for a in list(vals) if a in AXES}
            out.append((B_NONMODAL, ir.SetPosition(target)))
        if frame is not None:
            self._frame(frame, vals, out)
        if pole:
            # G30 I J: the polar origin at (I, J) of the plane, absolute in work coordinates; G30
            # alone: at the current point (spec §7.16)
            if "I" in vals or "J" in vals:
                a1, a2 = _PLANE_LETTERS[self.plane]
                target = {a1: ir.AxisValue(vals.pop("I", ir.Num(0.0, "0"))),
                          a2: ir.AxisValue(vals.pop("J", ir.Num(0.0, "0")))}
                out.append((B_NONMODAL, ir.PolarPole("zero", target, code="G30")))
            else:
                out.append((B_NONMODAL, ir.PolarPole("last_point", {}, code="G30")))
        if shift:
            # G158 X Y: incremental zero offset, per axis (a new value replaces that axis'; G158
            # alone cancels all); followed in source order and written whole, as G53 clears it
            axes = {a: vals.pop(a) for a in list(vals) if a in AXES}
            if not axes:
                self.local_shift = {}
            self.local_shift.update(axes)
            self.local_shift = {a: e for a, e in self.local_shift.items() if _const(e) != 0}
            out.append((B_WCS + 1, ir.FrameOp("trans", dict(self.local_shift), local=True)
                        if self.local_shift else ir.FrameOp("trans", clear=True, local=True)))

        # numbered axes and spindles other than the first (X1=.., S2=..): not in the machine model
        for name, value in w.numbered.items():
            self.note("NC415", "warning", f"{name}= addresses an axis or spindle the machine model does "
                      "not have; kept verbatim")
            out.append((B_NONMODAL, ir.Passthrough(f"{name}={_text_expr(value)}", "numbered axis",
                                                   DIALECT)))

        if w.call is not None:
            call = w.call
            call.named_args = dict(w.call_params)
            call.bindings = {k: (param_var(PARAM_LETTERS.index(k)) if len(k) == 1 else
                                 param_var(int(k[1:]))) for k in call.named_args}
            out.append((B_CALL, call))

        cycle_code = next((c for r, c, _ in w.gs if r.group == "cycle" and r.value != "off"), None)
        if cycle_code is not None:
            # the cycle block's words are the cycle's parameters (its own manual defines them)
            words = " ".join(f"{k}{_text_expr(e)}" for k, e in vals.items())
            vals.clear()
            out.append((B_MOTION, ir.Passthrough(f"{cycle_code} {words}".strip(), "canned cycle",
                                                 DIALECT)))
        elif self.cycle and any(a in vals for a in AXES):
            self.note("NC416", "warning", "positioning while a canned cycle is modal: the cycle would "
                      "run here; only the positioning is analysed")

        if unmodelled:
            # the words of a function the interpreter does not model are its own (G30 I J, G36 I,
            # G158 X Y, G33 Z K ...): kept with it, and the block's path is not analysed
            words = " ".join(f"{k}{_text_expr(e)}" for k, e in vals.items())
            unmodelled = [" ".join(unmodelled + ([words] if words else []))]
            vals.clear()
        motion = self._motion(vals, arc_once, motion_g, out)
        nr = vals.pop("NR", None)
        if motion is not None:
            reps = 1
            if nr is not None:
                c = _const(nr)
                if c is None or c < 0 or c != int(c):
                    self.note("NC415", "warning", "NR with a computed count: the block is analysed once")
                else:
                    reps = int(c)
            for _ in range(reps):
                out.append((B_MOTION, motion))
        elif nr is not None:
            self.note("NC105", "warning", "NR repeats only blocks with a motion")

        for code in unmodelled:
            out.append((B_NONMODAL, ir.Passthrough(code, "not modelled", DIALECT)))
        for k, v in list(vals.items()):
            self.note("NC415", "warning", f"{k}{_text_expr(v)}: address {k} has no meaning in this block "
                      "here; kept verbatim")
            out.append((B_NONMODAL, ir.Passthrough(f"{k}{_text_expr(v)}", f"address {k}", DIALECT)))
        out.sort(key=lambda x: x[0])
        return [s for _, s in out]

    def _motion(self, vals: dict, arc_once, motion_g, out) -> Optional[ir.Motion]:
        target = {a: ir.AxisValue(vals.pop(a)) for a in [k for k in vals if k in AXES]}
        mode = motion_g or self.motion
        arc = mode in ("arc_cw", "arc_ccw") or arc_once in ("tangent", "three_point")
        center = radius = polar = via = None
        if "Q" in vals or ("R" in vals and not arc):
            polar = {}
            if "R" in vals:
                polar["radius"] = vals.pop("R")
            if "Q" in vals:
                polar["angle"] = vals.pop("Q")
        if arc_once == "three_point":
            via = {a: ir.AxisValue(vals.pop(k)) for k, a in zip("IJK", "XYZ") if k in vals}
            out.append((B_MOTION - 1, ir.ModeChange("motion", "arc_3point", "G09")))
            out.append((B_MOTION + 1, ir.ModeChange("motion", self.motion, "")))
        elif arc_once == "tangent":
            out.append((B_MOTION - 1, ir.ModeChange("motion", "arc_tangent", "G08")))
            out.append((B_MOTION + 1, ir.ModeChange("motion", self.motion, "")))
        elif arc:
            cmode = "abs" if arc_once == "absolute_centre" else None
            if vals.keys() & set("IJK"):
                center = {k: ir.AxisValue(vals.pop(k), cmode) for k in "IJK" if k in vals}
            if "R" in vals:
                radius = vals.pop("R")
            if "R1" in vals:
                radius = vals.pop("R1")
        if target or center or radius is not None or polar or via:
            return ir.Motion(target, center, radius, None, via=via, polar=polar)
        return None

    def _frame(self, frame, vals: dict, out) -> None:
        code, kind = frame
        if kind == "scale":
            s = vals.pop("S", None)
            c = _const(s) if s is not None else 0.0
            if s is None or c in (0.0, 1.0):
                out.append((B_NONMODAL, ir.FrameOp("scale", clear=True)))
            else:
                out.append((B_NONMODAL, ir.FrameOp("scale", {a: s for a in "XYZ"}, additive=True)))
        elif kind == "rotation":
            q = vals.pop("Q", None)
            i, j = vals.pop("I", None), vals.pop("J", None)
            if q is None:
                out.append((B_NONMODAL, ir.FrameOp("rot", clear=True)))
            else:
                center = None
                if i is not None or j is not None:
                    center = {"X": ir.AxisValue(i or ir.Num(0.0)), "Y": ir.AxisValue(j or ir.Num(0.0))}
                # G73 Q is incremental: it adds to the rotation in force (spec §10.5)
                out.append((B_NONMODAL, ir.FrameOp("rot", angle=q, center=center, additive=True)))
        elif kind == "mirror_off":
            self.mirror = set()
            out.append((B_NONMODAL, ir.FrameOp("mirror", clear=True)))
        else:
            # G11/G12/G13 add an axis, G14 X-1 / X1 switch axes on / off (spec §10.4); the mirror
            # set is followed in source order and written whole, since the IR's mirror replaces
            if kind == "mirror_axes":
                for a in [a for a in list(vals) if a in AXES]:
                    c = _const(vals.pop(a))
                    if c not in (1.0, -1.0):
                        self.note("NC105", "error", f"G14 {a} takes -1 (mirror on) or 1 (off)")
                        continue
                    (self.mirror.add if c == -1.0 else self.mirror.discard)(a)
            else:
                self.mirror.add(kind[-1].upper())
            if self.mirror:
                out.append((B_NONMODAL, ir.FrameOp("mirror", {a: ir.Num(1.0) for a in sorted(
                    self.mirror)}, additive=True)))
            else:
                out.append((B_NONMODAL, ir.FrameOp("mirror", clear=True)))

    def _soft_limits(self, w: _Words, vals: dict, out) -> None:
        """G198/G199: software limits for the machine check (TravelLimit; constant ones also as
        Program.meta["soft_limits"])."""
        for rule, code, _ in w.gs:
            if rule.group != "soft_limit":
                continue
            axes = {a: vals.pop(a) for a in list(vals) if a in AXES}
            # G90: machine coordinates; G91: relative to the limit in force (spec §11.2)
            entry = {"line": self.line, "bound": rule.value, "axes": {},
                     "incremental": self.distance == "incremental"}
            for a, e in axes.items():
                c = _const(e)
                if c is not None:           # (the interpreter evaluates computed values)
                    entry["axes"][a] = c
            self.soft_limits.append(entry)
            # machine axis positions (the interpreter sends them to the check as `limits`)
            out.append((B_NONMODAL, ir.TravelLimit(
                rule.value, "machine", axes, incremental=self.distance == "incremental",
                text=code + " " + " ".join(f"{a}{_text_expr(e)}" for a, e in axes.items()),
                dialect=DIALECT)))


_PLANE_LETTERS = {"XY": ("X", "Y"), "ZX": ("Z", "X"), "YZ": ("Y", "Z")}


def _const(e) -> Optional[float]:
    if isinstance(e, ir.Num):
        return e.value
    if isinstance(e, ir.Unary) and e.op == "-" and isinstance(e.operand, ir.Num):
        return -e.operand.value
    return None


def _text(t) -> str:
    if isinstance(t, Token):
        return str(t)
    return "".join(_text(c) for c in t.children)


def _text_expr(e) -> str:
    from .emitter import format_expr
    try:
        return format_expr(e)
    except Exception:
        return "?"


def _unquote(tok) -> str:
    s = str(tok)
    return s[1:-1] if s.startswith('"') else s


def _program_name(path: str) -> str:
    """A global subroutine is called by its file name (with optional path): the resolver's name."""
    return path.replace("\\", "/").rsplit("/", 1)[-1]


# ------------------------------------------------------------------ instructions

_INSTR = re.compile(r'#([A-Z][A-Z0-9]*)')


def find_instruction(code: str) -> Optional[tuple[int, int, str]]:
    """(start, end, name) of the `#` instruction in a block (outside strings), or None."""
    if "#" not in code:
        return None
    inq = False
    for i, ch in enumerate(code):
        if ch == '"':
            inq = not inq
        elif ch == "#" and not inq:
            m = _INSTR.match(code, i)
            if m:
                return i, m.end(), "#" + m.group(1)
    return None


# ------------------------------------------------------------------ structure

# grammar rules that open a control structure, and the structure's name
_OPENERS = {"if_": "$IF", "while_": "$WHILE", "do_": "$DO", "for_": "$FOR", "switch": "$SWITCH"}


class _Open:
    __slots__ = ("kind", "node", "body", "line", "extra")

    def __init__(self, kind, node, body, line, extra=None):
        self.kind, self.node, self.body, self.line, self.extra = kind, node, body, line, extra


class _Unit:
    def __init__(self, name: Optional[str], span: ir.Span):
        self.name = name
        self.span = span
        self.body: list = []
        self.stack: list[_Open] = []

    @property
    def current(self) -> list:
        return self.stack[-1].body if self.stack else self.body


class Parser:
    """One program: lines -> units of structured IR."""

    def __init__(self, text: str, file: str):
        self.file = file
        self.low = Lowerer(file)
        self.diags = self.low.diags
        self.main = _Unit(None, ir.Span(file, 1))
        self.subs: list[_Unit] = []
        self.unit = self.main
        self.meta: dict = {"defaults": table().defaults()}
        self.labels = 0
        self.rpts: list = []
        self.macros: dict[str, str] = {}       # #DEF table: name -> block text
        self.text = text

    def error(self, rule: str, message: str, line: int, col: int = 1, severity: str = "error") -> None:
        self.diags.append(Diagnostic(rule, severity, message, self.file, line, col))

    def fresh(self, what: str) -> str:
        self.labels += 1
        return f"{what}{self.labels}"

    def run(self) -> ir.Program:
        for line in blocks.lines(self.text):
            self.take(line)
        self.close_unit(None)
        self.unit = self.main
        self.close_unit(None)
        return self.program()

    def take(self, line: blocks.Line) -> None:
        """One split line into the unit being read (the streamed parse, nctrans.dialects.fagor.
        stream, hands its lines here one at a time as well)."""
        if line.kind == "unclosed_comment":
            self.error("NC006", "#COMMENT BEGIN without #COMMENT END", 1)
            return
        self.low.line = line.lineno
        self.low.col = line.col
        if line.kind == "blank":
            if line.comment and line.raw.strip():
                self.unit.current.append(ir.Block(self.span(line), [], comment=line.comment))
            return
        if line.kind == "local_sub":
            self.close_unit(line.lineno)
            self.unit = _Unit(line.name.upper(), self.span(line))
            self.subs.append(self.unit)
            return
        if line.kind == "header":
            if self.unit is not self.main:
                self.close_unit(line.lineno)
                self.unit = self.main
            if line.name and "program_name" not in self.meta:
                self.meta["program_name"] = line.name
            self.meta.setdefault("headers", []).append(line.name or "")
            return
        self.block(line)

    def close_unit(self, line: Optional[int]) -> None:
        u = self.unit
        while u.stack:
            op = u.stack.pop()
            self.error("NC006", f"{op.kind} is not closed (missing {_CLOSER[op.kind]})", op.line)
        if u is not self.main and not ir_walk.ends_with_return(u.body):
            self.error("NC006", f"local subroutine {u.name} has no end (M17, M29 or #RET)", u.span.line,
                       severity="warning")

    def span(self, line: blocks.Line) -> ir.Span:
        return ir.Span(self.file, line.lineno, 1, line.lineno, len(line.raw) + 1)

    def program(self) -> ir.Program:
        prog = ir.Program(self.file, DIALECT, self.main.body, {}, self.meta,
                          self.meta.get("program_name"))
        for u in self.subs:
            prog.subprograms[u.name] = ir.Subprogram(u.name, u.span, u.body, attrs=["LOCAL"])
        if self.low.soft_limits:
            self.meta["soft_limits"] = self.low.soft_limits
        self._expand_rpts(prog)
        self._check_gotos(prog)
        return prog

    # ---------------------------------------------------------------- one block
    def block(self, line: blocks.Line) -> None:
        span = self.span(line)
        number = line.number
        if line.error is not None:
            rule, msg, col = line.error
            self.error(rule, msg, line.lineno, col)
            self.unit.current.append(ir.Block(span, [ir.Passthrough(line.raw.strip(), "syntax error",
                                                                   DIALECT)], number, line.label))
            return
        code = line.code
        deep = _too_complex(code)
        if deep is not None:
            return self._not_read(line, span, "NC008", deep[1], deep[0])
        if "$GOTO" in code:
            code = re.sub(r'(\$GOTO\s*)\[\s*([A-Z0-9_]+)\s*\]', r'\1"\2"', code)
        found = find_instruction(code)
        head, instr, tail = code, None, ""
        if found is not None:
            head, instr, tail = code[:found[0]], found[2], code[found[1]:]
        if instr == "#DEF":
            self._define(tail, line)
        elif self.macros and '"' in head:
            try:
                head = self._expand(head, line)
            except _MacroTooLong as e:
                return self._not_read(line, span, "NC010", f"its macros expand to more than "
                                      f"{e.args[0]:,} characters (NCTRANS_MAX_BLOCK_CHARS): block too long")
            deep = _too_complex(head)       # the expanded text: its columns are not the source's
            if deep is not None:
                return self._not_read(line, span, "NC008", f"its macros expand to {deep[1]}")
        body: list = []
        try:
            fast = _plain_items(head)
            ch = fast if fast is not None else (
                parser().parse(head, start="start").children if head.strip() else [])
        except UnexpectedInput as e:
            self._syntax(e, head, line)
            self.unit.current.append(ir.Block(span, [ir.Passthrough(code, "syntax error", DIALECT)],
                                              number, line.label, 0 if line.skip else None,
                                              line.comment))
            return
        if ch and isinstance(ch[0], Tree) and ch[0].data in _FLOW:
            if instr is not None:
                self.error("NC002", "a $ statement stands alone in its block", line.lineno, line.col)
            self.flow(ch[0], line, span)
            return
        try:
            body = self.low.items(ch, line)
            if instr is not None:
                body = self.instruction(instr, tail, body, line)
        except (ValueError, KeyError, IndexError) as e:
            self.error("NC002", f"cannot read the block: {e}", line.lineno, line.col)
            body = [ir.Passthrough(code, "syntax error", DIALECT)]
        self.unit.current.append(ir.Block(span, body, number, line.label, 0 if line.skip else None,
                                          line.comment))

    def _not_read(self, line: blocks.Line, span: ir.Span, rule: str, message: str, index: int = 0) -> None:
        """A block refused before its grammar sees it (error `rule` at the `index`-th character of
        its code): kept in the IR as unread text, so it moves nothing."""
        self.error(rule, message, line.lineno, line.col + index)
        self.unit.current.append(ir.Block(span, [ir.Passthrough(line.code, "syntax error", DIALECT)],
                                          line.number, line.label, 0 if line.skip else None,
                                          line.comment))

    def _syntax(self, e: UnexpectedInput, code: str, line: blocks.Line) -> None:
        depth = 0
        inq = False
        for ch in code:
            if ch == '"':
                inq = not inq
            elif not inq:
                depth += {"[": 1, "]": -1}.get(ch, 0)
        col = line.col + max(0, (getattr(e, "column", 1) or 1) - 1)
        if depth:
            self.error("NC003", "'[' opened and not closed" if depth > 0 else "unmatched ']'",
                       line.lineno, col)
            return
        if isinstance(e, UnexpectedToken):
            got = "end of block" if e.token.type == "$END" else repr(str(e.token))
            exp = sorted(x for x in (e.expected or ()) if not x.startswith("__"))
            msg = f"unexpected {got}" + (f"; expected one of: {', '.join(exp[:8])}" if exp else "")
        elif isinstance(e, UnexpectedCharacters):
            msg = f"unexpected character {code[e.pos_in_stream]!r}" if e.pos_in_stream < len(code) \
                else "unexpected input"
        else:
            msg = "unexpected input"
        self.error("NC002", msg, line.lineno, col)

    # ---------------------------------------------------------------- #DEF macros
    _MACRO = re.compile(r'"((?:[^"\\]|\\.)*)"\s*=\s*"((?:[^"\\]|\\.)*)"')

    def _define(self, tail: str, line: blocks.Line) -> None:
        """#DEF "NAME"="block text" ...: the macro table (spec §16.12), kept program-wide."""
        pairs = self._MACRO.findall(tail)
        if not pairs:
            self.error("NC002", '#DEF needs "NAME"="text" pairs', line.lineno, line.col)
        for name, text in pairs:
            self.macros[name.upper()] = text.replace('\\"', '"')

    def _expand(self, code: str, line: blocks.Line, depth: int = 0) -> str:
        """A block's "NAME" macro references replaced by their text (nested ones too). The
        expansion is a block like any other, so it is held to limits.MAX_BLOCK_CHARS as it grows:
        ten macros each naming the next ten times would otherwise expand to 10^10 characters."""
        most = limits.setting("MAX_BLOCK_CHARS", limits.MAX_BLOCK_CHARS)
        size = [len(code)]

        def sub(m):
            key = m.group(1).upper()
            if key not in self.macros:
                return m.group(0)
            text = blocks.upper_outside_strings(self.macros[key])
            text = " " + (self._expand(text, line, depth + 1) if depth < 10 else text) + " "
            size[0] += len(text) - len(m.group(0))
            if size[0] > most:
                raise _MacroTooLong(most)
            return text
        return re.sub(r'"([A-Za-z0-9_]+)"', sub, code)

    # ---------------------------------------------------------------- # instructions
    def instruction(self, name: str, tail: str, body: list, line: blocks.Line) -> list:
        tail = tail.strip()
        low = self.low
        p = parser()

        def parse(start: str):
            try:
                return p.parse(tail, start=start)
            except UnexpectedInput as e:
                self._syntax(e, tail, line)
                return None

        if name in ("#RET",):
            return body + [ir.Return()]
        if name in MESSAGES:
            t = parse("msg_tail")
            if t is None:
                return body
            kind = MESSAGES[name]
            if t.data == "msg_number":
                text: ir.Expr = low.expr(t.children[0])
            else:
                fmt = _unquote(t.children[0]).replace('\\"', '"').replace("%%", "%")
                args = [low.expr(c) for c in t.children[1:]]
                text = ir.Str(fmt) if not args else ir.Func("format", [ir.Str(fmt)] + args)
            if kind == "error":
                # #ERROR [n]: error n of the CNC's list; #ERROR ["text"]: no number (seed L15818-15892)
                if t.data == "msg_number":
                    return body + [ir.Alarm(text)]
                return body + [ir.Alarm(None, text)]
            if name == "#WARNINGSTOP":
                return body + [ir.Message(text), ir.Stop()]
            return body + [ir.Message(text)]
        if name in ("#CALL", "#PCALL", "#MCALL"):
            t = parse("call_tail")
            if t is None:
                return body
            target = _unquote(t.children[0])
            named: dict[str, ir.Expr] = {}
            for c in t.children[1:]:
                if c.data == "letter_param":
                    named[str(c.children[0])] = low.expr(c.children[1])
                else:
                    key = str(c.children[0]).lstrip("P")
                    if not key.isdigit():
                        self.error("NC002", f"{c.children[0]}= is not a parameter", line.lineno, line.col)
                        continue
                    named["P" + key] = low.expr(c.children[1])
            if name == "#CALL" and named:
                self.error("NC002", "#CALL cannot initialise parameters (use #PCALL)", line.lineno,
                           line.col)
            name_ = target if "\\" not in target and "/" not in target else _program_name(target)
            call = ir.SubCall(name_.upper() if "." not in name_ else name_,
                              named_args=named, kind="shared" if name == "#CALL" else "pcall",
                              modal="after_move" if name == "#MCALL" else "none")
            call.bindings = {k: (param_var(PARAM_LETTERS.index(k)) if len(k) == 1 else
                                 param_var(int(k[1:]))) for k in named}
            return body + [call]
        if name == "#MDOFF":
            return body + [ir.ModalCallOff()]
        if name == "#TIME":
            t = parse("value_tail")
            return body + ([ir.Dwell(seconds=low.expr(t.children[0] if t.children else t))]
                           if t is not None else [])
        if name == "#SCALE":
            t = parse("value_tail")
            if t is None:
                return body
            s = low.expr(t.children[0] if t.children else t)
            c = _const(s)
            if c in (0.0, 1.0):
                return body + [ir.FrameOp("scale", clear=True)]
            return body + [ir.FrameOp("scale", {a: s for a in "XYZ"}, additive=True)]
        if name == "#RPT":
            t = parse("rpt_tail")
            if t is None:
                return body
            a, b = (_rpt_label(c) for c in t.children[:2])
            count = low.expr(t.children[2]) if len(t.children) > 2 else ir.Num(1.0, "1")
            marker = ir.Passthrough(f"#RPT [{a},{b}]", "block repetition", DIALECT)
            self.rpts.append((self.unit, marker, a, b, count, line.lineno))
            return body + [marker]
        if name == "#PATH":
            self.meta.setdefault("path", tail)
            return body + [ir.Passthrough(f"#PATH {tail}", NO_PATH_EFFECT, DIALECT)]
        if name == "#MCS":
            if tail.strip().upper() in ("ON", "OFF"):
                low.note("NC415", "warning", f"#MCS {tail.strip()}: machine-coordinate programming "
                         "over several blocks is not modelled; kept verbatim")
                return body + [ir.Passthrough(f"#MCS {tail.strip()}", "machine coordinates", DIALECT)]
            t = parse("words_tail")
            if t is None:
                return body
            more = low.items(t.children, line)
            for s in more:
                if isinstance(s, ir.Motion):
                    s.machine_coords = True
            return body + more
        if name == "#COMMENT":
            return body
        # the rest: checked for balance, kept verbatim
        depth = 0
        for ch in tail:
            depth += {"[": 1, "]": -1}.get(ch, 0)
            if depth < 0:
                break
        if depth:
            self.error("NC003", "'[' opened and not closed" if depth > 0 else "unmatched ']'",
                       line.lineno, line.col)
        text = f"{name} {tail}".strip()
        if name not in NO_EFFECT:
            low.note("NC415", "warning", f"{name}: its effect on the toolpath is not modelled; kept "
                     "verbatim")
        return body + [ir.Passthrough(text, NO_PATH_EFFECT if name in NO_EFFECT else "instruction",
                                      DIALECT)]

    # ---------------------------------------------------------------- $ flow
    def flow(self, t: Tree, line: blocks.Line, span: ir.Span) -> None:
        u = self.unit
        low = self.low
        d = t.data
        ch = t.children
        if line.number or line.label or line.comment:
            u.current.append(ir.Block(span, [], line.number, line.label, None, line.comment))
        most = int(table().options.get("max_structure_nesting", limits.MAX_STRUCTURE_NESTING))
        if d in _OPENERS and len(u.stack) >= most:
            # past the limit: NC008, and the structure stays out of the IR (its blocks go to the
            # enclosing body) so that no walker of the IR recurses deeper than the limit
            kind = _OPENERS[d]
            if len(u.stack) == most:            # once per excursion past the limit
                self.error("NC008", f"{kind} nested {len(u.stack) + 1} deep: nesting too deep (at "
                           f"most {most} control structures)", line.lineno, line.col)
            u.stack.append(_Open(kind, ir.If(span, ir.Num(0.0), []), u.current, line.lineno,
                                 (self.fresh("BRK"), self.fresh("CNT"), kind == "$SWITCH")))
            return
        if d == "goto":
            u.current.append(ir.Block(span, [ir.Goto(_target(ch[0], low))]))
        elif d == "if_goto":
            u.current.append(ir.Block(span, [ir.Goto(_target(ch[1], low), cond=low.expr(ch[0]))]))
        elif d == "if_":
            node = ir.If(span, low.expr(ch[0]), [])
            u.current.append(node)
            u.stack.append(_Open("$IF", node, node.then, line.lineno))
        elif d in ("elseif", "else_"):
            op = u.stack[-1] if u.stack else None
            if op is None or op.kind != "$IF" or op.extra == "else":
                self.error("NC002", f"{'$ELSEIF' if d == 'elseif' else '$ELSE'} without $IF",
                           line.lineno, line.col)
                return
            if d == "else_":
                op.node.orelse = op.body = []
                op.extra = "else"
                # the chain of ELSEIF nodes shares the last one's orelse
                self._set_else(op, op.body)
            else:
                inner = ir.If(span, low.expr(ch[0]), [])
                self._set_else(op, [inner])
                op.node = inner
                op.body = inner.then
                op.extra = "elseif"
        elif d == "endif":
            self._close("$IF", line)
        elif d == "while_":
            brk, cont = self.fresh("BRK"), self.fresh("CNT")
            node = ir.While(span, low.expr(ch[0]), [])
            u.current.append(node)
            u.stack.append(_Open("$WHILE", node, node.body, line.lineno, (brk, cont, False)))
        elif d == "do_":
            brk, cont = self.fresh("BRK"), self.fresh("CNT")
            node = ir.RepeatUntil(span, [], ir.Num(1.0))
            u.current.append(node)
            u.stack.append(_Open("$DO", node, node.body, line.lineno, (brk, cont, False)))
        elif d == "for_":
            var = low.expr(ch[0])
            node = ir.ForLoop(span, var, low.expr(ch[1]), low.expr(ch[2]), [], low.expr(ch[3]))
            brk, cont = self.fresh("BRK"), self.fresh("CNT")
            u.current.append(node)
            u.stack.append(_Open("$FOR", node, node.body, line.lineno, (brk, cont, False)))
        elif d in ("endwhile", "enddo", "endfor"):
            kind = {"endwhile": "$WHILE", "enddo": "$DO", "endfor": "$FOR"}[d]
            op = self._close(kind, line)
            if op is not None and d == "enddo":
                op.node.cond = ir.Unary("not", low.expr(ch[0]))
        elif d == "switch":
            node = ir.Case(span, low.expr(ch[0]), [], None)
            u.current.append(node)
            end = self.fresh("SWE")
            body: list = []
            u.stack.append(_Open("$SWITCH", node, body, line.lineno, (end, None, True)))
        elif d in ("case", "default"):
            op = u.stack[-1] if u.stack else None
            if op is None or op.kind != "$SWITCH":
                self.error("NC002", f"{'$CASE' if d == 'case' else '$DEFAULT'} outside $SWITCH",
                           line.lineno, line.col)
                return
            label = self.fresh("CASE")
            if d == "case":
                op.node.branches.append((low.expr(ch[0]), label))
            else:
                op.node.default = label
            op.body.append(ir.Block(span, [], None, label))
        elif d == "endswitch":
            op = self._close("$SWITCH", line)
            if op is not None:
                end = op.extra[0]
                if op.node.default is None:
                    op.node.default = end
                # the Case node jumps; its bodies follow it, then the end label
                u.current.extend(op.body)
                u.current.append(ir.Block(span, [], None, end))
        elif d in ("break_", "continue_"):
            loop = next((o for o in reversed(u.stack) if o.kind in ("$WHILE", "$DO", "$FOR", "$SWITCH")),
                        None)
            if loop is None or (d == "continue_" and loop.kind == "$SWITCH"):
                self.error("NC002", f"{'$BREAK' if d == 'break_' else '$CONTINUE'} outside a loop",
                           line.lineno, line.col)
                return
            if d == "break_":
                target = loop.extra[0]
            else:
                target = loop.extra[1]
                loop.extra = (loop.extra[0], loop.extra[1], True)
            u.current.append(ir.Block(span, [ir.Goto(target)]))
            if d == "break_" and loop.kind != "$SWITCH":
                loop.extra = (loop.extra[0], loop.extra[1], True)

    def _set_else(self, op: _Open, orelse: list) -> None:
        node = op.node
        node.orelse = orelse

    def _close(self, kind: str, line: blocks.Line) -> Optional[_Open]:
        u = self.unit
        if not u.stack or u.stack[-1].kind != kind:
            open_kind = u.stack[-1].kind if u.stack else "nothing"
            self.error("NC002", f"{_CLOSER[kind]} does not close {open_kind} (no open {kind})",
                       line.lineno, line.col)
            return None
        op = u.stack.pop()
        if kind in ("$WHILE", "$DO", "$FOR") and op.extra[2]:
            brk, cont, _ = op.extra
            body = op.node.body
            body.append(ir.Block(self.span(line), [], None, cont))
            u.current.append(ir.Block(self.span(line), [], None, brk))
        return op

    # ---------------------------------------------------------------- checks and #RPT
    def _check_gotos(self, prog: ir.Program) -> None:
        """A $GOTO to a label that is not in its program or subroutine is NC102 (spec F024)."""
        for _, body in ir_walk.units(prog):
            labels: set = set()
            gotos: list = []
            for node in ir_walk.blocks(body):
                if node.number is not None:
                    labels.add(_key(node.number))
                if node.label is not None:
                    labels.add(_key(node.label))
                for s in node.body:
                    if isinstance(s, ir.Goto):
                        gotos.append((s, node.span))
            for s, span in gotos:
                if _key(s.target) not in labels:
                    self.diags.append(Diagnostic("NC102", "error", f"$GOTO target {s.target} is not a "
                                                 "block of this program or subroutine", self.file,
                                                 span.line, 1))

    def _expand_rpts(self, prog: ir.Program) -> None:
        """#RPT [a, b, n]: the blocks from label a to label b run n times in place of the #RPT
        block (copies without their labels), when both labels are plain blocks of the same body.
        The copies are held in the IR, so all of them together are bounded like other blocks made
        from one construct (limits.MAX_LOWERED_BLOCKS): `#RPT [N10, N20, 100000000]` is an NC205
        error at its line, not a hang."""
        most = limits.setting("MAX_LOWERED_BLOCKS", limits.MAX_LOWERED_BLOCKS)
        held = 0
        for unit, marker, a, b, count, lineno in self.rpts:
            body = unit.body
            flat = [x for x in body]
            ia = next((i for i, x in enumerate(flat) if isinstance(x, ir.Block) and _has_label(x, a)), None)
            ib = next((i for i, x in enumerate(flat) if isinstance(x, ir.Block) and _has_label(x, b)), None)
            host = next((blk for blk in ir_walk.blocks(body) if marker in blk.body), None)
            n = _const(count)
            if ia is None or ib is None or ib < ia or host is None or n is None or n < 0:
                self.diags.append(Diagnostic("NC415", "warning", "#RPT: the range is not a run of blocks "
                                             "of this body, or the count is computed; not analysed",
                                             self.file, lineno, 1))
                continue
            held += int(n) * (ib - ia + 1)
            if held > most:
                self.diags.append(Diagnostic("NC205", "error", f"#RPT repeats {ib - ia + 1} blocks "
                                             f"{int(n):,} times: more than the {most:,} repeated blocks "
                                             "nctrans expands (NCTRANS_MAX_LOWERED_BLOCKS); not analysed",
                                             self.file, lineno, 1))
                continue
            copies = []
            for _ in range(int(n)):
                for x in flat[ia:ib + 1]:
                    c = copy.deepcopy(x)
                    if isinstance(c, ir.Block):
                        c.number = c.label = None
                    copies.append(c)
            idx = next((i for i, x in enumerate(body) if x is host), None)
            if idx is None:
                self.diags.append(Diagnostic("NC415", "warning", "#RPT inside a structured statement is "
                                             "not analysed", self.file, lineno, 1))
                continue
            host.body.remove(marker)
            body[idx + 1:idx + 1] = copies


_NUM = r"(?:\d+\.?\d*|\.\d+)"
_PLAIN = re.compile(rf"(?:\s*[A-Z]\s*[-+]?\s*{_NUM})+\s*")
_PAIR = re.compile(rf"([A-Z])\s*([-+]?)\s*({_NUM})")


class _PlainWord:
    """A letter-number word read without the grammar: the shape of the grammar's word tree, with
    its value already an IR number."""
    __slots__ = ("data", "children")

    def __init__(self, letter: str, value: ir.Num):
        self.data = "gword" if letter == "G" else "word"
        self.children = (letter, value)


_QUOTED = re.compile(r'"[^"]*"')


class _MacroTooLong(Exception):
    """A #DEF macro expansion grew past limits.MAX_BLOCK_CHARS (args: the limit)."""


def _too_complex(code: str) -> Optional[tuple[int, str]]:
    """(0-based index, message) when the block nests `[ ]` or chains operators past what the
    expression walkers may recurse into (nctrans/limits.py, as the ISO and Sinumerik front ends);
    text in quotes (#MSG) is not looked into."""
    if '"' in code:
        code = _QUOTED.sub(lambda m: '"' + " " * (len(m.group()) - 2) + '"', code)
    return limits.too_complex(code, "[", "]")


def _plain_items(code: str) -> Optional[list]:
    """Blocks made only of letter-number words (`G01 X10.5 Y-3 F500`, the bulk of CAM output), as
    the words the grammar would build, without the lexer and parser; anything else returns None
    and takes the grammar of record (tests hold both to the same result)."""
    if not code or not _PLAIN.fullmatch(code):
        return None
    out = []
    for m in _PAIR.finditer(code):
        letter, sign, number = m.groups()
        value = float(number)
        out.append(_PlainWord(letter, ir.Num(-value if sign == "-" else value,
                                             ("-" if sign == "-" else "") + number)))
    return out


_FLOW = frozenset(("if_", "if_goto", "elseif", "else_", "endif", "while_", "endwhile", "do_", "enddo",
                   "for_", "endfor", "switch", "case", "default", "endswitch", "break_", "continue_",
                   "goto"))
_CLOSER = {"$IF": "$ENDIF", "$WHILE": "$ENDWHILE", "$DO": "$ENDDO", "$FOR": "$ENDFOR",
           "$SWITCH": "$ENDSWITCH"}


def _target(t: Tree, low: Lowerer) -> str:
    if t.data == "target_label":
        return _unquote(t.children[0]).upper()
    e = low.expr(t.children[0])
    c = _const(e)
    if c is None:
        low.note("NC415", "warning", "$GOTO N<expr> with a computed block number is not analysed")
        return "?"
    return str(int(c))


def _rpt_label(t: Tree) -> str:
    if t.data == "target_label":
        return _unquote(t.children[0]).upper()
    return str(int(float(t.children[0])))


def _has_label(b: ir.Block, name: str) -> bool:
    return (b.number is not None and _key(b.number) == _key(name)) or (
        b.label is not None and _key(b.label) == _key(name))


def _key(s: str):
    s = str(s).strip().upper()
    return int(s) if s.isdigit() else s



def parse(text: str, file: str = "<stdin>") -> ParseResult:
    """Fagor source -> IR Program with diagnostics (never raises on bad input)."""
    from nctrans.source import from_text
    src = from_text(text, file)
    p = Parser(src.text, file)
    try:
        prog = p.run()
    except LarkError as e:        # a grammar failure the block handler did not catch
        p.error("NC002", f"cannot parse: {e}", 1)
        prog = p.program()
    return ParseResult(prog, src.diagnostics + p.diags)
