"""Which bare argument uses of an ISO macro are guarded by the macro's own vacancy test.

A macro written as a PROC cannot tell an argument left out from one passed as 0 except through
$P_SUBPAR, so an argument it uses as a whole value (`X#24`: ISO drops the word when #24 is vacant)
is checked on entry with an alarm (nctrans.lower.macro_procs). Where the macro already tests the
argument itself before every such use (`IF[#24EQ#0]GOTO8000` ... `G1 X#24`), that check would stop a
call the ISO macro handles in its own way: a false stop. This pass follows the macro's jumps,
IF/THEN and WHILE loops forward and keeps, at each point, the arguments every path to it has
shown to be passed; a bare use at a point where its argument is known passed needs no entry check.

What a branch shows (Fanuc macro B: vacant equals only vacant under EQ/NE, and reads as 0 in
every other operation): `#k EQ #0` false or `#k NE #0` true shows #k passed; a comparison of #k
with a constant (`#k LT 0.1`) shows it passed on the side where its value with #k = 0 is not the
outcome (a vacant #k would have gone the other way); AND / OR / NOT combine as usual. A path ends
at M99, M30 or an alarm (#3000: the control stops). An assignment to a candidate (a macro that
sets an argument it was passed, Renishaw O9810's #26=#26+..) makes it passed after it, unless it
assigns #0 (vacant again) or copies another candidate (passed where that one is). Anything the
pass does not follow (computed GOTO, structures ISO does not have) leaves every use unguarded.
"""
from __future__ import annotations

import operator
from typing import Optional

from nctrans.ir import nodes as ir

_RELATIONS = {"<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge,
              "==": operator.eq, "!=": operator.ne}
_MIRROR = {"<": ">", "<=": ">=", ">": "<", ">=": "<=", "==": "==", "!=": "!="}


class _GiveUp(Exception):
    """A construct the pass does not follow: every bare use stays unchecked-for (entry check)."""


def _number(label) -> Optional[int]:
    text = str(label or "").strip().lstrip("Nn")
    return int(text) if text.isdigit() else None


def _local(e, locals_: set[int]) -> Optional[int]:
    if type(e) is ir.Var and e.space == "num" and isinstance(e.key, int) and e.key in locals_:
        return e.key
    return None


def _vacant(e) -> bool:
    return type(e) is ir.Var and e.space == "num" and e.key == 0 and not e.indices


def _constant(e) -> Optional[float]:
    if type(e) is ir.Num:
        return e.value
    if type(e) is ir.Unary and e.op in ("-", "+") and type(e.operand) is ir.Num:
        return -e.operand.value if e.op == "-" else e.operand.value
    return None


def shows_passed(cond, outcome: bool, locals_: set[int]) -> set[int]:
    """The locals a condition with this outcome shows to be passed (not vacant)."""
    if type(cond) is ir.Unary and cond.op == "not":
        return shows_passed(cond.operand, not outcome, locals_)
    if type(cond) is not ir.Binary:
        return set()
    if cond.op in ("and", "or"):
        left = shows_passed(cond.left, outcome, locals_)
        right = shows_passed(cond.right, outcome, locals_)
        # AND true / OR false: both sides had that outcome; otherwise only what both sides show
        return left | right if (cond.op == "and") == outcome else left & right
    if cond.op not in _RELATIONS:
        return set()
    left, right, op = cond.left, cond.right, cond.op
    if _local(left, locals_) is None:
        left, right, op = right, left, _MIRROR[op]
    k = _local(left, locals_)
    if k is None:
        return set()
    if _vacant(right) and op in ("==", "!="):
        return {k} if (op == "!=") == outcome else set()
    c = _constant(right)
    if c is None:
        return set()
    if op in ("==", "!="):
        # vacant EQ c is false for every constant c (vacant equals only vacant)
        return {k} if (op == "==") == outcome else set()
    return {k} if _RELATIONS[op](0.0, c) != outcome else set()


class _Flow:
    """The macro's body as a list of steps with jumps, and a forward must-analysis over it."""

    def __init__(self, body: list, candidates: set[int], bare_of) -> None:
        self.candidates = candidates
        self.bare_of = bare_of    # (statement or condition, is a statement) -> candidates used bare
        self.steps: list[tuple] = []      # ("use", set) | ("jump", label|int, cond, outcome) | ("end",)
        self.labels: dict[object, int] = {}
        self._counter = 0
        self._lay(body)

    def _mark(self) -> object:
        self._counter += 1
        return ("internal", self._counter)

    def _place(self, label) -> None:
        self.labels.setdefault(label, len(self.steps))

    def _lay(self, nodes: list) -> None:
        for node in nodes:
            t = type(node)
            if t is ir.Block:
                number = _number(node.number)
                if number is not None:
                    self._place(number)
                for st in node.body:
                    used = self.bare_of(st, True)
                    if used:
                        self.steps.append(("use", used))
                    ts = type(st)
                    if ts is ir.Assign and not st.target.indices and \
                            _local(st.target, self.candidates) is not None:
                        self.steps.append(("set", st.target.key, st.value))
                    if ts is ir.Goto:
                        if st.computed is not None:
                            raise _GiveUp
                        target = _number(st.target)
                        if target is None:
                            raise _GiveUp
                        self.steps.append(("jump", target, st.cond))
                    elif ts in (ir.Return, ir.ProgramEnd, ir.Alarm):    # an alarm stops the control
                        self.steps.append(("end",))
            elif t is ir.If:
                used = self.bare_of(node.cond, False)
                if used:
                    self.steps.append(("use", used))
                other, done = self._mark(), self._mark()
                self.steps.append(("jump", other, ir.Unary("not", node.cond)))
                self._lay(node.then)
                self.steps.append(("jump", done, None))
                self._place(other)
                self._lay(node.orelse)
                self._place(done)
            elif t is ir.While:
                head, done = self._mark(), self._mark()
                self._place(head)
                used = self.bare_of(node.cond, False)
                if used:
                    self.steps.append(("use", used))
                self.steps.append(("jump", done, ir.Unary("not", node.cond)))
                self._lay(node.body)
                self.steps.append(("jump", head, None))
                self._place(done)
            else:
                raise _GiveUp

    def unguarded(self) -> set[int]:
        """The candidates used bare somewhere not every path has shown them passed."""
        n = len(self.steps)
        universe = frozenset(self.candidates)
        known: list[Optional[frozenset]] = [None] * (n + 1)     # None: not reached yet
        known[0] = frozenset()
        for step in self.steps:
            if step[0] == "jump" and step[1] not in self.labels:
                raise _GiveUp                                    # a jump out of the macro
        work = [0]
        while work:
            i = work.pop()
            state = known[i]
            if i >= n:
                continue
            step = self.steps[i]
            outs: list[tuple[int, frozenset]] = []
            if step[0] == "use":
                outs.append((i + 1, state))
            elif step[0] == "set":
                _, k, value = step
                source = _local(value, universe)
                passed = (not _vacant(value)) and (source is None or source in state)
                outs.append((i + 1, (state | {k}) if passed else (state - {k})))
            elif step[0] == "jump":
                _, target, cond = step
                to = self.labels[target]
                if cond is None:
                    outs.append((to, state))
                else:
                    outs.append((to, state | (shows_passed(cond, True, universe) & universe)))
                    outs.append((i + 1, state | (shows_passed(cond, False, universe) & universe)))
            for j, s in outs:
                merged = s if known[j] is None else known[j] & s
                if known[j] is None or merged != known[j]:
                    known[j] = merged
                    work.append(j)
        out: set[int] = set()
        for i, step in enumerate(self.steps):
            if step[0] == "use" and known[i] is not None:
                out |= step[1] - known[i]
        return out


def unguarded_bare(body: list, candidates: set[int], bare_of) -> set[int]:
    """Of the candidate arguments, those used bare at a point the macro has not shown them passed
    on every path to it; all candidates where the pass cannot follow the macro's flow. `bare_of`
    maps (a statement, True) or (a structure's condition, False) to the candidate locals it uses
    as a whole value."""
    if not candidates:
        return set()
    try:
        return _Flow(body, set(candidates), bare_of).unguarded()
    except _GiveUp:
        return set(candidates)
