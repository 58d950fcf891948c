"""Statements that set state without moving: modal G/M groups (ModeChange), F, S, T and tool change,
dwell, variable assignment and declaration, programmed travel limits, and constructs the
interpreter does not model (Passthrough: NC220 at their line, or known to have no path effect).

A mixin of Interpreter. Spindle speed limits (SpindleLimit) are handled in lathe.py.
"""
from __future__ import annotations

from nctrans.interp import computed_g, contour_offset, corner_elements, indirect_g, polar_words, rigid_tap, spindle_position, unmodelled
from nctrans.interp.evaluate import constant
from nctrans.interp.offsets import NORMAL
from nctrans.interp.travel_limits import ProgrammedLimits
from nctrans.interp.words import LENGTH_WORDS
from nctrans.ir import nodes as n
from nctrans.ir.vocabulary import UNMODELLED_LIMITS, UNMODELLED_MODES


def reported_unmodelled(s: n.Passthrough, kind: str = "mill") -> bool:
    """Whether running this construct reports it as not modelled (NC220): neither one the
    interpreter models itself (a computed G, a corner element, a contour offset, a compensating
    chuck, spindle positioning, SETMS) nor one known to have no effect on the path (or reported
    as an error instead). linting.checks asks the same of blocks the run never reached (NC240)."""
    return not (computed_g.is_computed_g(s) or corner_elements.kind_of(s)
                or contour_offset.is_offset_word(s) or s.reason == rigid_tap.COMPENSATING_CHUCK
                or spindle_position.is_positioning(s) or spindle_position.is_setms(s)
                or unmodelled.no_motion_effect(s.reason, kind) or s.reason in unmodelled.REPORTED_AS_ERROR)

_BY_T_WORD = n.ToolChange(turret=True)      # the change a T word makes where it changes the tool

class StatementsMixin:
    """Modal and setting statements."""

    def _statements_table(self) -> dict:
        """Compilers of modal, feed, speed, tool, dwell, variable, limit and unmodelled statements."""
        return {
            n.ModeChange: self._c_mode, n.Feed: self._c_feed,
            n.ModeSelect: lambda s: (lambda d: indirect_g.select_mode(self, d),
                                     (s, self.ev.compile(s.index))),            # indirect_g.py
            n.SpindleSpeed: self._c_speed, n.ToolSelect: self._c_tool,
            n.ToolChange: lambda s: (self._h_toolchange, s), n.Dwell: self._c_dwell,
            n.Assign: self._c_assign, n.VarDecl: lambda s: (self._h_decl, s),
            n.Passthrough: self._c_passthrough,
            n.SpindleLimit: lambda s: (self._h_spindle_limit, s),      # lathe.py
            n.TravelLimit: lambda s: (self._h_travel_limit, (s, self._words(s.values),
                                                             self._words(s.corner))),
        }

    def _c_mode(self, s: n.ModeChange):
        if s.group == "spindle" and spindle_position.numbered_mode(s) is not None:
            return (spindle_position.numbered_mode_change, (self, s))     # M1=3 after SETMS(2)
        return (self._h_mode, s)

    def _h_mode(self, s: n.ModeChange):
        st = self.st
        g, v = s.group, s.value
        self._rc_mode(g, v)
        if s.code:
            self.spelt_codes[g] = s.code
        if self.contour_table is not None:      # G9 in a contour table's block (contour_tables)
            self.contour_table.note_mode(self, g)
        if g == "motion":
            if st.cycle != "off":
                self._cycle_off()
            st.set(g, v)
            self.unmodelled_motion = None
        elif g == "cycle":
            self.unmodelled_motion = None
            if v == "off":
                self._cycle_off()
            else:
                if st.cycle == "off" or self.cycle_initial is None:
                    self.cycle_initial = self.pos.get(NORMAL[st.plane], 0.0)
                st.set(g, v)
        elif g == "work_offset":
            st.set(g, v)
            self.off.set_work(self._work_offset(v))
            if self.settable is not None:        # its rotation, scale, mirror (settable_frames)
                self.settable.selected(v)
            self._resync()
        elif g == "tool_length":
            st.set(g, v)
            self._apply_length()
        elif g == "cutter_comp":
            prev = st.comp_side
            st.set(g, v)
            if v != prev:
                self.comp_d_reported = False
                self.comp_on_span, self.comp_checked = self.span, v == "off"
            if v == "off" and prev != "off" and self.comp is not None:
                self.comp_exit = True
            elif v != "off" and self.comp is not None and prev != v:
                # side switch while active: finish with the next move, restart after
                self.comp_exit = True
        elif g == "spindle":
            # M3/M4 with the spindle already turning that way changes nothing: no second record
            # (CYCLE84's code turns it back to M3 after G332 did: one cw record, as the model)
            same = v in ("cw", "ccw") and v == st.spindle_dir and not self.spindle_stopped
            st.set(g, v)
            self.spindle_stopped = v == "off"
            self.spindle_stopped_by_tap = False
            # M19 positions at SD 43240 M19_SPOS, 0 degrees by default (spindle_position.py)
            self.spindle_angle = 0.0 if v == "orient" else None
            self.spindle_reported = False
            rigid_tap.spindle_programmed(self)
            if not same:
                self._record("spindle", spindle_dir=v, spindle=st.spindle_speed)
        elif g == "coolant":
            st.set(g, v)
            self._record("coolant", coolant=v)
        elif g == "units":
            st.set(g, v)
        elif g == "polar":
            st.set(g, v)
            self.polar_input_last = None     # polar_input.py: no angle programmed in this mode yet
        elif g == "plane":
            if v != st.plane:
                polar_words.plane_changed(self)
            st.set(g, v)
        elif g == "spindle_mode":
            st.set(g, v)
            self._css_mode(v)
        else:
            st.set(g, v)
        left_out = UNMODELLED_MODES.get((g, v))
        if left_out is not None:
            self.diag("NC220", "warning", f"{s.code or g + '=' + v} is not modelled ({left_out})")

    def _c_feed(self, s: n.Feed):
        c = constant(s.value)
        f = None if c is not None else self.ev.compile(s.value)
        return (self._h_feed, (c, f))

    def _h_feed(self, d):
        c, f = d
        v = c if c is not None else self._value(f, "feed")
        if v is None:
            return
        if v < 0:
            self.diag("NC105", "error", f"negative feed {v:g}")
            return
        st = self.st
        st.feed = v if st.feed_mode == "inverse_time" else v * st.feed_scale
        self.feed_reported = False
        self._rc_feed_set()

    def _c_speed(self, s: n.SpindleSpeed):
        if s.spindle != 1 or getattr(s, "addressed", False):     # S2=: spindle_position.py
            return (spindle_position.numbered_speed, (self, s, self.ev.compile(s.value)))
        return (self._h_speed, self.ev.compile(s.value))

    def _h_speed(self, f):
        v = self._value(f, "spindle speed")
        if v is None:
            return
        if v < 0:
            self.diag("NC105", "error", f"negative spindle speed {v:g}")
            return
        st = self.st
        if st.groups.get("spindle_mode") == "css" and self._css_applies():
            v = self._css_speed_word(v)
        changed = v != st.spindle_speed
        st.spindle_speed = v
        if changed and st.spindle_dir in ("cw", "ccw"):
            self._record("spindle", spindle_dir=st.spindle_dir, spindle=v)

    def _c_tool(self, s: n.ToolSelect):
        return (self._h_tool, self.ev.compile(s.tool))

    def _h_tool(self, f):
        raw = f()
        if isinstance(raw, str):          # Sinumerik tool management: T="DRILL"
            self.st.tool_selected = self._named_tool(raw)
            if self.t_changes_tool:
                self._h_toolchange(_BY_T_WORD)
            return
        v = self._value(lambda: raw, "tool number")
        if v is not None:
            self.st.tool_selected = int(round(v))
            if self.t_changes_tool:             # a turret, or T set to change (tool_change.py)
                self._h_toolchange(_BY_T_WORD)

    def _named_tool(self, name: str) -> int:
        """The number of a tool selected by name: the machine's tool with that `name`, else a
        stable number of its own above the machine's tools (reported once as NC107)."""
        key = name.strip().upper()
        numbers = self.__dict__.setdefault("_tool_names", {})
        if key not in numbers:
            tools = getattr(self.machine, "tools", None) or []
            match = next((t.number for t in tools if str(getattr(t, "name", "")).upper() == key), None)
            if match is None:
                match = max([t.number for t in tools] + [0] + list(numbers.values())) + 1
                self.unnumbered_tools[match] = name
                self.diag("NC107", "info", f"tool {name!r} is not named in the machine's tool table; "
                          f"analysed as tool {match} with no geometry")
            numbers[key] = match
        return numbers[key]

    def _h_toolchange(self, s):
        st = self.st
        if (s.turret or self.t_changes_tool) and st.tool is not None and st.tool == st.tool_selected:
            return                              # the turret stays: only the offset changes
        self._rc_tool_change()
        if st.tool_selected is None:
            self.diag("NC105", "warning", "tool change without a selected tool")
        st.tool = st.tool_selected
        self._record("tool_change", tool=st.tool)
        if self.edges is not None:              # the new tool's edge D1 (tool_edges)
            self.edges.tool_changed()

    def _c_dwell(self, s: n.Dwell):
        sec = None if s.seconds is None else self.ev.compile(s.seconds)
        rev = None if s.revolutions is None else self.ev.compile(s.revolutions)
        return (self._h_dwell, (sec, rev))

    def _h_dwell(self, d):
        sec, rev = d
        t = 0.0
        if sec is not None:
            t = self._value(sec, "dwell") or 0.0
        elif rev is not None:
            r = self._value(rev, "dwell") or 0.0
            s = self.st.spindle_speed
            if not s:
                self.diag("NC105", "warning", "dwell in revolutions with no spindle speed")
                t = 0.0
            else:
                t = r * 60.0 / s
        if t < 0:
            self.diag("NC105", "error", f"negative dwell {t:g}")
            return
        self._record("dwell", dwell_s=t)

    def _c_assign(self, s: n.Assign):
        v = s.value
        if type(v) is n.Func and v.name.upper() in ("SET", "REP") and s.target.indices:
            return (self._h_exec, self.ev.compile_assign(s.target, v))
        return (self._h_assign, (self.ev.compile_store(s.target), self.ev.compile(s.value)))

    @staticmethod
    def _h_exec(f):
        f()

    def _h_assign(self, d):
        put, f = d
        put(f())

    def _h_decl(self, s: n.VarDecl):
        self.ev.declare(s)

    def _c_passthrough(self, s: n.Passthrough):
        if computed_g.is_computed_g(s):
            return (computed_g.select, (self, s, self.ev.compile(s.value)))
        if corner_elements.kind_of(s):
            return corner_elements.compile_word(self, s)
        if contour_offset.is_offset_word(s):
            return contour_offset.compile_word(self, s)
        if s.reason == rigid_tap.COMPENSATING_CHUCK:
            return (rigid_tap.compensating_chuck, self)
        if spindle_position.is_positioning(s):
            return (spindle_position.position, spindle_position.compile_position(self, s))
        if spindle_position.is_setms(s):
            return (spindle_position.set_master, (self, s))
        if not reported_unmodelled(s, getattr(self.machine, "kind", "mill")):
            return (self._h_known, None)
        return (self._h_unmodelled, (s, unmodelled.takes_motion(s)))

    @staticmethod
    def _h_known(_):
        """A construct known to have no effect on the programmed path."""

    def _h_unmodelled(self, d):
        s, code = d
        what = f"{s.text!r}" + (f" ({s.reason})" if s.reason else "")
        if code is not None and code in unmodelled.one_block_codes(s.dialect):
            self.unmodelled_motion = code       # this block only (motion.py clears it after)
            self.unmodelled_one_block = True
            self._unmodelled_at = self.span
            self.diag("NC220", "warning", f"{what} is not modelled: its axis words move nothing in "
                      "the analysed toolpath (the blocks after it move with the modal motion code)")
        elif code is not None:
            self.unmodelled_motion = code
            self.unmodelled_one_block = False
            self._unmodelled_at = self.span
            self.diag("NC220", "warning", f"{what} is not modelled: its axis words, and those of "
                      "the blocks after it until the next motion code, move nothing in the analysed "
                      "toolpath")
        else:
            self.diag("NC220", "warning", f"{what} is not modelled: the analysed toolpath leaves "
                      "it out")
        if s.reason in UNMODELLED_LIMITS:       # tell the machine check it cannot judge these
            self._record("limits", zone="unmodelled")

    def _h_travel_limit(self, d) -> None:
        """Programmed travel limits (travel_limits.py): nothing moves; `limits` records tell the
        machine check. Values are lengths in program units, X as a radius."""
        s, words, corner = d
        if self.travel_limits is None:
            self.travel_limits = ProgrammedLimits(getattr(self.machine, "axes", None))
        scale = self.st.scale

        def values(ws):
            out = {}
            for axis, c, f, _mode in ws:
                v = c if c is not None else self._value(f, f"{axis} limit")
                if v is not None:
                    out[axis] = v * scale if axis in LENGTH_WORDS else v
            return out
        self.travel_limits.apply(s.kind, s.scope, values(words), values(corner), s.incremental)
        self._send_limits()

    def _send_limits(self) -> None:
        for kw in self.travel_limits.pending(self.off.tool_z):
            self._record("limits", **kw)
