"""The word list: what one cleaned block says, before any meaning is given to it.

Both readers of a block produce the same list, so the lowering (frontend.py) has one input:
- the lark grammar of record (grammars/iso-m.lark) for every block, built once per process;
- the fast path (fastpath.py) for plain address-word blocks, which are most of CAM output.

Items, in source order:
- ("X", value): an address word. value is the number's text as written (a str, sign included,
  e.g. "-1.5", "01", "54.1") when the word holds a plain number, else an IR expression.
- (",C", value) / (",R", value): chamfer / corner rounding word.
- ("=", Var, expr): assignment;  ("GOTO", target, None);  ("IFGOTO", cond, target);
  ("IFTHEN", cond, [("=", Var, expr), ...]);  ("WHILE", cond, "m");  ("END", "m", None);
  ("DO", "m", None).
"""
from __future__ import annotations

from typing import Any, Optional

from nctrans import resources
from nctrans.ir.nodes import Binary, Func, Num, Unary, Var

GRAMMAR_PATH = resources.path("grammars", "iso-m.lark")

_RELOPS = {"EQ": "==", "NE": "!=", "GT": ">", "GE": ">=", "LT": "<", "LE": "<="}


def _num_text(value: Any) -> Optional[str]:
    return value if isinstance(value, str) else None


def _as_expr(value: Any):
    """A word value as an IR expression (plain number texts become Num)."""
    if isinstance(value, str):
        return Num(float(value), value)
    return value


def _binary(op: str):
    def build(self, children):
        return Binary(op, _as_expr(children[0]), _as_expr(children[-1]))
    return build


def _make_transformer():
    from lark import Transformer

    class ToWords(Transformer):
        """Tree -> word list. Runs inline with the LALR parser (no tree is built)."""

        def start(self, items):
            return items

        def word(self, c):
            return (str(c[0]), c[1])

        def corner(self, c):
            return ("," + str(c[0]), c[1])

        def assign(self, c):
            return ("=", c[0], _as_expr(c[1]))

        def goto(self, c):
            return ("GOTO", c[0], None)

        def if_goto(self, c):
            return ("IFGOTO", _as_expr(c[0]), c[1])

        def if_then(self, c):
            return ("IFTHEN", _as_expr(c[0]), list(c[1:]))

        def while_do(self, c):
            return ("WHILE", _as_expr(c[0]), str(c[1]))

        def end_do(self, c):
            return ("END", str(c[0]), None)

        def do_loop(self, c):
            return ("DO", str(c[0]), None)

        def num(self, c):
            return str(c[0])

        def neg(self, c):
            v = c[0]
            if isinstance(v, str):                      # fold the sign into the literal, as written
                return "-" + v
            if isinstance(v, Num):
                return Num(-v.value, "-" + (v.text or repr(v.value)))
            return Unary("-", v)

        def pos(self, c):
            v = c[0]
            if isinstance(v, str):
                return "+" + v
            if isinstance(v, Num):
                return Num(v.value, "+" + (v.text or repr(v.value)))
            return Unary("+", v)

        add = _binary("+")
        sub = _binary("-")
        mul = _binary("*")
        div = _binary("/")
        or_ = _binary("or")
        xor = _binary("xor")
        and_ = _binary("and")
        mod = _binary("mod")

        def compare(self, c):
            return Binary(_RELOPS[str(c[1])], _as_expr(c[0]), _as_expr(c[2]))

        def func(self, c):
            return Func(str(c[0]).lower(), [_as_expr(a) for a in c[1:]])

        def atan(self, c):
            return Func("atan", [_as_expr(c[0])])

        def atan2(self, c):
            args = [x for x in c if not (hasattr(x, "type") and x.type == "ATAN_SEP")]
            return Func("atan2", [_as_expr(args[0]), _as_expr(args[1])])

        def var_num(self, c):
            text = str(c[0])
            return Var("num", int(float(text)))

        def var_ind(self, c):
            return Var("num", None, indices=[_as_expr(c[0])])

    return ToWords()


_parser = None


def parser():
    """The LALR parser of the grammar of record, built once per process (lark's cache keeps the
    compiled tables on disk between processes)."""
    global _parser
    if _parser is None:
        from lark import Lark

        from nctrans.lark_cache import cache_option
        _parser = Lark(GRAMMAR_PATH.read_text(encoding="utf-8"), parser="lalr", lexer="contextual",
                       transformer=_make_transformer(), cache=cache_option("iso-m"))
    return _parser


def lark_words(code: str) -> list:
    """Word list of a cleaned block by the grammar. Raises lark's UnexpectedInput on bad input."""
    return parser().parse(code)
