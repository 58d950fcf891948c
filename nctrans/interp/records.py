"""From a move in program coordinates to toolpath records: the machine point (programmable frame,
work offset, G92, tool length: offsets.py), cutter compensation (cutter_comp.py buffers moves and
hands them back shifted), and the flatten hook's work-coordinate points.

Records are in machine coordinates. The start of a record is the end dict of the previous motion
record (shared, never mutated). Each record is appended to `out`; flow.py numbers and yields them.
A mixin of Interpreter.
"""
from __future__ import annotations

from nctrans.interp import comp_radius, corner_elements, episode_frame
from nctrans.interp.cutter_comp import PlannedMove
from nctrans.interp.frames import PLANE_AXES
from nctrans.toolpath import ToolpathRecord

def _minus(p: dict[str, float], shift: dict[str, float]) -> dict[str, float]:
    return {a: v - shift.get(a, 0.0) for a, v in p.items()}


class RecordsMixin:
    """Moves and other records into `out`; cutter compensation glue."""

    def _record(self, kind: str, **kw) -> None:
        if self.contour_table is not None:      # a dwell, M function .. among a contour table's blocks
            self.contour_table.problems.append((self.span, f"a {kind} record (only G0-G3, RND/CHF, CIP, "
                                                "CT and the modal codes may describe the contour, seed "
                                                "L23281, L23600-23615): left out"))
            return
        rec = ToolpathRecord(0, self.span.file if self.span else self.program.file,
                             self.span.line if self.span else 1, kind, **kw)
        if self.corner is not None and corner_elements.record(self, rec):
            return                      # waits behind a move that leads to a corner element
        self._push_record(rec)

    def _push_record(self, rec) -> None:
        if self.comp is not None:
            self._comp_out(self.comp.push(rec))
        else:
            self.out.append(rec)
            if self.hook is not None:
                self._hookq.append(None)

    def _move(self, kind: str, end: dict[str, float], center=None, cw=None, turns=None) -> None:
        """Emit a move from the current program point to `end` (program coords); update position."""
        if self.watch and self.capture is None:
            self._rc_move(kind, end)
        start = self.pos
        self.pos = end
        if self.capture is not None:            # reading a turning contour: no motion
            self.capture.append((kind, start, end, center, cw, self.span))
            return
        if self.css_surface is not None:
            self._css_move(end)
        self.last_from = start
        self.last_arc = (center, cw) if kind == "arc" else None
        if self.corner is not None:         # a corner element is programmed or held
            corner_elements.move(self, kind, start, end, center, cw, turns, self._payload())
            return
        self._emit_move(kind, start, end, center, cw, turns, self._payload())

    def _emit_move(self, kind, start, end, center, cw, turns, payload) -> None:
        """A move of the programmed contour on to cutter compensation and the records."""
        if not self.comp_checked and self.comp is None and not self.comp_exit:
            self.comp_checked = True
            comp_radius.check_entry(self)       # NC123: the radius of a tool the program never chose
        if self.comp_exit or self.comp is not None or (
                self.st.comp_side != "off" and (self.comp_radius or self.contour_offset)):
            if self._comp_move(kind, start, end, center, cw, turns, payload):
                return
        elif self.st.comp_side != "off" and not self.st.radius_index:
            self._comp_without_offset(kind, start, end, center, cw, turns, payload)
            return
        self._finish_move(kind, start, end, center, cw, turns, payload)

    def _comp_without_offset(self, kind, start, end, center, cw, turns, payload) -> None:
        """G41/G42 on with no D word. Where the dialect's table names the cutting edge a tool
        brings by default (options.default_cutting_edge, Sinumerik D1), compensate with it as if
        written; else the controller compensates by zero: NC208, and the move runs as programmed.
        An explicit D0 brings no default edge: no offset (where D is an edge, as the control runs
        it; an ISO D0 is NC208 as before). It used to compensate with the default edge."""
        edge = self.default_edge if self.st.radius_index is None else 0
        loaded = comp_radius.loaded_tool_radius(self) if self.st.radius_index is None else None
        if loaded is not None:          # the control's profile takes the loaded tool's radius
            self.comp_radius = loaded
            if loaded and self._comp_move(kind, start, end, center, cw, turns, payload):
                return
        elif edge:
            self.st.radius_index = edge
            self.comp_radius = (self.edges.radius(int(self.st.tool or 0), edge) if self.edges is not None
                                else comp_radius.radius_of(self, edge))
            if self.comp_radius and self._comp_move(
                    kind, start, end, center, cw, turns, payload):
                return
        elif self.default_edge:
            pass                        # D0 where D is an edge: no offset, as the control runs it
        elif not self.comp_d_reported:
            self.comp_d_reported = True
            which = "no D word selects a radius offset" if self.st.radius_index is None else \
                "D0 selects no radius offset"
            self.diag("NC208", "error", f"cutter compensation ({self.st.comp_side}) is on but {which}: "
                      "the tool runs on the programmed contour uncompensated")
        self._finish_move(kind, start, end, center, cw, turns, payload)

    def _payload(self) -> tuple:
        sp = self.span
        st = self.st
        return (sp.file if sp else self.program.file, sp.line if sp else 1, st.feed, st.feed_mode,
                st.spindle_speed, st.tool, st.plane, self.off.total)

    def _machine_at(self, p: dict[str, float], total: dict[str, float]) -> dict[str, float]:
        """The machine point of program point `p` under the offsets `total` (work offset, G92, tool
        length: those in force when a move held by cutter compensation was programmed)."""
        fr = episode_frame.frame(self)
        w = p if fr.identity else fr.to_work(p)
        return {a: v + total.get(a, 0.0) for a, v in w.items()}

    def _finish_move(self, kind, start, end, center, cw, turns, payload, start_given=False) -> None:
        file, line, feed, feed_mode, speed, tool, plane, total = payload
        if start_given:                 # out of cutter compensation: in the episode's coordinates,
            mend = self._machine_at(end, total)         # under its offsets (_comp_move)
            mstart = self._machine_at(start, total)
        else:
            mend = self._to_machine(end)
            mstart = self.mpos
        if len(mstart) != len(mend):
            mstart = {**{a: mend[a] for a in mend if a not in mstart}, **mstart}
        if kind == "rapid":
            rec = ToolpathRecord(0, file, line, "rapid", mstart, mend, spindle=speed, tool=tool)
        else:
            rec = ToolpathRecord(0, file, line, "linear" if kind == "linear" else "arc", mstart,
                                 mend, feed=feed, feed_mode=feed_mode, spindle=speed, tool=tool)
        if self.css_surface is not None:    # constant surface speed, for `check` to judge
            rec.css, rec.spindle_limit = self.css_surface, self.css_limit
            rec.css_axis = mend.get("X", 0.0) - end.get("X", 0.0)
        mc = None
        if kind == "arc":
            a1, a2, an = PLANE_AXES[plane]
            cprog = {a1: center[0], a2: center[1], an: end.get(an, 0.0)}
            full = dict(end)
            full.update(cprog)
            mfull = self._machine_at(full, total) if start_given else self._to_machine(full)
            mc = {a1: mfull[a1], a2: mfull[a2], an: mfull[an]}
            rec.center = mc
            rec.plane = plane
            swap = (episode_frame.frame(self) if start_given else self.frame).mirror_swap
            rec.direction = ("cw" if cw else "ccw") if not swap else (
                "ccw" if cw else "cw")
            rec.turns = turns
        self.mpos = mend
        self.out.append(rec)
        if self.hook is not None:
            tot = self.off.total
            work = {a: v - tot.get(a, 0.0) for a, v in mend.items()}
            wc = None if mc is None else {a: v - tot.get(a, 0.0) for a, v in mc.items()}
            self._hookq.append((work, wc))

    def _comp_move(self, kind, start, end, center, cw, turns, payload=None) -> bool:
        """A move into cutter compensation. The compensator works in the program coordinates of
        the episode, those of its first move: after an offset change (tool length, work offset,
        G92) the moves are shifted back into them and emitted under the episode's offsets, which
        puts them where the new offsets do; so the move held before the change (its end waits for
        the next move's corner) keeps the offsets it was programmed with, and the corner between
        it and the next move is computed on the path the machine runs."""
        payload = payload or self._payload()
        if self.comp is None and not self.comp_exit:
            self.comp_total = payload[7]            # the episode's offsets
            episode_frame.snapshot(self)            # and its frame
        total = self.comp_total if self.comp_total is not None else payload[7]
        if self.comp is not None and episode_frame.changed(self):   # a frame change: episode_frame.py
            a1, a2, an = PLANE_AXES[self.st.plane]
            start = episode_frame.to_episode(self, start, total, payload[7])
            if center is not None:
                c = episode_frame.to_episode(self, {a1: center[0], a2: center[1], an: end.get(an, 0.0)},
                                             total, payload[7])
                center = (c[a1], c[a2])
            end = episode_frame.to_episode(self, end, total, payload[7])
            payload = payload[:7] + (total,)
        elif payload[7] is not total and payload[7] != total:
            shift = self._program_shift(total, payload[7])
            start, end = _minus(start, shift), _minus(end, shift)
            if center is not None:
                a1, a2, _ = PLANE_AXES[self.st.plane]
                center = (center[0] - shift.get(a1, 0.0), center[1] - shift.get(a2, 0.0))
            payload = payload[:7] + (total,)
        pm = PlannedMove(kind=kind, start=start, end=end,
                         center=None if center is None else self._center_dict(center, end),
                         direction=None if cw is None else ("cw" if cw else "ccw"),
                         turns=turns, payload=payload)
        # the machine point of the programmed end: where the program point is while the move is
        # held (offsets.py _resync, an offset change before the next move)
        self.comp_pos_machine = self._machine_at(end, total)
        if self.comp_exit:
            comp, self.comp, self.comp_exit = self.comp, None, False
            if comp is not None:
                self._comp_out(comp.finish(pm), comp)
                return True
            return False
        if self.comp is None:
            side = self.st.comp_side
            r = self.comp_radius + self.contour_offset      # OFFN: an allowance on the radius
            if r < 0:           # a negative stored radius swaps the side
                side, r = ("right" if side == "left" else "left"), -r
            self.comp = self._compensator(side, r)     # lathe.py: the tool-nose tip
        self._comp_out(self.comp.push(pm))
        return True

    def _program_shift(self, episode: dict[str, float], now: dict[str, float]) -> dict[str, float]:
        """How far the program coordinates moved when the offsets went from `episode` to `now`
        (the same point of the machine: program point now = in the episode + this)."""
        d = {a: episode.get(a, 0.0) - now.get(a, 0.0) for a in {**episode, **now}}
        if self.frame.identity:
            return d
        zero = self.frame.to_program({a: 0.0 for a in d})
        moved = self.frame.to_program(d)
        return {a: moved[a] - zero[a] for a in d}

    def _center_dict(self, center, end) -> dict[str, float]:
        a1, a2, an = PLANE_AXES[self.st.plane]
        return {a1: center[0], a2: center[1], an: end.get(an, 0.0)}

    def _comp_out(self, items, comp=None) -> None:
        comp = comp or self.comp
        probs = getattr(comp, "problems", None)
        if probs:
            from nctrans.diagnostics import Diagnostic
            for payload, msg in probs:
                file, line = (payload[0], payload[1]) if isinstance(payload, tuple) else (
                    self.program.file, 1)
                self.diags.append(Diagnostic("NC204", "error", msg, file, line))
            probs.clear()
        for it in items:
            if isinstance(it, PlannedMove):
                c = it.center
                plane = it.payload[6]
                a1, a2, _ = PLANE_AXES[plane]
                cc = None if c is None else (c[a1], c[a2])
                cw = None if it.direction is None else it.direction == "cw"
                self._finish_move(it.kind, it.start, it.end, cc, cw, it.turns, it.payload,
                                  start_given=True)
            else:
                self.out.append(it)
                if self.hook is not None:
                    self._hookq.append(None)

    def _comp_flush(self) -> None:
        if self.comp is not None:
            comp, self.comp = self.comp, None
            self._comp_out(comp.finish(None), comp)
