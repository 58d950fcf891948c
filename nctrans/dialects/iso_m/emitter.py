"""ISO milling emitter: IR Program -> normalised ISO text.

Normal form: `%`, the O number, N numbers kept, comments in parentheses, one G per modal group,
a decimal point on every address of the conversion list (X Y Z U V W A B C I J K Q R F, spec §2.3)
so the text means the same under every decimal-notation profile, macro B expressions and control
flow re-emitted, Passthrough text verbatim. parse(emit(parse(x))) == parse(x) up to spans and
number spellings (tests/test_iso_roundtrip.py).

Constructs from other dialects get an ISO equivalent where one exists, reported as NC401 (info):
named variables and R parameters -> common variables, FOR/REPEAT/LOOP/CASE -> WHILE/IF..GOTO,
messages -> `(MSG, ...)` comments. Where none exists the construct is reported as NC402 (error)
naming it and its source line, and left out of the text as a comment.
"""
from __future__ import annotations

from decimal import Decimal
from typing import Any, Optional

from nctrans.diagnostics import Diagnostic, at_span
from nctrans.ir import nodes as n
from nctrans.rules import load_table

POINT_LETTERS = frozenset("XYZUVWABCIJKQRF")
AXES = "XYZABCUVW"

_OPS = {"+": ("+", 2), "-": ("-", 2), "or": ("OR", 2), "xor": ("XOR", 2), "bor": ("OR", 2),
        "bxor": ("XOR", 2), "*": ("*", 3), "/": ("/", 3), "and": ("AND", 3), "band": ("AND", 3),
        "mod": ("MOD", 3), "==": ("EQ", 1), "!=": ("NE", 1), ">": ("GT", 1), ">=": ("GE", 1),
        "<": ("LT", 1), "<=": ("LE", 1)}
_FUNCS = {"sin": "SIN", "cos": "COS", "tan": "TAN", "asin": "ASIN", "acos": "ACOS", "atan": "ATAN",
          "sqrt": "SQRT", "abs": "ABS", "round": "ROUND", "fix": "FIX", "trunc": "FIX", "fup": "FUP",
          "ln": "LN", "exp": "EXP", "bin": "BIN", "bcd": "BCD", "adp": "ADP", "pow": "POW"}


class NotExpressible(Exception):
    """Raised inside expression formatting; the caller turns it into NC402."""


def format_number(v: float, point: bool = False) -> str:
    """Exact shortest decimal text of a float (no exponent); `point` forces a decimal point."""
    if v != v or v in (float("inf"), float("-inf")):
        raise NotExpressible(f"number {v!r}")
    if v == int(v) and abs(v) < 1e16:
        text = str(int(v))
        if v == 0 and str(v).startswith("-"):
            text = "-0"
        return text + "." if point else text
    text = format(Decimal(repr(v)), "f")
    if "." in text:
        text = text.rstrip("0")
    return text


def format_expr(e: Any, ctx: Optional["_Emitter"] = None) -> str:
    """An IR expression in macro B syntax (brackets only where precedence needs them)."""
    return _expr(e, ctx)[0]


def _wrap(text: str, prec: int, need: int) -> str:
    return f"[{text}]" if prec < need else text


def _expr(e: Any, ctx) -> tuple[str, int]:
    t = type(e)
    if t is n.Num:
        return format_number(e.value), 5 if e.value >= 0 else 4
    if t is n.Var:
        return _var(e, ctx), 5
    if t is n.Binary:
        op = e.op
        if op == "pow":
            return format_expr(n.Func("pow", [e.left, e.right]), ctx), 5
        if op == "div":
            return format_expr(n.Func("fix", [n.Binary("/", e.left, e.right)]), ctx), 5
        if op not in _OPS:
            raise NotExpressible(f"operator {op!r}")
        sym, prec = _OPS[op]
        lt, lp = _expr(e.left, ctx)
        rt, rp = _expr(e.right, ctx)
        if prec == 1:
            return f"{_wrap(lt, lp, 2)}{sym}{_wrap(rt, rp, 2)}", 1
        return f"{_wrap(lt, lp, prec)}{sym}{_wrap(rt, rp, prec + 1)}", prec
    if t is n.Unary:
        if e.op in ("-", "+"):
            ot, op_ = _expr(e.operand, ctx)
            return f"{e.op}{_wrap(ot, op_, 4)}", 4
        if e.op == "not":
            ot, op_ = _expr(e.operand, ctx)
            return f"[{ot}]EQ0", 1
        raise NotExpressible(f"unary operator {e.op!r}")
    if t is n.Func:
        name = e.name.lower()
        if name == "atan2" and len(e.args) == 2:
            return f"ATAN[{format_expr(e.args[0], ctx)}]/[{format_expr(e.args[1], ctx)}]", 5
        if name in ("minval", "maxval") and len(e.args) == 2:
            a, b = e.args
            sign = n.Binary("-" if name == "minval" else "+", n.Binary("+", a, b),
                            n.Func("abs", [n.Binary("-", a, b)]))
            if ctx is not None:
                ctx.lowered(f"{name.upper()} written as an ABS expression")
            return format_expr(n.Binary("/", sign, n.Num(2.0)), ctx), 3
        if name not in _FUNCS:
            raise NotExpressible(f"function {e.name.upper()}")
        args = ",".join(format_expr(a, ctx) for a in e.args)
        if name == "atan":              # bracketed, so a following "/[" is not read as ATAN[a]/[b]
            return f"[ATAN[{args}]]", 5
        return f"{_FUNCS[name]}[{args}]", 5
    if t is n.Str:
        raise NotExpressible("a string value")
    raise NotExpressible(f"expression {t.__name__}")


def _var(v: n.Var, ctx) -> str:
    if v.space == "num":
        if v.key is None and v.indices:
            return f"#[{format_expr(v.indices[0], ctx)}]"
        return f"#{v.key}"
    if ctx is None:
        raise NotExpressible(f"variable {v.space}:{v.key}")
    return f"#{ctx.map_var(v)}"


def format_value(e: Any, ctx=None) -> str:
    """An address value: numbers and variables as they are, anything else in brackets."""
    if type(e) is n.Num:
        return format_number(e.value)
    if type(e) is n.Var:
        return _var(e, ctx)
    return f"[{format_expr(e, ctx)}]"


class _Line:
    """Words of one output line, with the letters already used (a repeated letter starts a new line)."""
    __slots__ = ("words", "used")

    def __init__(self):
        self.words: list[str] = []
        self.used: set[str] = set()


class _Emitter:
    def __init__(self, program: n.Program):
        self.program = program
        self.table = load_table("iso-m")
        self.diags: list[Diagnostic] = []
        self.out: list[str] = []
        self.span = None
        self.var_map: dict = {}
        self.next_common = 100
        self.next_label = 90000
        self.used_numbers = set()
        self.depth = 0
        # distance mode in source order, so a one-block G91 (incremental reference-point
        # approach from other dialects) can be followed by the G90 that restores it
        self.distance = "absolute"
        self.restore_absolute = False

    # -------------------------------------------------------------- reporting
    def lowered(self, what: str) -> None:
        self.diags.append(at_span("NC401", "info", f"lowered for ISO: {what}", self.span))

    def refuse(self, what: str) -> None:
        line = self.span.line if self.span is not None else 1
        self.diags.append(at_span("NC402", "error",
                                  f"ISO milling cannot express {what} (source line {line})", self.span))

    def map_var(self, v: n.Var) -> int:
        key = (v.space, v.key)
        if key not in self.var_map:
            if v.space == "R" and isinstance(v.key, int) and 0 <= v.key < 400:
                self.var_map[key] = 500 + v.key
            elif v.space in ("name", "R", "arg"):
                while self.next_common in self.var_map.values():
                    self.next_common += 1
                self.var_map[key] = self.next_common
                self.next_common += 1
            else:
                raise NotExpressible(f"system variable {v.key}")
            self.lowered(f"variable {v.key} mapped to #{self.var_map[key]}")
        if v.indices and v.space != "num":
            raise NotExpressible(f"array variable {v.key}")
        return self.var_map[key]

    def val(self, e) -> str:
        return format_value(e, self)

    def addr(self, letter: str, e) -> str:
        if type(e) is n.Num:
            return letter + format_number(e.value, letter in POINT_LETTERS)
        return letter + format_value(e, self)

    def fresh_label(self) -> str:
        while str(self.next_label) in self.used_numbers:
            self.next_label += 1
        self.next_label += 1
        return str(self.next_label - 1)

    # -------------------------------------------------------------- program
    def run(self) -> str:
        p = self.program
        self._collect_numbers(p.body)
        for sub in p.subprograms.values():
            self._collect_numbers(sub.body)
        meta = p.meta or {}
        percent = meta.get("percent", True) if p.dialect == "iso-m" else True
        if percent:
            self.out.append("%")
        if meta.get("archive_header"):
            self.out.append(str(meta["archive_header"]))
        head = self._program_word(p.name, meta.get("program_number"))
        if head:
            title = meta.get("title")
            self.out.append(head + (f" {self._comment(str(title))}" if title is not None else ""))
        self.nodes(p.body)
        for key, sub in p.subprograms.items():
            word = self._program_word(key, None)
            self.span = sub.span
            if word is None:
                self.refuse(f"subprogram name {key!r} (ISO programs are O numbers)")
                word = f"({key})"
            self.out.append(word)
            if sub.params:
                self.refuse(f"parameters of subprogram {key}")
            self.nodes(sub.body)
        if percent:
            self.out.append("%")
        return "\n".join(self.out) + "\n"

    @staticmethod
    def _program_word(name, number) -> Optional[str]:
        if name and name[0] in "Oo" and name[1:].replace("_", "").isalnum():
            return "O" + name[1:]
        if name and name.isdigit():
            return "O" + name
        if number is not None:
            return f"O{number}"
        return None

    def _collect_numbers(self, nodes_) -> None:
        for node in nodes_:
            if type(node) is n.Block:
                if node.number:
                    self.used_numbers.add(node.number.lstrip("0") or "0")
            elif hasattr(node, "body"):
                self._collect_numbers(node.body)

    # -------------------------------------------------------------- structure
    def nodes(self, nodes_) -> None:
        for node in nodes_:
            self.span = node.span
            getattr(self, "s_" + type(node).__name__)(node)

    @staticmethod
    def _comment(text: str) -> str:
        depth = 0
        for ch in text:
            if ch == "(":
                depth += 1
            elif ch == ")":
                depth -= 1
                if depth < 0:
                    break
        if depth == 0:
            return f"({text})"
        return "; " + text.strip()      # unbalanced parentheses: only a ';' comment keeps the text

    def s_Block(self, b: n.Block) -> None:
        prefix = ""
        if b.skip is not None:
            prefix = "/" if b.skip == 0 else f"/{b.skip}"
        if b.number is not None:
            prefix += f"N{b.number} "
        if b.label:
            self.lowered(f"label {b.label} kept as a comment")
        lines = self.statements(b.body)
        comment = b.comment
        if b.label:
            comment = f"LABEL {b.label}" + (f" {comment}" if comment else "")
        tail = f" {self._comment(comment)}" if comment is not None else ""
        if not lines:
            text = (prefix + tail.lstrip()).strip() if (prefix or tail) else ""
            self.out.append(text)
            return
        for i, words in enumerate(lines):
            text = " ".join(words)
            if i == 0:
                text = prefix + text
            elif b.skip is not None:
                text = prefix.split("N")[0] + text
            if i == len(lines) - 1:
                text += tail
            self.out.append(text)
        if self.restore_absolute:
            self.restore_absolute = False
            self.out.append("G90")

    def s_If(self, node: n.If) -> None:
        then = node.then
        simple = (not node.orelse and len(then) == 1 and type(then[0]) is n.Block
                  and then[0].body and all(type(s) is n.Assign for s in then[0].body)
                  and then[0].number is None and then[0].comment is None)
        cond = self.cond(node.cond)
        if simple:
            skip = then[0].skip
            prefix = "" if skip is None else ("/" if skip == 0 else f"/{skip}")
            assigns = "".join(self.assign(s) for s in then[0].body)
            self.out.append(f"{prefix}IF[{cond}]THEN{assigns}")
            return
        self.lowered("IF/ELSE block written with IF..GOTO")
        else_label = self.fresh_label()
        end_label = self.fresh_label()
        self.out.append(f"IF[[{cond}]EQ0]GOTO{else_label}")
        self.nodes(then)
        self.span = node.span
        self.out.append(f"GOTO{end_label}")
        self.out.append(f"N{else_label}")
        self.nodes(node.orelse)
        self.out.append(f"N{end_label}")

    def _loop_label(self, label) -> str:
        if label is not None and str(label).isdigit():
            return str(label)
        return str(min(self.depth + 1, 3))

    def s_While(self, node: n.While) -> None:
        label = self._loop_label(node.label)
        self.out.append(f"WHILE[{self.cond(node.cond)}]DO{label}")
        self.depth += 1
        self.nodes(node.body)
        self.depth -= 1
        self.out.append(f"END{label}")

    def s_Loop(self, node: n.Loop) -> None:
        label = self._loop_label(None)
        self.out.append(f"DO{label}")
        self.depth += 1
        self.nodes(node.body)
        self.depth -= 1
        self.out.append(f"END{label}")

    def s_ForLoop(self, node: n.ForLoop) -> None:
        self.lowered("FOR loop written as WHILE with a # variable")
        var = self.val(node.var)
        step = node.step if node.step is not None else n.Num(1.0)
        down = type(step) is n.Num and step.value < 0
        label = self._loop_label(None)
        self.out.append(f"{var}={format_expr(node.start, self)}")
        self.out.append(f"WHILE[{var}{'GE' if down else 'LE'}{self._operand(node.end)}]DO{label}")
        self.depth += 1
        self.nodes(node.body)
        self.depth -= 1
        self.out.append(f"{var}={var}+{self._operand(step)}")
        self.out.append(f"END{label}")

    def s_RepeatUntil(self, node: n.RepeatUntil) -> None:
        self.lowered("REPEAT..UNTIL written with IF..GOTO")
        top = self.fresh_label()
        self.out.append(f"N{top}")
        self.nodes(node.body)
        self.span = node.span
        self.out.append(f"IF[[{self.cond(node.cond)}]EQ0]GOTO{top}")

    def s_Case(self, node: n.Case) -> None:
        self.lowered("CASE written as IF..GOTO")
        subject = self._operand(node.subject)
        for value, label in node.branches:
            self.out.append(f"IF[{subject}EQ{self._operand(value)}]GOTO{self._goto_target(label)}")
        if node.default is not None:
            self.out.append(f"GOTO{self._goto_target(node.default)}")

    def _operand(self, e) -> str:
        text, prec = _expr(e, self)
        return _wrap(text, prec, 4)

    def cond(self, e) -> str:
        try:
            return format_expr(e, self)
        except NotExpressible as err:
            self.refuse(str(err))
            return "0EQ1"

    def assign(self, s: n.Assign) -> str:
        try:
            return f"{self.val(s.target)}={format_expr(s.value, self)}"
        except NotExpressible as err:
            self.refuse(str(err))
            return ""

    def _goto_target(self, target: str) -> str:
        t = str(target)
        if t.isdigit():
            return t
        self.refuse(f"jump to label {t!r} (ISO jumps to N numbers)")
        return "0"

    # -------------------------------------------------------------- statements
    def statements(self, body) -> list[list[str]]:
        lines: list[_Line] = [_Line()]
        for s in body:
            try:
                words = getattr(self, "w_" + type(s).__name__)(s)
            except NotExpressible as err:
                self.refuse(f"{type(s).__name__}: {err}")
                continue
            if not words:
                continue
            line = lines[-1]
            keys = [k for k, _ in words if k]
            if any(k in line.used for k in keys):
                line = _Line()
                lines.append(line)
            line.words.extend(w for _, w in words)
            line.used.update(keys)
        return [ln.words for ln in lines if ln.words]

    def _g(self, group: str, value: str, code: str = "") -> tuple[str, str]:
        rule = self.table.lookup(code) if code else None
        if rule is None or (rule.group, rule.value) != (group, value):
            rule = self.table.code_for(group, value)
            code = rule.code if rule is not None else ""
        if rule is None:
            raise NotExpressible(f"mode {group}={value}")
        key = f"{code[0]}:{rule.dialect_group}" if rule.modal and rule.dialect_group is not None else ""
        return key, code

    def w_ModeChange(self, s: n.ModeChange):
        if s.group == "distance":
            self.distance = s.value
        if s.group == "work_offset" and s.value.startswith("G54.1P"):
            return [("G:14", "G54.1"), ("P", "P" + s.value[6:])]
        if s.group == "work_offset" and s.value not in ("G54", "G55", "G56", "G57", "G58", "G59"):
            raise NotExpressible(f"work offset {s.value}")
        code = s.code.upper() if s.code else ""
        if code and code[0] in "GM" and code[1:].replace(".", "").isdigit():
            from nctrans.rules import normalise_code
            code = normalise_code(code[0], code[1:])
        return [self._g(s.group, s.value, code)]

    def _axes(self, target: dict) -> list:
        words = []
        for k, av in target.items():
            if av.mode not in (None,):
                raise NotExpressible(f"per-word {av.mode} coordinate on {k}")
            words.append((k, self.addr(k, av.value)))
        return words

    def w_Motion(self, s: n.Motion):
        if s.via:
            raise NotExpressible("a three-point arc (CIP)")
        if s.polar:
            raise NotExpressible("polar motion words")
        words = []
        if s.machine_coords:
            words.append(("", "G53"))
        words += self._axes(s.target)
        if s.center:
            for k, av in s.center.items():
                letter = {"X": "I", "Y": "J", "Z": "K"}.get(k, k)
                words.append((letter, self.addr(letter, av.value)))
        if s.radius is not None:
            words.append(("R", self.addr("R", s.radius)))
        if s.turns is not None:
            t = s.turns
            if type(t) is n.Num:
                words.append(("L", "L" + format_number(t.value + 1)))
            elif type(t) is n.Binary and t.op == "-" and type(t.right) is n.Num and t.right.value == 1:
                words.append(("L", "L" + self.val(t.left)))
            else:
                words.append(("L", "L" + self.val(n.Binary("+", t, n.Num(1.0)))))
        return words

    def w_Feed(self, s):
        return [("F", self.addr("F", s.value))]

    def w_SpindleSpeed(self, s):
        if s.spindle != 1:
            raise NotExpressible(f"spindle {s.spindle}")
        return [("S", self.addr("S", s.value))]

    def w_ToolSelect(self, s):
        return [("T", self.addr("T", s.tool))]

    def w_ToolChange(self, s):
        return [("", "M6")]

    def w_OffsetSelect(self, s):
        letter = "H" if s.kind == "length" else "D"
        return [(letter, self.addr(letter, s.index))]

    def w_Dwell(self, s):
        if s.revolutions is not None:
            raise NotExpressible("a dwell in spindle revolutions")
        sec = s.seconds if s.seconds is not None else n.Num(0.0)
        if type(sec) is n.Num:
            ms = _ms_text(sec.value)
            if ms is not None:
                return [("G:18", "G4"), ("P", "P" + ms)]
            return [("G:18", "G4"), ("X", "X" + format_number(sec.value, True))]
        if type(sec) is n.Binary and sec.op == "/" and type(sec.right) is n.Num and sec.right.value == 1000:
            return [("G:18", "G4"), ("P", "P" + self.val(sec.left))]
        return [("G:18", "G4"), ("X", "X" + self.val(sec))]

    def w_SetPosition(self, s):
        return [("G:18", "G92")] + self._axes(s.target)

    def w_ResetSetPosition(self, s):
        return [("G:18", "G92.1")]

    def w_HomeReturn(self, s):
        words = [("G:18", "G28" if s.ref == 1 else "G30")]
        modes = {av.mode for av in s.via.values()}
        if modes == {"inc"}:
            # Sinumerik G74 (approach the reference point directly) arrives as a zero
            # incremental via point: ISO writes that as G91 G28 and restores G90 after the block.
            via = {k: n.AxisValue(av.value) for k, av in s.via.items()}
            if self.distance == "absolute":
                self.lowered("incremental reference-point approach written as G91 G28 ... then G90")
                self.restore_absolute = True
            return [("G:3", "G91")] + words + self._ref_index(s) + self._axes(via)
        return words + self._ref_index(s) + self._axes(s.via)

    def _ref_index(self, s) -> list:
        words = []
        if s.ref not in (1, 2) and s.ref_index is None:
            words.append(("P", f"P{s.ref}"))
        if s.ref_index is not None:
            words.append(("P", self.addr("P", s.ref_index)))
        return words

    def w_FrameOp(self, s: n.FrameOp):
        if s.additive:
            raise NotExpressible(f"an additive frame ({s.op})")
        if s.op == "trans":
            if s.clear:
                return [("G:18", "G52")] + [(k, k + "0.") for k in "XYZ"]
            if not s.local:
                self.lowered("programmable translation written as G52 local offset")
            return [("G:18", "G52")] + [(k, self.addr(k, v)) for k, v in s.values.items()]
        if s.op == "rot":
            if s.clear:
                return [("G:16", "G69")]
            words = [("G:16", "G68")] + (self._axes(s.center) if s.center else [])
            extra = {k: v for k, v in s.values.items() if k in "IJK"}
            if set(s.values) - set(extra):
                raise NotExpressible("rotation about a named axis")
            words += [(k, self.addr(k, v)) for k, v in extra.items()]
            if s.angle is not None:
                words.append(("R", self.addr("R", s.angle)))
            return words
        if s.op == "scale":
            if s.clear:
                return [("G:11", "G50")]
            words = [("G:11", "G51")] + (self._axes(s.center) if s.center else [])
            vals = s.values
            if set(vals) == {"X", "Y", "Z"} and _same(vals.values()):
                words.append(("P", "P" + self._factor(vals["X"])))
            else:
                for axis, letter in (("X", "I"), ("Y", "J"), ("Z", "K")):
                    if axis in vals:
                        words.append((letter, letter + self._factor(vals[axis])))
                if set(vals) - {"X", "Y", "Z"}:
                    raise NotExpressible("scaling of a rotary or extra axis")
            return words
        if s.op == "mirror":
            if s.clear:
                return [("G:22", "G50.1")] + [(k, k + "0.") for k in s.values]
            words = [("G:22", "G51.1")]
            center = dict(s.center or {})
            for k in s.values:
                center.setdefault(k, n.AxisValue(n.Num(0.0)))
            return words + self._axes(center)
        raise NotExpressible(f"frame operation {s.op}")

    def _factor(self, v) -> str:
        if type(v) is n.Num:
            return format_number(v.value, True)
        return self.val(v)

    def w_CycleParams(self, s: n.CycleParams):
        words = []
        letters = {"r_plane": "R", "peck": "Q", "shift": "Q", "repeat": "K"}
        for key, v in s.values.items():
            if key == "dwell":
                if type(v) is n.Num and _ms_text(v.value) is not None:
                    words.append(("P", "P" + _ms_text(v.value)))
                elif type(v) is n.Binary and v.op == "/" and type(v.right) is n.Num and v.right.value == 1000:
                    words.append(("P", "P" + self.val(v.left)))
                else:
                    words.append(("P", "P" + self.val(n.Binary("*", v, n.Num(1000.0)))))
            elif key in letters:
                words.append((letters[key], self.addr(letters[key], v)))
            else:
                raise NotExpressible(f"cycle parameter {key}")
        return words

    def w_CycleCall(self, s):
        raise NotExpressible(f"the cycle call {s.name or s.kind} (expand cycles first)")

    def w_SubCall(self, s: n.SubCall):
        kind = s.kind if s.kind in ("m98", "g65", "g66") else ("g66" if s.modal != "none" else "m98")
        if kind != s.kind:
            self.lowered(f"call of {s.name} written as {kind.upper()}")
        if s.args:
            raise NotExpressible(f"positional arguments of the call to {s.name}")
        words = []
        if kind == "m98":
            words.append(("", "M98"))
        else:
            words.append(("G:12" if kind == "g66" else "", "G65" if kind == "g65" else "G66"))
        prog = self._program_word(s.name, None) if s.name else None
        if s.name and (prog is None or not prog[1:].isdigit()):
            raise NotExpressible(f"a call of {s.name!r} by name (ISO calls O numbers)")
        if prog is not None:
            words.append(("P", "P" + prog[1:]))
        elif "P" in s.named_args:
            words.append(("P", "P" + self.val(s.named_args["P"])))
        if s.repeat is not None:
            words.append(("L", "L" + self.val(s.repeat)))
        if kind == "m98":
            if any(k != "P" for k in s.named_args):
                raise NotExpressible("arguments to an M98 subprogram")
            return words
        sets: dict[int, dict[str, Any]] = {}
        for key, v in s.named_args.items():
            if key == "P":
                continue
            letter = key[0]
            if letter in "IJK" and key[1:].isdigit():
                sets.setdefault(int(key[1:]), {})[letter] = v
            elif len(key) == 1 and key.isalpha():
                words.append(("", self.addr(key, v)))
            else:
                raise NotExpressible(f"macro argument {key!r}")
        for i in sorted(sets):
            for letter in "IJK":
                if letter in sets[i]:
                    words.append(("", self.addr(letter, sets[i][letter])))
        return words

    def w_ModalCallOff(self, s):
        return [("G:12", "G67")]

    def w_Return(self, s):
        words = [("", "M99")]
        if s.to_label is not None:
            words.append(("P", "P" + self._goto_target(s.to_label)))
        return words

    def w_ProgramEnd(self, s):
        return [("", {"end": "M2", "end_rewind": "M30", "restart": "M99"}.get(s.kind, "M30"))]

    def w_Stop(self, s):
        return [("", "M1" if s.optional else "M0")]

    def w_Assign(self, s):
        text = self.assign(s)
        return [("", text)] if text else []

    def w_Goto(self, s: n.Goto):
        target = self._goto_target(s.target)
        if s.cond is not None:
            return [("GOTO", f"IF[{self.cond(s.cond)}]GOTO{target}")]
        return [("GOTO", f"GOTO{target}")]

    def w_Message(self, s):
        self.lowered("message written as an (MSG, ...) comment")
        text = s.text.value if type(s.text) is n.Str else format_expr(s.text, self)
        return [("", self._comment(f"MSG, {text}"))]

    def w_Alarm(self, s):
        self.lowered("alarm written as #3000")
        num = self.val(s.number)
        text = ""
        if s.text is not None:
            text = " " + self._comment(s.text.value if type(s.text) is n.Str else format_expr(s.text, self))
        return [("#3000", f"#3000={num}{text}")]

    def w_VarDecl(self, s: n.VarDecl):
        if s.dims:
            raise NotExpressible(f"the array {s.name}")
        if s.type in ("STRING", "CHAR", "FRAME", "AXIS"):
            raise NotExpressible(f"a {s.type} variable {s.name}")
        var = n.Var("name", s.name)
        if s.init:
            return [("#", f"{self.val(var)}={format_expr(s.init[0], self)}")]
        self.map_var(var)
        return []

    def w_Passthrough(self, s: n.Passthrough):
        if s.dialect not in ("", "iso-m"):
            raise NotExpressible(f"{s.dialect} text {s.text!r}")
        return [("", s.text)]

    def w_DataSetting(self, s: n.DataSetting):
        classes = {("work_offset", False): "2", ("work_offset", True): "20", ("tool_length", False): "10",
                   ("tool_length_wear", False): "11", ("tool_radius", False): "12",
                   ("tool_radius_wear", False): "13"}
        lclass = classes.get((s.kind, s.extended))
        if lclass is None:
            raise NotExpressible(f"data setting {s.kind}")
        words = [("G:18", "G10"), ("L", "L" + lclass), ("P", self.addr("P", s.index))]
        if s.kind == "work_offset":
            words += [(k, self.addr(k, v)) for k, v in s.values.items()]
        elif "value" in s.values:
            words.append(("R", self.addr("R", s.values["value"])))
        return words


def _same(values) -> bool:
    vs = list(values)
    return all(type(v) is n.Num for v in vs) and len({v.value for v in vs}) == 1


def _ms_text(seconds: float) -> Optional[str]:
    """A P text in milliseconds that reads back to exactly `seconds`, or None."""
    ms = seconds * 1000
    for digits in range(0, 10):
        text = format_number(round(ms, digits))
        if float(text) / 1000 == seconds:
            return text
    return None


def emit_program(program: n.Program):
    from nctrans.dialects.base import EmitResult
    em = _Emitter(program)
    text = em.run()
    return EmitResult(text, em.diags)
