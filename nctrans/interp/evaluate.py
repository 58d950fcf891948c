"""Expressions and variables: IR expressions compiled once into closures, evaluated per run.

Values are floats, strings, bools, None (an ISO *vacant* variable) or UNKNOWN (a system value the
analysis cannot know, such as a probe result). Vacant follows Fanuc macro B: it counts as 0 in
arithmetic and ordering, is equal only to vacant, and a word whose value is vacant is as if it had
not been written (the interpreter drops it). Errors never raise out of the interpreter: the
closures raise EvalError, the interpreter turns it into a diagnostic at the statement's span.
"""
from __future__ import annotations

import math
from typing import Any, Callable, Optional

from nctrans.ir import nodes as n


class _Unknown:
    """A value unknown at analysis time (machine state, probe results). Absorbs arithmetic."""
    __slots__ = ()

    def __repr__(self) -> str:
        return "UNKNOWN"


UNKNOWN = _Unknown()


class EvalError(Exception):
    """A user-program error found while evaluating (rule code + message); never leaves interpret()."""

    def __init__(self, rule: str, message: str, severity: str = "error"):
        super().__init__(message)
        self.rule = rule
        self.message = message
        self.severity = severity


# Local ISO macro variables (#1..#33) live in the call frame; the rest are global.
LOCAL_NUM_MAX = 33

_TYPE_DEFAULTS = {"INT": 0, "REAL": 0.0, "BOOL": False, "CHAR": "", "STRING": "", "AXIS": "",
                  "FRAME": None}


class Scope:
    """One call level: ISO locals #1..#33, declared names, call arguments by letter."""
    __slots__ = ("num", "names", "args")

    def __init__(self, num: Optional[dict] = None, args: Optional[dict] = None):
        self.num: dict[int, Any] = {} if num is None else num
        self.names: dict[str, Any] = {}
        self.args: dict[str, Any] = args or {}


class Array:
    """A declared array (Sinumerik DEF REAL A[3,4]): bounds-checked element store."""
    __slots__ = ("dims", "data", "default")

    def __init__(self, dims: list[int], default: Any):
        self.dims = tuple(dims)
        self.data: dict[tuple, Any] = {}
        self.default = default

    def key(self, idx: tuple) -> tuple:
        if len(idx) != len(self.dims) or any(not 0 <= i < d for i, d in zip(idx, self.dims)):
            raise EvalError("NC105", f"array index {list(idx)} outside bounds {list(self.dims)}")
        return idx

    def get(self, idx: tuple) -> Any:
        return self.data.get(self.key(idx), self.default)

    def set(self, idx: tuple, value: Any) -> None:
        self.data[self.key(idx)] = value


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


def constant(expr: Any) -> Optional[float]:
    """The value of a literal number (or a signed one), else None: lets hot paths skip closures."""
    if type(expr) is n.Num:
        return float(expr.value)
    if type(expr) is n.Unary and type(expr.operand) is n.Num:
        if expr.op == "-":
            return -float(expr.operand.value)
        if expr.op == "+":
            return float(expr.operand.value)
    return None


_AXES = "XYZABC"
# system variable -> first ISO position number it mirrors (work / machine coordinates)
_AXIS_POSITION_VARS = {"$P_EP": 5001, "$AA_IW": 5001, "$P_AXN1": None, "$AA_IM": 5021, "$AA_MW": 5021}


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
        self.system: dict[Any, Callable[[], Any]] = {}
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
            try:
                return fn(a, b)
            except (OverflowError, ValueError) as ex:
                raise EvalError("NC106", f"arithmetic error in {op!r}: {ex}") from None

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
            if axis is not None:
                return lambda: self.read_axis_system(name, axis)
            return lambda: self.read_system(name, self._indices(fns) if fns else None)
        if space == "arg":
            key = str(var.key).upper()
            return lambda: self.scope.args.get(key)
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
            f = self.system.get(k)
            if f is not None:
                return f()
            self.unknown_used = True
            return UNKNOWN
        return None

    def write_num(self, k: int, value: Any) -> None:
        if k == 0:
            raise EvalError("NC105", "#0 is read-only")
        if k < 0:
            raise EvalError("NC105", f"variable #{k} does not exist")
        if k <= LOCAL_NUM_MAX:
            self.scope.num[k] = value
        else:
            self.num_globals[k] = value

    def _lookup_name(self, name: str):
        if name in self.scope.names:
            return self.scope.names
        if name in self.global_names:
            return self.global_names
        return None

    def read_name(self, name: str, idx: Optional[tuple]) -> Any:
        store = self._lookup_name(name)
        if store is None:
            raise EvalError("NC101", f"variable {name} is not defined")
        v = store[name]
        if isinstance(v, Array):
            if idx is None:
                raise EvalError("NC104", f"array {name} used without an index")
            return v.get(idx)
        return v

    def read_axis_system(self, name: str, axis: str) -> Any:
        """Axis-indexed position variables (Sinumerik $P_EP[Z], $AA_IW[X], $AA_IM[Y]) read the
        interpreter's current position, which it publishes as the ISO position numbers (#5001..
        work coordinates, #5021.. machine coordinates) in program units."""
        base = _AXIS_POSITION_VARS.get(name)
        f = self.system.get(base + _AXES.index(axis)) if base is not None and axis in _AXES else None
        if f is not None:
            return f()
        self.unknown_used = True
        return UNKNOWN

    def read_system(self, name: str, idx: Optional[tuple]) -> Any:
        f = self.system.get(name)
        if f is not None:
            return f()
        self.unknown_used = True
        return UNKNOWN

    def declare(self, decl: n.VarDecl) -> None:
        name = decl.name.upper()
        default = _TYPE_DEFAULTS.get(decl.type.upper(), 0.0)
        store = self.global_names if decl.scope != "local" else self.scope.names
        inits = [self.compile(e)() for e in (decl.init or [])]
        if decl.dims:
            arr = Array(decl.dims, default)
            # initialisers fill the array in row-major order
            if inits:
                flat = [()]
                for d in decl.dims:
                    flat = [p + (i,) for p in flat for i in range(d)]
                for key, v in zip(flat, inits):
                    arr.data[key] = v
            store[name] = arr
        else:
            store[name] = inits[0] if inits else default

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
                if isinstance(cur, Array):
                    if not fns:
                        raise EvalError("NC104", f"array {name} assigned without an index")
                    cur.set(self._indices(fns), v)
                else:
                    store[name] = v
            return set_name
        if space == "arg":
            key = str(var.key).upper()
            return lambda v: self.scope.args.__setitem__(key, v)
        if space == "system":
            name = str(var.key).upper()

            def set_sys(v):        # writable system data: kept so later reads see the value
                self.system[name] = lambda: v
            return set_sys
        return lambda v: (_ for _ in ()).throw(EvalError("NC104", f"cannot assign to {space}"))


def _concat(a: Any, b: Any) -> str:
    def s(v):
        if v is None:
            return ""
        if isinstance(v, float) and v.is_integer():
            return str(int(v))
        return str(v)
    return s(a) + s(b)
