"""Sinumerik expressions as text, without a program: the emitter base's table-driven printer
(operators, precedence and function names from rules/sinumerik.toml [expressions]) plus what a
table cannot say. The front end uses it to keep an expression as text (FP=, RPL=, array bounds);
the emitter extends it with what depends on the program (ISO macro variables, PROC parameters).

Precedence (spec 4.1): comparisons bind weakest and are bracketed inside any other operator, as
are signed numbers and unary operators; a comparison's operands are bracketed unless they are
atoms. Numbers keep their source spelling when it reads back to the same value (`1.50`, `'H1F'`),
and are written with the `EX` exponent otherwise.
"""
from __future__ import annotations

import math
import re
from typing import Any

from nctrans.dialects.emit import NotExpressible, Spelling, rewrites
from nctrans.dialects.sinumerik.lexer import number_value
from nctrans.ir import nodes as ir

DIALECT = "sinumerik"
_NUM_OK = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:EX[+-]?\d+)?$|'[HB][0-9A-F]+'$|TRUE$|FALSE$",
                     re.IGNORECASE)
# a bare name that would read back as an address word (C, R1R2): bracketed where it stands alone
_AMBIGUOUS = re.compile(r"^[A-Za-z](?:\d\w*)?$")


def format_number(v: float) -> str:
    """A float as Sinumerik writes it: integers bare, 12 significant digits, `EX` exponent."""
    if v != v or v in (float("inf"), float("-inf")):
        raise NotExpressible(f"the number {v!r}")
    if v == int(v) and abs(v) < 1e15:
        return str(int(v))
    s = format(v, ".12g")
    if "e" in s:
        mant, ex = s.split("e")
        return f"{mant}EX{int(ex)}"
    return s


class SinumerikSpelling(Spelling):
    """Expressions in Sinumerik syntax. `lowered` receives the lowerings (NC401) an emitter
    reports; here they are dropped."""
    syntax_table = DIALECT

    def lowered(self, what: str, once: Any = None) -> None:
        """A lowering made while spelling; only an emitter reports it."""

    # ------------------------------------------------------------------ leaves
    def number(self, e: ir.Num) -> str:
        if e.text == "":               # an omitted call argument f(1,,3) (frontend.OMITTED)
            return ""
        if e.text and _NUM_OK.match(e.text):
            try:
                if math.isclose(number_value(e.text.lstrip("+")), e.value, rel_tol=1e-12, abs_tol=1e-12):
                    return e.text.lstrip("+")
            except ValueError:
                pass
        return format_number(e.value)

    def string(self, e: ir.Str) -> str:
        if '"' in e.value:
            raise NotExpressible(f"a string with a double quote: {e.value!r}")
        return '"' + e.value + '"'

    def var_text(self, v: ir.Var) -> str:
        return self.var(v)

    def var(self, v: ir.Var, target: bool = False) -> str:
        """A variable; `target`: written to (a bare name then needs no brackets)."""
        idx = "[" + ", ".join(self.arg(i) for i in v.indices) + "]" if v.indices else ""
        if v.space == "R":
            return f"R{v.key}" if v.key is not None else f"R{idx}"
        if v.space == "name" and not idx and not target and _AMBIGUOUS.match(str(v.key)):
            return f"({v.key})"        # C or R1R2 alone would read back as address words
        if v.space in ("name", "system"):
            return f"{v.key}{idx}"
        return self.foreign_var(v, target, idx)

    def foreign_var(self, v: ir.Var, target: bool, idx: str) -> str:
        """A variable of another dialect's space (the emitter knows the program's)."""
        raise NotExpressible(f"the variable {v.space}:{v.key}")

    # ------------------------------------------------------------------ lists
    def arg(self, e: Any) -> str:
        """An element of an argument or index list: a name such as X or C1 stands bare there."""
        if isinstance(e, ir.Var) and e.space == "name" and not e.indices:
            return str(e.key)
        return self.expr(e)

    def args(self, args: list) -> str:
        sep = self.syntax.separator
        return sep.join(self.arg(a) for a in args).replace(sep + sep.strip(), sep.strip() * 2)

    # ------------------------------------------------------------------ what the table cannot say
    @rewrites(ir.Binary, "concat")
    def _concat(self, e: ir.Binary) -> tuple[str, int]:
        op = self.syntax.binary["concat"]
        if isinstance(e.left, ir.Str) and e.left.value == "":
            return op.text + self.expr(e.right, op.right), op.prec     # <<R1: a number as text
        return self.binary(e)

    @rewrites(ir.Binary, "pow")
    def _pow(self, e: ir.Binary) -> tuple[str, int]:
        return self.call(ir.Func("pow", [e.left, e.right])), self.syntax.atom

    def call(self, f: ir.Func) -> str:
        """A function call: neutral names from the table, the dialect's own names as written,
        and the lowerings of functions Sinumerik has not (FIX, FUP, general powers)."""
        name, a = f.name, f.args
        functions = self.syntax.functions
        wrap = self.syntax.wrap
        if name == "frame_chain":
            return ":".join(self.expr(x) for x in a)
        if name == "LIST":
            return wrap(",".join(self.arg(x) for x in a))
        if name == "pow":
            if len(a) == 2 and isinstance(a[1], ir.Num) and a[1].value == 2:
                return f"POT{wrap(self.expr(a[0]))}"
            if len(a) != 2:
                raise NotExpressible(f"POW with {len(a)} arguments")
            self.lowered("general power lowered to EXP(LN(a)*b) (valid for a > 0)", once="pow")
            times = self.syntax.binary["*"]
            inner = f"{functions['ln']}{wrap(self.expr(a[0]))}{times.text}{self.expr(a[1], times.right)}"
            return f"{functions['exp']}{wrap(inner)}"
        if name == "atan" and len(a) in (1, 2):
            second = self.expr(a[1]) if len(a) == 2 else "1"
            return f"{functions['atan2']}{wrap(self.expr(a[0]) + self.syntax.separator + second)}"
        if name == "fix":
            self.lowered("FIX lowered to TRUNC (rounds toward zero)", once="fix")
            return f"{functions['trunc']}{wrap(self.expr(a[0]))}"
        if name == "fup":
            x = self.expr(a[0], self.syntax.atom)
            self.lowered("FUP lowered to TRUNC arithmetic", once="fup")
            t = f"{functions['trunc']}{wrap(x)}"
            return f"({t}+({x}>{t})-({x}<{t}))"
        if name in functions:
            return f"{functions[name]}{wrap(self.args(a))}"
        if name.islower():
            raise NotExpressible(f"the function {name.upper()}")
        return f"{name}{wrap(self.args(a))}"       # a Sinumerik function or a user's


_BARE = SinumerikSpelling()


def format_expr(e: Any) -> str:
    """An IR expression in Sinumerik syntax (front-end metadata that must round-trip)."""
    return _BARE.expr(e)
