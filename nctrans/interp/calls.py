"""Subprogram calls and the call stack: finding a callee (in the program, or through the resolver),
argument binding and parameter scopes, modal calls (MCALL, G66), repeated program sections
(REPEAT), SAVE subprograms (modal state restored on return), and calls nothing defines.

Calls keep an explicit stack of frames (compiled.Frame; no Python recursion), so the loop in
flow.py stays one generator. A mixin of Interpreter.
"""
from __future__ import annotations

import re
from typing import Callable, Optional

from nctrans.interp import contour_tables, sections
from nctrans.interp.compiled import (Frame, JFALSE, JUMP, MAX_CALL_DEPTH, Unit, label_key,
                                     program_key)
from nctrans.interp.evaluate import EvalError, Scope
from nctrans.interp.offsets import copy_frame
from nctrans.ir import nodes as n

SHARED_SCOPE_CALLS = frozenset(("m98", "m97", "shared"))   # m97: Haas local subprogram

# Modal groups a SAVE subprogram does not restore: not G codes (spindle, coolant, tool length),
# or state whose restoring mid-path would need its own approach (cutter compensation, cycles).
NOT_SAVED_GROUPS = frozenset(("spindle", "coolant", "tool_length", "cutter_comp", "cycle"))
# the state a SAVE subprogram's return restores besides the groups themselves: every attribute the
# saved G groups set (group 29 DIAMON/DIAMOF too, seed L4386 "the modal G functions", L24279-24281)
SAVED_ATTRS = ("motion", "plane", "incremental", "arc_absolute", "scale", "feed_scale", "feed_mode",
               "work_offset", "cycle_retract", "polar", "diameter")


class CallsMixin:
    """Calls, returns, sections and the stack."""

    def _calls_table(self) -> dict:
        """Compilers of calls, modal-call cancel and program-section repeats."""
        return {
            n.SubCall: lambda s: (self._h_call, s),
            n.ModalCallOff: lambda s: (self._h_modal_off, s),
            n.SectionRepeat: lambda s: (self._h_section, (s, None if s.count is None
                                                          else self.ev.compile(s.count))),
        }

    def _index_subprograms(self, program: n.Program) -> None:
        for name, sub in (program.subprograms or {}).items():
            self.sub_index.setdefault(program_key(name), (sub, program.file))
            self.sub_index.setdefault(program_key(sub.name), (sub, program.file))

    def _h_mcall_trigger(self, _):
        """Sinumerik MCALL also calls after a block without path motion that programs G0/G1, or S
        or F while G0/G1 is active (seed L5076-5080); ISO G66 calls after moves only."""
        mc = self.modal_call
        if mc is not None and mc[0].kind == "mcall" and self.st.motion in ("rapid", "linear"):
            self.moved = True

    def _h_call(self, s: n.SubCall):
        what = self.contour_procs.get(s.name.upper()) if s.name and self.contour_procs else None
        if what and s.modal == "none" and s.target is None:     # CONTPRON, EXECUTE .. (seed 14)
            contour_tables.run_call(self, s, what)
            return None
        if s.modal == "after_move":
            self.modal_call = (s, self._call_args(s), self._depth())
            return None
        return ("call", s)

    def _depth(self) -> int:
        """The call level (a repeated section is not one: MCALL still calls in it)."""
        return len(self.stack) - self.sections

    def _h_section(self, d):
        s, count = d
        rep = 1
        if count is not None:
            r = self._value(count, "repeat count P")
            rep = 1 if r is None else int(round(r))
        return ("section", s, rep) if rep >= 1 else None

    def _section(self, s: n.SectionRepeat, rep: int, unit: Unit, pc: int, sidx: int):
        """Run a program section again `rep` times (nctrans.interp.sections), then resume after
        the REPEAT statement at (pc, sidx)."""
        first, last, problem = sections.section_bounds(s, unit.labels, label_key, pc)
        key = ("section", id(unit), first, last)
        callee = self.units.get(key)
        if callee is None and not problem:
            code, labels, problem = sections.section_code(unit.code, unit.labels, first, last,
                                                          (JUMP, JFALSE))
            if not problem:
                callee = Unit(unit.name, unit.file, unit.params)
                callee.code, callee.labels = code, labels
                callee.seen = bytearray(len(code))
                self.units[key] = callee
        if problem:
            self.diag("NC222", "error", f"{'REPEATB' if s.line_only else 'REPEAT'}: {problem}; "
                      "the repetition is skipped")
            return unit, unit.code, pc, sidx
        if len(self.stack) >= MAX_CALL_DEPTH:
            self.diag("NC105", "error", f"calls and repeated sections nested deeper than "
                      f"{MAX_CALL_DEPTH}; REPEAT {s.start} skipped")
            return unit, unit.code, pc, sidx
        scope = self.ev.scope
        self.stack.append(Frame(unit, pc, sidx, scope, callee, rep - 1, lambda: scope,
                                section=True))
        self.sections += 1
        return callee, callee.code, 0, 0

    def _h_modal_off(self, s):
        self.modal_call = None
        self.modal_cycle = None

    def _call_args(self, s: n.SubCall, params: Optional[list] = None) -> tuple[list, dict]:
        """Argument values; a VAR (by_ref) parameter of the callee gets a reference instead."""
        byref = [bool(getattr(p, "by_ref", False)) for p in params or ()]
        ev = self.ev
        pos = [ev.make_ref(e) if i < len(byref) and byref[i] else ev.compile(e)()
               for i, e in enumerate(s.args)]
        named = {k.upper(): self.ev.compile(e)() for k, e in s.named_args.items()}
        # ISO-style call arguments are in program units; they are passed as written
        return pos, named

    def _find_unit(self, name: str) -> Optional[Unit]:
        key = program_key(name)
        hit = self.sub_index.get(key)
        if hit is None and self.resolver is not None:
            if key not in self._resolved:
                from_file = self.span.file if self.span else self.program.file
                try:
                    prog = self.resolver(name, from_file)
                except Exception as ex:   # a resolver bug must not end the analysis
                    self.diag("NC103", "warning", f"cannot load subprogram {name}: {ex}")
                    prog = None
                self._resolved[key] = prog
                if prog is not None and prog.meta.get("parse_errors"):
                    count, first = prog.meta["parse_errors"]
                    self.diag("NC129", "warning", f"the file of {name}, {prog.file}, has {count} "
                              f"syntax error{'s' if count > 1 else ''} (first: {first}): what did "
                              "not parse is left out of the call's path; lint that file")
                if prog is not None:
                    self._index_subprograms(prog)
                    if key not in self.sub_index:
                        sub = n.Subprogram(name, n.Span(prog.file, 1), prog.body)
                        self.sub_index[key] = (sub, prog.file)
            hit = self.sub_index.get(key)
        if hit is None:
            return None
        sub, file = hit
        unit = self.unit_for(id(sub), sub.name, sub.body, file, sub.params)
        unit.save = any(str(a).upper() == "SAVE" for a in (sub.attrs or ()))
        return unit

    def _make_scope(self, s: n.SubCall, unit: Unit, args: tuple) -> Callable[[], Scope]:
        pos, named = args
        # calls that open no parameter level of their own: ISO M98, and "shared" (Fagor LL, L,
        # #CALL), which shares the caller's named locals too
        share = s.kind in SHARED_SCOPE_CALLS and not pos and not named
        caller = self.ev.scope

        def make():
            sc = Scope(num=caller.num if share else None, args=dict(named))
            if share and s.kind == "shared":
                sc.names, sc.args = caller.names, caller.args
            for p, v in zip(unit.params, pos):
                sc.names[p.name.upper()] = v
            if unit.params:                        # which parameters the call wrote ($P_SUBPAR)
                sc.programmed = {i + 1 for i, e in enumerate(s.args[:len(unit.params)])
                                 if not (type(e) is n.Num and e.text == "")}
            for p in unit.params[len(pos):]:       # not programmed in the call: preset to zero (seed
                if not p.by_ref and not p.dims:    # "Incomplete parameter transfer")
                    sc.names.setdefault(p.name.upper(), "" if p.type.upper().startswith("STRING") else 0)
            for k, v in named.items():
                var = s.bindings.get(k)
                if var is None:
                    continue
                if var.space == "num" and isinstance(var.key, int):
                    sc.num[var.key] = v
                elif var.space in ("name", "arg", "local"):
                    (sc.names if var.space == "name" else sc.args)[str(var.key).upper()] = v
                elif var.space == "R" and isinstance(var.key, int):
                    self.ev.R[var.key] = v
            return sc
        return make

    def _computed_call(self, s: n.SubCall) -> Optional[n.SubCall]:
        """The call with its program named by the value computed now: ISO `M98 P#144` (the
        number in named_args["P"]: program O<n>) or Sinumerik `CALL PROGNAME` (the string's last
        path part without _N_ and _SPF: "/_N_WCS_DIR/_N_PART1_SPF" -> PART1). None, said at the
        line, when the name cannot be known; the call is then skipped."""
        import dataclasses
        try:
            if s.target is not None:
                raw = self.ev.compile(s.target)()
                if not isinstance(raw, str) or not raw.strip():
                    raise EvalError("NC107", "the called program's name is not a string known to "
                                    "the analysis", "warning")
                name = re.sub(r"^_N_|_(?:SPF|MPF)$", "", raw.strip().rsplit("/", 1)[-1].upper())
                return dataclasses.replace(s, name=name, target=None)
            p = s.named_args.get("P")
            v = self._value(self.ev.compile(p), "program number P") if p is not None else None
            if v is None:
                raise EvalError("NC107", "the called program's number is not known to the "
                                "analysis", "warning")
            if v != int(v) or v < 0:
                raise EvalError("NC105", f"program number P{v:g} is not a program number")
            rest = {k: e for k, e in s.named_args.items() if k != "P"}
            return dataclasses.replace(s, name=f"O{int(v)}", named_args=rest)
        except EvalError as ex:
            self.diag(ex.rule, ex.severity, f"{ex.message}; the call is skipped")
            return None

    def _opaque_call(self, s: n.SubCall) -> None:
        """A call nothing here defines: a "call" record (name, evaluated arguments in the order
        nctrans.calls.call_arguments gives; a string as its string number), so a conversion that
        keeps the call can be compared with its source."""
        from nctrans.calls import SPILLED_AFTER, by_reference, call_arguments, string_number
        values = []
        declared = ((self.program.meta or {}).get("extern_params") or {}).get(str(s.name).upper())
        by_ref = by_reference(declared, len(s.args)) or [self._whole_array(e) for e in s.args]
        for i, e in enumerate(call_arguments(s)):
            if i < len(by_ref) and by_ref[i]:
                continue                        # passed in memory, not as a value (nctrans.calls)
            if e is None or (type(e) is n.Num and e.text == ""):
                values.append(None)             # an omitted argument
                continue
            try:
                raw = self.ev.compile(e)()
                if isinstance(raw, str):        # passed as its string number (nctrans.calls)
                    values.append(float(string_number(raw)))
                else:
                    values.append(self._value(lambda: raw, "call argument"))
            except EvalError:
                values.append(None)
        if s.named_args and not s.args and len(values) >= SPILLED_AFTER and values[SPILLED_AFTER - 1] is not None:
            values = self._with_spilled(values)     # all 18 letters used: more may be spilled
        self._record("call", call=s.name, args=values)

    def _whole_array(self, e) -> bool:
        """A call argument naming a whole array (passed by reference wherever it is passed)."""
        if type(e) is not n.Var or e.space != "name" or e.indices:
            return False
        try:
            from nctrans.interp.evaluate import Array
            return isinstance(self.ev.make_ref(e), Array)
        except EvalError:
            return False

    def _with_spilled(self, values: list) -> list:
        """A G65 of a converted program passes the parameters past its 18 letters in the spill
        slots #[#149+150].. (nctrans.dialects.iso_m.plan), ending at a vacant slot: they follow the
        letters in the call event, so it shows every argument the source call had."""
        from nctrans.calls import SPILLED_AFTER
        read = self.ev.read_num
        try:
            pointer = read(149)
            base = 150 + int(pointer if isinstance(pointer, float) else 0)
        except (EvalError, ValueError, OverflowError):
            return values
        spilled = []
        for k in range(base, 200):
            v = read(k)
            if not isinstance(v, float):
                break
            spilled.append(v)
        if not spilled:
            return values
        return values[:SPILLED_AFTER] + [None] * (SPILLED_AFTER - len(values)) + spilled

    def _return(self, to_label):
        fr = self.stack[-1]
        if fr.repeats > 0 and to_label is None:
            fr.repeats -= 1
            self.ev.scope = fr.make_scope()
            return fr.callee, fr.callee.code, 0, 0
        self.stack.pop()
        self.moved = False       # the caller's block resumes after the call: no motion of its own
        if self.contour_table is not None:  # CONTPRON/CONTDCON in the callee, no EXECUTE there
            contour_tables.left_by_return(self)
        if fr.section:
            self.sections -= 1
        if fr.modal:
            self.in_modal -= 1
        self.ev.scope = fr.scope
        if fr.saved is not None:
            self._restore_state(fr.saved)
        unit, pc, sidx = fr.unit, fr.pc, fr.sidx
        if to_label is not None:
            target = self._find_label(unit, to_label, "any", pc)
            if target is None:
                self.diag("NC102", "error", f"return target {to_label} not found in the caller")
            else:
                return unit, unit.code, target, 0
        return unit, unit.code, pc, sidx

    def _save_state(self) -> tuple:
        st = self.st
        return (dict(st.groups), {a: getattr(st, a) for a in SAVED_ATTRS}, st.feed,
                copy_frame(self.frame))

    def _restore_state(self, saved: tuple) -> None:
        """Return from a SAVE subprogram (spec 1.6): the modal G codes, the settable and the
        programmable frame as at the call; F too when the feed type (G group 15) changed."""
        groups, attrs, feed, frame = saved
        st = self.st
        feed_mode = st.feed_mode
        work = st.work_offset
        for g, v in groups.items():
            if g not in NOT_SAVED_GROUPS:
                st.groups[g] = v
        for a, v in attrs.items():
            setattr(st, a, v)
        if st.feed_mode != feed_mode:
            st.feed = feed
        if st.work_offset != work:
            self.off.set_work(self._work_offset(st.work_offset) if st.work_offset else {})
        copy_frame(frame, self.frame)
        self._resync()
