"""The emitter base: what every dialect's emitter (IR -> text) shares, so that an emitter keeps
only its dialect's spelling.

- One refusal path. Spelling code raises `NotExpressible`; the emitter turns it into NC402 with
  `refuse()` at the line of the statement being written, and reports a lowering (an equivalent
  spelled differently) as NC401 with `lowered()`.
- Codes from the rules table. `code_for(group, value)` spells a neutral meaning with the dialect's
  own code (rules/<table>.toml [[codes]]), so no G or M number is written in Python.
- A table-driven expression printer. `Spelling` prints IR expressions from the table's
  [expressions] section: operator spellings, precedence and bracketing, function names. What a
  table cannot say (ISO writes MINVAL as an ABS expression, Fagor ATAN2 as ARG) is a method marked
  `@rewrites(node type, name...)`.
- Number formatting: `format_number`, the exact shortest decimal (no exponent).
- Position and frame tracking: the constant programmed position and the programmable translation as
  far as the program text fixes them (for lowerings that compute from them: arc centres, G52).
- Dispatch by node type: `dispatch("w_", node)` calls the emitter's `w_<NodeType>`; a node type
  the emitter has no method for is not expressible (NC402, never silently dropped).
"""
from __future__ import annotations

import contextlib
from contextvars import ContextVar
from dataclasses import dataclass
from decimal import Decimal
from typing import Any, Callable, ClassVar, Optional

from nctrans.diagnostics import Diagnostic, at_span
from nctrans.ir import nodes as n
from nctrans.ir.walk import constant
from nctrans.rules import RulesTable, load_table


# the machine a conversion runs for (api.transpile: --machine, else the built-in one), as a
# callable asked only where an emitter needs the machine's data to choose what to write (the
# Sinumerik edge for ISO tool offsets: nctrans.dialects.sinumerik.edge_selection)
CONVERSION_MACHINE: ContextVar[Optional[Callable]] = ContextVar("conversion_machine", default=None)


@contextlib.contextmanager
def conversion_machine(get: Callable):
    """Within it, `get()` gives the machine a conversion is checked on."""
    token = CONVERSION_MACHINE.set(get)
    try:
        yield
    finally:
        CONVERSION_MACHINE.reset(token)


def flat_radius_number(k) -> bool:
    """Whether the machine of the conversion running gives offset number k as a flat radius
    (`radius_offsets`), which a D reads whatever tool is in the spindle (False outside one)."""
    get = CONVERSION_MACHINE.get()
    try:
        machine = get() if get is not None else None
    except Exception:           # a machine file that does not load: said where it is used
        return False
    return machine is not None and k in getattr(machine, "radius_offsets", {})


# the target of the conversion running and the control profile it is written for (`convert
# --profile` naming one of the target's `[options.profiles]`, None: the dialect's own default)
TARGET_PROFILE: ContextVar[Optional[tuple]] = ContextVar("target_profile", default=None)


@contextlib.contextmanager
def target_profile(dialect: str, profile: Optional[str]):
    """Within it, conversions write `dialect` for the control `profile`."""
    token = TARGET_PROFILE.set((dialect, profile))
    try:
        yield
    finally:
        TARGET_PROFILE.reset(token)


def flat_forms(dialect: Optional[str] = None) -> dict:
    """How plain motion (--flatten) spells spindle-synchronised moves for the target being
    written: its rules table's `[options.flat_motion]`, overridden by the profile's `flat_motion`
    (issue 8: a Fanuc taps with M29 S.. G84, LinuxCNC with G33.1). Also `dialect`: the target's
    name. `dialect`: the target's forms whatever the conversion running writes (its default
    control's, unless the conversion writes that dialect for a profile). Empty for a target whose
    table has no such forms, and outside a conversion when no dialect is named."""
    current = TARGET_PROFILE.get()
    profile = None
    if current is not None and dialect in (None, current[0]):
        dialect, profile = current
    if dialect is None:
        return {}
    from nctrans.rules import option
    forms = dict(option(dialect, "flat_motion") or {})
    if profile:
        forms.update(((option(dialect, "profiles") or {}).get(profile) or {}).get("flat_motion") or {})
    if forms:
        forms["dialect"] = dialect
        from nctrans.interp.cycles import cycle_table
        forms["tap_end"] = cycle_table().tap_end(dialect, profile)   # how its G84 ends a hole
    return forms


class NotExpressible(Exception):
    """Raised while spelling something the target dialect cannot write; the emitter reports it as
    NC402 at the current statement's line."""


def format_number(v: float, point: bool = False) -> str:
    """Exact shortest decimal text of a float (no exponent; -0.0 stays "-0"); `point` forces a
    decimal point on whole numbers ("5.")."""
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


# --------------------------------------------------------------------------- expression syntax

@dataclass(frozen=True)
class Operator:
    """How one neutral operator is spelled. An operand whose own precedence is below `left`
    (`right`) is bracketed; `always`: both operands are bracketed whatever they are."""
    text: str
    prec: int
    left: int
    right: int
    always: bool = False


def _operator(spec: dict, atom: int) -> Operator:
    prec = spec["prec"]
    operands = spec.get("operands")
    if operands == "always":
        return Operator(spec["text"], prec, prec, prec + 1, True)
    if operands == "atoms":
        return Operator(spec["text"], prec, atom, atom)
    if operands is not None:
        return Operator(spec["text"], prec, operands, operands)
    return Operator(spec["text"], prec, prec, prec + 1)


class ExpressionSyntax:
    """A dialect's expression syntax, read from the [expressions] section of its rules table.

    brackets: the pair that groups; separator: between function arguments; atom: the precedence of
    numbers, variables and function calls; negative_number: that of a number written with a sign;
    sign_after_sign = "bracket": a signed right operand of + or - is bracketed (ISO: `1-[-5]`, as
    two signs in a row do not read); binary / unary: neutral operator -> {text, prec, operands}
    (operands: the precedence below which both operands are bracketed, "atoms" for everything but
    atoms, "always"); functions: neutral function name -> spelling."""

    def __init__(self, data: dict):
        self.open, self.close = data.get("brackets", ["(", ")"])
        self.separator: str = data.get("separator", ",")
        self.atom: int = data.get("atom", 100)
        self.negative: int = data.get("negative_number", self.atom)
        self.bracket_sign_after_sign = data.get("sign_after_sign") == "bracket"
        self.binary = {op: _operator(spec, self.atom) for op, spec in data.get("binary", {}).items()}
        self.unary = {op: _operator(spec, self.atom) for op, spec in data.get("unary", {}).items()}
        self.functions: dict[str, str] = dict(data.get("functions", {}))

    def wrap(self, text: str) -> str:
        return f"{self.open}{text}{self.close}"


_SYNTAX: dict[str, ExpressionSyntax] = {}


def expression_syntax(table_name: str) -> ExpressionSyntax:
    syntax = _SYNTAX.get(table_name)
    if syntax is None:
        syntax = _SYNTAX[table_name] = ExpressionSyntax(load_table(table_name).expressions)
    return syntax


def rewrites(node_type: type, *names: str) -> Callable:
    """Mark a Spelling method as the spelling of these operators (Binary, Unary) or functions
    (Func, lower-case names): method(self, node) -> (text, precedence)."""
    def mark(fn: Callable) -> Callable:
        fn._rewrites = [(node_type, name) for name in names]     # type: ignore[attr-defined]
        return fn
    return mark


class Spelling:
    """Expressions and numbers in one dialect's syntax, without a program (front ends use it to
    show an expression as text). Subclasses set `syntax_table` and `var_text`."""

    syntax_table: ClassVar[str] = ""
    _rewrites: ClassVar[dict] = {}

    def __init_subclass__(cls, **kwargs) -> None:
        super().__init_subclass__(**kwargs)
        found = dict(cls._rewrites)
        for attr in vars(cls).values():
            for key in getattr(attr, "_rewrites", ()):
                found[key] = attr
        cls._rewrites = found

    @property
    def syntax(self) -> ExpressionSyntax:
        return expression_syntax(self.syntax_table)

    def lowered(self, what: str) -> None:
        """A lowering made while spelling; only an emitter reports it."""

    # ----------------------------------------------------------- what a dialect provides
    def var_text(self, v: n.Var) -> str:
        raise NotExpressible(f"variable {v.space}:{v.key}")

    def number(self, e: n.Num) -> str:
        return format_number(e.value)

    def string(self, e: n.Str) -> str:
        raise NotExpressible("a string value")

    # ----------------------------------------------------------- the printer
    def expr(self, e: Any, context: int = 0) -> str:
        """`e` as text, bracketed when it binds less tightly than `context` (a precedence)."""
        text, prec = self.term(e)
        return self.syntax.wrap(text) if prec < context else text

    def term(self, e: Any) -> tuple[str, int]:
        """(text, precedence) of an expression."""
        t = type(e)
        syntax = self.syntax
        if t is n.Num:
            text = self.number(e)
            return text, syntax.negative if text[:1] == "-" else syntax.atom
        if t is n.Var:
            return self.var_text(e), syntax.atom
        if t is n.Str:
            return self.string(e), syntax.atom
        if t is n.Binary or t is n.Unary:
            rewrite = self._rewrites.get((t, e.op))
            if rewrite is not None:
                return rewrite(self, e)
            return self.binary(e) if t is n.Binary else self.unary(e)
        if t is n.Func:
            rewrite = self._rewrites.get((t, e.name.lower()))
            if rewrite is not None:
                return rewrite(self, e)
            return self.call(e), syntax.atom
        raise NotExpressible(f"expression {t.__name__}")

    def binary(self, e: n.Binary) -> tuple[str, int]:
        syntax = self.syntax
        op = syntax.binary.get(e.op)
        if op is None:
            raise NotExpressible(f"operator {e.op!r}")
        lt, lp = self.term(e.left)
        rt, rp = self.term(e.right)
        if op.always:
            return f"{syntax.wrap(lt)}{op.text}{syntax.wrap(rt)}", op.prec
        if syntax.bracket_sign_after_sign and rt[:1] in "+-" and op.text in ("+", "-"):
            rp = -1
        left = syntax.wrap(lt) if lp < op.left else lt
        right = syntax.wrap(rt) if rp < op.right else rt
        return f"{left}{op.text}{right}", op.prec

    def unary(self, e: n.Unary) -> tuple[str, int]:
        syntax = self.syntax
        op = syntax.unary.get(e.op)
        if op is None:
            raise NotExpressible(f"unary operator {e.op!r}")
        ot, prec = self.term(e.operand)
        if syntax.bracket_sign_after_sign and ot[:1] in "+-":
            prec = -1
        return op.text + (syntax.wrap(ot) if prec < op.right else ot), op.prec

    def call(self, e: n.Func) -> str:
        """A function call spelled from the table's function names."""
        name = self.syntax.functions.get(e.name.lower())
        if name is None:
            raise NotExpressible(f"function {e.name.upper()}")
        return name + self.syntax.wrap(self.syntax.separator.join(self.expr(a) for a in e.args))


# --------------------------------------------------------------------------- the emitter base

class Emitter(Spelling):
    """IR -> text for one dialect. Subclasses set `table_name` (rules/<table>.toml: codes and
    expression syntax), `dialect` (the name of programs already in this dialect) and `target_text`
    (the dialect as NC402 names it), and write statements in `w_<NodeType>` methods."""

    dialect: ClassVar[str] = ""
    table_name: ClassVar[str] = ""
    target_text: ClassVar[str] = ""
    # NC401 wording: "lowered for <lowered_for>: <what>"
    lowered_for: ClassVar[str] = ""

    def __init__(self, program: n.Program):
        self.program = program
        self.table: RulesTable = load_table(self.table_name)
        self.diags: list[Diagnostic] = []
        self.span: Optional[n.Span] = None
        self._once: set = set()
        # what is known at emit time: the constant programmed position per axis, and the constant
        # programmable translation (None: unknown) with whether rotation/scale/mirror may be active
        self.pos: dict[str, float] = {}
        self.distance = "absolute"
        self.frame_trans: Optional[dict[str, float]] = {}
        self.frame_other = False

    @property
    def syntax(self) -> ExpressionSyntax:
        return expression_syntax(self.syntax_table or self.table_name)

    # -------------------------------------------------------------- reporting
    def _where(self) -> n.Span:
        """The current statement's span, or the program's first line outside any statement."""
        return self.span if self.span is not None else n.Span(self.program.file, 1)

    def lowered(self, what: str, once: Any = None) -> None:
        """NC401: `what` is written with an equivalent of the target's; `once`: a key reported
        only the first time it is seen."""
        if once is not None:
            if once in self._once:
                return
            self._once.add(once)
        text = f"lowered for {self.lowered_for}: {what}" if self.lowered_for else what
        self.diags.append(at_span("NC401", "info", text, self._where()))

    def lowered_once_per_program(self, what: str) -> None:
        """NC401 once per distinct `what` in the program, at its first line; the later lines are
        counted in that note ("(and 2999 more lines)"): a lowering at every tool change of a
        3000-change program was 3000 notes saying one thing."""
        folded = self.__dict__.setdefault("_folded_notes", {})
        line = self._where().line
        seen = folded.get(what)
        if seen is None:
            text = f"lowered for {self.lowered_for}: {what}" if self.lowered_for else what
            d = at_span("NC401", "info", text, self._where())
            folded[what] = [d, text, line, 0]
            self.diags.append(d)
        elif line != seen[2]:
            seen[2] = line
            seen[3] += 1
            seen[0].message = f"{seen[1]} (and {seen[3]} more line{'s' if seen[3] > 1 else ''})"

    def foreign_function_comment(self, s: n.Passthrough) -> str:
        """NC413: a function of the source control with no effect on the path and no counterpart
        here (ISO POPEN/DPRNT, Haas G103): the text of the comment that stands in its place, never
        a word the target would read as something else."""
        self.diags.append(at_span("NC413", "warning", f"{s.dialect} {s.text} has no {self.target_text} "
                                  f"equivalent ({s.reason}): written as a comment; the toolpath is the "
                                  "same, but what it does on its own control is not done", self._where()))
        return f"NC413 {s.dialect}: {s.text}"

    def settings_cycle(self, s: n.SubCall) -> Optional[n.Passthrough]:
        """A call of another control's standard cycle that only sets modes and has no path of its
        own (rules/cycles.toml [[unmodelled]] with moves = false: CYCLE832's tolerance and
        continuous-path settings), as the no-motion function it is: the toolpath passes it over,
        so the target gets the NC413 comment (what it does on its own control is not done) instead
        of a call of a program no target control has (G65 P9134, L CYCLE832). None otherwise."""
        if not s.name or s.target is not None or self.program.dialect == self.dialect:
            return None
        from nctrans.interp.cycles import unmodelled_cycle
        from nctrans.ir.vocabulary import NO_EFFECT_PREFIX
        what = unmodelled_cycle(str(s.name))
        if what is None or what.moves:
            return None
        try:
            args = ",".join("" if a is None else self.expr(a) for a in s.args)
        except Exception:           # an argument the target cannot spell: the comment names the call
            args = ".."
        return n.Passthrough(f"{s.name}({args})", f"{NO_EFFECT_PREFIX}: {what.meaning}",
                             self.program.dialect)

    def refuse(self, what: str) -> None:
        """NC402: the target cannot express `what`; the text leaves it out."""
        line = self.span.line if self.span is not None else 1
        self.diags.append(at_span("NC402", "error", f"{self.target_text} cannot express {what} "
                                  f"(source line {line})", self._where()))

    # -------------------------------------------------------------- codes
    def code_for(self, group: str, value: str = "") -> str:
        """The dialect's code for a neutral meaning (rules table order = preferred code), as the
        dialect writes it (a rule's `spelling`: Fagor G00)."""
        rule = self.table.code_for(group, value)
        if rule is None:
            raise NotExpressible(f"mode {group}={value}")
        return rule.spelling or rule.code

    def power_on_codes(self, groups: tuple[str, ...]) -> list[str]:
        """The codes that select, in this dialect, the source controller's power-on modes of
        `groups` where this dialect's own power-on modes differ: a program relies on its
        controller's (an ISO lathe feeds per revolution, a mill per minute), so the converted
        program must say them. Empty for a program already in this dialect."""
        p = self.program
        meta = p.meta or {}
        if p.dialect == self.dialect or meta.get("flattened_from"):
            return []                   # a flattened program selects its modes in its first block
        source = meta.get("defaults") or {}
        mine = self.table.defaults()
        codes = []
        for group in groups:
            value = source.get(group)
            if value is None or mine.get(group) == value:
                continue
            codes.append(self.code_for(group, value))
        return codes

    def code_word(self, group: str, value: str = "") -> tuple[str, str]:
        """(modal-group key, code) of a meaning: two codes of one group of the dialect's manual
        cannot share a block, so the key makes the second start a new line."""
        rule = self.table.code_for(group, value)
        if rule is None:
            raise NotExpressible(f"mode {group}={value}")
        return self._word(rule)

    def word_of(self, code: str) -> tuple[str, str]:
        """(modal-group key, code) of a code of this dialect's table."""
        rule = self.table.lookup(code)
        if rule is None:
            raise NotExpressible(f"code {code}")
        return self._word(rule)

    @staticmethod
    def _word(rule) -> tuple[str, str]:
        key = f"{rule.code[0]}:{rule.dialect_group}" if rule.dialect_group is not None else ""
        return key, rule.spelling or rule.code

    # -------------------------------------------------------------- dispatch
    def dispatch(self, prefix: str, node: Any, *args: Any) -> Any:
        """Call `<prefix><NodeType>(node, *args)`; a node type without one is not expressible."""
        write = getattr(self, prefix + type(node).__name__, None)
        if write is None:
            raise NotExpressible(self.describe(node))
        t = type(node)
        if t is n.PolarPole:                # polar_words_check: a plane change since the pole
            self.pole_plane = "same"
        elif t is n.ModeChange and node.group == "plane" and getattr(self, "pole_plane", None):
            self.pole_plane = "changed"
        return write(node, *args)

    def describe(self, node: Any) -> str:
        """How NC402 names a node the dialect has no spelling for."""
        return f"the statement {type(node).__name__}"

    def polar_words_check(self, s: n.Motion) -> None:
        """Polar end points mean what the reading control's table says (nctrans.interp.polar_words):
        a left-out angle or radius is the value last programmed or the current point's (option
        `polar_memory`), and under incremental distance the words are increments or not (option
        `polar_incremental`). Where the source's and this target's differ the words are written
        only where they say the same point: both given, under absolute distance, and not after a
        plane change since the pole where one control keeps the pole and the other does not
        (option `pole_on_plane_change`)."""
        from nctrans.rules import option

        def semantics(dialect):
            return (option(dialect, "polar_memory") or "position",
                    option(dialect, "polar_incremental") or "never",
                    option(dialect, "pole_on_plane_change") or "kept")
        if not s.polar:
            return
        source, target = semantics(self.program.dialect), semantics(self.table_name)
        if source[0] != target[0] and not {"angle", "radius"} <= set(s.polar):
            raise NotExpressible("a polar end point with its angle or radius left out (the source "
                                 "control takes the value it stored, this one reads another)")
        if source[1] != target[1] and self.distance != "absolute":
            raise NotExpressible("polar words under incremental distance (the two controls read "
                                 "them differently)")
        if source[2] != target[2] and getattr(self, "pole_plane", None) == "changed":
            raise NotExpressible("polar words after a plane change since the pole was set (one "
                                 "control keeps the pole, the other goes back to the work zero)")

    # -------------------------------------------------------------- position and frame
    def forget(self) -> None:
        """A place reached from elsewhere (jump target, structure, call): positions and the
        programmable frame are no longer known constants."""
        self.pos = {}
        self.frame_trans = None
        self.frame_other = True
        if getattr(self, "pole_plane", None):
            self.pole_plane = "changed"

    def incremental(self, av: n.AxisValue) -> bool:
        return av.mode == "inc" or (av.mode is None and self.distance == "incremental")

    def track(self, s: n.Motion) -> None:
        """The constant programmed end point, where the words say it."""
        if s.polar or s.machine_coords:
            for k in s.target:
                self.pos.pop(k, None)
            if s.polar:
                self.pos = {}
            return
        for k, av in s.target.items():
            v = constant(av.value)
            inc = self.incremental(av)
            if v is None or (inc and k not in self.pos):
                self.pos.pop(k, None)
            else:
                self.pos[k] = self.pos[k] + v if inc else v

    def track_frame(self, s: n.FrameOp) -> None:
        """Follow the programmable frame as far as it is constant (source semantics: an op that is
        not additive, local or pivoted replaces the whole frame)."""
        self.pos = {}
        if s.op == "all" and s.clear:
            self.frame_trans, self.frame_other = {}, False
        elif s.op == "trans":
            if s.clear:
                self.frame_trans = {}
                return
            vals = {k: constant(v) for k, v in s.values.items()}
            self.frame_trans = None if None in vals.values() else vals
            if not s.local:
                self.frame_other = False
        elif not s.clear:
            self.frame_other = True
            if not s.local and s.center is None:
                self.frame_trans = {}
