"""Expressions and variables: IR expressions compiled once into closures, evaluated per run.

Values are floats, strings, bools, None (an ISO *vacant* variable) or UNKNOWN (a system value the
analysis cannot know, such as a probe result). Vacant follows Fanuc macro B: it counts as 0 in
arithmetic and ordering, is equal only to vacant, and a word whose value is vacant is as if it had
not been written (the interpreter drops it). Errors never raise out of the interpreter: the
closures raise EvalError, the interpreter turns it into a diagnostic at the statement's span.
"""
from __future__ import annotations

import math
import re
from typing import Any, Callable, Optional

from nctrans import limits
from nctrans.ir import nodes as n
from nctrans.ir.walk import literal
from nctrans.rules import system_meaning
from nctrans.interp import strings as _strings


class _Unknown:
    """A value unknown at analysis time (machine state, probe results). Absorbs arithmetic."""
    __slots__ = ()

    def __repr__(self) -> str:
        return "UNKNOWN"


UNKNOWN = _Unknown()
_MISSING = object()
_MISSING_KEY = object()      # no first subscript given to Evaluator._system_key


class EvalError(Exception):
    """A user-program error found while evaluating (rule code + message); never leaves interpret()."""

    def __init__(self, rule: str, message: str, severity: str = "error"):
        super().__init__(message)
        self.rule = rule
        self.message = message
        self.severity = severity


# Local ISO macro variables (#1..#33) live in the call frame; the rest are global.
LOCAL_NUM_MAX = 33

class AxisName(str):
    """An axis identifier used as a value (Sinumerik DEF AXIS A=(X), CTRANS(X,5), $AA_IM[A]): a
    string that compares with other axis names and serves as an axis index or address."""
    __slots__ = ()

    @property
    def geometry(self) -> str:
        """The axis letter a channel/machine axis name stands for (X1 -> X)."""
        return self.rstrip("0123456789")


# names that are axis identifiers when no variable of that name is declared
AXIS_NAME = re.compile(r"^(?:[XYZABCUVW][0-9]{0,2})$")


def check_limits(limits: Optional[tuple], value: Any) -> None:
    """`limits` (name, LLI, ULI) of a Sinumerik DEF: a value outside them is refused as the
    control refuses it (an alarm): NC223, and the variable keeps its value."""
    if limits is None:
        return
    name, lo, hi = limits
    if isinstance(value, (int, float)) and not isinstance(value, bool) and (
            (lo is not None and value < lo) or (hi is not None and value > hi)):
        raise EvalError("NC223", f"{value:g} assigned to {name} is outside its declared limits "
                        f"(LLI {'-' if lo is None else f'{lo:g}'}, ULI "
                        f"{'-' if hi is None else f'{hi:g}'}); the value is not taken")


class Ref:
    """A by-reference binding (Sinumerik PROC VAR parameter): reads and writes go to the caller's
    variable (a name, an R parameter, an ISO number or one array element), within its DEF limits."""
    __slots__ = ("store", "key", "array", "limits")

    def __init__(self, store: Any, key: Any, array: bool = False, limits: Optional[tuple] = None):
        self.store, self.key, self.array, self.limits = store, key, array, limits

    def get(self) -> Any:
        return self.store.get(self.key) if self.array else self.store.get(self.key, 0.0)

    def set(self, value: Any) -> None:
        if self.array:
            self.store.set(self.key, value)
        else:
            check_limits(self.limits, value)
            self.store[self.key] = value


class FrameValue:
    """A FRAME value (Sinumerik CTRANS(..):CROT(..), a FRAME variable, $P_PFRAME read back).

    steps, applied in order, each in the system the previous ones produce (M(F1:F2) = M(F1)·M(F2)):
    ("trans"|"rot"|"scale"|"mirror", {axis: value}) as the frame instructions TRANS/ROT/SCALE/
    MIRROR would take them, or ("state", snapshot) for a frame read back from the interpreter.
    No steps is the neutral frame."""
    __slots__ = ("steps",)

    def __init__(self, steps: tuple = ()):
        self.steps = tuple(steps)

    def __eq__(self, other: Any) -> bool:
        return isinstance(other, FrameValue) and self.steps == other.steps

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"FrameValue{self.steps!r}"


NEUTRAL_FRAME = FrameValue()

# frame constructors (Sinumerik spec 7.2) -> the frame instruction each step acts as
_FRAME_FUNCS = {"CTRANS": "trans", "CFINE": "trans", "CROT": "rot", "CSCALE": "scale",
                "CMIRROR": "mirror", "TRANS": "trans", "ROT": "rot", "SCALE": "scale",
                "MIRROR": "mirror"}

_TYPE_DEFAULTS = {"INT": 0, "REAL": 0.0, "BOOL": False, "CHAR": "", "STRING": "", "AXIS": "",
                  "FRAME": NEUTRAL_FRAME}


class Scope:
    """One call level: ISO locals #1..#33, declared names, call arguments by letter; programmed:
    the 1-based positions of the PROC parameters the call wrote (Sinumerik $P_SUBPAR), None at a
    level no parameter call opened."""
    __slots__ = ("num", "names", "args", "lengths", "programmed")

    def __init__(self, num: Optional[dict] = None, args: Optional[dict] = None):
        self.num: dict[int, Any] = {} if num is None else num
        self.names: dict[str, Any] = {}
        self.args: dict[str, Any] = args or {}
        self.lengths: dict[str, int] = {}     # declared STRING[n] lengths of `names`
        self.programmed: Optional[set[int]] = None


class Array:
    """A declared array (Sinumerik DEF REAL A[3,4]): bounds-checked element store; `limits`
    (name, LLI, ULI) of its DEF hold for every element."""
    __slots__ = ("dims", "data", "default", "limits")

    def __init__(self, dims: list[int], default: Any, limits: Optional[tuple] = None):
        self.dims = tuple(dims)
        self.data: dict[tuple, Any] = {}
        self.default = default
        self.limits = limits

    def key(self, idx: tuple) -> tuple:
        if len(idx) != len(self.dims) or any(not 0 <= i < d for i, d in zip(idx, self.dims)):
            raise EvalError("NC105", f"array index {list(idx)} outside bounds {list(self.dims)}")
        return idx

    def get(self, idx: tuple) -> Any:
        return self.data.get(self.key(idx), self.default)

    def set(self, idx: tuple, value: Any) -> None:
        key = self.key(idx)
        check_limits(self.limits, value)
        self.data[key] = value

    def keys_from(self, idx: tuple) -> list[tuple]:
        """Element keys in storage order (right index fastest) from `idx` to the end."""
        self.key(idx)
        keys: list[tuple] = [()]
        for d in self.dims:
            keys = [k + (i,) for k in keys for i in range(d)]
        return keys[keys.index(tuple(idx)):]


def _num(v: Any) -> Any:
    """Arithmetic operand: vacant counts as 0; bools as 0/1."""
    if v is None:
        return 0.0
    return v


def _check_str(v: Any, what: str) -> None:
    if isinstance(v, str):
        raise EvalError("NC104", f"string used in {what}")


def _div(a, b):
    if b == 0:
        raise EvalError("NC106", "division by zero")
    return a / b


def _intdiv(a, b):
    if b == 0:
        raise EvalError("NC106", "division by zero")
    return float(math.trunc(a / b))


def _mod(a, b):
    if b == 0:
        raise EvalError("NC106", "modulo by zero")
    return math.fmod(a, b)


def _pow(a, b):
    try:
        r = a ** b
    except (ZeroDivisionError, OverflowError):
        raise EvalError("NC106", f"{a} to the power {b} is undefined") from None
    if isinstance(r, complex):
        raise EvalError("NC106", f"{a} to the power {b} is not a real number")
    return r


def _eq(a, b):
    if a is None or b is None:
        return a is None and b is None
    return a == b


_ARITH: dict[str, Callable[[Any, Any], Any]] = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "/": _div, "div": _intdiv, "mod": _mod, "pow": _pow,
    "<": lambda a, b: a < b, "<=": lambda a, b: a <= b,
    ">": lambda a, b: a > b, ">=": lambda a, b: a >= b,
    "and": lambda a, b: bool(a) and bool(b), "or": lambda a, b: bool(a) or bool(b),
    "xor": lambda a, b: bool(a) != bool(b),
    "band": lambda a, b: float(int(a) & int(b)), "bor": lambda a, b: float(int(a) | int(b)),
    "bxor": lambda a, b: float(int(a) ^ int(b)),
}


def _sqrt(x):
    if x < 0:
        raise EvalError("NC106", f"square root of negative number {x}")
    return math.sqrt(x)


def _ln(x):
    if x <= 0:
        raise EvalError("NC106", f"logarithm of non-positive number {x}")
    return math.log(x)


def _asin(x):
    if not -1 <= x <= 1:
        raise EvalError("NC106", f"arc sine of {x} (outside -1..1)")
    return math.degrees(math.asin(x))


def _acos(x):
    if not -1 <= x <= 1:
        raise EvalError("NC106", f"arc cosine of {x} (outside -1..1)")
    return math.degrees(math.acos(x))


def _tan(x):
    c = math.cos(math.radians(x))
    if abs(c) < 1e-15:
        raise EvalError("NC106", f"tangent of {x} degrees is undefined")
    return math.tan(math.radians(x))


def _round(x, digits=None):
    if digits is not None:
        f = 10.0 ** int(digits)
        return math.copysign(math.floor(abs(x) * f + 0.5), x) / f
    return math.copysign(math.floor(abs(x) + 0.5), x)     # half away from zero


def _exp(x):
    try:
        return math.exp(x)
    except OverflowError:
        raise EvalError("NC106", f"exp({x}) overflows") from None


def _atan(*a):
    if len(a) == 2:
        return math.degrees(math.atan2(a[0], a[1]))
    return math.degrees(math.atan(a[0]))


_FUNCS: dict[str, Callable[..., Any]] = {
    "sin": lambda x: math.sin(math.radians(x)),
    "cos": lambda x: math.cos(math.radians(x)),
    "tan": _tan, "asin": _asin, "acos": _acos, "atan": _atan,
    "atan2": lambda y, x: math.degrees(math.atan2(y, x)),
    "sqrt": _sqrt, "abs": abs, "round": _round,
    "fix": lambda x: float(math.floor(x)) if x >= 0 else float(math.ceil(x)),
    "fup": lambda x: float(math.ceil(x)) if x >= 0 else float(math.floor(x)),
    "trunc": lambda x: float(math.trunc(x)),
    "ln": _ln, "exp": _exp, "pow": _pow,
    "minval": min, "maxval": max,
}


# The value of a literal number (or a signed one), else None: lets hot paths skip closures.
constant = literal


_AXES = "XYZABC"


def _axis_index(var: n.Var) -> Optional[str]:
    """The axis named as the only subscript of a system variable ($P_EP[Z]), else None."""
    if not var.indices or len(var.indices) != 1:
        return None
    ix = var.indices[0]
    if type(ix) is n.Var and ix.space == "name" and not ix.indices:
        key = str(ix.key).upper()
        if key in _AXES:
            return key
    return None


class Evaluator:
    """Variable stores plus the expression compiler. One per interpreter run.

    `system` maps $-names (upper case) and ISO system numbers (#1000+) to callables returning the
    current value (the interpreter registers position, tool, feed ...); anything else is UNKNOWN.
    """

    def __init__(self) -> None:
        self.scope = Scope()
        self.global_scope = self.scope
        self.num_globals: dict[int, Any] = {}
        self.R: dict[int, Any] = {}
        self.global_names: dict[str, Any] = {}
        # system variables by spelling (a name, or an int for a numbered one): filled from `meanings`
        # through the rules tables (rules.system_meaning) on first read, and by writes
        self.global_lengths: dict[str, int] = {}   # declared STRING[n] lengths of global_names
        self.limits: dict[str, tuple] = {}         # declared LLI/ULI of names (lower, upper)
        self.system: dict[Any, Callable[[], Any]] = {}
        # indexed system variables read with their subscripts ($P_GG[n]), by spelling
        self.indexed_system: dict[str, Callable[[tuple], Any]] = {}
        # neutral meaning (vocabulary.SYSTEM_VARIABLES, "<meaning>.<axis>" per axis) -> reader and
        # writer; the interpreter registers them
        self.meanings: dict[str, Callable[[], Any]] = {}
        self.meaning_setters: dict[str, Callable[[Any], None]] = {}
        # numbered system variables whose write changes machine data (ISO #2001 tool offsets,
        # #5221 work offsets): number -> writer (nctrans.interp.sysvars registers them)
        self.system_setters: dict[int, Callable[[Any], None]] = {}
        # frame variables whose components a program writes (Sinumerik $P_EXTFRAME[X,TR]=v):
        # name -> writer(indices as written, value) (nctrans.interp.settable_frames)
        self.frame_component_setters: dict[str, Callable[[list, Any], None]] = {}
        # indexed system data a program writes with an effect (Sinumerik settable frames
        # $P_UIFR[n,X,TR], tool edges $TC_DP3[t,d]): name -> writer(subscripts, value), the
        # subscripts evaluated (numbers as int, axis and component names as upper-case strings)
        self.system_writers: dict[str, Callable[[tuple, Any], None]] = {}
        # system variables written that nothing models: (name, subscripts) -> value, read back
        self.written_system: dict[tuple[str, tuple], Any] = {}
        # what a write to an unmodelled system variable is: "read_only" (NC228), "no_effect"
        # (stored quietly) or "unmodelled" (stored, NC237); set from the rules table (sysvars)
        self.write_policy: Callable[[str], str] = lambda name: "unmodelled"
        # told the name of a system variable read that nothing models (the interpreter says
        # NC236 at the line); None: reads stay quiet (tests that run the evaluator alone)
        self.on_unmodelled_read: Optional[Callable[[str], None]] = None
        # number ranges (first, last) a write refuses / a write leaves unknown (sysvars registers)
        self.read_only_numbers: tuple[tuple[int, int], ...] = ()
        # numbered variables from this number on are the control's system variables (ISO #1000..):
        # a write nothing models is said (NC237) unless the number is a plain common variable of
        # the program's control (a profile's common_variables, Haas #10000-#10999) or one the
        # rules table maps (common_numbers); None: none
        self.system_numbers_from: Optional[int] = None
        self.common_numbers: tuple[tuple[int, int], ...] = ()
        self.running_numbers: tuple[tuple[int, int], ...] = ()
        self.unknown_used = False     # set when UNKNOWN was read; the interpreter reports it

    # ---------------------------------------------------------------- compiler
    def compile(self, expr: Any) -> Callable[[], Any]:
        t = type(expr)
        if t is n.Num:
            v = float(expr.value)
            return lambda: v
        if t is n.Str:
            s = expr.value
            return lambda: s
        if t is n.Var:
            return self._compile_var(expr)
        if t is n.Unary:
            f = self.compile(expr.operand)
            op = expr.op
            if op == "-":
                def neg():
                    v = f()
                    if v is None:
                        return 0.0
                    if v is UNKNOWN:
                        return v
                    _check_str(v, "arithmetic")
                    return -v
                return neg
            if op == "+":
                return lambda: _num(f())
            if op == "not":
                return lambda: (UNKNOWN if (v := f()) is UNKNOWN else not v)
            if op == "bnot":
                return lambda: (UNKNOWN if (v := f()) is UNKNOWN else float(~int(_num(v))))
            return self._bad(f"unknown unary operator {op!r}")
        if t is n.Binary:
            return self._compile_binary(expr)
        if t is n.Func:
            return self._compile_func(expr)
        return self._bad(f"cannot evaluate {type(expr).__name__}")

    @staticmethod
    def _bad(msg: str) -> Callable[[], Any]:
        def f():
            raise EvalError("NC104", msg)
        return f

    def _compile_binary(self, e: n.Binary) -> Callable[[], Any]:
        fa, fb, op = self.compile(e.left), self.compile(e.right), e.op
        if op in ("==", "!="):
            want = op == "=="

            def cmp():
                a, b = fa(), fb()
                if a is UNKNOWN or b is UNKNOWN:
                    return UNKNOWN
                return _eq(a, b) == want
            return cmp
        if op == "concat":
            return lambda: _concat(fa(), fb())
        fn = _ARITH.get(op)
        if fn is None:
            return self._bad(f"unknown operator {op!r}")

        def slow(a, b):
            if a is UNKNOWN or b is UNKNOWN:
                return UNKNOWN
            if a is None:
                a = 0.0
            if b is None:
                b = 0.0
            if op == "+" and isinstance(a, str) and isinstance(b, str):
                return a + b
            if isinstance(a, str) or isinstance(b, str):
                if op in ("<", "<=", ">", ">=") and isinstance(a, str) and isinstance(b, str):
                    return fn(a, b)
                raise EvalError("NC104", f"string operand of {op!r}")
            if isinstance(a, FrameValue) or isinstance(b, FrameValue):
                raise EvalError("NC104", f"frame operand of {op!r} (frames chain with ':' only)")
            try:
                return fn(a, b)
            except (OverflowError, ValueError) as ex:
                raise EvalError("NC106", f"arithmetic error in {op!r}: {ex}") from None
            except TypeError:
                raise EvalError("NC104", f"operands of {op!r} have the wrong type") from None

        # fast paths: two floats (the normal case) skip the vacant/unknown/string checks
        if op == "+":
            def add():
                a, b = fa(), fb()
                if type(a) is float and type(b) is float:
                    return a + b
                return slow(a, b)
            return add
        if op == "-":
            def sub():
                a, b = fa(), fb()
                if type(a) is float and type(b) is float:
                    return a - b
                return slow(a, b)
            return sub
        if op == "*":
            def mul():
                a, b = fa(), fb()
                if type(a) is float and type(b) is float:
                    return a * b
                return slow(a, b)
            return mul

        def binop():
            a, b = fa(), fb()
            if type(a) is float and type(b) is float:
                try:
                    return fn(a, b)
                except (OverflowError, ValueError) as ex:
                    raise EvalError("NC106", f"arithmetic error in {op!r}: {ex}") from None
            return slow(a, b)
        return binop

    def _compile_func(self, e: n.Func) -> Callable[[], Any]:
        name = e.name.lower()
        fn = _FUNCS.get(name)
        if fn is None:
            if name == "frame_chain":
                return self._compile_chain(e)
            if e.name.upper() in _FRAME_FUNCS:
                return self._compile_frame(e)
            if e.name.upper() in ("SET", "REP"):
                return self._bad(f"{e.name.upper()}() initialises an array or array element only")
            if e.name.upper() in _strings.FUNCTIONS:
                return self._compile_string_func(e)
            if e.name.upper() == "INTERSEC":        # contour-table rows (seed 14.4)
                from nctrans.interp import contour_tables
                return contour_tables.compile_intersec(self, e)
            return self._bad(f"unknown function {e.name!r}")
        args = [self.compile(a) for a in e.args]

        if len(args) == 1:
            (f1,) = args

            def call1():
                v = f1()
                if type(v) is float:
                    try:
                        return fn(v)
                    except EvalError:
                        raise
                    except (TypeError, ValueError, OverflowError) as ex:
                        raise EvalError("NC106", f"{name}: {ex}") from None
                return call()
        else:
            call1 = None

        def call():
            vals = []
            for a in args:
                v = a()
                if v is UNKNOWN:
                    return UNKNOWN
                if v is None:
                    v = 0.0
                _check_str(v, f"function {name}")
                vals.append(v)
            try:
                return fn(*vals)
            except EvalError:
                raise
            except (TypeError, ValueError, OverflowError) as ex:
                raise EvalError("NC106", f"{name}: {ex}") from None
        return call1 or call

    def _compile_string_func(self, e: n.Func) -> Callable[[], Any]:
        """STRLEN, INDEX, SUBSTR ... (nctrans.interp.strings); AXSTRING(X) takes the axis name."""
        name = e.name.upper()
        fn = _strings.FUNCTIONS[name]
        args = []
        for a in e.args:
            if name == "AXSTRING" and type(a) is n.Var and a.space == "name" and not a.indices:
                args.append(self._axis_or_variable(a))
            else:
                args.append(self.compile(a))

        def call():
            vals = [a() for a in args]
            if any(v is UNKNOWN for v in vals):
                return UNKNOWN
            try:
                return fn(*vals)
            except TypeError:
                raise EvalError("NC104", f"{name}: wrong number of arguments") from None
            except ValueError as ex:
                raise EvalError("NC104", str(ex)) from None
        return call

    def _axis_or_variable(self, a: n.Var) -> Callable[[], Any]:
        """AXSTRING's argument: an AXIS variable's value (_A=AXNAME("Y")), else the axis name as
        written (AXSTRING(X), AXSTRING(SPINDLE1))."""
        read, key = self.compile(a), str(a.key)

        def value():
            if self._lookup_name(key.upper()) is None and self._lookup_name(key) is None:
                return key
            return read()
        return value

    # ---------------------------------------------------------------- frames
    def _compile_frame(self, e: n.Func) -> Callable[[], Any]:
        """CTRANS(X,5,Y,0) / CROT(Z,30) / CSCALE(X,2) / CMIRROR(X,Y): a one-step frame."""
        op = _FRAME_FUNCS[e.name.upper()]
        fns = [self.compile(a) for a in e.args]
        pairs = op != "mirror"
        fname = e.name.upper()

        def frame():
            vals = [f() for f in fns]
            if not vals:
                return NEUTRAL_FRAME
            if pairs and len(vals) % 2:
                raise EvalError("NC104", f"{fname} takes axis, value pairs")
            axes = vals[0::2] if pairs else vals
            out: dict[str, Any] = {}
            for i, ax in enumerate(axes):
                if not isinstance(ax, str) or not ax:
                    raise EvalError("NC104", f"{fname}: {ax!r} is not an axis name")
                key = AxisName(ax.upper()).geometry
                if pairs:
                    v = vals[2 * i + 1]
                    if v is UNKNOWN:
                        self.unknown_used = True
                        return UNKNOWN
                    if isinstance(v, str) or isinstance(v, FrameValue):
                        raise EvalError("NC104", f"{fname}: the value for {ax} is not a number")
                    out[key] = float(_num(v))
                else:
                    out[key] = 0.0
            return FrameValue(((op, tuple(out.items())),))
        return frame

    def _compile_chain(self, e: n.Func) -> Callable[[], Any]:
        """F1 : F2 : ... — the frames applied one after the other (spec 7.2)."""
        fns = [self.compile(a) for a in e.args]

        def chain():
            steps: list = []
            for f in fns:
                v = f()
                if v is UNKNOWN:
                    return UNKNOWN
                if not isinstance(v, FrameValue):
                    raise EvalError("NC104", "the ':' operator chains frames only")
                steps.extend(v.steps)
            return FrameValue(tuple(steps))
        return chain

    # ---------------------------------------------------------------- variables
    def _index_fns(self, var: n.Var) -> list[Callable[[], Any]]:
        return [self.compile(i) for i in (var.indices or [])]

    def _indices(self, fns) -> tuple:
        out = []
        for f in fns:
            v = f()
            if v is None or v is UNKNOWN or isinstance(v, str):
                raise EvalError("NC104", "array index is not a number")
            out.append(int(round(v)))
        return tuple(out)

    def _system_index_fns(self, var: n.Var) -> list[Callable[[], Any]]:
        """Subscripts of a system variable: a bare name that is no variable of the program is
        itself the subscript ($P_UIFR[1,X,TR], $AA_IW[X]): its upper-case name."""
        out = []
        for ix in var.indices or ():
            if type(ix) is n.Var and ix.space == "name" and not ix.indices:
                key = str(ix.key).upper()
                out.append(lambda key=key: (key if self._lookup_name(key) is None
                                            else self.read_name(key, None)))
            else:
                out.append(self.compile(ix))
        return out

    def _system_key(self, fns, first: Any = _MISSING_KEY) -> tuple:
        """The evaluated subscripts: numbers as int, axis names as their geometry axis, other
        names upper case; NC104 for a vacant or unknown subscript."""
        out = []
        for i, f in enumerate(fns):
            v = first if i == 0 and first is not _MISSING_KEY else f()
            if isinstance(v, AxisName):
                out.append(v.geometry)
            elif isinstance(v, str):
                out.append(v.upper())
            elif v is UNKNOWN:
                raise EvalError("NC107", "system variable index is not known to the analysis: the "
                                "variable is not read or written here", "warning")
            elif v is None or isinstance(v, FrameValue):
                raise EvalError("NC104", "system variable index is not a number or a name")
            else:
                out.append(int(round(v)))
        return tuple(out)

    def _num_key(self, var: n.Var, fns) -> int:
        if fns:
            (k,) = self._indices(fns[:1])
            return k
        if var.key is None:
            raise EvalError("NC104", "variable without a number")
        return int(var.key)

    def _compile_var(self, var: n.Var) -> Callable[[], Any]:
        space = var.space
        fns = self._index_fns(var)
        if space == "num":
            if not fns and isinstance(var.key, int):
                k = var.key
                if k == 0:
                    return lambda: None
                if 1 <= k <= LOCAL_NUM_MAX:
                    return lambda: self.scope.num.get(k)
                if k < 1000:
                    return lambda: self.num_globals.get(k)
            return lambda: self.read_num(self._num_key(var, fns))
        if space == "R":
            if not fns:
                k = int(var.key) if var.key is not None else 0
                return lambda: self.R.get(k, 0.0)
            return lambda: self.R.get(self._indices(fns)[0], 0.0)
        if space == "name":
            name = str(var.key).upper()
            return lambda: self.read_name(name, self._indices(fns) if fns else None)
        if space == "system":
            name = str(var.key).upper()
            axis = _axis_index(var)
            if axis is not None and name not in self.system_writers:
                return lambda: self.read_axis_system(name, axis)
            if not fns:
                return lambda: self.read_system(name, None)
            kfns = self._system_index_fns(var)
            if len(fns) == 1 and name not in self.system_writers:
                (f1,) = kfns

                def read_indexed():
                    ix = f1()
                    if isinstance(ix, str) and AXIS_NAME.match(ix):
                        ix = AxisName(ix)             # $AA_IM[X1]: an axis named as written
                    if isinstance(ix, AxisName):      # $AA_IM[AXNAME], AXNAME an AXIS variable
                        return self.read_axis_system(name, ix.geometry)
                    return self.read_system(name, self._system_key(kfns, ix))
                return read_indexed
            return lambda: self.read_system(name, self._system_key(kfns))
        if space == "arg":
            key = str(var.key).upper()
            return lambda: self.scope.args.get(key)
        if space == "local":
            key = str(var.key).upper()

            def read_local():
                v = self.scope.args.get(key, _MISSING)
                if v is _MISSING:
                    raise EvalError("NC101", f"local parameter {key} is read before it is assigned")
                return v
            return read_local
        return self._bad(f"unknown variable space {space!r}")

    def read_num(self, k: int) -> Any:
        if k == 0:
            return None
        if k < 0:
            raise EvalError("NC105", f"variable #{k} does not exist")
        if k <= LOCAL_NUM_MAX:
            return self.scope.num.get(k)
        if k in self.num_globals:
            return self.num_globals[k]
        if k >= 1000:
            f = self._system_reader(k)
            if f is not None:
                return f()
            self.unknown_used = True
            return UNKNOWN
        return None

    def _system_reader(self, key: Any) -> Optional[Callable[[], Any]]:
        """The reader of a system variable by its spelling, through its neutral meaning."""
        f = self.system.get(key)
        if f is None:
            meaning = system_meaning(key)
            f = self.meanings.get(meaning) if meaning is not None else None
            if f is not None:
                self.system[key] = f
        return f

    def _system_setter(self, name: str) -> Optional[Callable[[Any], None]]:
        """The writer of a writable system variable with an effect (the programmable frame)."""
        meaning = system_meaning(name)
        return self.meaning_setters.get(meaning) if meaning is not None else None

    def write_num(self, k: int, value: Any) -> None:
        if k == 0:
            raise EvalError("NC105", "#0 is read-only")
        if k < 0:
            raise EvalError("NC105", f"variable #{k} does not exist")
        if k <= LOCAL_NUM_MAX:
            self.scope.num[k] = value
        elif k in self.system_setters:
            self.system_setters[k](value)       # the machine data itself: later moves use it
        elif k >= 1000 and any(a <= k <= b for a, b in self.read_only_numbers):
            # kept as a plain variable, a later read would give the written value instead of
            # the position or modal state: the control refuses the write with an alarm
            raise EvalError("NC228", f"#{k} is a read-only system variable: the control refuses "
                            "the write with an alarm (write-protected variable); the analysis "
                            "goes on without it")
        elif k >= 1000 and any(a <= k <= b for a, b in self.running_numbers):
            self.num_globals.pop(k, None)       # a timer: set, it runs on; reads stay unknown
        else:
            self.num_globals[k] = value
            if self.system_numbers_from is not None and k >= self.system_numbers_from and \
                    not any(a <= k <= b for a, b in self.common_numbers):
                # kept for later reads; what the control does with it (an output, an offset of
                # the tool memory, a setting) is not modelled
                raise EvalError("NC237", f"write to system variable #{k} is not modelled: what it "
                                "changes on the control (an output, an offset, a setting) is not in "
                                "the analysed toolpath", "warning")

    def _lookup_name(self, name: str):
        if name in self.scope.names:
            return self.scope.names
        if name in self.global_names:
            return self.global_names
        return None

    def read_name(self, name: str, idx: Optional[tuple]) -> Any:
        store = self._lookup_name(name)
        if store is None:
            if idx is None and AXIS_NAME.match(name):
                return AxisName(name)          # an axis identifier as a value: CTRANS(X,..), =(X)
            raise EvalError("NC101", f"variable {name} is not defined")
        v = store[name]
        if type(v) is Ref:
            v = v.get()
        if isinstance(v, Array):
            if idx is None:
                raise EvalError("NC104", f"array {name} used without an index")
            return v.get(idx)
        return v

    def read_axis_system(self, name: str, axis: str) -> Any:
        """Axis-indexed position variables (a per-axis meaning read with an axis index, such as
        Sinumerik $AA_IW[X]) read the interpreter's current position of that axis."""
        meaning = system_meaning(name)
        f = self.meanings.get(f"{meaning}.{axis}") if meaning is not None and axis in _AXES else None
        if f is not None:
            return f()
        written = self.written_system.get((name, (axis,)), _MISSING)
        if written is not _MISSING:
            return written
        self.unknown_used = True
        if meaning is None and self.on_unmodelled_read is not None:
            self.on_unmodelled_read(name)
        return UNKNOWN

    def read_system(self, name: str, idx: Optional[tuple]) -> Any:
        if idx is not None:
            g = self.indexed_system.get(name)
            if g is not None:
                v = g(idx)
                if v is UNKNOWN:
                    self.unknown_used = True
                return v
        written = self.written_system.get((name, idx or ()), _MISSING)
        if written is not _MISSING:
            return written
        f = self._system_reader(name)
        if f is not None:
            return f()
        self.unknown_used = True
        if system_meaning(name) is None and self.on_unmodelled_read is not None:
            self.on_unmodelled_read(name)
        return UNKNOWN

    def declare(self, decl: n.VarDecl, scope: Optional[str] = None) -> None:
        """Run a DEF: `scope` overrides the declaration's own (preloaded GUD files are global)."""
        name = decl.name.upper()
        typ = decl.type.upper()
        default = _TYPE_DEFAULTS.get(typ, 0.0)
        store = self.global_names if (scope or decl.scope) != "local" else self.scope.names
        lengths = self.global_lengths if store is self.global_names else self.scope.lengths
        if decl.dims:
            elements = math.prod(decl.dims)
            if elements > limits.MAX_ARRAY_ELEMENTS:
                raise EvalError("NC109", f"array {name} of {elements} elements is larger than "
                                f"{limits.MAX_ARRAY_ELEMENTS}")
        if typ == "STRING":
            lengths[name] = min(decl.length or limits.MAX_STRING, limits.MAX_STRING)
        else:
            lengths.pop(name, None)
        init = decl.init or []
        rep = len(init) == 1 and type(init[0]) is n.Func and init[0].name.upper() == "REP"
        if rep:
            init = init[0].args[:1]
        inits = [self._typed(typ, self.compile(e)()) for e in init]
        refused: Optional[EvalError] = None     # an initial value outside LLI/ULI: not taken
        if decl.dims:
            arr = Array(decl.dims, default, (name, *decl.limits) if decl.limits else None)
            # initialisers fill the array in storage order (right index fastest); REP fills all
            if inits:
                keys = arr.keys_from((0,) * len(decl.dims))
                if rep:
                    keys, inits = keys, [inits[0]] * len(keys)
                elif len(inits) > len(keys):
                    raise EvalError("NC105", f"{len(inits)} initial values for the "
                                    f"{len(keys)} elements of {name}")
                for key, v in zip(keys, inits):
                    try:
                        arr.set(key, v)
                    except EvalError as err:
                        refused = refused or err
            store[name] = arr
        else:
            value = inits[0] if inits else default
            if decl.limits:
                self.limits[name] = tuple(decl.limits)
                try:
                    if inits:
                        self._check_limits(name, value)
                except EvalError as err:
                    refused, value = err, default
            else:
                self.limits.pop(name, None)
            store[name] = value
            if inits and typ == "STRING":
                self._cap_string(store, lengths, name, store[name])
        if refused is not None:
            raise refused

    def _check_limits(self, name: str, value: Any) -> None:
        """A value outside a name's declared LLI/ULI: NC223 (check_limits)."""
        check_limits((name, *self.limits[name]), value)

    @staticmethod
    def _cap_string(store: dict, lengths: dict, name: str, value: Any) -> None:
        """Keep a declared STRING[n] within its n characters: longer values are cut (NC109)."""
        cap = lengths.get(name)
        if cap is not None and isinstance(value, str) and len(value) > cap:
            store[name] = value[:cap]
            raise EvalError("NC109", f"string of {len(value)} characters assigned to {name}, "
                            f"declared STRING[{cap}]: cut to {cap} characters")
    @staticmethod
    def _typed(typ: str, v: Any) -> Any:
        """AXIS values are axis names (DEF AXIS A=(X) and DEF AXIS A="X" alike)."""
        if typ == "AXIS" and isinstance(v, str):
            return AxisName(v.upper())
        return v

    def make_ref(self, expr: Any) -> Any:
        """A by-reference argument (PROC VAR parameter): a Ref to the caller's variable, the array
        itself for a whole array, or the plain value when the argument is not a variable."""
        if type(expr) is n.Var:
            fns = self._index_fns(expr)
            if expr.space == "name":
                name = str(expr.key).upper()
                store = self._lookup_name(name)
                if store is not None:
                    cur = store[name]
                    if type(cur) is Ref and not fns:
                        return cur                       # passed on: same caller variable
                    if isinstance(cur, Array):
                        return Ref(cur, self._indices(fns), True) if fns else cur
                    if not fns:
                        lim = self.limits.get(name)
                        return Ref(store, name, limits=(name, *lim) if lim else None)
            elif expr.space == "R":
                k = self._indices(fns)[0] if fns else int(expr.key or 0)
                return Ref(self.R, k)
        return self.compile(expr)()

    def compile_assign(self, target: n.Var, value: Any) -> Callable[[], None]:
        """An assignment; A[i,j]=SET(a,b,..) writes consecutive elements from [i,j] on and
        A[i,j]=REP(v) every element from [i,j] to the end (spec 3.4); R[i]=SET(..) likewise."""
        kind = value.name.upper() if type(value) is n.Func else ""
        if kind not in ("SET", "REP") or not target.indices:
            put, f = self.compile_store(target), self.compile(value)
            return lambda: put(f())
        vals = [self.compile(a) for a in (value.args[:1] if kind == "REP" else value.args)]
        fns = self._index_fns(target)
        omitted = [type(a) is n.Num and a.text == "" for a in value.args]

        def fill():
            idx = self._indices(fns)
            if target.space == "R":
                if kind == "REP":
                    raise EvalError("NC104", "REP() fills arrays; R parameters have no end to fill to")
                keys = [(k,) for k in range(idx[0], idx[0] + len(vals))]
                arr = None
            else:
                store = self._lookup_name(str(target.key).upper()) if target.space == "name" else None
                arr = store[str(target.key).upper()] if store is not None else None
                if not isinstance(arr, Array):
                    raise EvalError("NC104", f"{kind}() assigned to {target.key}, which is not an array")
                keys = arr.keys_from(idx)
            if kind == "REP":
                v = vals[0]()
                for k in keys:
                    arr.set(k, v)
                return
            if len(vals) > len(keys):
                raise EvalError("NC105", f"SET() writes {len(vals)} values but {target.key} has "
                                f"{len(keys)} elements from {list(idx)}")
            for k, f, gap in zip(keys, vals, omitted):
                if gap:
                    continue                      # SET(1,,3): the gap keeps its element
                if arr is None:
                    self.R[k[0]] = f()
                else:
                    arr.set(k, f())
        return fill

    def compile_store(self, var: n.Var) -> Callable[[Any], None]:
        """A setter closure for an assignment target."""
        space = var.space
        fns = self._index_fns(var)
        if space == "num":
            return lambda v: self.write_num(self._num_key(var, fns), v)
        if space == "R":
            if not fns:
                k = int(var.key) if var.key is not None else 0
                return lambda v: self.R.__setitem__(k, v)
            return lambda v: self.R.__setitem__(self._indices(fns)[0], v)
        if space == "name":
            name = str(var.key).upper()

            def set_name(v):
                store = self._lookup_name(name)
                if store is None:
                    raise EvalError("NC101", f"variable {name} is not defined")
                cur = store[name]
                if type(cur) is Ref and not fns:
                    cur.set(v)
                elif isinstance(cur, Array):
                    if not fns:
                        raise EvalError("NC104", f"array {name} assigned without an index")
                    cur.set(self._indices(fns), v)
                else:
                    if name in self.limits:
                        self._check_limits(name, v)
                    store[name] = v
                    if type(v) is str and len(v) > 0:
                        lengths = (self.global_lengths if store is self.global_names
                                   else self.scope.lengths)
                        self._cap_string(store, lengths, name, v)
            return set_name
        if space in ("arg", "local"):       # a local parameter lives with the call's arguments
            key = str(var.key).upper()
            return lambda v: self.scope.args.__setitem__(key, v)
        if space == "system":
            name = str(var.key).upper()
            component = self.frame_component_setters.get(name)
            if component is not None and var.indices:
                return lambda v, ix=var.indices: component(ix, v)
            kfns = self._system_index_fns(var)

            def set_sys(v):
                writer = self.system_writers.get(name)
                if writer is not None:
                    writer(self._system_key(kfns), v)
                    return
                setter = self._system_setter(name)
                if setter is not None and fns:
                    # $P_PFRAME[X,TR]=25: component writes are not modelled; keep the frame
                    raise EvalError("NC237", f"{name}[..] component write is not modelled; the "
                                    "frame is kept as it was", "warning")
                if setter is not None:
                    setter(v)
                    return
                self._write_unmodelled(name, self._system_key(kfns) if kfns else (), v)
            return set_sys
        return lambda v: (_ for _ in ()).throw(EvalError("NC104", f"cannot assign to {space}"))


    def _write_unmodelled(self, name: str, key: tuple, v: Any) -> None:
        """A write to a system variable nothing models: refused when the control only lets it
        be read (NC228: later reads keep the machine's value), else kept for later reads, and
        reported unless the table says it has no effect on motion (NC237)."""
        policy = self.write_policy(name)
        if policy == "read_only":
            raise EvalError("NC228", f"{name} is a read-only system variable: the control refuses "
                            "the write with an alarm; the analysis goes on without it")
        self.written_system[(name, key)] = v
        if policy != "no_effect":
            raise EvalError("NC237", f"write to system variable {name} is not modelled: what it "
                            "changes on the control is not in the analysed toolpath", "warning")


def _concat(a: Any, b: Any) -> str:
    def s(v):
        if v is None:
            return ""
        if isinstance(v, float) and v.is_integer():
            return str(int(v))
        return str(v)
    out = s(a) + s(b)
    if len(out) > limits.MAX_STRING:
        raise EvalError("NC109", f"string of {len(out)} characters: longer than the "
                        f"{limits.MAX_STRING} a controller string holds")
    return out
