"""Evaluating a block's words: numeric values (vacant, unknown, out of range), axis words
pre-compiled into (axis, constant, closure, mode), scaled for inch and diameter programming, and
the program-coordinate target they name from the current point.

A mixin of Interpreter, used by every statement concern (motion, offsets, cycles, statements).
"""
from __future__ import annotations

from typing import Any, Callable, Optional

from nctrans.interp.evaluate import EvalError, UNKNOWN, constant
from nctrans.interp.state import LINEAR_AXES
from nctrans.ir import nodes as n

LENGTH_WORDS = LINEAR_AXES | frozenset("IJK")     # words converted by inch mode


class WordsMixin:
    """Word values and targets; no handlers of its own."""

    def _value(self, f, what: str) -> Optional[float]:
        """Evaluate a compiled expression that must be a number; None if vacant/unknown."""
        v = f()
        if v is None:
            return None
        if v is UNKNOWN:
            self.diag("NC107", "warning", f"{what} depends on a value unknown at analysis time; "
                      "the word is ignored")
            return None
        if isinstance(v, str):
            raise EvalError("NC104", f"string used as {what}")
        if not isinstance(v, (int, float)):      # a FRAME or an AXIS value ($P_PFRAME as X=)
            raise EvalError("NC104", f"{type(v).__name__.removesuffix('Value').lower()} value "
                            f"used as {what}")
        v = float(v)
        if v - v != 0.0:                 # infinity or NaN: never let it reach a record
            raise EvalError("NC108", f"{what} is {v} (out of range)")
        return v

    def _words(self, d: Optional[dict]) -> tuple:
        """Pre-compile axis words: (axis, constant|None, closure, mode)."""
        if not d:
            return ()
        out = []
        AV, Num = n.AxisValue, n.Num
        for axis, av in d.items():
            if type(av) is AV:
                expr, mode = av.value, av.mode
            else:
                expr, mode = av, None
            c = float(expr.value) if type(expr) is Num else constant(expr)
            if c is not None and c - c != 0.0:      # infinite/NaN constant: an error when it runs
                out.append((axis.upper(), None, _non_finite(axis, c), mode))
                continue
            if type(expr) is Num:
                out.append((axis.upper(), c, None, mode))
                continue
            out.append((axis.upper(), c, None if c is not None else self.ev.compile(expr), mode))
        return tuple(out)

    def _eval_words(self, words: tuple) -> list:
        """[(axis, value in mm/deg, mode)] with vacant words dropped."""
        scale = self.st.scale
        diameter = self.st.diameter
        out = []
        for axis, c, f, mode in words:
            if type(axis) is not str:
                axis = self._indirect_axis(axis())
            v = c if c is not None else self._value(f, f"{axis} word")
            if v is None:
                continue
            if axis in LENGTH_WORDS:
                v *= scale
            if diameter and axis == "X":        # the toolpath holds the radius (lathe.py)
                v *= 0.5
            out.append((axis, v, mode))
        return out

    @staticmethod
    def _indirect_axis(value: Any) -> str:
        """The axis of AX[expr]: an axis name (a DEF AXIS variable, $P_AXN3, X)."""
        if isinstance(value, str) and value.strip():
            return value.strip().upper()
        raise EvalError("NC104", f"AX[..] needs an axis name, not {value!r}")

    def _target(self, vals: list) -> dict[str, float]:
        """Program-coordinate target of evaluated words from the current point."""
        tgt = dict(self.pos)
        inc_default = self.st.incremental
        for axis, v, mode in vals:
            self.positioned.add(axis)
            cur = tgt.get(axis)
            if cur is None:
                cur = self._new_axis(axis)
                tgt[axis] = cur
            inc = inc_default if mode is None else mode == "inc"
            tgt[axis] = cur + v if inc else v
        return tgt

    def _new_axis(self, axis: str) -> float:
        """First use of an axis: it was at machine 0; add it to the machine and program points."""
        self.mpos = dict(self.mpos)
        self.mpos[axis] = 0.0
        self._resync()
        return self.pos[axis]


def _non_finite(axis: str, value: float) -> Callable[[], Any]:
    def fail():
        raise EvalError("NC108", f"{axis.upper()} word is {value} (out of range)")
    return fail
