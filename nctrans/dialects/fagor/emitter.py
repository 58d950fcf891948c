"""Fagor 8060/8065 emitter: IR Program -> idiomatic Fagor text (spec §20.3).

Shape of the output: local subroutines first (`%L NAME` .. `M17`, callees before callers), then the
main program under `%NAME`; P parameters, `$IF/$WHILE/$FOR/$DO` flow, expressions in `[ ]`,
comments after `;`, jump targets written `N<n>:` or `[LABEL]`, G codes spelled from rules/fagor.toml.

How other dialects' constructs land (NC401 info where the spelling changes meaning in detail, NC402
error where Fagor has no equivalent, so the conversion policy lowers the program to plain motion):
- ISO #1..#33 and #100..#999 are P1..P33 (local) and P100..P999 (global); R parameters are global
  P parameters (R n -> P n from 100, R0..R99 -> P9000..P9099); #5001.. / #5021.. are V.A.PPOS /
  V.A.POS; named user variables are V.P.<name>.
- Tool length: Fagor takes it from the D offset of the active tool (no G43/G44): G43 H<n> -> D<n>,
  G49 -> D0; an M06 implies D1 on Fagor (reported when the source did not select the length).
- A canned cycle, a home return, a data setting, a translation frame, an additive mirror on a
  non-X/Y/Z axis or an arc with extra turns is refused (NC402).
"""
from __future__ import annotations

from typing import Any, Optional

from nctrans import spilled
from nctrans.dialects.base import EmitResult
from nctrans.dialects.base import get as get_dialect
from nctrans.dialects.emit import Emitter, NotExpressible, Spelling, flat_radius_number, rewrites
from nctrans.dialects.tool_timing import ToolTiming
from nctrans.ir import nodes as n
from nctrans.plainrun import RUNS, run_blocks
from nctrans.ir import walk as ir_walk
from nctrans.lower import macro_procs, restart_loop
from nctrans.ir.vocabulary import NO_EFFECT_PREFIX
from nctrans import alarm_numbers
from nctrans.rules import load_table, option as rules_option
from nctrans.diagnostics import at_span

import re as _re

# one M word with a plain number: a function of the machine builder's (NC403 when kept)
_MACHINE_M = _re.compile(r"[Mm]\d{1,4}")

__all__ = ["FagorSpelling", "FagorEmitter", "NotExpressible", "format_number", "format_expr", "emit_program"]

DIALECT = "fagor"
AXES = "XYZUVWABC"


def _fagor_spelling(key) -> Optional[str]:
    """The Fagor spelling of another dialect's system variable, through its neutral meaning."""
    from nctrans.rules import system_meaning
    meaning = system_meaning(key)
    if meaning is None:
        return None
    own = load_table(DIALECT).system_variables
    return next((sp for sp, m in own.items() if m == meaning), None)


def format_number(v: float) -> str:
    """Shortest decimal text of a float, no exponent."""
    if v != v or v in (float("inf"), float("-inf")):
        raise NotExpressible(f"number {v!r}")
    if v == int(v) and abs(v) < 1e15:
        return str(int(v))
    text = format(v, ".10f").rstrip("0").rstrip(".")
    if float(text) != v:
        text = repr(v)
        if "e" in text:
            from decimal import Decimal
            text = format(Decimal(text), "f")
    return text


class FagorSpelling(Spelling):
    """Expressions and variables in Fagor syntax (operators, precedence and functions from
    rules/fagor.toml [expressions]); an emitter receives the lowerings (NC401)."""
    syntax_table = DIALECT

    def number(self, e: n.Num) -> str:
        return format_number(e.value)

    def string(self, e: n.Str) -> str:
        raise NotExpressible("a string value outside a message")

    def value(self, e: Any) -> str:
        """An address value: numbers, parameters and variables as they are, the rest in brackets."""
        if type(e) is n.Num:
            return format_number(e.value)
        if type(e) is n.Var:
            return self.var_text(e)
        if type(e) is n.Unary and e.op == "-" and type(e.operand) in (n.Num, n.Var):
            return "-" + self.value(e.operand)
        return f"[{self.expr(e)}]"

    @rewrites(n.Binary, "div")
    def _div(self, e: n.Binary) -> tuple[str, int]:
        return f"{self.syntax.functions['fix']}[{self.expr(n.Binary('/', e.left, e.right))}]", self.syntax.atom

    @rewrites(n.Binary, "xor")
    def _xor(self, e: n.Binary) -> tuple[str, int]:
        return self.term(n.Binary("!=", _truth(e.left), _truth(e.right)))

    @rewrites(n.Binary, "pow")
    def _pow(self, e: n.Binary) -> tuple[str, int]:
        if isinstance(e.right, n.Num) and e.right.value == 2:
            lt, _ = self.term(e.left)
            return f"SQR[{lt}]", self.syntax.atom
        return self.binary(e)

    @rewrites(n.Unary, "+")
    def _plus(self, e: n.Unary) -> tuple[str, int]:
        return self.term(e.operand)

    @rewrites(n.Unary, "not")
    def _not(self, e: n.Unary) -> tuple[str, int]:
        return f"[{self.expr(e.operand)}]==0", self.syntax.binary["=="].prec

    @rewrites(n.Unary, "bnot")
    def _bnot(self, e: n.Unary) -> tuple[str, int]:
        return f"{self.syntax.functions['bnot']}[{self.expr(e.operand)}]", self.syntax.atom

    @rewrites(n.Func, "atan2", "atan")
    def _atan(self, e: n.Func) -> tuple[str, int]:
        if e.name.lower() == "atan" and len(e.args) != 2:
            return self.call(e), self.syntax.atom
        # ARG[x, y] is the angle of the vector (x, y) = atan2(y, x), 0..360
        return f"ARG[{self.expr(e.args[1])},{self.expr(e.args[0])}]", self.syntax.atom

    @rewrites(n.Func, "pow")
    def _pow_call(self, e: n.Func) -> tuple[str, int]:
        if len(e.args) == 2:
            return self.term(n.Binary("pow", e.args[0], e.args[1]))
        return self.call(e), self.syntax.atom

    @rewrites(n.Func, "minval", "maxval")
    def _min_max(self, e: n.Func) -> tuple[str, int]:
        name = e.name.lower()
        if len(e.args) != 2:
            return self.call(e), self.syntax.atom
        a, b = e.args
        total = n.Binary("-" if name == "minval" else "+", n.Binary("+", a, b),
                         n.Func("abs", [n.Binary("-", a, b)]))
        self.lowered(f"{name.upper()} written as an ABS expression")
        return self.term(n.Binary("/", total, n.Num(2.0)))

    def var_text(self, v: n.Var) -> str:
        sp, key = v.space, v.key
        if sp in ("arg", "local"):
            k = str(key).upper()
            if (k.startswith("P") and k[1:].isdigit() or k.startswith(("V.P.", "V.S."))) and not v.indices:
                return k
            raise NotExpressible(f"call argument {key} read by letter")
        if sp == "name":
            k = str(key).upper()
            if v.indices:
                raise NotExpressible(f"array variable {key}")
            if k.startswith("P") and k[1:].isdigit():
                return k
            return f"V.P.{k}"
        if sp == "R":
            if key is None and v.indices and len(v.indices) == 1:
                return f"P[{self.expr(v.indices[0])}]"
            if v.indices or key is None:
                raise NotExpressible(f"R parameter array {key}")
            k = int(key)
            if k >= 100:
                return f"P{k}"
            self.lowered(f"R{k} written as the global parameter P{9000 + k}")
            return f"P{9000 + k}"
        if sp == "num":
            if key is None and v.indices and len(v.indices) == 1:
                return f"P[{self.expr(v.indices[0])}]"
            if not isinstance(key, int) or v.indices:
                raise NotExpressible(f"macro variable {key}")
            if 1 <= key <= 33 or 100 <= key <= 999:
                return f"P{key}"
            spelling = _fagor_spelling(key)
            if spelling is not None:
                return spelling
            raise NotExpressible(f"system variable #{key}")
        if sp == "system":
            k = str(key).upper()
            if not k.startswith("V."):
                spelling = _fagor_spelling(k)
                if spelling is None:
                    raise NotExpressible(f"system variable {key}")
                return spelling
            idx = "".join(f"[{self.expr(i)}]" for i in v.indices or ())
            if idx:
                head, _, tail = k.rpartition(".")
                return f"{head}{idx}.{tail}" if head.count(".") >= 2 else k + idx
            return k
        raise NotExpressible(f"variable {sp}:{key}")


def _truth(e):
    return n.Binary("!=", e, n.Num(0.0))


_BARE = FagorSpelling()


def format_expr(e: Any) -> str:
    """An IR expression in Fagor syntax (for messages and verbatim text)."""
    return _BARE.expr(e)


class FagorEmitter(FagorSpelling, Emitter):
    dialect = DIALECT
    table_name = DIALECT
    target_text = "Fagor 8060/8065"
    lowered_for = "Fagor"

    def __init__(self, program: n.Program):
        super().__init__(program)
        self.out = spilled.output_lines()      # to a temporary file once many (spilled.OutputLines)
        self.targets: set = set()
        self.motion = "rapid"
        # the mode a main program's first move runs in: the source control's power-on motion mode
        # (Sinumerik G1: `X10 F100` is a feed move; set by prologue), else Fagor's own, G00; None:
        # a subprogram file's, whose first move runs in its caller's mode (nothing written)
        self.first_motion: Optional[str] = "rapid"
        self.plane = "XY"
        self.pending_motion: Optional[str] = None     # arc_3point / arc_tangent: one-shot G09/G08
        self.radius_index: Any = None
        self.length_on = False
        # the tool in the spindle (T<n> M06, constant numbers only) and the T selected for it
        self.tool_selected: Optional[float] = None
        self.tool_active: Optional[float] = None
        # the tool words moved to where this control's words change the tool as the source's do
        self.tool_timing = ToolTiming(program.dialect, "fagor")
        self.in_sub = False
        # an ISO macro file (it reads G65 arguments and ends with M99): its M99 is the return
        body = program.body
        self.macro_file = (program.dialect != DIALECT and type(body) is list
                           and macro_procs.ends_with_restart(body) and macro_procs.reads_arguments(body))
        # spindle-synchronised moves ("thread") are written as G63: S and the feed mode they need
        self.speed: Optional[float] = None            # the last constant S written (rev/min)
        self.feed_mode = "per_min"
        self.tap_cancelled = False                    # an M3/M4/M5/M19 ended G63 on the control
        self.s_negative = False                       # a G63 wrote S negative: positive before M3/M4
        self.last_feed: Optional[str] = None          # the F the source programmed last, as written
        self.feed_clobbered = False                   # a G63 wrote its own F since: write it again
        self.spindle_dir: Optional[str] = None
        # An ISO source keeps its length register (G43 H<k>) over a tool change, where a Fagor
        # M06 brings D1 of the new tool: what the ISO program has in force ("off", a register
        # number, None: not known) and, after an M06 that made them differ, what Fagor must still
        # be told before a block lets the length show ("off": write D0; a register: refused)
        # (a mill's: a lathe applies no length along the tool axis, its T<tt><oo> selects the offset)
        self.registers = (program.dialect != DIALECT and not _table_option(program.dialect, "edge_offsets")
                          and _machine_kind(program.dialect) == "mill")
        # any source whose D (or ISO-T T-word offset) names an offset register, mill or lathe
        self.register_radius = (program.dialect != DIALECT
                                and not _table_option(program.dialect, "offsets_of_active_tool"))
        self.iso_length: Any = "off"
        self.iso_h: Optional[float] = None
        self.length_behind: Any = None
        self.comp_on = False

    def lowered(self, what: str, once: Any = None) -> None:
        """Each lowering once per program, at its first line, the later lines counted."""
        self.lowered_once_per_program(what)

    # ---------------------------------------------------------------- program
    def run(self) -> str:
        p = self.program
        for _, body in ir_walk.units(p):
            self.targets |= _goto_targets(body)
        for name in _sub_order(p):
            sub = p.subprograms[name]
            self.span = sub.span
            if sub.params:
                self.refuse(f"the parameters of subprogram {name} (Fagor subroutines take P values)")
            self.out.append(f"%L {_sub_name(name)}")
            self.in_sub = True
            self.tool_selected = self.tool_active = None    # called with whatever tool is in the spindle
            self.iso_length, self.iso_h, self.length_behind = None, None, None   # the caller's
            self._reset()
            self.nodes(sub.body)
            if not ir_walk.ends_with_return(sub.body):
                self.out.append(self.code_for("return"))
        self.in_sub = False
        self.iso_length, self.iso_h, self.length_behind = "off", None, None
        self._reset()
        self.out.append(f"%{_program_header(p)}")
        self.prologue()
        self.nodes(self._restart_as_loop(p.body if type(p.body) is list else list(p.body)))
        return spilled.joined(self.out)

    def _restart_as_loop(self, body: list) -> list:
        """M99 ending a main program of another dialect starts it again for ever: the body runs
        inside $WHILE 1 ... $ENDWHILE (lowered alone it would be one pass and a program end)."""
        last = restart_loop.restart_block(body) if self.program.dialect != DIALECT else None
        if last is None:
            return body
        if self.macro_file:
            self.span = body[last].span
            self.lowered("M99 of a macro file (it reads G65 arguments) is its return: written "
                         f"{self.code_for('return')}")
            return body
        self.span = body[last].span
        self.lowered("M99 in a main program (it starts again for ever) written as $WHILE 1 ... $ENDWHILE")
        return restart_loop.as_loop(body, last)

    def prologue(self) -> None:
        """The source controller's power-on modes that change what the words mean, where Fagor's
        differ (an ISO lathe: G18, G95 feed per revolution, diameter X). A lathe program says G151
        or G152 whatever it relies on: a Fagor lathe starts in G151 on its DIAMPROG axes."""
        p = self.program
        if p.dialect == DIALECT:
            return
        source = dict((p.meta or {}).get("defaults") or {})
        try:
            lathe = get_dialect(p.dialect).machine_kind == "lathe"
        except Exception:           # a dialect not registered here (a test's): no lathe defaults
            lathe = False
        if lathe:
            source.setdefault("diameter", "radius")
        mine = self.table.defaults()
        words = []
        # a flattened program selects its own modes in its first block (radius X, though)
        groups = ("diameter",) if (p.meta or {}).get("flattened_from") else (
            "units", "plane", "feed_mode", "diameter")
        for group in groups:
            value = source.get(group)
            if value is None or (mine.get(group) == value and not (lathe and group == "diameter")):
                continue
            rule = self.table.code_for(group, value)
            if rule is not None and rule.group == group:
                words.append(rule.spelling or rule.code)
                if group == "plane":
                    self.plane = value
        if words:
            self.span = n.Span(p.file, 1)
            self.lowered(f"power-on modes of {p.dialect} written out: {' '.join(words)}")
            self.out.append(" ".join(words))
        from nctrans.convert import subprogram_file
        motion = source.get("motion")
        if (p.meta or {}).get("flattened_from"):
            pass
        elif subprogram_file(p):
            self.first_motion = None        # a subprogram file's first move runs in its caller's
        elif motion:
            self.first_motion = motion

    def _reset(self) -> None:
        self.motion = None
        self.pending_motion = None

    def nodes(self, nodes: list) -> None:
        for node in nodes:
            t = type(node)
            if t in RUNS:                       # a compact body's run (base.CompactBody)
                self.nodes(run_blocks(node))
                continue
            self.span = getattr(node, "span", self.span)
            if self.length_behind is not None and (t is not n.Block or _is_target(node, self.targets)):
                try:                            # a structure or jump target lets the length show
                    self._length_shows(None)
                except NotExpressible as e:     # refused at its line, as inside a block
                    self.refuse(str(e))
            if t is n.Block:
                if _is_target(node, self.targets):
                    self.tool_timing.forget()   # the tool held depends on the path taken
                self.block(node)
                continue
            self.tool_timing.forget()           # loops and branches: the tool held depends on the path
            self._structure(node, t)
            self.tool_timing.forget()

    def _structure(self, node, t) -> None:
        """A loop, branch or CASE, with its body."""
        if t is n.If:
            self._if(node, "$IF")
            self.out.append("$ENDIF")
        elif t is n.While:
            self._flow_line(f"$WHILE {self._cond(node.cond)}")
            self.nodes(node.body)
            self.out.append("$ENDWHILE")
        elif t is n.Loop:
            self.out.append("$WHILE 1")
            self.nodes(node.body)
            self.out.append("$ENDWHILE")
        elif t is n.RepeatUntil:
            self.out.append("$DO")
            self.nodes(node.body)
            c = node.cond
            keep = c.operand if isinstance(c, n.Unary) and c.op == "not" else n.Unary("not", c)
            self._flow_line(f"$ENDDO {self._cond(keep)}")
        elif t is n.ForLoop:
            try:
                var = self.var_text(node.var)
                step = node.step if node.step is not None else n.Num(1.0)
                self.out.append(f"$FOR {var}={self.expr(node.start)},"
                                f"{self.expr(node.end)},{self.expr(step)}")
            except NotExpressible as e:
                self.refuse(str(e))
            self.nodes(node.body)
            self.out.append("$ENDFOR")
        elif t is n.Case:
            try:
                subj = self.expr(node.subject)
                for value, label in node.branches:
                    self.out.append(f"$IF [{subj}]==[{self.expr(value)}] $GOTO "
                                    f"{self._target(label)}")
                if node.default is not None:
                    self.out.append(f"$GOTO {self._target(node.default)}")
            except NotExpressible as e:
                self.refuse(str(e))
        else:
            self.refuse(f"the structure {t.__name__}")

    def _if(self, node: n.If, kw: str) -> None:
        self._flow_line(f"{kw} {self._cond(node.cond)}")
        self.nodes(node.then)
        if len(node.orelse) == 1 and isinstance(node.orelse[0], n.If):
            self._if(node.orelse[0], "$ELSEIF")
        elif node.orelse:
            self.out.append("$ELSE")
            self.nodes(node.orelse)

    def _flow_line(self, text: Optional[str]) -> None:
        if text is not None:
            self.out.append(text)

    def _cond(self, e) -> Optional[str]:
        try:
            return self.expr(e)
        except NotExpressible as ex:
            self.refuse(str(ex))
            return "0"

    def _target(self, label: str) -> str:
        s = str(label).strip()
        if s.upper().lstrip("N").isdigit():
            return f"N{int(s.upper().lstrip('N'))}"
        return f"[{_label_name(s)}]"

    # ---------------------------------------------------------------- blocks
    def block(self, b: n.Block) -> None:
        head = []
        if b.skip is not None:
            head.append("/")
        if b.number is not None:
            num = str(b.number).upper().lstrip("N")
            if num.isdigit():
                head.append(f"N{int(num)}" + (":" if _key(num) in self.targets else ""))
        if b.label is not None:
            head.append(f"[{_label_name(b.label)}]")
        lines: list[list[str]] = [[]]
        used: set = set()

        def new_line():
            if lines[-1]:
                lines.append([])
                used.clear()

        def word(letter: str, text: str, alone: bool = False):
            if letter and letter in used and text in lines[-1]:
                return                       # the same word twice (D of G43 and of G41)
            if alone or letter in used:
                new_line()
            lines[-1].append(text)
            if letter:
                used.add(letter)
            if alone:
                new_line()

        body = self.tool_timing.apply(self, b.body)
        i = 0
        while i < len(body):
            s = body[i]
            if type(s) is n.Feed and any(type(x) is n.ModeChange and x.group == "units" for x in body[:i]):
                new_line()      # Fagor reads F before G70/G71: an F read after the switch follows it
            try:
                skip = self.statement(s, word, new_line, body[i + 1:])
            except NotExpressible as e:
                self.refuse(str(e))
                skip = 0
            i += 1 + (skip or 0)
        comment = f"; {b.comment}" if b.comment else None
        texts = [" ".join(sorted(ws, key=_word_order)) for ws in lines if ws]
        if not texts:
            if head or comment:
                self.out.append(" ".join(head + ([comment] if comment else [])))
            return
        for k, text in enumerate(texts):
            parts = (head if k == 0 else []) + [text]
            if comment and k == len(texts) - 1:
                parts.append(comment)
            self.out.append(" ".join(parts))

    def describe(self, s) -> str:
        return _describe(s)

    def statement(self, s, word, new_line, rest: list) -> int:
        """Write one statement (`w_<NodeType>`); returns how many following statements it consumed."""
        if self.length_behind is not None and _shows_length(s):
            self._length_shows(word)
        return self.dispatch("w_", s, word, new_line, rest) or 0

    def _length_shows(self, word) -> None:
        """A block (or structure) that lets the tool length show while Fagor's M06 has put D1 of
        the new tool where the ISO program keeps another length: D0 where the ISO length is off,
        else refused (no Fagor D takes another tool's length)."""
        behind, self.length_behind = self.length_behind, None
        if behind == "off" and not self.comp_on:
            if word is None:
                self.out.append("D0")
            else:
                word("D", "D0")
            self.length_on = False
            self.lowered("ISO tool length off over the tool change: D0 written, as a Fagor M06 "
                         "applies the new tool's offset D1")
            return
        what = ("no length (G49, or none selected)" if behind == "off"
                else f"the length of register H{behind:g}")
        raise NotExpressible(f"{what} still in force after the tool change to T{self.tool_active:g} "
                             "(ISO keeps it until G43/G49; a Fagor M06 applies the new tool's own "
                             "offset D1" + (", and D0 would end the radius compensation)" if
                                            behind == "off" else ", and no Fagor D takes another tool's length)"))

    def w_Motion(self, s: n.Motion, word, new_line, rest: list):
        self.motion_words(s, word)
        if (self.feed_clobbered and self.motion != "thread" and s.target and self.last_feed
                and not any(isinstance(x, n.Feed) for x in rest)):
            word("F", self.last_feed)        # a G63's F (lead x S) is the modal feed after it
            self.feed_clobbered = False
        new_line()
        return 0

    def w_Feed(self, s: n.Feed, word, new_line, rest: list):
        val = self.value
        self.last_feed = "F" + val(s.value)
        self.feed_clobbered = False
        word("F", self.last_feed)

    def w_SpindleSpeed(self, s: n.SpindleSpeed, word, new_line, rest: list):
        val = self.value
        if s.spindle not in (0, 1):
            word("", f"S{s.spindle}={self.expr(s.value)}")
        else:
            self.speed = ir_walk.literal(s.value)
            self.s_negative = self._tap_block(rest) and self.spindle_dir == "ccw"
            if self.s_negative:
                if self.speed is None:
                    raise NotExpressible("G63 reversed with a computed spindle speed")
                word("S", "S" + format_number(-abs(self.speed)))
            else:
                word("S", "S" + val(s.value))

    def _tap_block(self, rest: list) -> bool:
        """A Fagor G63 is in force or set later in this block."""
        return self.motion == "tap_interp" or any(
            isinstance(x, n.ModeChange) and x.group == "motion" and x.value == "tap_interp" for x in rest)

    def w_SpindleLimit(self, s: n.SpindleLimit, word, new_line, rest: list):
        val = self.value
        code = self.code_for("spindle_limit")
        word(code, code)
        word("S", "S" + val(s.value))

    def w_ToolSelect(self, s: n.ToolSelect, word, new_line, rest: list):
        val = self.value
        word("T", "T" + val(s.tool))
        self.tool_selected = _num(s.tool)

    def w_ToolChange(self, s: n.ToolChange, word, new_line, rest: list):
        self.tool_active = self.tool_selected
        code = self.code_for("tool_change")
        word(code, code)
        # Fagor: D1 is implicit after a tool change (the front end writes it as these two)
        if (len(rest) >= 2 and isinstance(rest[0], n.ModeChange) and rest[0].group == "tool_length"
                and rest[0].value == "plus" and isinstance(rest[1], n.OffsetSelect)
                and _num(rest[1].index) == 1):
            self.length_on, self.radius_index = True, 1
            return 2
        if not self.length_on:
            self.lowered("M06 on Fagor activates offset D1 of the new tool (tool length on)")
        self.length_on, self.radius_index = True, 1
        if self.registers and self.tool_active is not None and self.iso_length is not None \
                and self.iso_length != self.tool_active:
            self.length_behind = self.iso_length        # until the program sets its length again

    def w_OffsetSelect(self, s: n.OffsetSelect, word, new_line, rest: list):
        val = self.value
        if s.kind == "radius":
            k = _num(s.index)
            if self.register_radius and k == 1 and self.tool_active not in (None, 1):
                # ISO radius register 1 (tool 1's radius) while another tool is in the spindle:
                # a Fagor D1 is that tool's own corrector (nctrans.interp.comp_radius)
                raise NotExpressible(f"radius register D1 while T{self.tool_active:g} is in the spindle: "
                                     f"a Fagor D1 is the corrector of T{self.tool_active:g}, not register 1")
            if self.register_radius and k and self.tool_active is None and not flat_radius_number(k):
                # no tool change before it: a Fagor D<k> is a corrector of the tool the machine
                # holds from before (its analysis: NC123, radius 0), register k is not
                raise NotExpressible(f"radius register D{k:g} with no tool change before it: a Fagor "
                                     f"D{k:g} is a corrector of the tool the machine holds, which the "
                                     f"program does not say, not register {k:g}")
            word("D", "D" + val(s.index))
            self.radius_index = s.index
            if not self.length_on and _num(s.index) != 0:
                self.lowered("D selects the tool length offset too on Fagor")
        else:
            self._length_of_active_tool(s.index)
            self.iso_h = _num(s.index)
            if self.iso_length != "off":
                self.iso_length = self.iso_h
            self.length_behind = None
            word("D", "D" + val(s.index))
            self.lowered("length offset H written as the Fagor offset D of the active tool")

    def _length_of_active_tool(self, h: n.Expr) -> None:
        """A Fagor D takes the length of the tool in the spindle; an ISO H<k> names offset register k,
        which (as nctrans reads ISO: register k holds tool k's length) is another tool's length when k
        is not the active tool's number: no Fagor D says that."""
        k = _num(h)
        if k is not None and k != 0 and self.tool_active is not None and k != self.tool_active:
            raise NotExpressible(f"tool length offset H{k:g} of another tool than the one in the "
                                 f"spindle (T{self.tool_active:g}): a Fagor D takes the active tool's own length")

    def w_Dwell(self, s: n.Dwell, word, new_line, rest: list):
        val = self.value
        if s.seconds is None:
            raise NotExpressible("a dwell in spindle revolutions")
        code = self.code_for("dwell")
        word(code, f"{code} K" + val(s.seconds))

    def w_Assign(self, s: n.Assign, word, new_line, rest: list):
        new_line()
        word("", f"{self.var_text(s.target)}={self.expr(s.value)}", alone=True)

    def w_Goto(self, s: n.Goto, word, new_line, rest: list):
        if s.computed is not None:
            # $GOTO N<expr> exists, but nctrans cannot follow it on Fagor (NC415 when read back)
            raise NotExpressible(f"a computed jump (GOTO {s.target}): a Fagor $GOTO to a computed "
                                 "block number is not analysed, so the conversion could not be proven")
        new_line()
        target = self._target(s.target)
        if s.cond is not None:
            word("", f"$IF {self.expr(s.cond)} $GOTO {target}", alone=True)
        else:
            word("", f"$GOTO {target}", alone=True)

    def w_SubCall(self, s: n.SubCall, word, new_line, rest: list):
        settings = self.settings_cycle(s)
        if settings is not None:
            return self.w_Passthrough(settings, word, new_line, rest)
        if s.target is not None:
            raise NotExpressible("an indirect call (the called program's name is a string computed as the program runs)")
        self._subcall(s, word)

    def w_ModalCallOff(self, s: n.ModalCallOff, word, new_line, rest: list):
        word("", "#MDOFF", alone=True)

    def w_Return(self, s: n.Return, word, new_line, rest: list):
        if s.to_label is not None:
            raise NotExpressible("a return to a label")
        word("M", self.code_for("return") if self.in_sub else self.code_for("program_end", "end_rewind"))

    def w_ProgramEnd(self, s: n.ProgramEnd, word, new_line, rest: list):
        if s.kind == "restart" and self.macro_file:
            word("M", self.code_for("return"))         # a macro file's M99: its return
            return
        if s.kind == "restart":
            raise NotExpressible("a program restart (M99 in a main program)")
        word("M", self.code_for("program_end", "end" if s.kind == "end" else "end_rewind"))

    def w_Stop(self, s: n.Stop, word, new_line, rest: list):
        word("M", self.code_for("stop", "optional" if s.optional else "program"))

    def w_Message(self, s: n.Message, word, new_line, rest: list):
        word("", f"#MSG [{self.message(s.text)}]", alone=True)

    def w_Alarm(self, s: n.Alarm, word, new_line, rest: list):
        """#ERROR ["text"] (or #ERROR [n] of the CNC's list): Fagor has no band of numbered user
        alarms, so another control's alarm is raised by its text (nctrans.alarm_numbers)."""
        w = alarm_numbers.written(s, DIALECT, self.program.dialect)
        if w.number is None:
            text = self.message(w.text)
        elif w.text is None:
            text = self.expr(w.number)
        else:
            text = self.message(w.text)
        word("", f"#ERROR [{text}]", alone=True)

    def w_FrameOp(self, s: n.FrameOp, word, new_line, rest: list):
        self.frame(s, word)

    def w_PolarPole(self, s: n.PolarPole, word, new_line, rest: list):
        val = self.value
        # until a pole is written again, polar words cannot be written: a pole this writer refuses
        # is lowered alone, and Fagor's polar origin would stay where it was
        self.pole_unwritten = True
        if s.relative_to == "last_point" and not s.target and not s.polar:
            word("", self.code_for("polar_pole"), alone=True)
        elif s.relative_to == "zero" and not s.polar and len(s.target) <= 2:
            a1, a2 = {"XY": ("X", "Y"), "ZX": ("Z", "X"), "YZ": ("Y", "Z")}[self.plane]
            if set(s.target) - {a1, a2}:
                raise NotExpressible("a polar pole outside the plane")
            i = s.target.get(a1)
            j = s.target.get(a2)
            word("", f"{self.code_for('polar_pole')} I{val(i.value if i else n.Num(0.0))} "
                 f"J{val(j.value if j else n.Num(0.0))}",
                 alone=True)
        else:
            raise NotExpressible(f"a polar pole relative to the {s.relative_to.replace('_', ' ')}")
        self.pole_unwritten = False

    def w_SetPosition(self, s: n.SetPosition, word, new_line, rest: list):
        val = self.value
        words = " ".join(f"{a}{val(v.value)}" for a, v in s.target.items())
        word("", f"{self.code_for('set_position')} {words}".strip(), alone=True)

    def w_TravelLimit(self, s: n.TravelLimit, word, new_line, rest: list):
        if s.dialect != DIALECT:
            raise NotExpressible(f"travel limits {s.text!r} from {s.dialect or 'the source'} "
                                 f"({s.scope.replace('_', ' ')} limits differ between controls)")
        word("", s.text, alone=True)

    def w_Passthrough(self, s: n.Passthrough, word, new_line, rest: list):
        if s.dialect == DIALECT:
            word("", s.text, alone=s.text.startswith("#"))
        elif s.dialect and s.reason.startswith(NO_EFFECT_PREFIX):
            word("", "; " + self.foreign_function_comment(s), alone=True)
        elif self.program.dialect != DIALECT and _MACHINE_M.fullmatch(s.text.strip()):
            # a machine's own M function (a clamp, a conveyor, a PLC output: M27, M95): its number
            # is the machine builder's on either control, so it is kept as written, as the ISO and
            # Sinumerik emitters keep it, and said (NC403); refused, it stopped the conversion
            text = s.text.strip().upper()
            self.diags.append(at_span("NC403", "warning", f"kept verbatim from {s.dialect or self.program.dialect}: {text} "
                                      f"({s.reason}): the machine's own M function", self._where()))
            word("M", text)
        else:
            raise NotExpressible(f"{s.text!r} ({s.reason or 'kept verbatim'} from {s.dialect or 'the source'})")

    def message(self, e) -> str:
        if isinstance(e, n.Str):
            return '"' + e.value.replace("%", "%%").replace('"', '\\"') + '"'
        if isinstance(e, n.Func) and e.name == "format" and e.args and isinstance(e.args[0], n.Str):
            fmt = '"' + e.args[0].value.replace('"', '\\"') + '"'
            return ", ".join([fmt] + [self.expr(a) for a in e.args[1:]])
        return f'"%D", {self.expr(e)}'

    def w_ModeChange(self, s: n.ModeChange, word, new_line, rest: list) -> int:
        g, v = s.group, s.value
        if g == "spindle":
            self.spindle_dir = v
            if s.code == "" and self._tap_block(rest):
                return 0                             # a Fagor G63's direction: the sign of its S
            if self.motion == "thread":
                self.tap_cancelled = True            # Fagor: M3/M4/M5/M19 end G63
            if self.s_negative and v in ("cw", "ccw") and self.speed is not None:
                word("S", "S" + format_number(abs(self.speed)))     # negative S only under G63
                self.s_negative = False
        if g == "feed_mode":
            self.feed_mode = v
        if g == "motion":
            if v in ("arc_3point", "arc_tangent"):
                self.pending_motion = v
                return 0
            self.pending_motion = None
            if v == self.motion and s.code == "":
                return 0                 # the front end's restore after a one-shot G08/G09
            if self.motion == "tap_interp" and v == "rapid" and s.code == "":
                self.motion = v          # the front end's: M3/M4/M5/M19 ended G63
                return 0
            self.motion = v
            if v == "thread":            # spindle-synchronised: G63, its F and S in motion_words
                self.tap_cancelled = False
                word("GMOTION", self.code_for("motion", "tap_interp"))
                return 0
        if g == "cutter_comp":
            self.comp_on = v != "off"
        if g == "distance":
            self.distance = v
        if g == "plane":
            self.plane = v
        if g == "tool_length":
            if v == "minus":
                raise NotExpressible("negative tool length compensation (G44)")
            self.length_behind = None
            if v == "off":
                if self.comp_on and self.registers:
                    raise NotExpressible("tool length off (G49) under cutter radius compensation: a "
                                         "Fagor D0 ends the radius compensation too (8065 manual, "
                                         "tool offsets)")
                self.length_on = False
                self.iso_length = "off"
                word("D", "D0")
                return 0
            self.length_on = True
            # a Fagor source names its D in the code; an ISO G43 takes the H of this block
            nxt = next((x for x in rest if isinstance(x, n.OffsetSelect)), None)
            h = _num(nxt.index) if nxt is not None and nxt.kind == "length" else self.iso_h
            self.iso_length = h if h is not None else self.tool_active
            if nxt is not None and nxt.kind == "length":
                self._length_of_active_tool(nxt.index)
            if s.code.upper().startswith("D") and len(s.code) > 1:
                word("D", s.code.upper())
            elif nxt is None:
                word("D", "D" + (self.value(self.radius_index) if self.radius_index is not None
                                 else "1"))
            return 0
        if g == "work_offset":
            if v.upper().startswith("G54.1P"):
                word("G", f"{self.code_for('work_offset')}={int(v[6:]) + 6}")
                return 0
        rule = self.table.code_for(g, v)
        if rule is None or rule.group != g:
            raise NotExpressible(f"{s.code or g + ' ' + v} ({g} {v})")
        word("G" + str(rule.dialect_group or rule.code), rule.spelling or rule.code)
        return 0

    def motion_words(self, s: n.Motion, word) -> None:
        val = self.value
        if s.aperture is not None:
            raise NotExpressible("an arc by opening angle")
        if s.thread_start is not None and _num(s.thread_start) != 0:
            # Fagor's Q1= holds for its G33 block only, the source's angle is a setting that
            # holds for later threads too (interp/thread_starts.py): not written
            raise NotExpressible("a thread start angle (SF=, G33 Q)")
        if s.turns is not None and _num(s.turns) != 0:
            raise NotExpressible("an arc with extra full turns")
        if s.machine_coords:
            word("", "#MCS")
        if self.pending_motion == "arc_3point":
            if not s.via:
                raise NotExpressible("a three-point arc without an intermediate point")
            if self.distance != "absolute":
                self.lowered("G09 intermediate point in incremental coordinates")
            word("G", self.code_for("arc_once", "three_point"))
        elif self.pending_motion == "arc_tangent":
            word("G", self.code_for("arc_once", "tangent"))
        elif s.via:
            raise NotExpressible("an intermediate point outside a three-point arc")
        if self.motion is None and not self.in_sub and self.first_motion is None:
            self.motion = "caller"          # a subprogram file's first move: its caller's mode, as written
        elif self.motion is None:
            # the first move of a unit: its mode is the power-on default (the source control's in
            # a main program), written out
            self.motion = "rapid" if self.in_sub else self.first_motion
            word("GMOTION", self.code_for("motion", self.motion))
        if self.motion == "thread" and self.tap_cancelled:
            self.tap_cancelled = False
            word("GMOTION", self.code_for("motion", "tap_interp"))
        for a, av in s.target.items():
            if av.mode is not None and av.mode != ("abs" if self.distance == "absolute" else "inc"):
                raise NotExpressible(f"{a} in {av.mode} mode for one word")
            word(a, a + val(av.value))
        if self.motion == "thread":
            self._tap_words(s, word)
            return
        if s.polar:
            if self.distance != "absolute":
                raise NotExpressible("polar coordinates in incremental mode")
            self.polar_words_check(s)
            if getattr(self, "pole_unwritten", False):
                raise NotExpressible("polar coordinates about a pole that was written as plain motion "
                                     "(Fagor's polar origin is not there)")
            if "radius" in s.polar:
                word("R", "R" + val(s.polar["radius"]))
            if "angle" in s.polar:
                word("Q", "Q" + val(s.polar["angle"]))
        if s.via:
            for a, letter in zip("XYZ", "IJK"):
                if a in s.via:
                    word(letter, letter + val(s.via[a].value))
        if s.center:
            absolute = {av.mode for av in s.center.values()} == {"abs"}
            if absolute:
                word("G6", self.code_for("arc_once", "absolute_centre"))
            for a in "IJK":
                if a in s.center:
                    word(a, a + val(s.center[a].value))
        if s.radius is not None:
            if s.polar:
                raise NotExpressible("an arc radius together with polar coordinates")
            word("R", "R" + val(s.radius))

    def _tap_words(self, s: n.Motion, word) -> None:
        """F and signed S of a spindle-synchronised move written as G63 (seed L8556-8780: lead =
        F / S, the spindle turning by the sign of S): the lead is the move's I/J/K word."""
        leads = [ir_walk.literal(av.value) for av in (s.center or {}).values()]
        lead = next((x for x in leads if x), None)
        if lead is None or not self.speed or self.feed_mode == "inverse_time":
            raise NotExpressible("a spindle-synchronised move without a constant lead and spindle speed")
        self.lowered("tapping and threads written as Fagor G63 (interpolated tapping: lead = F / S, "
                     "the spindle turning by the sign of S)")
        feed = abs(lead) if self.feed_mode == "per_rev" else abs(lead) * self.speed
        word("F", "F" + format_number(round(feed, 6)))
        self.feed_clobbered = True
        negative = self.spindle_dir == "ccw"
        word("S", "S" + format_number(-self.speed if negative else self.speed))
        self.s_negative = negative

    def _subcall(self, s: n.SubCall, word) -> None:
        if s.args:
            raise NotExpressible(f"positional arguments of the call to {s.name}")
        if s.repeat is not None and _num(s.repeat) != 1:
            raise NotExpressible(f"a repeated call of {s.name}")
        name = str(s.name)
        local = name in self.program.subprograms
        params = []
        for key, e in s.named_args.items():
            var = s.bindings.get(key)
            if var is None:
                if key == "P" and not params and not local:
                    continue
                raise NotExpressible(f"the call argument {key} of {name}")
            target = self.var_text(var)
            if not (target.startswith("P") and target[1:].isdigit()):
                raise NotExpressible(f"the call argument {key} of {name}")
            k = int(target[1:])
            params.append(f"{'ABCDEFGHIJKLMNOPQRSTUVWXYZ'[k]}{self.value(e)}" if k < 26
                          else f"P{k}={self.expr(e)}")
        callee = _sub_name(name) if local else name
        if s.modal != "none":
            word("", " ".join([f"#MCALL {callee}"] + params), alone=True)
        elif params or s.kind in ("pcall", "g65"):
            word("", " ".join([f"#PCALL {callee}"] + params), alone=True)
        elif local:
            word("", f"LL {callee}", alone=True)
        else:
            word("", f"L {callee}", alone=True)

    def frame(self, s: n.FrameOp, word) -> None:
        if s.indirect:
            raise NotExpressible("a frame value with a computed axis (AX[..]=)")
        scale, rotation = self.code_for("frame", "scale"), self.code_for("frame", "rotation")
        mirror_off, shift = self.code_for("frame", "mirror_off"), self.code_for("incremental_offset")
        if s.op in ("scale", "mirror") and s.additive and not s.clear:
            from nctrans.interp.offsets import additive_frames_compose
            if additive_frames_compose(self.program.dialect):
                # Sinumerik AMIRROR/ASCALE compose in the current (rotated, mirrored) system;
                # Fagor's G11-G14 and G72 replace the mirror set and the factor in a fixed order
                raise NotExpressible(f"an additive {s.op} in the current coordinate system")
        if s.op == "scale":
            if s.clear:
                word("", scale, alone=True)
                return
            vals = list(s.values.values())
            if set(s.values) != {"X", "Y", "Z"} or len({self.expr(v) for v in vals}) != 1 or s.center:
                raise NotExpressible("a scale that differs per axis or has a centre")
            word("", f"{scale} S{self.value(vals[0])}", alone=True)
        elif s.op == "rot":
            if s.clear:
                word("", rotation, alone=True)
                return
            if s.angle is None or s.values:
                raise NotExpressible("a rotation about a named axis")
            if s.center is not None and not s.center:
                raise NotExpressible("a rotation about the current position (ISO G68 without a centre)")
            centre = ""
            if s.center:
                ci = s.center.get("X")
                cj = s.center.get("Y")
                centre = (f" I{self.value(ci.value if ci else n.Num(0.0))}"
                          f" J{self.value(cj.value if cj else n.Num(0.0))}")
            if not s.additive:
                word("", rotation, alone=True)     # G73 Q adds; a replacing rotation cancels first
                self.lowered("a rotation that replaces the one in force written as G73 then G73 Q")
            word("", f"{rotation} Q{self.value(s.angle)}{centre}", alone=True)
        elif s.op == "mirror":
            if s.clear and not s.values:
                word("", mirror_off, alone=True)
                return
            if s.clear or s.center or not s.additive:
                raise NotExpressible("a mirror about a point or that replaces other frames")
            axes = sorted(s.values)
            if not set(axes) <= set(AXES):
                raise NotExpressible(f"mirror of {axes}")
            word("", mirror_off, alone=True)
            word("", f"{self.code_for('frame', 'mirror_axes')} " + " ".join(f"{a}-1" for a in axes), alone=True)
        elif s.op == "trans" and s.local and not s.additive:
            if s.clear or not s.values:
                word("", shift, alone=True)
                return
            # G158 replaces per axis: cancel first so axes left out of this one are 0 too
            word("", shift, alone=True)
            word("", f"{shift} " + " ".join(f"{a}{self.value(e)}" for a, e in s.values.items()), alone=True)
        else:
            raise NotExpressible(f"the frame operation {s.op} (a translation)")


_ORDER = {c: i for i, c in enumerate("#GXYZUVWABCRQIJKFSTDMH")}


def _word_order(w: str) -> int:
    """Fagor's reference layout G.. X..C F S T D M (spec §2.1); the order is free."""
    if w.startswith(("$", "P", "V.", "L", "LL")) and not w[:1] in "G":
        return 100 if not w.startswith("#") else 0
    return _ORDER.get(w[:1], 50)


# statements that never let the control see the tool length (a motion is judged by its axes)
_LENGTH_HIDDEN = (n.ToolSelect, n.ToolChange, n.OffsetSelect, n.Feed, n.SpindleSpeed, n.SpindleLimit,
                  n.Dwell, n.Stop, n.Message, n.VarDecl, n.Assign, n.ModeChange, n.ProgramEnd)


def _shows_length(s) -> bool:
    """A statement that can show the tool length: a move with a tool-axis (or any non-X/Y) word,
    machine coordinates, polar or indirect axes; anything not known to hide it (a call, a jump)."""
    if type(s) is n.Motion:
        return bool(s.machine_coords or s.polar or s.indirect or any(a.upper() not in ("X", "Y") for a in s.target))
    if type(s) is n.ModeChange:
        return s.group == "cycle"
    return not isinstance(s, _LENGTH_HIDDEN)


def _is_target(b, targets: set) -> bool:
    """A block a jump may land on (its state depends on the path)."""
    num = str(b.number).upper().lstrip("N") if b.number is not None else None
    return b.label is not None or (num is not None and num.isdigit() and _key(num) in targets)


def _machine_kind(dialect: str) -> Optional[str]:
    try:
        return get_dialect(dialect).machine_kind
    except Exception:           # a dialect not registered here (a test's)
        return None


def _table_option(dialect: str, key: str) -> Any:
    return rules_option(dialect, key)


def _num(e) -> Optional[float]:
    return e.value if isinstance(e, n.Num) else None


def _key(s) -> Any:
    s = str(s).strip().upper()
    s2 = s.lstrip("N")
    return int(s2) if s2.isdigit() else s


def _label_name(s: str) -> str:
    import re
    name = re.sub(r"[^A-Za-z0-9]", "", str(s)).upper()[:14]
    return name or "L"


def _sub_name(name: str) -> str:
    import re
    return re.sub(r"[^A-Za-z0-9]", "", name).upper()[:14] or "SUB"


def _program_header(p: n.Program) -> str:
    import re
    name = p.name or (p.meta or {}).get("program_name") or "PROGRAM"
    name = re.sub(r"[^A-Za-z0-9]", "", str(name)).upper()[:14]
    return name or "PROGRAM"


def _goto_targets(body: list) -> set:
    return {_key(t) for t in ir_walk.jump_targets(body)}


def _sub_order(p: n.Program) -> list[str]:
    """Local subroutines with callees first (a local sub may only call one defined before it)."""
    calls = {name: {s.name for b in ir_walk.blocks(sub.body) for s in b.body
                    if isinstance(s, n.SubCall) and s.name in p.subprograms}
             for name, sub in p.subprograms.items()}
    order: list[str] = []
    seen: set = set()

    def visit(k, depth=0):
        if k in seen or depth > 50:
            return
        seen.add(k)
        for c in sorted(calls.get(k, ())):
            visit(c, depth + 1)
        order.append(k)
    for k in p.subprograms:
        visit(k)
    return order



def _describe(s) -> str:
    t = type(s).__name__
    if isinstance(s, n.CycleCall):
        return f"the cycle call {s.name or s.kind} (expand cycles first)"
    if isinstance(s, n.CycleParams):
        return "canned-cycle parameters (expand cycles first)"
    if isinstance(s, n.HomeReturn):
        return "a reference-point return"
    if isinstance(s, n.DataSetting):
        return f"a data setting ({s.kind})"
    return f"the statement {t}"


def emit_program(program: n.Program) -> EmitResult:
    e = FagorEmitter(program)
    text = e.run()
    return EmitResult(text, e.diags)
