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

from nctrans.diagnostics import Diagnostic, at_span
from nctrans.dialects.base import EmitResult
from nctrans.dialects.base import get as get_dialect
from nctrans.ir import nodes as n
from nctrans.ir import walk as ir_walk
from nctrans.rules import load_table

DIALECT = "fagor"
AXES = "XYZUVWABC"

# neutral op -> (Fagor spelling, precedence); higher binds tighter (spec §6.5)
_OPS = {"bor": ("|", 1), "or": ("+", 4), "band": ("&", 2), "bxor": ("^", 2),
        "==": ("==", 3), "!=": ("!=", 3), "<": ("<", 3), "<=": ("<=", 3), ">": (">", 3), ">=": (">=", 3),
        "+": ("+", 4), "-": ("-", 4), "*": ("*", 5), "/": ("/", 5), "and": ("*", 5),
        "pow": ("**", 6), "mod": ("MOD", 6)}
_LOGICAL = frozenset(("and", "or"))
_FUNCS = {"sin": "SIN", "cos": "COS", "tan": "TAN", "asin": "ASIN", "acos": "ACOS", "atan": "ATAN",
          "sqrt": "SQRT", "abs": "ABS", "round": "ROUND", "fix": "INT", "trunc": "INT", "fup": "FUP",
          "ln": "LN", "exp": "EXP", "bnot": "INV"}


def _fagor_spelling(key) -> Optional[str]:
    """The Fagor spelling of another dialect's system variable, through its neutral meaning."""
    from nctrans.rules import system_meaning
    meaning = system_meaning(key)
    if meaning is None:
        return None
    own = load_table(DIALECT).system_variables
    return next((sp for sp, m in own.items() if m == meaning), None)


class NotExpressible(Exception):
    """Raised while spelling; the emitter turns it into NC402 at the statement's line."""


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


class _Spell:
    """Expressions and variables in Fagor syntax; `ctx` receives lowerings (NC401)."""

    def __init__(self, ctx=None):
        self.ctx = ctx

    def info(self, what: str) -> None:
        if self.ctx is not None:
            self.ctx.lowered(what)

    def expr(self, e: Any) -> str:
        return self._expr(e)[0]

    def _expr(self, e: Any) -> tuple[str, int]:
        t = type(e)
        if t is n.Num:
            return format_number(e.value), 9 if e.value >= 0 else 7
        if t is n.Var:
            return self.var(e), 9
        if t is n.Binary:
            op = e.op
            if op == "div":
                return f"INT[{self.expr(n.Binary('/', e.left, e.right))}]", 9
            if op == "xor":
                return self._expr(n.Binary("!=", _truth(e.left), _truth(e.right)))
            if op not in _OPS:
                raise NotExpressible(f"operator {op!r}")
            sym, prec = _OPS[op]
            lt, lp = self._expr(e.left)
            rt, rp = self._expr(e.right)
            if op in _LOGICAL:        # "*" / "+" as AND / OR act on bracketed conditions
                return f"[{lt}]{sym}[{rt}]", prec
            left = lt if lp >= prec else f"[{lt}]"
            right = rt if rp > prec else f"[{rt}]"
            if op == "pow" and isinstance(e.right, n.Num) and e.right.value == 2:
                return f"SQR[{lt}]", 9
            return f"{left}{sym}{right}" if sym not in ("MOD",) else f"{left} MOD {right}", prec
        if t is n.Unary:
            if e.op == "-":
                ot, op_ = self._expr(e.operand)
                return f"-{ot if op_ >= 7 else '[' + ot + ']'}", 7
            if e.op == "+":
                return self._expr(e.operand)
            if e.op == "not":
                return f"[{self.expr(e.operand)}]==0", 3
            if e.op == "bnot":
                return f"INV[{self.expr(e.operand)}]", 9
            raise NotExpressible(f"unary operator {e.op!r}")
        if t is n.Func:
            name = e.name.lower()
            args = e.args
            if name in ("atan2",) or (name == "atan" and len(args) == 2):
                # ARG[x, y] is the angle of the vector (x, y) = atan2(y, x), 0..360
                return f"ARG[{self.expr(args[1])},{self.expr(args[0])}]", 9
            if name == "pow" and len(args) == 2:
                return self._expr(n.Binary("pow", args[0], args[1]))
            if name in ("minval", "maxval") and len(args) == 2:
                a, b = args
                total = n.Binary("-" if name == "minval" else "+", n.Binary("+", a, b),
                                 n.Func("abs", [n.Binary("-", a, b)]))
                self.info(f"{name.upper()} written as an ABS expression")
                return self._expr(n.Binary("/", total, n.Num(2.0)))
            if name not in _FUNCS:
                raise NotExpressible(f"function {e.name.upper()}")
            return f"{_FUNCS[name]}[{','.join(self.expr(a) for a in args)}]", 9
        if t is n.Str:
            raise NotExpressible("a string value outside a message")
        raise NotExpressible(f"expression {t.__name__}")

    def var(self, v: n.Var) -> str:
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
            self.info(f"R{k} written as the global parameter P{9000 + k}")
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
            if k.startswith("V."):
                idx = "".join(f"[{self.expr(i)}]" for i in v.indices or ())
                if idx:
                    head, _, tail = k.rpartition(".")
                    return f"{head}{idx}.{tail}" if head.count(".") >= 2 else k + idx
                return k
            raise NotExpressible(f"system variable {key}")
        raise NotExpressible(f"variable {sp}:{key}")


def _truth(e):
    return n.Binary("!=", e, n.Num(0.0))


def format_expr(e: Any) -> str:
    """An IR expression in Fagor syntax (for messages and verbatim text)."""
    return _Spell().expr(e)


def _value(sp: _Spell, e: Any) -> str:
    """An address value: numbers, parameters and variables as they are, the rest in brackets."""
    if type(e) is n.Num:
        return format_number(e.value)
    if type(e) is n.Var:
        return sp.var(e)
    if type(e) is n.Unary and e.op == "-" and type(e.operand) in (n.Num, n.Var):
        return "-" + _value(sp, e.operand)
    return f"[{sp.expr(e)}]"


class _Emitter:
    def __init__(self, program: n.Program):
        self.program = program
        self.table = load_table(DIALECT)
        self.diags: list[Diagnostic] = []
        self.out: list[str] = []
        self.span: Optional[n.Span] = None
        self.spell = _Spell(self)
        self.targets: set = set()
        self.motion = "rapid"
        self.distance = "absolute"
        self.plane = "XY"
        self.pending_motion: Optional[str] = None     # arc_3point / arc_tangent: one-shot G09/G08
        self.radius_index: Any = None
        self.length_on = False
        self.in_sub = False
        self._reported: set = set()

    # ---------------------------------------------------------------- reporting
    def lowered(self, what: str) -> None:
        key = (what, self.span.line if self.span else 0)
        if key not in self._reported:
            self._reported.add(key)
            self.diags.append(at_span("NC401", "info", f"lowered for Fagor: {what}", self._where()))

    def refuse(self, what: str) -> None:
        line = self.span.line if self.span is not None else 1
        self.diags.append(at_span("NC402", "error", f"Fagor 8060/8065 cannot express {what} (source "
                                  f"line {line})", self._where()))

    def _where(self):
        return self.span if self.span is not None else n.Span(self.program.file, 1)

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
            self._reset()
            self.nodes(sub.body)
            if not ir_walk.ends_with_return(sub.body):
                self.out.append("M17")
        self.in_sub = False
        self._reset()
        self.out.append(f"%{_program_header(p)}")
        self.prologue()
        self.nodes(p.body)
        return "\n".join(self.out) + "\n"

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
                words.append(_g(rule.code))
                if group == "plane":
                    self.plane = value
        if words:
            self.span = n.Span(p.file, 1)
            self.lowered(f"power-on modes of {p.dialect} written out: {' '.join(words)}")
            self.out.append(" ".join(words))

    def _reset(self) -> None:
        self.motion = None
        self.pending_motion = None

    def nodes(self, nodes: list) -> None:
        for node in nodes:
            self.span = getattr(node, "span", self.span)
            t = type(node)
            if t is n.Block:
                self.block(node)
            elif t is n.If:
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
                    var = self.spell.var(node.var)
                    step = node.step if node.step is not None else n.Num(1.0)
                    self.out.append(f"$FOR {var}={self.spell.expr(node.start)},"
                                    f"{self.spell.expr(node.end)},{self.spell.expr(step)}")
                except NotExpressible as e:
                    self.refuse(str(e))
                self.nodes(node.body)
                self.out.append("$ENDFOR")
            elif t is n.Case:
                try:
                    subj = self.spell.expr(node.subject)
                    for value, label in node.branches:
                        self.out.append(f"$IF [{subj}]==[{self.spell.expr(value)}] $GOTO "
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
            return self.spell.expr(e)
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

        body = b.body
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

    def statement(self, s, word, new_line, rest: list) -> int:
        """Write one statement; returns how many following statements it consumed."""
        sp = self.spell
        t = type(s)
        val = lambda e: _value(sp, e)            # noqa: E731
        if t is n.ModeChange:
            return self.mode(s, word, rest)
        if t is n.Motion:
            self.motion_words(s, word)
            new_line()
            return 0
        if t is n.Feed:
            word("F", "F" + val(s.value))
        elif t is n.SpindleSpeed:
            if s.spindle not in (0, 1):
                word("", f"S{s.spindle}={sp.expr(s.value)}")
            else:
                word("S", "S" + val(s.value))
        elif t is n.SpindleLimit:
            word("G192", "G192")
            word("S", "S" + val(s.value))
        elif t is n.ToolSelect:
            word("T", "T" + val(s.tool))
        elif t is n.ToolChange:
            word("M6", "M6")
            # Fagor: D1 is implicit after a tool change (the front end writes it as these two)
            if (len(rest) >= 2 and isinstance(rest[0], n.ModeChange) and rest[0].group == "tool_length"
                    and rest[0].value == "plus" and isinstance(rest[1], n.OffsetSelect)
                    and _num(rest[1].index) == 1):
                self.length_on, self.radius_index = True, 1
                return 2
            if not self.length_on:
                self.lowered("M06 on Fagor activates offset D1 of the new tool (tool length on)")
            self.length_on, self.radius_index = True, 1
        elif t is n.OffsetSelect:
            if s.kind == "radius":
                word("D", "D" + val(s.index))
                self.radius_index = s.index
                if not self.length_on and _num(s.index) != 0:
                    self.lowered("D selects the tool length offset too on Fagor")
            else:
                word("D", "D" + val(s.index))
                self.lowered("length offset H written as the Fagor offset D of the active tool")
        elif t is n.Dwell:
            if s.seconds is None:
                raise NotExpressible("a dwell in spindle revolutions")
            word("G4", "G4 K" + val(s.seconds))
        elif t is n.Assign:
            new_line()
            word("", f"{sp.var(s.target)}={sp.expr(s.value)}", alone=True)
        elif t is n.Goto:
            new_line()
            target = self._target(s.target)
            if s.cond is not None:
                word("", f"$IF {sp.expr(s.cond)} $GOTO {target}", alone=True)
            else:
                word("", f"$GOTO {target}", alone=True)
        elif t is n.SubCall:
            self.call(s, word)
        elif t is n.ModalCallOff:
            word("", "#MDOFF", alone=True)
        elif t is n.Return:
            if s.to_label is not None:
                raise NotExpressible("a return to a label")
            word("M", "M17" if self.in_sub else "M30")
        elif t is n.ProgramEnd:
            if s.kind == "restart":
                raise NotExpressible("a program restart (M99 in a main program)")
            word("M", "M02" if s.kind == "end" else "M30")
        elif t is n.Stop:
            word("M", "M01" if s.optional else "M00")
        elif t is n.Message:
            word("", f"#MSG [{self.message(s.text)}]", alone=True)
        elif t is n.Alarm:
            text = self.message(s.text) if s.text is not None else f'"ALARM %D", {sp.expr(s.number)}'
            word("", f"#ERROR [{text}]", alone=True)
        elif t is n.FrameOp:
            self.frame(s, word)
        elif t is n.PolarPole:
            if s.relative_to == "last_point" and not s.target and not s.polar:
                word("", "G30", alone=True)
            elif s.relative_to == "zero" and not s.polar and len(s.target) <= 2:
                a1, a2 = {"XY": ("X", "Y"), "ZX": ("Z", "X"), "YZ": ("Y", "Z")}[self.plane]
                if set(s.target) - {a1, a2}:
                    raise NotExpressible("a polar pole outside the plane")
                i = s.target.get(a1)
                j = s.target.get(a2)
                word("", f"G30 I{val(i.value if i else n.Num(0.0))} J{val(j.value if j else n.Num(0.0))}",
                     alone=True)
            else:
                raise NotExpressible(f"a polar pole relative to the {s.relative_to.replace('_', ' ')}")
        elif t is n.SetPosition:
            words = " ".join(f"{a}{val(v.value)}" for a, v in s.target.items())
            word("", f"G92 {words}".strip(), alone=True)
        elif t is n.TravelLimit:
            if s.dialect != DIALECT:
                raise NotExpressible(f"travel limits {s.text!r} from {s.dialect or 'the source'} "
                                     f"({s.scope.replace('_', ' ')} limits differ between controls)")
            word("", s.text, alone=True)
        elif t is n.Passthrough:
            if s.dialect == DIALECT:
                word("", s.text, alone=s.text.startswith("#"))
            else:
                raise NotExpressible(f"{s.text!r} ({s.reason or 'kept verbatim'} from {s.dialect or 'the source'})")
        else:
            raise NotExpressible(_describe(s))
        return 0

    def message(self, e) -> str:
        if isinstance(e, n.Str):
            return '"' + e.value.replace("%", "%%").replace('"', '\\"') + '"'
        if isinstance(e, n.Func) and e.name == "format" and e.args and isinstance(e.args[0], n.Str):
            fmt = '"' + e.args[0].value.replace('"', '\\"') + '"'
            return ", ".join([fmt] + [self.spell.expr(a) for a in e.args[1:]])
        return f'"%D", {self.spell.expr(e)}'

    def mode(self, s: n.ModeChange, word, rest: list) -> int:
        g, v = s.group, s.value
        if g == "motion":
            if v in ("arc_3point", "arc_tangent"):
                self.pending_motion = v
                return 0
            self.pending_motion = None
            if v == self.motion and s.code == "":
                return 0                 # the front end's restore after a one-shot G08/G09
            self.motion = v
        if g == "distance":
            self.distance = v
        if g == "plane":
            self.plane = v
        if g == "tool_length":
            if v == "minus":
                raise NotExpressible("negative tool length compensation (G44)")
            if v == "off":
                self.length_on = False
                word("D", "D0")
                return 0
            self.length_on = True
            # a Fagor source names its D in the code; an ISO G43 takes the H of this block
            nxt = next((x for x in rest if isinstance(x, n.OffsetSelect)), None)
            if s.code.upper().startswith("D") and len(s.code) > 1:
                word("D", s.code.upper())
            elif nxt is None:
                word("D", "D" + (_value(self.spell, self.radius_index) if self.radius_index is not None
                                 else "1"))
            return 0
        if g == "work_offset":
            if v.upper().startswith("G54.1P"):
                word("G", f"G159={int(v[6:]) + 6}")
                return 0
        rule = self.table.code_for(g, v)
        if rule is None or rule.group != g:
            raise NotExpressible(f"{s.code or g + ' ' + v} ({g} {v})")
        word("G" + str(rule.dialect_group or rule.code), rule.code if rule.code[0] != "G" else
             _g(rule.code))
        return 0

    def motion_words(self, s: n.Motion, word) -> None:
        sp = self.spell
        val = lambda e: _value(sp, e)        # noqa: E731
        if s.aperture is not None:
            raise NotExpressible("an arc by opening angle")
        if s.turns is not None and _num(s.turns) != 0:
            raise NotExpressible("an arc with extra full turns")
        if s.machine_coords:
            word("", "#MCS")
        if self.pending_motion == "arc_3point":
            if not s.via:
                raise NotExpressible("a three-point arc without an intermediate point")
            if self.distance != "absolute":
                self.lowered("G09 intermediate point in incremental coordinates")
            word("G", "G09")
        elif self.pending_motion == "arc_tangent":
            word("G", "G08")
        elif s.via:
            raise NotExpressible("an intermediate point outside a three-point arc")
        if self.motion is None:
            # the first move of a unit: its mode is the power-on default, written out
            self.motion = "rapid"
            word("GMOTION", "G00")
        for a, av in s.target.items():
            if av.mode is not None and av.mode != ("abs" if self.distance == "absolute" else "inc"):
                raise NotExpressible(f"{a} in {av.mode} mode for one word")
            word(a, a + val(av.value))
        if s.polar:
            if self.distance != "absolute":
                raise NotExpressible("polar coordinates in incremental mode")
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
                word("G6", "G06")
            for a in "IJK":
                if a in s.center:
                    word(a, a + val(s.center[a].value))
        if s.radius is not None:
            if s.polar:
                raise NotExpressible("an arc radius together with polar coordinates")
            word("R", "R" + val(s.radius))

    def call(self, s: n.SubCall, word) -> None:
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
            target = self.spell.var(var)
            if not (target.startswith("P") and target[1:].isdigit()):
                raise NotExpressible(f"the call argument {key} of {name}")
            k = int(target[1:])
            params.append(f"{'ABCDEFGHIJKLMNOPQRSTUVWXYZ'[k]}{_value(self.spell, e)}" if k < 26
                          else f"P{k}={self.spell.expr(e)}")
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
        sp = self.spell
        if s.op == "scale":
            if s.clear:
                word("", "G72", alone=True)
                return
            vals = list(s.values.values())
            if set(s.values) != {"X", "Y", "Z"} or len({sp.expr(v) for v in vals}) != 1 or s.center:
                raise NotExpressible("a scale that differs per axis or has a centre")
            word("", f"G72 S{_value(sp, vals[0])}", alone=True)
        elif s.op == "rot":
            if s.clear:
                word("", "G73", alone=True)
                return
            if s.angle is None or s.values:
                raise NotExpressible("a rotation about a named axis")
            centre = ""
            if s.center:
                ci = s.center.get("X")
                cj = s.center.get("Y")
                centre = (f" I{_value(sp, ci.value if ci else n.Num(0.0))}"
                          f" J{_value(sp, cj.value if cj else n.Num(0.0))}")
            if not s.additive:
                word("", "G73", alone=True)     # G73 Q adds; a replacing rotation cancels first
                self.lowered("a rotation that replaces the one in force written as G73 then G73 Q")
            word("", f"G73 Q{_value(sp, s.angle)}{centre}", alone=True)
        elif s.op == "mirror":
            if s.clear and not s.values:
                word("", "G10", alone=True)
                return
            if s.clear or s.center or not s.additive:
                raise NotExpressible("a mirror about a point or that replaces other frames")
            axes = sorted(s.values)
            if not set(axes) <= set(AXES):
                raise NotExpressible(f"mirror of {axes}")
            word("", "G10", alone=True)
            word("", "G14 " + " ".join(f"{a}-1" for a in axes), alone=True)
        elif s.op == "trans" and s.local and not s.additive:
            if s.clear or not s.values:
                word("", "G158", alone=True)
                return
            # G158 replaces per axis: cancel first so axes left out of this one are 0 too
            word("", "G158", alone=True)
            word("", "G158 " + " ".join(f"{a}{_value(sp, e)}" for a, e in s.values.items()), alone=True)
        else:
            raise NotExpressible(f"the frame operation {s.op} (a translation)")


_ORDER = {c: i for i, c in enumerate("#GXYZUVWABCRQIJKFSTDMH")}


def _word_order(w: str) -> int:
    """Fagor's reference layout G.. X..C F S T D M (spec §2.1); the order is free."""
    if w.startswith(("$", "P", "V.", "L", "LL")) and not w[:1] in "G":
        return 100 if not w.startswith("#") else 0
    return _ORDER.get(w[:1], 50)


def _g(code: str) -> str:
    """G0 -> G00 as Fagor manuals write them; longer codes as they are."""
    return f"G{int(code[1:]):02d}" if code[1:].isdigit() and int(code[1:]) < 10 else code


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
    e = _Emitter(program)
    text = e.run()
    return EmitResult(text, e.diags)
