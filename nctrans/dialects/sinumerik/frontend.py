"""Sinumerik 840D front end: program text -> neutral IR (nctrans.ir.nodes).

Pipeline (spec section 11.1), one NC block at a time so one bad block costs one NC0xx diagnostic
and never the rest of the program:
1. split the line: block skip `/n`, block number `N10`/`:10`, label `NAME:`, `;` comment;
   file headers `%_N_NAME_MPF` and `;$PATH=` go to Program.meta;
2. expand `DEFINE ... AS` macros of the file (textual, spec 6.5);
3. keep verbatim what the IR has no concept for: synchronized actions, REDEF/APR/APW data
   attributes, data sections (CTABDEF..CTABEND, CONTPRON..EXECUTE, CPROTDEF..EXECUTE), ISO-mode
   sections (G291..G290, parsed by the iso-m front end when it is installed);
4. lex (lexer.py) and parse the statement part with the LALR grammar grammars/sinumerik.lark;
5. lower the words to IR statements in execution order, then nest control structures.

Numbers stay in program units (the interpreter applies G70/G71). Codes map to neutral values
through rules/sinumerik.toml; standard cycles through rules/cycles.toml.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Optional

from nctrans import limits, plainrun, resources
from nctrans.diagnostics import Diagnostic, DiagnosticList
from nctrans.dialects.base import ParseResult
from nctrans.dialects.sinumerik import names
from nctrans.dialects.sinumerik.lexer import LexError, number_value, tokenize
from nctrans.ir import nodes as ir
from nctrans.ir.vocabulary import MILL_ONLY, MODAL_GROUPS, NO_EFFECT_PREFIX
from nctrans.lark_cache import cache_option
from nctrans.rules import load_table, normalise_code

GRAMMAR = resources.path("grammars", "sinumerik.lark")
DIALECT = "sinumerik"


class _LarkNotLoaded(Exception):
    """What lark's names below stand for until _load_lark(): nothing is an instance of it."""


# lark (~40 ms of start-up, and ~15 ms more for the cached tables) is imported when the first block
# needs the grammar: blocks of plain words (frontend._plain_words, the kernel's runs) never do, so a
# CAM program runs without it. Until then its names are the placeholder above.
Lark = Token = Tree = _LarkNotLoaded
UnexpectedInput = UnexpectedToken = UnexpectedCharacters = UnexpectedEOF = _LarkNotLoaded


def _load_lark() -> None:
    global Lark, Token, Tree, UnexpectedInput, UnexpectedToken, UnexpectedCharacters, UnexpectedEOF
    global _BlockLexer
    from lark import Lark, Token, Tree
    from lark.exceptions import UnexpectedInput, UnexpectedToken, UnexpectedCharacters, UnexpectedEOF
    from lark.lexer import Lexer

    class _BlockLexer(Lexer):
        """Adapter: lark calls this with the statement text; tokens come from lexer.tokenize.
        A module attribute (lark's table cache pickles the class by name)."""

        def __init__(self, lexer_conf):   # noqa: D401 - lark's interface
            pass

        def lex(self, data):
            yield from tokenize(data)


@lru_cache(maxsize=1)
def parser():
    """The LALR parser of grammars/sinumerik.lark (tables cached on disk, see lark_cache)."""
    _load_lark()
    return Lark(GRAMMAR.read_text(encoding="utf-8"), parser="lalr", lexer=_BlockLexer,
                maybe_placeholders=True, cache=cache_option(DIALECT))


@lru_cache(maxsize=1)
def table():
    return load_table(DIALECT)


@lru_cache(maxsize=1)
def _cycles():
    """name -> (kind, [neutral keys], kind_by) from rules/cycles.toml (shared with the interpreter)."""
    from nctrans.interp.cycles import cycle_table
    t = cycle_table()
    out = {}
    for c in t.cycle:
        out[c.name] = (c.kind, [t.neutral(p) for p in c.params], c.kind_by and (
            t.neutral(c.kind_by.param), c.kind_by.values))
    for p in t.pattern:
        out[p.name] = ({"row": "holes_line", "grid": "holes_grid"}.get(p.shape, "holes_circle"),
                       [t.neutral(x) for x in p.params], None)
    for c in t.swivel:                   # CYCLE800 swivel plane: a frame change, not a hole
        out[c.name] = (c.kind, [t.neutral(x) for x in c.params], None)
    for c in t.milling:                  # POCKET1 ...: milling cycles (interp.milling_cycles)
        out[c.name] = ("milling", [t.neutral(x) for x in c.params], None)
    return out


# --------------------------------------------------------------------------- line splitting

_SKIP = re.compile(r"\s*/(\d)?")
_BLOCKNO = re.compile(r"\s*(?:[Nn](\d+)|:(\d+))(?=[^\d._=\[\w]|$)")
_BLOCKNO_GLUED = re.compile(r"\s*[Nn](\d+)(?=[A-Za-z])")
_LABEL = re.compile(r"\s*([A-Za-z_][A-Za-z0-9_]*)\s*:(?![=:])")
_SYNC = re.compile(r"^\s*(?:(?:ID|IDS)\s*=|(?:WHEN|WHENEVER|FROM|EVERY|DO)\b)", re.IGNORECASE)
_DATA_ATTR = re.compile(r"^\s*(?:REDEF|APR|APW)\b", re.IGNORECASE)
_DEFINE = re.compile(r"^\s*DEFINE\s+([A-Za-z_$][A-Za-z0-9_]*)\s+AS\b\s?(.*)$", re.IGNORECASE)
_HEADER = re.compile(r"^\s*%(\S*)")
_PATH = re.compile(r"^\s*;\s*\$PATH\s*=\s*(\S*)", re.IGNORECASE)
_UNIT_NAME = re.compile(r"^_N_(\w+?)_(MPF|SPF)$", re.IGNORECASE)
_PCALL_PATH = re.compile(r"\b(PCALL\s+)(/[^\s(]*/)([A-Za-z_]\w*)", re.IGNORECASE)
_WORD_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
# CONTPRON/CONTDCON .. EXECUTE are not sections: their blocks are parsed and run (the interpreter
# files them in the contour table, nctrans.interp.contour_tables; rules options.contour_tables)
_SECTION_START = re.compile(r"^\s*(CTABDEF|CPROTDEF|NPROTDEF)\s*\(", re.IGNORECASE)
_G291 = re.compile(r"(?<![\w.])G291(?![\w.])", re.IGNORECASE)
_G290 = re.compile(r"(?<![\w.])G290(?![\w.])", re.IGNORECASE)
_SECTION_END = {"CTABDEF": "CTABEND", "CPROTDEF": "EXECUTE", "NPROTDEF": "EXECUTE"}
_SECTION_REASON = {"CTABDEF": "curve table definition", "CPROTDEF": "protection zone definition",
                   "NPROTDEF": "protection zone definition"}


def split_comment(line: str) -> tuple[str, Optional[str]]:
    """(code, comment): the first `;` outside a double-quoted string starts the comment."""
    inq = False
    for i, ch in enumerate(line):
        if ch == '"':
            inq = not inq
        elif ch == ";" and not inq:
            return line[:i], line[i + 1:].rstrip()
    return line, None


@dataclass
class Line:
    """One source line split into its parts. `col` is the 1-based column where `code` starts."""
    lineno: int
    raw: str
    code: str
    col: int
    skip: Optional[int] = None
    number: Optional[str] = None
    label: Optional[str] = None
    comment: Optional[str] = None


def split_line(lineno: int, raw: str) -> Line:
    code, comment = split_comment(raw)
    pos = 0
    skip = None
    m = _SKIP.match(code)
    if m:
        skip = int(m.group(1)) if m.group(1) else 0
        pos = m.end()
    number = None
    m = _BLOCKNO.match(code, pos) or _BLOCKNO_GLUED.match(code, pos)
    if m:
        number = m.group(1) if m.group(1) is not None else (m.group(2) if m.re is _BLOCKNO else None)
        if m.re is _BLOCKNO and m.group(2) is not None:
            number = m.group(2)
        pos = m.end()
    label = None
    m = _LABEL.match(code, pos)
    if m:
        label = m.group(1).upper()
        pos = m.end()
    rest = code[pos:]
    lead = len(rest) - len(rest.lstrip())
    return Line(lineno, raw, rest.strip(), pos + lead + 1, skip, number, label, comment)


# --------------------------------------------------------------------------- expressions

_BINOPS = {"+": "+", "-": "-", "*": "*", "/": "/", "DIV": "div", "MOD": "mod", "AND": "and",
           "OR": "or", "XOR": "xor", "B_AND": "band", "B_OR": "bor", "B_XOR": "bxor",
           "==": "==", "<>": "!=", "<": "<", ">": ">", "<=": "<=", ">=": ">=", "=<": "<=",
           "=>": ">=", "<<": "concat"}
_PREFIX = {"-": "-", "+": "+", "NOT": "not", "B_NOT": "bnot"}
_RPARAM = re.compile(r"R(\d+)$")
# spindle positioning words the interpreter models for the master spindle (interp/spindle_position.py)
SPINDLE_POSITIONING = ("SPOS", "SPOSA")


def _own_alarm_base(number) -> Optional[int]:
    """The user band's base when SETAL(number) raises one of the program's own alarms (66000+n;
    rules sinumerik.toml alarms), else None: a cycle alarm of the control's list, or computed."""
    from nctrans.alarm_numbers import band
    b = band(DIALECT)
    if type(number) is ir.Num and b.user_base is not None and \
            b.user_base <= number.value < b.user_base + b.user_count and number.value == int(number.value):
        return b.user_base
    return None


def _spindle_number(index: list) -> bool:
    """SPOS[n]: the index is a constant spindle number (the run positions the master, SETMS)."""
    return (len(index) == 1 and isinstance(index[0], ir.Num) and index[0].value >= 1
            and index[0].value == int(index[0].value))
_INTEGER_ADDRESSES = frozenset("NGMLTDP")     # spec 2.2 / table: integer values only


def _num(tok: Token) -> ir.Num:
    return ir.Num(number_value(str(tok)), str(tok))


def expr(t) -> Optional[ir.Expr]:
    """Lower an expression tree (or token) to IR."""
    if t is None:
        return None
    if isinstance(t, Token):
        if t.type in ("NUMBER", "HEXBIN", "TRUE", "FALSE"):
            return _num(t)
        if t.type == "STR":
            return ir.Str(str(t))
        if t.type == "RPARAM":
            return ir.Var("R", int(str(t)[1:]))
        if t.type == "IDENT":
            return ir.Var("name", str(t))
        raise ValueError(f"unexpected token {t!r}")
    d = t.data
    ch = t.children
    if d == "number":
        return _num(ch[0])
    if d == "string":
        return ir.Str(str(ch[0]))
    if d == "rparam":
        return ir.Var("R", int(str(ch[0])[1:]))
    if d == "name":
        name = str(ch[0])
        idx = _index(ch[2]) if len(ch) > 1 and ch[2] is not None else None
        if name == "R" and idx:
            return ir.Var("R", None, idx)
        return ir.Var("name", name, idx)
    if d == "sysvar":
        idx = _index(ch[2]) if len(ch) > 1 and ch[2] is not None else None
        return ir.Var("system", str(ch[0]), idx)
    if d == "func":
        return func(str(ch[0]), _args(ch[2]))
    if d == "paren":
        args = _args(ch[1])
        if len(args) == 1:
            return args[0]
        return ir.Func("LIST", args)
    if d == "prefix":
        op = str(ch[0])
        operand = expr(ch[1])
        if op == "-" and isinstance(operand, ir.Num) and operand.value >= 0 and not (
                operand.text or "").startswith(("-", "+")) and (operand.text or "").upper() not in ("TRUE", "FALSE"):
            return ir.Num(-operand.value, "-" + (operand.text or repr(operand.value)))
        return ir.Unary(_PREFIX[op], operand)
    if d == "to_string":
        return ir.Binary("concat", ir.Str(""), expr(ch[1]))
    if len(ch) == 3 and isinstance(ch[1], Token):
        return ir.Binary(_BINOPS[str(ch[1])], expr(ch[0]), expr(ch[2]))
    raise ValueError(f"unexpected tree {d}")


OMITTED = ""      # Num.text of an omitted argument `f(1,,3)`: value 0, as the control passes it


def omitted() -> ir.Num:
    return ir.Num(0.0, OMITTED)


def is_omitted(e) -> bool:
    return e is None or (isinstance(e, ir.Num) and e.text == OMITTED)


def _args(t) -> list[ir.Expr]:
    """arglist -> expressions; an omitted argument (`f(1,,3)`) is Num(0, text="") (spec 6.1:
    omitted parameters are 0 / ""), so argument positions and the JSON schema both hold."""
    if t is None:
        return []
    args = [expr(a.children[0]) if a.children and a.children[0] is not None else omitted()
            for a in t.children if isinstance(a, Tree)]
    return [] if len(args) == 1 and is_omitted(args[0]) else args


def _index(t) -> list[ir.Expr]:
    """Subscripts of A[...]; an empty `A[]` keeps one omitted subscript so it is written back."""
    return _args(t) or [omitted()]


_FUNCTIONS: list = [None, {}]


def _functions() -> dict[str, str]:
    """Sinumerik function name -> neutral name (rules/sinumerik.toml [expressions.functions], the
    emitter's spellings read the other way), remembered per table."""
    t = table()
    if _FUNCTIONS[0] is not t:
        _FUNCTIONS[:] = [t, {sp: neutral for neutral, sp in t.expressions.get("functions", {}).items()}]
    return _FUNCTIONS[1]


def func(name: str, args: list) -> ir.Expr:
    fn = _functions()
    if name == "POT" and len(args) == 1:
        return ir.Func("pow", [args[0], ir.Num(2.0, "2")])
    if name in fn:
        return ir.Func(fn[name], args)
    return ir.Func(name, args)


# --------------------------------------------------------------------------- block lowering

_ORDER = {"Assign": 0, "VarDecl": 0, "ModeChange": 1, "Feed": 2, "SpindleSpeed": 2, "SpindleLimit": 1,
          "ModeSelect": 1, "ToolSelect": 2, "OffsetSelect": 2, "ToolChange": 3, "Message": 5, "Alarm": 5,
          "Passthrough": 5, "FrameOp": 5, "HomeReturn": 5, "Dwell": 6, "Motion": 6, "CycleCall": 6,
          "CycleParams": 6, "PolarPole": 5, "SubCall": 7, "ModalCallOff": 7, "Stop": 8, "ProgramEnd": 8,
          "Return": 8, "Goto": 8}


_LEADING = re.compile(r"\s*([A-Za-z_][A-Za-z_0-9]*)")


def _t(text) -> str:
    """Statement text for a Passthrough: computed lazily (only kept constructs need it)."""
    return text() if callable(text) else text


@lru_cache(maxsize=None)
def _g_group_choices(family: int) -> list:
    """[group, value, code] (or None) per G code number of G group `family`, shared by every
    G[family]= of every program (read only)."""
    t = table()
    choices: list = []
    for code in (t.options.get("g_group_index") or {}).get(str(family)) or ():
        rule = t.lookup(code) if code else None
        choices.append([rule.group, rule.value, rule.code] if rule is not None and rule.group
                       and rule.modal else None)
    return choices


def _priority(st) -> int:
    kind = type(st).__name__
    if kind == "ModeChange":
        # spindle and coolant switch before the block's motion, on and off alike, the spindle
        # first (as RS274/NGC orders them and the ISO and Fagor readings do: `M9 M5` and `M5 M9`
        # are one block's output to the PLC, whose timing "with the motion" is a PLC matter)
        if st.group == "spindle":
            return 4
        return 4.5 if st.group == "coolant" else 1
    if kind == "SubCall" and st.modal != "none":
        return 7
    return _ORDER.get(kind, 5)


def _axis_value(e: ir.Expr) -> ir.AxisValue:
    """X=AC(v) / X=IC(v) / DC/ACP/ACN (absolute with a direction the IR does not keep)."""
    if isinstance(e, ir.Func) and len(e.args) == 1 and e.args[0] is not None:
        if e.name == "AC":
            return ir.AxisValue(e.args[0], "abs")
        if e.name == "IC":
            return ir.AxisValue(e.args[0], "inc")
        if e.name in ("DC", "ACP", "ACN", "CAC", "CACP", "CACN", "CDC"):
            return ir.AxisValue(e.args[0], "abs")
        if e.name == "CIC":
            return ir.AxisValue(e.args[0], "inc")
    return ir.AxisValue(e)


@dataclass
class _Words:
    """What one block programs, gathered before it becomes statements."""
    out: list = field(default_factory=list)
    target: dict = field(default_factory=dict)
    center: dict = field(default_factory=dict)
    via: dict = field(default_factory=dict)
    polar: dict = field(default_factory=dict)
    radius: Optional[ir.Expr] = None
    aperture: Optional[ir.Expr] = None
    thread_start: Optional[ir.Expr] = None
    turns: Optional[ir.Expr] = None
    rpl: Optional[ir.Expr] = None
    feed: Optional[ir.Expr] = None
    speed: list = field(default_factory=list)
    repeat: Optional[ir.Expr] = None
    dwell: bool = False
    machine: bool = False
    home: Optional[str] = None          # G74 / G75
    fixed_point: Optional[ir.Expr] = None
    frame: Optional[str] = None
    pole: Optional[tuple[str, str]] = None   # G110/G111/G112: (relative_to, code)
    indirect: list = field(default_factory=list)   # AX[expr]=value
    limit: Optional[tuple[str, str]] = None   # G25/G26/WALIMON/WALIMOF: (kind, code as written)


class Lowerer:
    """Lowers parsed blocks of one file; collects diagnostics and program metadata."""

    def __init__(self, file: str):
        self.file = file
        self.diags: list[Diagnostic] = DiagnosticList()
        self.meta: dict = {}
        t = table()
        self.axes = set(t.options.get("axes", []))
        self.centre = t.options.get("centre_words", {})
        self.via = t.options.get("via_words", {})
        self.motion_words = t.options.get("motion_words", {})
        self.pass_words = t.options.get("passthrough_words", {})
        self.corner_words = t.options.get("corner_elements", {}).get("words", {})
        self.offset_word = t.options.get("contour_offset", {}).get("word", "")
        self.commands = t.options.get("machine_commands", {})
        self.whole_block = set(t.options.get("whole_block_commands", []))
        self.unsupported = t.options.get("unsupported_functions", {})
        self.travel_limits = t.options.get("travel_limits", {})
        known = t.options.get("no_motion_effect", {})
        self.no_effect = {w: NO_EFFECT_PREFIX for w in known.get("words", ())}
        self.no_effect.update({w: MILL_ONLY for w in known.get("mill_only", ())})

    @staticmethod
    def indirect_g(index: list, value: ir.Expr) -> Optional[ir.ModeSelect]:
        """`G[n]=expr` (spec 3.6): the codes of G group n in their "index as PLC interface" order
        (`[options.g_group_index]`, as $P_GG[n] reads them); None when n is not a constant the
        table lists (a group whose codes the state cannot tell apart stays unmodelled, NC220)."""
        if len(index) != 1 or type(index[0]) is not ir.Num or index[0].value != int(index[0].value):
            return None
        family = int(index[0].value)
        choices = _g_group_choices(family)
        return ir.ModeSelect(family, value, choices) if choices else None

    # ---- diagnostics
    def error(self, rule: str, msg: str, line: int, col: int, end_col: int = 0) -> None:
        self.diags.append(Diagnostic(rule, "error", msg, self.file, line, col, line,
                                     end_col or col + 1))

    # ---- codes
    def code(self, code: str, w: _Words, text: str) -> None:
        rule = table().lookup(code)
        if rule is None and code in self.travel_limits:
            w.limit = (self.travel_limits[code], _t(text))
            return
        if rule is None:
            reason = self.unsupported.get(code)
            if reason is None and code.startswith("M"):
                reason = "auxiliary function"
                w.out.append(ir.Passthrough(_t(text), reason, ""))
                return
            w.out.append(ir.Passthrough(_t(text), reason or "unknown function", DIALECT))
            return
        g = rule.group
        if g in MODAL_GROUPS:
            w.out.append(ir.ModeChange(g, rule.value, code))
        elif g == "stop":
            w.out.append(ir.Stop(optional=rule.value == "optional"))
        elif g == "end":
            w.out.append(ir.ProgramEnd(rule.value))
        elif g == "return":
            w.out.append(ir.Return())
        elif g == "tool_change":
            w.out.append(ir.ToolChange())
        elif g == "dwell":
            w.dwell = True
        elif g == "machine_coords":
            w.machine = True
        elif g == "frame":
            w.frame = rule.value
        elif g == "home":
            w.home = rule.code
        elif g == "pole":
            w.pole = (rule.value, rule.code)
        else:
            w.out.append(ir.Passthrough(_t(text), g, DIALECT))

    def address(self, letter: str, num: ir.Num, w: _Words, text: str) -> None:
        """A word `letter number` (X10, G1, M3, F100, L47 ...)."""
        if letter in _INTEGER_ADDRESSES and (num.value != int(num.value) or "." in (num.text or "")
                                             or "EX" in (num.text or "").upper()):
            self.invalid_number = (f"address {letter} takes an integer, not {num.text}",
                                   getattr(self, "word_col", 1))
            w.out.append(ir.Passthrough(_t(text), "invalid number", DIALECT))
            return
        if letter == "G":
            self.code(normalise_code("G", num.text or num.value), w, text)
        elif letter == "M":
            try:
                code = normalise_code("M", num.text)
            except ValueError:
                code = "M" + (num.text or "")
            self.code(code, w, text)
        elif letter in self.axes:
            w.target[letter] = ir.AxisValue(num)
        elif letter in self.centre:
            w.center[letter] = ir.AxisValue(num)
        elif letter == "F":
            w.feed = num
        elif letter == "S":
            w.speed.append((1, num, False))
        elif letter == "T":
            w.out.append(ir.ToolSelect(num))
        elif letter == "D":
            w.out.append(ir.OffsetSelect("radius", num))
        elif letter == "L":
            w.out.append(ir.SubCall("L" + (num.text or str(int(num.value))), kind="l"))
        elif letter == "P":
            w.repeat = num
        else:
            reason = self.pass_words.get(letter, f"address {letter}")
            w.out.append(ir.Passthrough(_t(text), reason, DIALECT if letter != "H" else ""))

    def named(self, name: str, value: ir.Expr, w: _Words, text: str) -> None:
        """A word `NAME=expr`: axis, arc parameter, extended address or an assignment."""
        if name in self.axes:
            w.target[name] = _axis_value(value)
        elif name in self.centre:
            w.center[name] = _axis_value(value)
        elif name in self.via:
            w.via[self.via[name]] = _axis_value(value)
        elif name in self.motion_words:
            part = self.motion_words[name]
            if part.startswith("polar."):
                w.polar[part[6:]] = value
            else:
                setattr(w, part, value)
        elif name == "S" or re.fullmatch(r"S\d+", name):
            w.speed.append((int(name[1:] or 1), value, bool(name[1:])))
        elif name == "T" or re.fullmatch(r"T\d+", name):
            w.out.append(ir.ToolSelect(value))
        elif name == "D":
            w.out.append(ir.OffsetSelect("radius", value))
        elif _RPARAM.match(name):
            w.out.append(ir.Assign(ir.Var("R", int(name[1:])), value))
        elif name == "LIMS":                                  # the clamp of G96 (lathe.py)
            w.out.append(ir.SpindleLimit(value))
        elif name in self.corner_words or name == self.offset_word:   # RND=, OFFN= ...: modelled
            w.out.append(ir.Passthrough(_t(text), self.pass_words.get(name, "corner element"), DIALECT,
                                        address=name, value=value))
        elif name in SPINDLE_POSITIONING:                     # SPOS=90 (interp/spindle_position.py)
            w.out.append(ir.Passthrough(_t(text), self.pass_words[name], DIALECT, name, value))
        elif name in self.pass_words:
            w.out.append(ir.Passthrough(_t(text), self.pass_words[name], DIALECT))
        elif re.fullmatch(r"M\d+", name) and name == "M1" and isinstance(value, ir.Num) and \
                f"M{value.value:g}" in ("M3", "M4", "M5", "M19"):
            self.code(f"M{value.value:g}", w, text)          # M1=3: spindle 1 clockwise
            if w.out and isinstance(w.out[-1], ir.ModeChange):
                # spelt with its spindle number: spindle 1's, which is the master only until a
                # SETMS(n) (interp/spindle_position.py); the writer keeps the number
                w.out[-1] = ir.ModeChange(w.out[-1].group, w.out[-1].value, f"M1={value.value:g}")
        elif re.fullmatch(r"[A-Z]\d+", name):
            reason = self.pass_words.get(name[0], f"extended address {name[0]}")
            if name[0] == "M":
                reason = "spindle-addressed M function"
            w.out.append(ir.Passthrough(_t(text), reason, DIALECT))
        else:
            w.out.append(ir.Assign(ir.Var("name", name), value))

    def call(self, name: str, args: Optional[list], w: _Words, text: str, modal: bool = False) -> None:
        """A call by name (with or without arguments), a procedure or a keyword function."""
        if args is None and not modal:
            if table().lookup(name) is not None or name in self.unsupported or name in self.travel_limits:
                self.code(name, w, text)
                return
        if name in self.commands and not modal:
            w.out.append(ir.Passthrough(_t(text), self.commands[name], DIALECT))
            return
        if name == "MSG" and not modal:
            w.out.append(ir.Message(args[0] if args and not is_omitted(args[0]) else ir.Str("")))
            return
        if name == "SETAL" and not modal and args:
            w.out.append(ir.Alarm(args[0], args[1] if len(args) > 1 else None, _own_alarm_base(args[0])))
            return
        cyc = _cycles().get(name)
        if cyc is not None and args is not None:
            kind, keys, kind_by = cyc
            params = {k: a for k, a in zip(keys, args) if not is_omitted(a)}
            if kind_by:
                sel = params.get(kind_by[0])
                if isinstance(sel, ir.Num):
                    kind = kind_by[1].get(str(int(sel.value)), kind)
            w.out.append(ir.CycleCall(kind, params, modal=modal, name=name))
            if len(args) > len(keys):
                self.meta.setdefault("cycle_extra_args", []).append(name)
            return
        kind = "l" if re.fullmatch(r"L\d+", name) else "proc"
        if modal:
            kind = "mcall"
        w.out.append(ir.SubCall(name, list(args or []), modal="after_move" if modal else "none",
                                kind=kind))

    def home(self, w: _Words) -> None:
        """G74 X1=0 Z1=0 / G75 FP=n ...: the named axes go straight to the reference (fixed)
        point, i.e. ISO G28 with an incremental-zero intermediate point (HomeReturn)."""
        via = {}
        for name in w.target:
            axis = name[:-1] if name.endswith("1") and name[:-1] in self.axes else name
            via[axis] = ir.AxisValue(ir.Num(0.0, "0"), "inc")
        w.target.clear()
        ref = 1
        if w.home == "G75":
            fp = w.fixed_point
            ref = 1 + (int(fp.value) if isinstance(fp, ir.Num) else 1)
        w.out.append(ir.HomeReturn(ref, via))

    def frame_op(self, w: _Words) -> None:
        op = w.frame
        additive = op.endswith("_add")
        base = op.replace("_add", "")
        values = {k: v.value for k, v in w.target.items()}
        # AX[axis]=value is the axis word written indirectly (seed L1422): in a frame instruction
        # it is one of the frame's values (TRANS AX[AXVAR]=10 shifts that axis), never a motion
        indirect = [(axis, av.value) for axis, av in w.indirect] or None
        w.indirect = []
        if not values and w.rpl is None and not indirect:
            if additive:
                return
            w.out.append(ir.FrameOp("all", clear=True))
            return
        if base == "rot" and w.rpl is not None:
            w.out.append(ir.FrameOp("rot", values, angle=w.rpl, additive=additive, indirect=indirect))
            w.rpl = None
        else:
            w.out.append(ir.FrameOp(base, values, additive=additive, indirect=indirect))
        w.target.clear()

    def statements(self, stmts: list, line: Line) -> list:
        """The statements of one (non-control) block in execution order."""
        w = _Words()
        self.invalid_number = None
        try:
            return self._statements(stmts, line, w)
        finally:
            if self.invalid_number:
                msg, col = self.invalid_number
                self.error("NC007", msg, line.lineno, col, col + 1)

    def _statements(self, stmts: list, line: Line, w: _Words) -> list:
        code = line.code
        for st in stmts:
            d = st.data
            ch = st.children
            text = (lambda c=code, t=st: _slice(c, t))
            if d == "rword":           # R5 standing alone: an address word, not an assignment
                self.address("R", ir.Num(float(str(ch[0])[1:]), str(ch[0])[1:]), w, text)
            elif d == "word":
                if ch[1] is None:
                    w.out.append(ir.Passthrough(_t(text), "address without value", DIALECT))
                else:
                    self.word_col = line.col + ch[0].start_pos
                    self.address(str(ch[0]), _num(ch[1]), w, text)
            elif d == "plain_assign":      # NAME=number read without the parser (_plain_words)
                self.named(str(ch[0]), _num(ch[1]), w, text)
            elif d == "assign":
                lv = ch[0]
                values = [expr(c) for c in ch[2:] if isinstance(c, Tree) or (
                    isinstance(c, Token) and c.type not in ("COLON",))]
                value = values[0] if len(values) == 1 else ir.Func("frame_chain", values)
                lt = lv.children[0]
                idx = lv.children[2] if len(lv.children) > 2 else None
                if lt.type == "RPARAM":
                    w.out.append(ir.Assign(ir.Var("R", int(str(lt)[1:])), value))
                elif lt.type == "SYSVAR":
                    w.out.append(ir.Assign(ir.Var("system", str(lt), _index(idx) if idx else None), value))
                elif idx is not None:
                    name = str(lt)
                    if name == "AX" and len(_index(idx)) == 1:
                        # indirect axis: the axis is a value (AX[_AXN]=RTP, spec 3.6)
                        w.indirect.append((_index(idx)[0], _axis_value(value)))
                    elif name == "G" and (select := self.indirect_g(_index(idx), value)) is not None:
                        w.out.append(select)
                    elif name in SPINDLE_POSITIONING and _spindle_number(_index(idx)):
                        # SPOS[n]=..: the master's where n is the master (SETMS), else NC220 at run
                        w.out.append(ir.Passthrough(_t(text), self.pass_words[name], DIALECT, name, value))
                    elif name in self.pass_words:
                        w.out.append(ir.Passthrough(_t(text), self.pass_words[name], DIALECT))
                    elif name == "R":
                        w.out.append(ir.Assign(ir.Var("R", None, _index(idx)), value))
                    else:
                        w.out.append(ir.Assign(ir.Var("name", name, _index(idx)), value))
                else:
                    self.named(str(lt), value, w, text)
            elif d == "call_name":
                self.call(str(ch[0]), None, w, text)
            elif d == "call_args":
                name = str(ch[0])
                if name in self.whole_block:
                    return [ir.Passthrough(code, self.commands.get(name, "machine command"), DIALECT)]
                self.call(name, _args(ch[2]), w, text)
            elif d == "mcall_off":
                w.out.append(ir.ModalCallOff())
            elif d == "mcall_name":
                self.call(str(ch[1]), [], w, text, modal=True)
            elif d == "mcall_args":
                self.call(str(ch[1]), _args(ch[3]), w, text, modal=True)
            elif d == "mcall_l":
                w.out.append(ir.SubCall("L" + str(ch[2]), modal="after_move", kind="mcall"))
            elif d == "call_stmt":
                target = expr(ch[1]) if ch[1] is not None else None
                if isinstance(target, ir.Str) and ch[2] is None:
                    w.out.append(ir.SubCall(target.value.upper(), kind="call"))
                elif type(target) is ir.Var and ch[2] is None:
                    # CALL PROGNAME: the name is the string variable's value when the call runs
                    w.out.append(ir.SubCall("", kind="call", target=target))
                else:
                    w.out.append(ir.Passthrough(_t(text), "indirect call", DIALECT))
            elif d == "pcall_stmt":
                w.out.append(ir.SubCall(str(ch[1]), _args(ch[3]) if ch[3] is not None else [],
                                        kind="pcall"))
            elif d in ("isocall_stmt", "extcall_stmt"):
                target = expr(ch[1]) if ch[1] is not None else None
                if isinstance(target, ir.Str):
                    w.out.append(ir.SubCall(target.value.upper(), kind=d.split("_")[0]))
                else:
                    w.out.append(ir.Passthrough(_t(text), "indirect call", DIALECT))
            elif d == "ret_stmt":
                if ch[1] is None:
                    w.out.append(ir.Return())
                else:
                    w.out.append(ir.Passthrough(_t(text), "parameterized return", DIALECT))
            elif d == "endproc_stmt":
                w.out.append(ir.Return())
            elif d == "frame_stmt":
                w.frame = table().lookup(str(ch[0])).value
            elif d == "procattr_stmt":
                w.out.append(ir.Passthrough(_t(text), self.commands.get(str(ch[0]), "program attribute"),
                                            DIALECT))
            elif d == "goto_stmt":
                w.out.append(_goto(ch[0], ch[1], None))
            elif d == "def_stmt":
                w.out.extend(self.vardecls(st, code, line))
            elif d == "extern_stmt":
                w.out.append(ir.Passthrough(_t(text), "declaration", DIALECT))
                self.meta.setdefault("externs", []).append(str(ch[1]))
                signature = _extern_signature(_t(text))
                if signature is not None:
                    self.meta.setdefault("extern_params", {})[str(ch[1]).upper()] = signature
            else:
                self.error("NC002", f"{_KW.get(d, d)} must stand in its own block", line.lineno,
                           line.col)
        # frame instructions take the block's axis words as their values
        if w.frame:
            self.frame_op(w)
        if w.home:
            self.home(w)
        elif w.fixed_point is not None:
            w.out.append(ir.Passthrough("FP=" + _expr_text(w.fixed_point), "fixed point without G75",
                                        DIALECT))
        if w.limit:
            self.travel_limit(w)
        if w.pole:
            # the block's axis / polar words place the pole; it moves nothing (spec 9.2)
            w.out.append(ir.PolarPole(w.pole[0], dict(w.target), dict(w.polar) or None, w.pole[1]))
            w.target.clear()
            w.polar.clear()
        if w.dwell:
            secs = w.feed
            revs = w.speed[0][1] if w.speed else None
            w.feed, w.speed = None, []
            w.out.append(ir.Dwell(secs, revs))
        if w.feed is not None:
            w.out.append(ir.Feed(w.feed))
        for sp, v, addressed in w.speed:
            w.out.append(ir.SpindleSpeed(v, sp, addressed))
        if w.target or w.center or w.via or w.polar or w.radius is not None or w.aperture is not None \
                or w.turns is not None or w.indirect or w.thread_start is not None:
            w.out.append(ir.Motion(dict(w.target), dict(w.center) or None, w.radius, w.turns,
                                   dict(w.via) or None, w.machine, dict(w.polar) or None, w.aperture,
                                   list(w.indirect) or None, w.thread_start))
        elif w.rpl is not None:
            w.out.append(ir.Passthrough("RPL=" + _expr_text(w.rpl), "plane rotation outside ROT", DIALECT))
        if w.repeat is not None:
            calls = [s for s in w.out if isinstance(s, ir.SubCall)]
            if calls:
                calls[-1].repeat = w.repeat
            else:
                w.out.append(ir.Passthrough(f"P{w.repeat.text}", "address P", DIALECT))
        for st in w.out:
            if type(st) is ir.Passthrough and self.no_effect:
                m = _LEADING.match(st.text)
                mark = self.no_effect.get(m.group(1).upper()) if m else None
                if mark and not st.reason.startswith(NO_EFFECT_PREFIX):
                    st.reason = f"{mark} ({st.reason})" if st.reason else mark
        return sorted(w.out, key=_priority)

    def travel_limit(self, w: _Words) -> None:
        """G25/G26 (working-area limits: the block's axis words are the limits, it moves nothing)
        and WALIMON/WALIMOF; G25/G26 S (spindle speed limits) are not modelled (NC220)."""
        kind, code = w.limit
        values = {a: (v.value if isinstance(v, ir.AxisValue) else v) for a, v in w.target.items()}
        text = " ".join([code] + [f"{a}={_expr_text(e)}" for a, e in values.items()])
        w.out.append(ir.TravelLimit(kind, "work_area", values, text=text, dialect=DIALECT))
        w.target.clear()
        if w.speed:
            w.out.append(ir.Passthrough(f"{code} S", "spindle speed limit", DIALECT))
            w.speed = []

    def refuse_name(self, name: Token, line: Line) -> None:
        """NC126 at a declared name the control refuses (names.py)."""
        why = names.refused(str(name), table().options)
        if why:
            self.error("NC126", why, line.lineno, name.column, name.column + len(name))

    def vardecls(self, st: Tree, code: str = "", line: Optional[Line] = None) -> list:
        ch = st.children
        limits = None
        found = {k.upper(): number_value(v) for k, v in _LIMIT.findall(code)}
        if found:
            # DEF CHAN INT LLI 0 ULI 4 NAME (spec 1.8): the limits of every name of the DEF
            limits = [found.get("LLI"), found.get("ULI")]
        scope = "local"
        type_spec = None
        decls = []
        for c in ch:
            if isinstance(c, Token) and c.type == "SCOPE":
                scope = str(c).lower()
            elif isinstance(c, Tree) and c.data == "type_spec":
                type_spec = c
            elif isinstance(c, Tree) and c.data == "decl":
                decls.append(c)
        typ, length = _type(type_spec)
        out = []
        for dcl in decls:
            name = str(dcl.children[0])
            if line is not None:
                self.refuse_name(dcl.children[0], line)
            dims = []
            if dcl.children[2] is not None:
                dim_exprs = _args(dcl.children[2]) or [omitted()]
                for a in dim_exprs:
                    dims.append(int(a.value) if isinstance(a, ir.Num) and not is_omitted(a) else 0)
                if any(not isinstance(a, ir.Num) for a in dim_exprs):
                    # DEF REAL A[MAXFAZA]: a dimension named by a macro/GUD constant (spec 3.4)
                    self.meta.setdefault("symbolic_dims", {})[name] = [
                        None if isinstance(a, ir.Num) else _expr_text(a) for a in dim_exprs]
            init = None
            if dcl.children[5] is not None:
                v = expr(dcl.children[5])
                if isinstance(v, ir.Func) and v.name in ("LIST", "SET"):
                    init = [ir.Num(0.0, "0") if is_omitted(a) else a for a in v.args]
                else:
                    init = [v]
            out.append(ir.VarDecl(name, typ, dims, init, length, scope, limits))
        return out


_LIMIT = re.compile(r"\b(LLI|ULI)\s+([+-]?(?:\d+\.?\d*|\.\d+)(?:EX[+-]?\d+)?)", re.IGNORECASE)
_KW = {"if_stmt": "IF", "else_stmt": "ELSE", "endif_stmt": "ENDIF", "while_stmt": "WHILE",
       "endwhile_stmt": "ENDWHILE", "for_stmt": "FOR", "endfor_stmt": "ENDFOR", "loop_stmt": "LOOP",
       "endloop_stmt": "ENDLOOP", "repeat_stmt": "REPEAT", "until_stmt": "UNTIL", "case_stmt": "CASE",
       "proc_stmt": "PROC"}
_DIRECTION = {"GOTOF": "forward", "GOTOB": "backward", "GOTO": "any", "GOTOC": "any"}


def _target(t: Tree) -> str:
    ch = t.children
    if len(ch) == 2:            # N100 is a block number, L1 a label
        return str(ch[1]) if str(ch[0]) == "N" else str(ch[0]) + str(ch[1])
    tok = ch[0]
    return str(tok) if tok.type != "STR" else str(tok).upper()


def _goto(kw: Token, target: Tree, cond) -> ir.Goto:
    return ir.Goto(_target(target), _DIRECTION[str(kw)], cond)


def _type(type_spec: Tree) -> tuple[str, Optional[int]]:
    typ = str(type_spec.children[0])
    if typ == "DOUBLE":
        typ = "REAL"
    length = None
    if len(type_spec.children) > 2 and type_spec.children[2] is not None:
        length = int(number_value(str(type_spec.children[2])))
    return typ, length


def _slice(code: str, st: Tree) -> str:
    """Source text of a statement (for Passthrough), from its first to its last token."""
    toks = [t for t in st.scan_values(lambda v: isinstance(v, (Token, _PlainToken)))]
    if not toks:
        return ""
    return code[toks[0].start_pos:max(t.end_pos for t in toks)].strip()


# --------------------------------------------------------------------------- program assembly

@dataclass
class _Open:
    kind: str
    node: object
    body: list
    line: int


class _Unit:
    """One program unit (the file, or one `%_N_NAME_SPF` member of an archive)."""

    def __init__(self, name: Optional[str]):
        self.name = name
        self.pre: list = []          # nodes before PROC
        self.proc: Optional[ir.Subprogram] = None
        self.root: list = self.pre
        self.stack: list[_Open] = []

    @property
    def current(self) -> list:
        return self.stack[-1].body if self.stack else self.root


def _comment_only(node) -> bool:
    """A block holding only a comment (no statement, number or label)."""
    return (type(node) is ir.Block and not node.body and node.number is None and not node.label
            and node.skip is None)


def _span(file: str, line: Line) -> ir.Span:
    return ir.Span(file, line.lineno, 1, line.lineno, len(line.raw) + 1)


def _passthrough_block(file: str, line: Line, text: str, reason: str, dialect: str = DIALECT) -> ir.Block:
    return ir.Block(_span(file, line), [ir.Passthrough(_t(text), reason, dialect)] if text else [],
                    line.number, line.label, line.skip, line.comment)


def _iso_section(file: str, lines: list[Line]) -> Optional[list]:
    """Parse an ISO-mode section with the iso-m front end, or None when it is not installed."""
    try:
        from nctrans.dialects import base
        iso = base.get("iso-m")
    except Exception:        # the iso-m package may not be importable yet
        return None
    if iso is None or not lines:
        return None
    first = lines[0].lineno
    text = "\n" * (first - 1) + "\n".join(l.raw for l in lines) + "\n"
    try:
        res = iso.parse(text, file)
    except Exception:
        return None
    return list(res.program.body)


_NUM_RE = r"(?:\d+\.?\d*|\.\d+)(?:[Ee][Xx][+-]?\d+)?"
# a plain word: `X10`, `G1`, or a number given to an address by name, `Z1=0`, `CR=-5.5` (no `+`:
# the parser reads `X=+5` as a unary plus); names are checked against _plain_names()
_PLAIN = re.compile(rf"(?:\s*(?:[A-Z_][A-Z0-9_]*\s*=\s*-?{_NUM_RE}|[A-Za-z]\s*[+-]?{_NUM_RE})(?![A-Za-z_]))+\s*")
_PAIR = re.compile(rf"([A-Z_][A-Z0-9_]*)\s*=\s*(-?{_NUM_RE})|([A-Za-z])\s*([+-]?{_NUM_RE})")


def parse(text: str, file: str = "<stdin>") -> ParseResult:
    """Sinumerik source -> IR Program with NC0xx diagnostics (never raises on bad input)."""
    fp = _FileParse(text, file)
    for _ in fp.blocks(stream=False):
        pass
    return ParseResult(fp.program, fp.low.diags)


def parse_stream(text: str, file: str = "<stdin>") -> Optional[ParseResult]:
    """Lazy parse for programs that run straight through (CAM output): a ParseResult whose
    Program.body is a StreamedBody that parses as it is iterated (the diagnostics fill as it goes;
    complete once drained), so memory stays flat however long the program. With the native kernel
    runs of plain lines become PlainRuns, the fast lane the ISO family takes too. None when the text
    needs the whole IR (see streamable)."""
    from nctrans.dialects.base import StreamedBody
    if not streamable(text):
        return None
    fp = _FileParse(text, file)
    fp.read_first_header()
    fp.program.body = StreamedBody(fp.blocks(stream=True))
    return ParseResult(fp.program, fp.low.diags)


def parse_compact(text: str, file: str = "<stdin>", jumps: bool = False) -> Optional[ParseResult]:
    """A whole parse whose main body is held compact (base.CompactBody): each run of plain lines
    at the top level of the main program (outside loops, branches and PROC) is one PlainRun, a
    span of the text read again when it runs or is written, instead of its Blocks, so a CAM
    program of millions of lines around a few loops and calls costs little. None when anything
    may jump to a place in the main body (a GOTO, CASE, REPEAT, contour reference or return
    there: the interpreter runs a compact body straight through, as a streamed one), when the
    file holds a PROC or ISO-mode section in its main program, or when nothing would be compacted
    (without the native kernel there are no runs): parse() then. `jumps`: a program that jumps
    into its main body is held compact too, its runs split at the blocks jumps land on
    (dialects/compact_jumps.py); not one with an ISO-mode section."""
    from nctrans.dialects.base import CompactBody
    if plainrun.native is None:
        return None
    fp = _FileParse(text, file)
    for _ in fp.blocks(stream=False, compact=True):
        pass
    program = fp.program
    items = program.body
    if not any(type(x) is plainrun.PlainRun for x in items) or fp.program.meta.get("entry") is not None:
        return None
    if _jumps_into_main(program):
        from nctrans.dialects.compact_jumps import split_at_targets
        split = split_at_targets(program) if jumps and not _iso_sections(program) else None
        if split is None:
            return None
        program.body = CompactBody(split, jumps=True)
        return ParseResult(program, fp.low.diags)
    program.body = CompactBody(items)
    return ParseResult(program, fp.low.diags)


def _iso_sections(program: ir.Program) -> bool:
    """Whether the main body switches to ISO dialect mode."""
    from nctrans.ir import walk
    return any(type(s) is ir.Passthrough and s.reason in ("ISO dialect mode", "ISO dialect section")
               for b in walk.blocks([x for x in program.body if type(x) is not plainrun.PlainRun])
               for s in b.body)


def _jumps_into_main(program: ir.Program) -> bool:
    """Whether anything may jump to a place in the main body, or it holds an ISO-mode section
    (see parse_compact)."""
    from nctrans.ir import walk
    main = [x for x in program.body if type(x) is not plainrun.PlainRun]
    if walk.jump_targets(main):
        return True
    for b in walk.blocks(main):
        for s in b.body:
            t = type(s)
            if t in (ir.Goto, ir.Return, ir.SectionRepeat) or (t is ir.ProgramEnd and s.kind == "restart") \
                    or (t is ir.Passthrough and s.reason in ("ISO dialect mode", "ISO dialect section")):
                return True
    return any(walk.return_targets(sub.body) for sub in program.subprograms.values())


# Words after which a program cannot run straight through block after block, or whose meaning the
# IR analyses of a full parse check (declarations, variables): such a program is parsed whole.
_NOT_STREAMED = frozenset({
    "IF", "ELSE", "ENDIF", "WHILE", "ENDWHILE", "FOR", "ENDFOR", "LOOP", "ENDLOOP", "REPEAT", "REPEATB",
    "UNTIL", "CASE", "GOTO", "GOTOF", "GOTOB", "GOTOC", "GOTOS", "PROC", "RET", "DEFINE", "DEF", "EXTERN",
    "CALL", "PCALL", "MCALL", "EXTCALL", "ISOCALL", "CTABDEF", "CONTPRON", "CONTDCON", "CPROTDEF", "NPROTDEF",
    "WHEN", "WHENEVER", "EVERY", "FROM", "DO", "ID", "IDS", "SETAL", "SAVE"})
# What the stream check looks at in a line's code (upper-cased, strings emptied): names and
# address words, `=`, system variables, indices and program headers.
_STREAM_MARK = re.compile(r"[A-Z_][A-Z0-9_]*|[=$\[%]")
_STREAM_ADDRESS = re.compile(r"[A-Z]\d+")
_STREAM_STRING = re.compile(r'"[^"]*"')
_STREAM_VALUE = re.compile(rf"\s*(?:[+-]?{_NUM_RE}|(?:AC|IC|DC|ACP|ACN)\s*\(\s*[+-]?{_NUM_RE}\s*\)|\"\")\s*(?=\s|$)")
_STREAM_NAME = re.compile(r"(\w+)\s*$")
# Address words that end or leave the program's straight run: ISO mode, subprogram return.
_STREAM_CODES = frozenset({("G", 291), ("M", 17)})


@lru_cache(maxsize=1)
def _stream_words() -> tuple[frozenset, frozenset]:
    """(names a streamed program may use, names it may assign a number to): the codes and commands
    of the rules table and the address words `named` takes without an assignment."""
    t = table()
    o = t.options
    words = {r.code.upper() for r in t.codes} | {"MSG", "AC", "IC", "DC", "ACP", "ACN"}
    words |= {w.upper() for w in (*o.get("machine_commands", {}), *o.get("passthrough_words", {}),
                                  *o.get("unsupported_functions", {}))}
    targets = {w.upper() for w in (*o.get("axes", ()), *o.get("centre_words", {}), *o.get("via_words", {}),
                                   *o.get("motion_words", {}))} | {"S", "T", "D"}
    targets |= {f"{a}{i}" for a in "STD" for i in range(1, 10)}
    return frozenset(words - _NOT_STREAMED), frozenset(targets - _NOT_STREAMED)


def streamable(text: str) -> bool:
    """Whether `text` runs straight through, block after block, with nothing the full parse's
    analyses need (see _NOT_STREAMED): only known codes and commands, numbers assigned to address
    words (`Z1=0`, `X=IC(5)`, `T="MILL"`), MSG texts and `;` comments, a program header only as
    the first line. Errs towards the full parse, which is always right. With the native kernel the
    plain lines are stepped over in runs (its strict scan) and only the others are looked at."""
    scan = plainrun.native.scan if plainrun.native is not None else None
    arc = plainrun.MOTIONS.index("arc_cw")
    first = True
    pos, n = 0, len(text)
    while pos < n:
        if scan is not None:
            end, _, blocks, _ = scan(text, pos, "\n", arc, True, False, True)
            if blocks:
                pos, first = end, False
                continue
        nl = text.find("\n", pos)
        if nl < 0:
            nl = n
        line, pos = text[pos:nl], nl + 1
        if not _stream_line(line, first):
            return False
        if first and line.strip():
            first = False
    return True


def _stream_line(line: str, first: bool) -> bool:
    """The stream check of one line (`first`: no code or comment before it)."""
    code = split_comment(line)[0].upper()
    if '"' in code:
        code = _STREAM_STRING.sub('""', code)
    words, targets = _stream_words()
    for m in _STREAM_MARK.finditer(code):
        tok = m.group()
        if tok == "=":
            name = _STREAM_NAME.search(code, 0, m.start())
            if name is None or name.group(1) not in targets or _STREAM_VALUE.match(code, m.end()) is None:
                return False
        elif tok == "%":
            if not first or code[:m.start()].strip():
                return False            # a second program unit, or `%` inside a block
            return True                 # the header line itself
        elif tok in ("$", "["):
            return False
        elif _STREAM_ADDRESS.fullmatch(tok):
            if tok[0] == "L" or (tok[0], int(tok[1:])) in _STREAM_CODES:
                return False            # L: a subprogram call
        elif tok not in words and tok not in targets:
            return False
    return True


class _FileParse:
    """One file's parse: `blocks()` runs through the lines and, streamed, yields the blocks of the
    main program as they are lowered (and keeps none); `program` is complete when it is done."""

    def __init__(self, text: str, file: str):
        from nctrans.source import from_text
        self.src = from_text(text, file)
        self.file = file
        self.low = Lowerer(file)
        self.low.meta["defaults"] = table().defaults()
        self.low.meta["contour_tables"] = dict(table().options.get("contour_tables", {}))
        self.low.diags.extend(self.src.diagnostics)
        self.program = ir.Program(file, DIALECT, [], {}, self.low.meta)

    def read_first_header(self) -> None:
        """The program header of the first line, ahead of the streamed parse (the interpreter
        reads the program's name when it starts; blocks() reads the line again, the same way)."""
        first = self.src.text.lstrip().split("\n", 1)[0]
        m = _HEADER.match(first)
        if m and not first.startswith("%%"):
            _read_header(self.low.meta, m.group(1))
            self.program.name = self.low.meta.get("program_name")

    def blocks(self, stream: bool, compact: bool = False):
        """`compact` (parse_compact): runs of plain lines at the top of the main program are
        kept in its body as PlainRuns."""
        file, low, prog = self.file, self.low, self.program
        text = self.src.text
        meta = low.meta
        diags = low.diags
        units: list[_Unit] = [_Unit(None)]
        macros: dict[str, str] = {}
        section: Optional[tuple[str, str, list]] = None      # (start kw, end kw, lines) of a data section
        iso_lines: Optional[list[Line]] = None
        zones: list = []
        seen_code = False
        main = units[0].pre
        # streamed with the native kernel: runs of plain lines become one PlainRun each
        scan = plainrun.native.scan if (stream or compact) and plainrun.native is not None else None
        motion = meta["defaults"].get("motion")          # the static motion mode (arcs by centre)
        held = 0            # compact: the main body's nodes whose motion mode has been followed

        max_block = limits.setting("MAX_BLOCK_CHARS", limits.MAX_BLOCK_CHARS)
        pos, end, n = 0, len(text), 0
        while pos < end:
            nl = text.find("\n", pos)
            if nl < 0:
                nl = end
            start, raw = pos, text[pos:nl]
            pos, n = nl + 1, n + 1
            unit = units[-1]
            if stream and main and len(units) == 1 and not unit.stack and unit.proc is None:
                for b in main:
                    if type(b) is ir.Block:
                        for st in b.body:
                            if type(st) is ir.ModeChange and st.group == "motion":
                                motion = st.value
                yield from main
                main.clear()
            if compact and len(main) > held:
                motion = _static_motion(main, held, motion)
                held = len(main)
            if len(raw) > max_block:
                low.error("NC010", f"block of {len(raw)} characters: longer than the {max_block} "
                          "nctrans reads; not analysed", n, 1)
                continue
            if scan is not None and len(units) == 1 and not unit.stack and unit.proc is None \
                    and iso_lines is None and section is None and not macros:
                # a run starts here when its first PLAIN_RUN_MIN lines are plain; where it ends
                # the kernel finds as it runs it (one pass), else extent() with scan()
                if scan(text, start, "\n", plainrun.motion_code(motion), True, False, True, max_block,
                        PLAIN_RUN_MIN)[2] >= PLAIN_RUN_MIN:
                    run = plainrun.PlainRun.open(file, text, start, n, "\n", plain_line, motion, None, False,
                                                 True, max_block)
                    if compact:
                        main.append(run)
                        held = len(main)
                    else:
                        yield run
                    ends = run.extent()
                    pos, n = ends.pos, ends.line - 1
                    motion = ends.motion
                    seen_code = True
                    continue
            if not raw.strip():
                continue
            m = _HEADER.match(raw)
            if m and not raw.lstrip().startswith("%%"):
                name = m.group(1)
                um = _UNIT_NAME.match(name)
                # comment lines before the file's first header are the program's own: the header
                # opened an uncalled second unit, and the program ran nothing (exit 0, no diagnostic)
                if seen_code or units[-1].proc or any(not _comment_only(x) for x in units[-1].pre):
                    units.append(_Unit(um.group(1).upper() if um else name.upper()))
                    meta.setdefault("unit_headers", {})[units[-1].name] = name
                else:
                    _read_header(meta, name)
                continue
            m = _PATH.match(raw)
            if m:
                if len(units) == 1:
                    meta["path"] = m.group(1)
                else:
                    units[-1].path = m.group(1)
                continue
            line = split_line(n, raw)
            span = _span(file, line)
            code = line.code
            # macro expansion (identifier macros of this file)
            if macros and code:
                code = _expand(code, macros, max_block)
                if code is None:        # the expansion is a block too: held to the same length
                    low.error("NC010", f"its DEFINE macros expand to more than {max_block} characters, "
                              "longer than the block nctrans reads; not analysed", n, 1)
                    continue
                line.code = code
            # ---- verbatim sections
            if iso_lines is not None:
                if _G290.search(code):
                    blocks = _iso_section(file, iso_lines)
                    if blocks is None:
                        for il in iso_lines:
                            unit.current.append(_passthrough_block(file, il, il.code, "ISO dialect section",
                                                                   "iso-m"))
                    else:
                        unit.current.extend(blocks)
                    iso_lines = None
                    unit.current.append(_passthrough_block(file, line, code, "native dialect mode"))
                else:
                    iso_lines.append(line)
                continue
            if section is not None:
                start_kw, end_kw, body = section
                unit.current.append(_passthrough_block(file, line, code, _SECTION_REASON[start_kw]))
                body.append(line)
                if re.match(rf"^\s*{end_kw}\b", code, re.IGNORECASE):
                    if start_kw in ("CPROTDEF", "NPROTDEF"):
                        zones.append(_zone(low, start_kw, body))
                    section = None
                continue
            if not code:
                unit.current.append(ir.Block(span, [], line.number, line.label, line.skip, line.comment))
                continue
            seen_code = True
            m = _DEFINE.match(code)
            if m:
                macros[m.group(1).upper()] = m.group(2).strip()
                meta.setdefault("macros", {})[m.group(1).upper()] = m.group(2).strip()
                unit.current.append(_passthrough_block(file, line, code, "macro definition"))
                continue
            if _SYNC.match(code):
                unit.current.append(_passthrough_block(file, line, code, "synchronized action"))
                continue
            if _DATA_ATTR.match(code):
                unit.current.append(_passthrough_block(file, line, code, "data attribute"))
                continue
            if _G291.search(code):
                unit.current.append(_passthrough_block(file, line, code, "ISO dialect mode"))
                iso_lines = []
                continue
            m = _SECTION_START.match(code)
            if m:
                kw = m.group(1).upper()
                section = (kw, _SECTION_END[kw], [line])
                unit.current.append(_passthrough_block(file, line, code, _SECTION_REASON[kw]))
                continue
            code = _PCALL_PATH.sub(lambda mm: mm.group(1) + mm.group(3), code)
            # ---- parse the statement part (plain address words skip the LALR parser)
            try:
                fast = _plain_words(code)
                if fast is None:
                    deep = limits.too_complex(code)
                    if deep is not None:
                        raise LexError("NC008", deep[1], deep[0])
                stmts = fast if fast is not None else [c for c in parser().parse(code).children
                                                       if isinstance(c, Tree)]
            except LexError as e:
                low.error(e.rule, e.message, n, line.col + e.pos)
                unit.current.append(_passthrough_block(file, line, code, "syntax error"))
                continue
            except UnexpectedInput as e:
                _syntax_error(low, e, code, line)
                unit.current.append(_passthrough_block(file, line, code, "syntax error"))
                continue
            _assemble(low, unit, units, stmts, line, span)

        if iso_lines is not None:
            for il in iso_lines:
                units[-1].current.append(_passthrough_block(file, il, il.code, "ISO dialect section", "iso-m"))
        if section is not None:
            diags.append(Diagnostic("NC006", "error", f"{section[0]} section without {section[1]}", file,
                                    section[2][0].lineno, 1))
        if zones:
            meta["protection_zones"] = zones
        if stream:
            yield from main
            main.clear()

        for i, unit in enumerate(units):
            while unit.stack:
                op = unit.stack.pop()
                diags.append(Diagnostic("NC006", "error", f"{op.kind} is not closed (program ends first)",
                                        file, op.line, 1))
            if i == 0:
                if not stream:
                    prog.body = unit.pre
                if unit.proc is not None:
                    prog.subprograms[unit.proc.name] = unit.proc
                    prog.name = unit.proc.name
                    meta["entry"] = unit.proc.name
                else:
                    prog.name = meta.get("program_name")
            else:
                sub = unit.proc or ir.Subprogram(unit.name or f"UNIT{i}", ir.Span(file, 1), [])
                if unit.proc is not None and unit.pre:
                    sub.body = unit.pre + sub.body
                elif unit.proc is None:
                    sub.body = unit.pre
                    meta.setdefault("members_without_proc", []).append(sub.name)
                prog.subprograms[sub.name] = sub


def _read_header(meta: dict, name: str) -> None:
    """The file's own program header `%_N_NAME_MPF` into meta."""
    meta["header"] = name
    um = _UNIT_NAME.match(name)
    if um:
        meta["program_name"] = um.group(1).upper()
        meta["program_type"] = um.group(2).upper()


def _static_motion(nodes: list, start: int, motion: Optional[str]) -> Optional[str]:
    """The static motion mode after nodes[start:] (a compact parse's main body) given `motion`
    before them: a block's own motion code sets it; after a structure (a loop or branch may or
    may not have run its blocks) or a call (the subprogram or cycle may leave another) it is not
    known (None), so no run starts on centre words alone."""
    for node in nodes[start:]:
        if type(node) is ir.Block:
            for st in node.body:
                if type(st) is ir.ModeChange and st.group == "motion":
                    motion = st.value
                elif type(st) in (ir.SubCall, ir.CycleCall):
                    motion = None
        elif type(node) is not plainrun.PlainRun:
            motion = None
    return motion


# Plain lines in a row before the streamed parse hands them over as one PlainRun.
PLAIN_RUN_MIN = 2
_PLAIN_WORD = re.compile(r"([A-Z])([+-]?[0-9.]+)")


def plain_line(code: str, motion: Optional[str], cycle: Optional[str], arc_abs: bool) -> tuple:
    """(number, body, motion mode written or None) of a line the kernel's strict scan took (code
    with its blanks removed: [N] [G0-G3] axis words, I J K, F): the Block the lowering above
    builds for it (tests/test_sinumerik_streaming.py holds the two to each other). Unlike ISO,
    the meaning of these words does not depend on the modal state before the line."""
    number = feed = mode = None
    target: dict = {}
    center: dict = {}
    axes = _plain_axes()
    for letter, num in _PLAIN_WORD.findall(code):
        if letter == "N":
            number = num
        elif letter == "G":
            rule = table().lookup(normalise_code("G", num))
            mode = ir.ModeChange(rule.group, rule.value, rule.code)
        elif letter == "F":
            feed = ir.Feed(ir.Num(float(num), num))
        elif letter in axes:
            target[letter] = ir.AxisValue(ir.Num(float(num), num))
        else:
            center[letter] = ir.AxisValue(ir.Num(float(num), num))
    body: list = []
    if mode is not None:
        body.append(mode)
    if feed is not None:
        body.append(feed)
    if target or center:
        body.append(ir.Motion(target, center or None))
    return number, body, None if mode is None else mode.value


@lru_cache(maxsize=1)
def _plain_axes() -> frozenset:
    return frozenset(table().options.get("axes", ()))




def _plain_words(code: str) -> Optional[list]:
    """Blocks made only of `X10 G1 F100` words (the bulk of real programs), as word trees built
    without the lexer and parser; anything else returns None and takes the full path."""
    if not _PLAIN.fullmatch(code):
        return None
    out: list = []
    for m in _PAIR.finditer(code):
        named = m.group(1) is not None
        g = 1 if named else 3
        a0, a1, n0, n1 = m.start(g), m.end(g), m.start(g + 1), m.end(g + 1)
        number = m.group(g + 1)
        if n1 - n0 > 15 or "X" in number or "x" in number:
            return None                  # an exponent or a long number: the lexer checks its range
        if named:
            if m.group(1) not in _plain_names():
                return None
            out.append(_PlainWord([_PlainToken("IDENT", m.group(1), a0, a1),
                                   _PlainToken("NUMBER", number, n0, n1)], "plain_assign"))
        else:
            out.append(_PlainWord([_PlainToken("ADDR", m.group(3).upper(), a0, a1),
                                   _PlainToken("NUMBER", number, n0, n1)]))
    return out


@lru_cache(maxsize=1)
def _plain_names() -> frozenset:
    """Names whose `NAME=number` words _plain_words reads: the axes and the address words of one
    part of a motion (Lowerer.named gives them the number as it is)."""
    o = table().options
    return frozenset((*o.get("axes", ()), *o.get("centre_words", {}), *o.get("via_words", {}),
                      *o.get("motion_words", {})))


class _PlainToken(str):
    """A plain word's letter or number with what the lowering reads of lark's Token (type,
    start_pos, end_pos), so that plain blocks are lowered without loading lark."""

    def __new__(cls, type_: str, value: str, start_pos: int, end_pos: int):
        t = super().__new__(cls, value)
        t.type, t.start_pos, t.end_pos = type_, start_pos, end_pos
        return t


class _PlainWord:
    """The tree of a plain word, as lark's Tree shows it to the lowering: `word` (letter, number)
    or `plain_assign` (name, number)."""
    __slots__ = ("children", "data")

    def __init__(self, children: list, data: str = "word"):
        self.children = children
        self.data = data

    def scan_values(self, pred) -> list:
        return [c for c in self.children if pred(c)]


def _expr_text(e) -> str:
    """Sinumerik spelling of an expression (for metadata that must round-trip)."""
    from nctrans.dialects.sinumerik.spelling import format_expr
    return format_expr(e)


def _expand(code: str, macros: dict[str, str], most: int) -> Optional[str]:
    """`code` with the file's DEFINE macros replaced; None once it would pass `most` characters
    (thousands of uses of a long macro in one line would otherwise build gigabytes)."""
    out, pos = [], 0
    size = len(code)
    inq = False
    i = 0
    while i < len(code):
        ch = code[i]
        if ch == '"':
            inq = not inq
            i += 1
            continue
        if not inq and ch.isascii() and (ch.isalpha() or ch == "_"):
            m = _WORD_RE.match(code, i)
            w = m.group().upper()
            if w in macros:
                out.append(code[pos:i])
                out.append(macros[w])
                pos = m.end()
                size += len(macros[w]) - len(w)
                if size > most:
                    return None
            i = m.end()
            continue
        i += 1
    out.append(code[pos:])
    return "".join(out)


def _syntax_error(low: Lowerer, e: UnexpectedInput, code: str, line: Line) -> None:
    depth = 0
    inq = False
    for ch in code:
        if ch == '"':
            inq = not inq
        elif not inq:
            depth += {"(": 1, ")": -1, "[": 1, "]": -1}.get(ch, 0)
    col = line.col + (getattr(e, "column", 1) or 1) - 1
    if isinstance(e, UnexpectedToken) and e.token is not None and e.token.type != "$END":
        col = line.col + e.token.start_pos
    if depth != 0:
        low.error("NC003", "bracket opened and not closed" if depth > 0 else "unmatched closing bracket",
                  line.lineno, col)
        return
    expected = sorted(getattr(e, "expected", None) or getattr(e, "allowed", None) or [])
    if isinstance(e, UnexpectedToken):
        got = "end of block" if e.token.type == "$END" else repr(str(e.token))
        msg = f"unexpected {got}"
    else:
        msg = "unexpected input"
    if expected:
        msg += "; expected one of: " + ", ".join(expected[:8])
    low.error("NC002", msg, line.lineno, col)


def _assemble(low: Lowerer, unit: _Unit, units: list, stmts: list, line: Line, span: ir.Span) -> None:
    """Turn one parsed block into a Block or a control-structure event on the unit's stack."""
    file = low.file
    if not stmts:
        unit.current.append(ir.Block(span, [], line.number, line.label, line.skip, line.comment))
        return
    head = stmts[0]
    d = head.data
    if d == "proc_stmt":
        if unit.proc is not None:
            low.error("NC002", "second PROC in one program", line.lineno, line.col)
            return
        ch = head.children
        params = []
        for c in ch:
            if isinstance(c, Tree) and c.data == "formal":
                by_ref = any(isinstance(x, Token) and x.type == "VAR" for x in c.children)
                ts = next(x for x in c.children if isinstance(x, Tree) and x.data == "type_spec")
                name = next(str(x) for x in c.children if isinstance(x, Token) and x.type == "IDENT")
                low.refuse_name(next(x for x in c.children if isinstance(x, Token) and x.type == "IDENT"), line)
                arr = [x for x in c.children if isinstance(x, Tree) and x.data == "arglist"]
                dims = [0 if is_omitted(a) else int(a.value) if isinstance(a, ir.Num) else 0
                        for a in _args(arr[0])] or [0] if arr and arr[0] is not None else []
                typ, _len = _type(ts)
                params.append(ir.Param(name, typ, by_ref, dims))
        attrs = [str(c) for c in ch if isinstance(c, Token) and c.type == "PROCATTR"]
        unit.proc = ir.Subprogram(str(ch[1]), span, [], params, attrs)
        unit.root = unit.proc.body
        if line.label or line.comment:
            unit.root.append(ir.Block(span, [], None, line.label, None, line.comment))
        return
    if (d == "repeat_stmt" and len(stmts) > 1) or (
            d == "call_name" and str(head.children[0]) == "REPEATB"):
        # REPEAT label [label] [P=n] / REPEATB label [P=n]: program section repetition, not the
        # REPEAT..UNTIL loop (a bare REPEAT)
        node = _section_repeat(low, stmts[1:], line, line_only=d == "call_name")
        unit.current.append(ir.Block(span, [node] if node else [], line.number, line.label,
                                     line.skip, line.comment))
        return
    ctrl = d in _KW or (d == "if_stmt")
    decls = [st for st in stmts if st.data == "def_stmt"]
    if decls and len(decls) != len(stmts):
        low.error("NC002", "DEF must stand in its own block", line.lineno, line.col)
        unit.current.append(_passthrough_block(file, line, line.code, "syntax error"))
        return
    if not ctrl:
        for st in stmts[1:]:
            if st.data in _KW:
                low.error("NC002", f"{_KW[st.data]} must stand at the start of its own block",
                          line.lineno, line.col)
                return
        body = low.statements(stmts, line)
        unit.current.append(ir.Block(span, body, line.number, line.label, line.skip, line.comment))
        return
    ch = head.children
    rest = stmts[1:]
    if d == "if_stmt" and ch[2] is not None:       # IF cond GOTOF label: a plain block
        jumps = [_goto(ch[2], ch[3], expr(ch[1]))]
        # several conditional jumps in one block run in order (real cycle code:
        # IF DPR==0 GOTOF _MM1 IF RTP==RFP GOTOF _FEHL1)
        while rest and rest[0].data == "if_stmt" and rest[0].children[2] is not None:
            c = rest[0].children
            jumps.append(_goto(c[2], c[3], expr(c[1])))
            rest = rest[1:]
        unit.current.append(ir.Block(span, jumps, line.number, line.label, line.skip, line.comment))
        if rest:
            low.error("NC002", "statement after the jump target", line.lineno, line.col)
        return
    # control structures: a label/number/comment on the line is kept in an empty block before it
    if line.label or line.number or line.comment:
        unit.current.append(ir.Block(span, [], line.number, line.label, line.skip, line.comment))
    if d == "if_stmt":
        cond = expr(ch[1])
        node = ir.If(span, cond, [])
        if rest:          # IF cond stmt... in one block: a one-block conditional
            node.then.append(ir.Block(span, low.statements(rest, line)))
            unit.current.append(node)
            return
        _open(low, unit, "IF", node, node.then, line)
    elif d == "else_stmt":
        if unit.stack and unit.stack[-1].kind == "IF" and unit.stack[-1].body is unit.stack[-1].node.then:
            unit.stack[-1].body = unit.stack[-1].node.orelse
        else:
            low.error("NC002", "ELSE without IF", line.lineno, line.col)
    elif d == "while_stmt":
        node = ir.While(span, expr(ch[1]), [])
        _open(low, unit, "WHILE", node, node.body, line)
    elif d == "for_stmt":
        lv = ch[1].children[0]
        var = ir.Var("R", int(str(lv)[1:])) if _RPARAM.match(str(lv)) else (
            ir.Var("system", str(lv)) if lv.type == "SYSVAR" else ir.Var("name", str(lv)))
        node = ir.ForLoop(span, var, expr(ch[3]), expr(ch[5]), [])
        _open(low, unit, "FOR", node, node.body, line)
    elif d == "loop_stmt":
        node = ir.Loop(span, [])
        _open(low, unit, "LOOP", node, node.body, line)
    elif d == "repeat_stmt":
        node = ir.RepeatUntil(span, [], ir.Num(1.0, "1"))
        _open(low, unit, "REPEAT", node, node.body, line)
    elif d in ("endif_stmt", "endwhile_stmt", "endfor_stmt", "endloop_stmt", "until_stmt"):
        want = {"endif_stmt": "IF", "endwhile_stmt": "WHILE", "endfor_stmt": "FOR",
                "endloop_stmt": "LOOP", "until_stmt": "REPEAT"}[d]
        if unit.stack and unit.stack[-1].kind == want:
            op = unit.stack.pop()
            if d == "until_stmt":
                op.node.cond = expr(ch[1])
        else:
            open_kind = unit.stack[-1].kind if unit.stack else "nothing"
            low.error("NC002", f"{_KW[d]} does not close {open_kind} (no open {want})", line.lineno,
                      line.col)
    elif d == "case_stmt":
        branches = []
        default = None
        for c in ch:
            if isinstance(c, Tree) and c.data == "case_branch":
                branches.append((expr(c.children[0]), _target(c.children[2])))
        if ch[-3] is not None and isinstance(ch[-1], Tree) and ch[-1].data == "target" \
                and isinstance(ch[-3], Token) and ch[-3].type == "DEFAULT":
            default = _target(ch[-1])
        unit.current.append(ir.Case(span, expr(ch[1]), branches, default))
    if rest and d not in ("if_stmt",):
        low.error("NC002", f"{_KW.get(d, d)} must stand in its own block", line.lineno, line.col)


def _section_repeat(low: Lowerer, args: list, line: Line, line_only: bool) -> Optional[ir.SectionRepeat]:
    """`REPEAT start [end] [P=n]` / `REPEATB label [P=n]` [GK: Siemens Fundamentals manual, program
    section repetition; the seed lists REPEATB only in its keyword table, L24650]."""
    kw = "REPEATB" if line_only else "REPEAT"
    labels: list[str] = []
    count = None
    for st in args:
        if st.data == "call_name" and count is None and len(labels) < (1 if line_only else 2):
            labels.append(str(st.children[0]))
        elif st.data == "assign" and count is None and str(st.children[0].children[0]) == "P" \
                and len(st.children) == 3:
            count = expr(st.children[2])
        else:
            low.error("NC002", f"{kw} expects a jump label{'' if line_only else ' (and an end label)'}"
                      " and P=<number of repetitions>", line.lineno, line.col)
            return None
    if not labels:
        low.error("NC002", f"{kw} without the jump label of the section to repeat", line.lineno,
                  line.col)
        return None
    return ir.SectionRepeat(labels[0], labels[1] if len(labels) > 1 else None, count, line_only)


def _open(low: Lowerer, unit: _Unit, kind: str, node, body: list, line: Line) -> None:
    """Open a control structure. Past the controller's nesting limit it is an NC008 error and the
    structure is kept out of the IR (its blocks stay in the enclosing body), so no walker of the
    IR recurses deeper than the limit."""
    most = int(table().options.get("max_structure_nesting", limits.MAX_STRUCTURE_NESTING))
    if len(unit.stack) >= most:
        low.error("NC008", f"{kind} nested {len(unit.stack) + 1} deep: nesting too deep (at most "
                  f"{most} control structures per program level)",
                  line.lineno, line.col)
        unit.stack.append(_Open(kind, node, unit.current, line.lineno))
        return
    unit.current.append(node)
    unit.stack.append(_Open(kind, node, body, line.lineno))


def _zone(low: Lowerer, start: str, lines: list[Line]) -> dict:
    """A CPROTDEF/NPROTDEF .. EXECUTE definition as data (spec 8.3): header values and the contour."""
    zone: dict = {"scope": "chan" if start == "CPROTDEF" else "nck", "line": lines[0].lineno,
                  "contour": []}
    try:
        head = parser().parse(lines[0].code)
        call = head.children[0]
        args = _args(call.children[2])
        keys = ["number", "tool_oriented", "applim", "applus", "appminus"]
        for k, a in zip(keys, args):
            zone[k] = a.value if isinstance(a, ir.Num) else None
    except Exception:          # the header is kept verbatim in the program anyway
        pass
    motion = "linear"
    for l in lines[1:-1]:
        if not l.code:
            continue
        try:
            stmts = [c for c in parser().parse(l.code).children if isinstance(c, Tree)]
            body = Lowerer(low.file).statements(stmts, l)
        except Exception:
            continue
        for st in body:
            if isinstance(st, ir.ModeChange) and st.group == "motion":
                motion = st.value
            if isinstance(st, ir.Motion):
                el = {"motion": motion, "line": l.lineno}
                for k, v in st.target.items():
                    if isinstance(v.value, ir.Num):
                        el[k] = v.value.value
                for k, v in (st.center or {}).items():
                    if isinstance(v.value, ir.Num):
                        el[k] = v.value.value
                zone["contour"].append(el)
    return zone


_EXTERN = re.compile(r"^\s*EXTERN\s+\w+\s*\((.*)\)\s*$", re.IGNORECASE)
_EXTERN_PARAM = re.compile(r"^(VAR\s+)?([A-Z]+)\s*(?:\[([^\]]*)\])?$", re.IGNORECASE)


def _extern_signature(text: str) -> Optional[list]:
    """The parameters an EXTERN declaration gives a subprogram (by reference, type, constant
    dimensions), as plain data for emitters that lay out calls: None when it does not read."""
    m = _EXTERN.match(text.split(";")[0])
    if m is None:
        return None
    params = []
    parts = re.split(r",(?![^\[]*\])", m.group(1)) if m.group(1).strip() else []
    for part in (p.strip() for p in parts):
        pm = _EXTERN_PARAM.match(part)
        if pm is None:
            return None
        dims = [int(d) if d.strip().isdigit() else 0 for d in pm.group(3).split(",")] if pm.group(3) else []
        params.append({"by_ref": bool(pm.group(1)), "type": pm.group(2).upper(), "dims": dims})
    return params
