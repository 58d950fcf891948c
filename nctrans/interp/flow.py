"""Program flow: compiling bodies into instructions (compiled.py), the run loop, jumps, and the
statements that end or redirect the run (GOTO, RET, M30/M99, M0/M1, alarms).

How it runs
- Each program or subprogram body is compiled once (cached per Subprogram) into a flat list of
  instructions with jumps, so GOTO to any block number or label works whatever the structure.
  A block's statements compile on its first execution into (handler, data) pairs: each concern
  module contributes the compilers of its statement types (Interpreter._compiler_table).
- A handler returns None, or a control tuple ("goto", ...), ("call", ...), ("return", ...),
  ("section", ...), ("pattern", ...), ("turning", ...) that _control applies; calls.py keeps the
  call stack.
- Records are built into a small buffer (`out`) per instruction and yielded at once (_release);
  nothing accumulates.
- A streamed main body (not a list) compiles STREAM_BATCH blocks at a time; runs of plain blocks
  in it go to the native lane (native.py).

A mixin of Interpreter.
"""
from __future__ import annotations

from contextvars import ContextVar
from typing import Any, Callable, Iterator, Optional

from nctrans.interp import contour_tables, corner_elements, unmodelled
from nctrans.interp.compiled import (BLOCK, CASE, EXEC, Frame, JFALSE, JUMP, MAX_CALL_DEPTH, PLAIN,
                                     Unit, _Stop, _plain_entry, label_key)
from nctrans.interp.compact_code import CompactCode
from nctrans.interp.cycles import unmodelled_cycle
from nctrans.interp.evaluate import EvalError, UNKNOWN
from nctrans.interp.native import KERNEL_BLOCKS
from nctrans.limits import MAX_COORDINATE
from nctrans.ir import nodes as n
from nctrans.plainrun import JsonChunk, PlainRun
from nctrans.toolpath import ToolpathRecord

# M99 in a main program restarts it on the control, for ever. A toolpath analyses one pass (NC205
# warning); `equiv` sets this so the program restarts as on the control (state kept, as a jump to
# its first block), within the step budget, and compares with a Sinumerik LOOP of the same body.
RESTART_MAIN: ContextVar[bool] = ContextVar("RESTART_MAIN", default=False)

STREAM_BATCH = 256          # blocks of a streamed main body compiled at a time


def _next_batch(stream: Iterator) -> list:
    """The next STREAM_BATCH items of a streamed body, or fewer: a batch ends with a PlainRun, so
    that the run is run before the front end is asked for more and the kernel, not scan(), finds
    where the run ends (see plainrun)."""
    batch: list = []
    for item in stream:
        batch.append(item)
        if type(item) is PlainRun or len(batch) >= STREAM_BATCH:
            break
    return batch


class FlowMixin:
    """Compile, run, jump, stop."""

    def _flow_table(self) -> dict:
        """Compilers of the statements that redirect or end the run."""
        return {
            n.Goto: self._c_goto, n.Return: lambda s: (self._h_return, s),
            n.ProgramEnd: lambda s: (self._h_end, s), n.Stop: lambda s: (self._h_stop, s),
            n.Alarm: lambda s: (self._h_alarm, s),
        }

    def unit_for(self, key: int, name: str, body: list, file: str, params: list) -> Unit:
        unit = self.units.get(key)
        if unit is None:
            unit = Unit(name, file, params)
            self._emit_nodes(body, unit)
            unit.seen = bytearray(len(unit.code))
            self.units[key] = unit
        return unit

    def _emit_nodes(self, nodes_: list, unit: Unit) -> None:
        code = unit.code
        for node in nodes_:
            t = type(node)
            if t is n.Block:
                # statements compile on first execution (see run): the first record of a huge
                # program comes after one cheap flattening pass, not a full compile
                pc = len(code)
                code.append((BLOCK, None, node, node.span))
                if node.number is not None and node.number != "":
                    unit.labels.setdefault(label_key(node.number), []).append(pc)
                if node.label:
                    unit.labels.setdefault(label_key(node.label), []).append(pc)
            elif t is PlainRun:
                if type(code) is list:
                    code.append(_plain_entry(node))
                else:                           # a compact body that jumps (compact_code)
                    code.add_run(node)
            elif t is n.If:
                j = len(code)
                code.append(None)
                self._emit_nodes(node.then, unit)
                if node.orelse:
                    k = len(code)
                    code.append(None)
                    code[j] = (JFALSE, self._cond(node.cond), len(code), node.span)
                    self._emit_nodes(node.orelse, unit)
                    code[k] = (JUMP, len(code), None, node.span)
                else:
                    code[j] = (JFALSE, self._cond(node.cond), len(code), node.span)
            elif t is n.While:
                top = len(code)
                code.append(None)
                self._emit_nodes(node.body, unit)
                code.append((JUMP, top, None, node.span))
                code[top] = (JFALSE, self._cond(node.cond), len(code), node.span)
                if node.label:
                    unit.labels.setdefault(label_key(node.label), []).append(top)
            elif t is n.Loop:
                top = len(code)
                self._emit_nodes(node.body, unit)
                code.append((JUMP, top, None, node.span))
            elif t is n.RepeatUntil:
                top = len(code)
                self._emit_nodes(node.body, unit)
                code.append((JFALSE, self._cond(node.cond), top, node.span))
            elif t is n.ForLoop:
                init, test, incr = self._for_parts(node)
                code.append((EXEC, init, None, node.span))
                top = len(code)
                code.append(None)
                self._emit_nodes(node.body, unit)
                code.append((EXEC, incr, None, node.span))
                code.append((JUMP, top, None, node.span))
                code[top] = (JFALSE, test, len(code), node.span)
            elif t is n.Case:
                subj = self.ev.compile(node.subject)
                branches = [(self.ev.compile(v), lab) for v, lab in node.branches]
                code.append((CASE, (subj, branches, node.default), None, node.span))

    def _compile_block(self, block: n.Block) -> list:
        out = []
        comp = self.compilers
        trigger = False
        for s in block.body:
            c = comp.get(type(s))
            if c is not None:
                if type(s) is n.Passthrough and (unmodelled.takes_motion(s) or corner_elements.kind_of(s)):
                    out.insert(0, c(s))      # it owns the block's axis words: before the motion
                    continue
                out.append(c(s))
            t = type(s)
            if (t is n.ModeChange and s.group == "motion" and s.value in ("rapid", "linear")) or \
                    t is n.Feed or t is n.SpindleSpeed:
                trigger = True
        if trigger:
            out.append((self._h_mcall_trigger, None))
        return out

    def _cond(self, expr) -> Callable[[], Any]:
        f = self.ev.compile(expr)

        def cond():
            v = f()
            if v is UNKNOWN:
                self.diag("NC107", "warning", "condition depends on a value unknown at analysis "
                          "time; taken as false")
                return False
            return bool(v) if v is not None else False
        return cond

    def _for_parts(self, node: n.ForLoop):
        ev = self.ev
        get = ev.compile(node.var)
        put = ev.compile_store(node.var)
        start, end = ev.compile(node.start), ev.compile(node.end)
        step = ev.compile(node.step) if node.step is not None else (lambda: 1.0)

        def init():
            put(start())

        def test():
            s, v, e = step(), get(), end()
            if UNKNOWN in (s, v, e):
                return False
            return (v or 0) <= (e or 0) if (s or 0) >= 0 else (v or 0) >= (e or 0)

        def incr():
            put((get() or 0) + (step() or 0))
        return init, test, incr

    def _c_goto(self, s: n.Goto):
        cond = None if s.cond is None else self._cond(s.cond)
        if s.computed is not None:
            return (self._h_goto, (self.ev.compile(s.computed), s.direction, cond))
        return (self._h_goto, (label_key(s.target), s.direction, cond))

    def _h_goto(self, d):
        target, direction, cond = d
        if cond is not None and not cond():
            return None
        if callable(target):             # ISO GOTO #2: the block number its value rounds to
            value = target()
            if isinstance(value, (int, float)) and value == value and abs(value) < 1e9:
                target = int(round(value))
            else:                        # reported as a target not found, and the run stops
                target = f"(computed block number {value})"
        return ("goto", target, direction)

    def _h_return(self, s: n.Return):
        return ("return", s.to_label)

    def _h_end(self, s: n.ProgramEnd):
        if s.kind == "restart" and self.stack:
            # M99 at the end of a file's main body that was called as a subprogram: a return
            return ("return", None)
        alone = getattr(self, "_macro_alone", False)     # a macro file run alone: M99 returns
        if s.kind == "restart" and not self.stack and RESTART_MAIN.get() and self._main is not None \
                and not alone:
            return ("restart",)
        self._comp_flush()
        self._record("stop", stop_kind="end")
        if s.kind == "restart" and not self.stack and not alone:
            self.diag("NC205", "warning", f"analysis truncated at line {self.span.line}: the "
                      "program restarts (return in a main program); one pass analysed")
        raise _Stop

    def _h_stop(self, s: n.Stop):
        self._record("stop", stop_kind="optional" if s.optional else "stop")

    def _h_alarm(self, s: n.Alarm):
        """Sinumerik SETAL(n), Fanuc #3000=n (message): the control stops with alarm n (NC221)."""
        try:
            num = "(no number)" if s.number is None else self.ev.compile(s.number)()
            text = None if s.text is None else self.ev.compile(s.text)()
        except EvalError:
            num, text = "?", None
        if isinstance(num, float) and num == int(num):
            num = int(num)
        if num is UNKNOWN:
            num = "(unknown number)"
        what = f": {text}" if isinstance(text, str) and text else ""
        self.alarm = (n.Num(float(num)) if isinstance(num, (int, float)) else s.number,
                      n.Str(text) if isinstance(text, str) and text else None, self.span, s.own_base)
        self.diag("NC221", "error", f"the program raises alarm {num}{what}; the control stops "
                  "here, so the analysis ends at this line")
        raise _Stop

    def run(self) -> Iterator[ToolpathRecord]:
        prog = self.program
        body = prog.body
        # A main body that is not a list is streamed (iso-m parse_stream: no jumps, no calls):
        # it is compiled a batch of blocks at a time, run, and the batch dropped, so memory does
        # not grow with the program. Labels are per batch (nothing jumps to them).
        stream = None
        if getattr(body, "jumps", False):
            # a compact body that may be jumped into: the whole parse's code, its runs' blocks
            # built as they run (compact_code)
            main = Unit(prog.name or "main", prog.file, [])
            main.code = CompactCode()       # type: ignore[assignment]
            self._emit_nodes(body.items, main)
            main.seen = bytearray(len(main.code))
            self.units[id(prog)] = main
        else:
            if type(body) is not list:
                stream = iter(body)
                body = []
            main = self.unit_for(id(prog), prog.name or "main", body, prog.file, [])
        self._main = main if stream is None else None      # a streamed body cannot restart
        from nctrans.interp.macro_alone import note_if_alone
        self._macro_alone = stream is None and note_if_alone(self)
        unit, code = main, main.code
        pc = sidx = 0
        steps = 0
        max_steps = self.max_steps
        # Records written by repeated execution for a flatten hook (what a lowering to plain
        # motion unrolls a loop into): a cycle repeated by a loop writes tens of blocks per step,
        # so the step budget alone would let an endless loop write for minutes.
        unrolled = 0
        max_unrolled = self.max_unrolled if self.hook is not None else None
        repeated = False
        out = self.out
        self._seq = 0
        diag = self.diag
        try:
            while True:
                if pc >= len(code):
                    if stream is not None and unit is main and not self.stack:
                        batch = _next_batch(stream)
                        if batch:
                            code.clear()
                            main.labels.clear()
                            if all(type(x) is n.Block for x in batch):
                                # straight blocks: no labels to index (nothing jumps)
                                code.extend([(BLOCK, None, x, x.span) for x in batch])
                            else:
                                self._emit_nodes(batch, main)
                            main.seen = bytearray(len(code))
                            pc = sidx = 0
                            continue
                        stream = None
                    # falling off the end of a body: implicit return / end of program
                    if not self.stack:
                        break
                    unit, code, pc, sidx = self._return(None)
                    continue
                ins = code[pc]
                op = ins[0]
                # The budget counts repeated execution (a block run again by a loop, a jump back
                # or a call, and every control instruction), never a straight-line block (or a
                # PlainRun of them, which only a streamed main body holds) running the first
                # time: a 30 M-block CAM program runs to its end, an endless loop stops.
                # Running out is an error: the analysis is incomplete.
                repeated = (op != BLOCK and op != PLAIN
                            or op == BLOCK and (ins[1] is not None or unit.seen[pc]))
                if repeated:
                    steps += 1
                    if steps > max_steps:
                        sp = ins[3]
                        diag("NC205", "error", f"analysis truncated at line {sp.line if sp else 0}: "
                             f"step budget of {max_steps} repeated steps (loop iterations, jumps "
                             "back, calls) exhausted", sp)
                        break
                if op == BLOCK:
                    self.span = ins[3]
                    stmts = ins[1]
                    if stmts is None:
                        # a block runs compiled; the compiled form is kept only once it runs a
                        # second time (loops, calls), so straight-line code adds no memory
                        stmts = self._compile_block(ins[2])
                        seen = unit.seen
                        if seen[pc]:
                            code[pc] = (BLOCK, stmts, ins[2], ins[3])
                        else:
                            seen[pc] = 1
                    ctl = None
                    if sidx == 0:
                        self.moved = False
                    nst = len(stmts)
                    while sidx < nst:
                        h, data = stmts[sidx]
                        sidx += 1
                        try:
                            ctl = h(data)
                        except EvalError as ex:
                            diag(ex.rule, ex.severity, ex.message)
                            ctl = None
                        if ctl is not None:
                            break
                    if ctl is None:
                        sidx = 0
                        pc += 1
                        if self.moved and self.modal_call is not None and not self.in_modal:
                            ctl = ("modal_call",)
                    if ctl is not None:
                        unit, code, pc, sidx = self._control(ctl, unit, pc, sidx)
                elif op == PLAIN:
                    self.span = ins[3]
                    done, rest = self._plain(ins[1], KERNEL_BLOCKS + 1)   # straight blocks: free
                    pc += 1
                    if rest:
                        # What the kernel left (Blocks, and the rest of the run) replaces what has
                        # run: runs only come in streamed main bodies, where nothing jumps back,
                        # so the batch stays short however long the run is.
                        code[:pc] = rest
                        pc = 0
                        unit.seen = bytearray(len(code))
                elif op == JUMP:
                    pc = ins[1]
                elif op == JFALSE:
                    self.span = ins[3]
                    try:
                        ok = ins[1]()
                    except EvalError as ex:
                        diag(ex.rule, ex.severity, ex.message)
                        ok = False
                    pc = pc + 1 if ok else ins[2]
                elif op == EXEC:
                    self.span = ins[3]
                    try:
                        ins[1]()
                    except EvalError as ex:
                        diag(ex.rule, ex.severity, ex.message)
                    pc += 1
                elif op == CASE:
                    self.span = ins[3]
                    subj, branches, default = ins[1]
                    target = default
                    try:
                        v = subj()
                        for f, lab in branches:
                            if f() == v:
                                target = lab
                                break
                    except EvalError as ex:
                        diag(ex.rule, ex.severity, ex.message)
                    pc += 1
                    if target is not None:
                        unit, code, pc, sidx = self._control(("goto", target, "forward"),
                                                             unit, pc - 1, 0)
                if out:
                    if repeated and max_unrolled is not None:
                        unrolled += len(out)
                        if unrolled > max_unrolled:
                            out.clear()
                            diag("NC205", "error", f"analysis truncated at line {self.span.line}: "
                                 f"budget of {max_unrolled:,} moves written by repeated execution "
                                 "(loop iterations, calls) when lowering to plain motion exhausted "
                                 "(NCTRANS_MAX_UNROLLED; an endless loop?)", self.span)
                            break
                    yield from self._release(out)
        except _Stop:
            pass
        try:
            contour_tables.unclosed(self)   # CONTPRON/CONTDCON whose EXECUTE never came
            corner_elements.finish(self)    # a move held for a corner element that never came
            self._comp_flush()
            yield from self._release(out)
        except _Stop:
            pass

    def _release(self, out: list) -> Iterator[ToolpathRecord]:
        """Number the records a block produced, show them to the flatten hook, and hand them on."""
        hook, hookq = self.hook, self._hookq
        for rec in out:
            if rec.__class__ is JsonChunk:
                self._seq += rec.count
                yield rec
                continue
            end = rec.end
            if end is not None and not _finite_point(end, rec.center):
                out.clear()
                self.diag("NC108", "error", f"a coordinate of this {rec.kind} move is out of range "
                          f"(infinite, not a number, or beyond {MAX_COORDINATE:g}): {end}; the analysis stops here",
                          n.Span(rec.file, rec.line, 1))
                raise _Stop()
            self._seq += 1
            rec.seq = self._seq
            if hook is not None:
                w = hookq.popleft() if hookq else None
                hook(rec, *(w or (None, None)))
            yield rec
        out.clear()

    def _control(self, ctl, unit, pc, sidx):
        """Apply a control result from a statement: goto, call, return."""
        kind = ctl[0]
        if kind == "turning":
            try:
                return self._turning_control(ctl[1], unit, pc, sidx)
            except EvalError as ex:         # a parameter that cannot be evaluated (SQRT(-1))
                self.diag(ex.rule, ex.severity, f"{ex.message}; the cycle is skipped and moves nothing "
                          "in the analysed toolpath")
                return unit, unit.code, pc, sidx
        if kind == "restart":
            return self._main, self._main.code, 0, 0
        if kind == "goto":
            target = self._find_label(unit, ctl[1], ctl[2], pc)
            if target is None and self.stack and self.stack[-1].section:
                self.diag("NC222", "error", f"jump to {ctl[1]} out of a repeated program section "
                          "is not modelled; the repetition ends here")
                self.stack[-1].repeats = 0
                return self._return(None)
            if target is None:
                self.diag("NC102", "error", f"jump target {ctl[1]} not found")
                if self.stack:
                    return self._return(None)
                raise _Stop
            return unit, unit.code, target, 0
        if kind == "return":
            if not self.stack:
                # M17/RET in the main body of a program run on its own ends it, as M30 does (seed
                # 840D: a main program's M2/M30 is read as M17 when it is called; the reverse here)
                self._comp_flush()
                self._record("stop", stop_kind="end")
                raise _Stop
            while self.stack[-1].section:          # RET inside a repeated section ends the call
                self.stack[-1].repeats = 0
                self._return(None)
                if not self.stack:
                    raise _Stop
            return self._return(ctl[1])
        if kind == "section":
            return self._section(ctl[1], ctl[2], unit, pc, sidx)
        if kind in ("call", "modal_call"):
            if kind == "call":
                s = ctl[1]
                args = None
            else:
                s, args, _ = self.modal_call
            if not s.name:                  # M98 P#144, CALL PROGNAME: named as the call runs
                s = self._computed_call(s)
                if s is None:
                    return unit, unit.code, pc, sidx
            callee = self._find_unit(s.name)
            if callee is None:
                what = unmodelled_cycle(s.name)
                if what is not None and not what.moves:
                    return unit, unit.code, pc, sidx      # settings only (CYCLE832): no path effect
                if what is not None:
                    self.diag("NC103", "warning", f"{s.name} ({what.meaning}) is a standard "
                              f"cycle nctrans does not model, and no {s.name} PROC was found "
                              "beside the program or on the search path: the call is skipped and "
                              "moves nothing in the analysed toolpath")
                    return unit, unit.code, pc, sidx
                self.diag("NC103", "warning", f"subprogram {s.name} not found; the call is skipped")
                self._opaque_call(s)
                return unit, unit.code, pc, sidx
            if len(self.stack) >= MAX_CALL_DEPTH:
                self.diag("NC105", "error", f"subprogram calls nested deeper than "
                          f"{MAX_CALL_DEPTH}; call of {s.name} skipped")
                return unit, unit.code, pc, sidx
            try:
                if args is None:
                    args = self._call_args(s, callee.params)
                rep = 1
                if s.repeat is not None:
                    r = self._value(self.ev.compile(s.repeat), "repeat count")
                    rep = 1 if r is None else int(round(r))
            except EvalError as ex:
                self.diag(ex.rule, ex.severity, ex.message)
                return unit, unit.code, pc, sidx
            if rep < 1:
                return unit, unit.code, pc, sidx
            make = self._make_scope(s, callee, args)
            saved = self._save_state() if callee.save else None
            modal = kind == "modal_call"
            self.stack.append(Frame(unit, pc, sidx, self.ev.scope, callee, rep - 1, make,
                                    modal=modal, saved=saved))
            self.in_modal += modal
            self.ev.scope = make()
            return callee, callee.code, 0, 0
        if kind == "pattern":
            scope = self.ev.scope
            self.stack.append(Frame(unit, pc, sidx, scope, ctl[1], 0, lambda: scope, section=True))
            self.sections += 1
            return ctl[1], ctl[1].code, 0, 0
        return unit, unit.code, pc, sidx

    @staticmethod
    def _find_label(unit: Unit, target, direction: str, pc: int) -> Optional[int]:
        pcs = unit.labels.get(target if type(target) is int else label_key(target))
        if not pcs:
            return None
        if direction in ("forward", "any"):
            for p in pcs:
                if p > pc:
                    return p
            if direction == "forward":
                return None
        best = None
        for p in pcs:
            if p <= pc:
                best = p
        if best is None and direction == "any":
            return pcs[0]
        return best


def _finite_point(end: dict, center: Optional[dict]) -> bool:
    """No infinity or NaN in a record's end point or centre, and no coordinate beyond
    limits.MAX_COORDINATE (squared or summed by every consumer, 1e300 overflowed them)."""
    for point in (end, center):
        if point:
            t = sum(point.values())
            if t - t != 0.0 or max(point.values()) > MAX_COORDINATE or min(point.values()) < -MAX_COORDINATE:
                return False
    return True
