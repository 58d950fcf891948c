"""Motion statements: G0/G1 (with the Python fast path _h_fast for literal words in the plain
state), G2/G3 by centre, radius, opening angle or turns, 3-point (CIP) and tangential (CT) arcs,
G33 threads, polar words and poles, G53 machine moves, G28/G30 home returns; under a canned cycle
the axis words position a hole instead (cycle_calls.py).

Arcs: `turns` is the number of EXTRA full turns (LinuxCNC ARC_FEED |rotation| - 1); an arc whose
start equals its end in the plane is a full circle. `center` holds the plane's two axes plus the
normal axis at the arc's end height (as tests/rs274.py reads LinuxCNC).

Each handler computes a target in program coordinates and hands it to records.py (_move).
A mixin of Interpreter.
"""
from __future__ import annotations

import math
from typing import Optional

from nctrans.interp import arcs, contour_tables, corner_elements, polar_input, polar_words, rigid_tap, thread_starts
from nctrans.interp.frames import PLANE_AXES
from nctrans.interp.state import LINEAR_AXES
from nctrans.ir import nodes as n
from nctrans.toolpath import ToolpathRecord

# which of a block's circle words each motion mode uses (the rest: NC238); modes not listed
# (tapping, threads with their own words) are not checked
ARC_WORDS_USED = {
    "rapid": frozenset(), "linear": frozenset(),
    "arc_cw": frozenset(("center", "radius", "turns", "aperture")),
    "arc_ccw": frozenset(("center", "radius", "turns", "aperture")),
    "arc_3point": frozenset(("via", "turns")),
    "arc_tangent": frozenset(("turns",)),
}
MODE_NAMES = {"rapid": "rapid (G0)", "linear": "straight feed (G1)", "arc_cw": "circle (G2)",
              "arc_ccw": "circle (G3)", "arc_3point": "three-point circle",
              "arc_tangent": "tangential circle"}


class MotionMixin:
    """Motion words to program-coordinate moves."""

    def _motion_table(self) -> dict:
        """Compilers of motion, home return and polar pole statements."""
        return {
            n.Motion: self._c_motion, n.HomeReturn: lambda s: (self._h_home, s),
            n.PolarPole: lambda s: (self._h_pole, s),
        }

    def _c_motion(self, s: n.Motion):
        if s.thread_start is not None:          # SF= / G33 Q: a setting, then the move
            return (self._h_thread_start, thread_starts.compile_motion(self, s))
        if (s.center is None and s.radius is None and s.turns is None and not s.polar
                and not s.machine_coords and s.via is None and s.aperture is None
                and not s.indirect):
            fast = []
            AV, Num = n.AxisValue, n.Num
            for axis, av in s.target.items():
                if type(av) is AV and type(av.value) is Num and av.mode in (None, "abs", "inc") \
                        and float(av.value.value) - float(av.value.value) == 0.0:
                    a = axis.upper()
                    fast.append((a, float(av.value.value), av.mode, a in LINEAR_AXES))
                else:
                    break
            else:
                return (self._h_fast, [tuple(fast), s, None])
        return (self._h_motion, self._c_motion_full(s))

    def _c_motion_full(self, s: n.Motion) -> tuple:
        words = self._words(s.target)
        if s.indirect:
            words += tuple((self.ev.compile(axis), None, self.ev.compile(av.value), av.mode)
                           for axis, av in s.indirect)
        center = self._words(s.center)
        radius = None if s.radius is None else self.ev.compile(s.radius)
        turns = None if s.turns is None else self.ev.compile(s.turns)
        polar = polar_words.compile_words(self, s.polar) if s.polar else None
        via = self._words(s.via)
        ap = getattr(s, "aperture", None)
        aperture = None if ap is None else self.ev.compile(ap)
        return (words, center, radius, turns, s.machine_coords, polar, via, aperture)

    def _h_thread_start(self, d):
        thread_starts.run_motion(self, d)

    def _slow(self, d):
        full = d[2]
        if full is None:
            full = d[2] = self._c_motion_full(d[1])
        return self._h_motion(full)

    def _h_fast(self, d):
        """The hot path: a rapid/linear move with literal words and no frame, comp or cycle."""
        words = d[0]
        st = self.st
        if (st.cycle != "off" or self.modal_cycle is not None or self.comp is not None
                or self.comp_exit or st.comp_side != "off" or not self.frame.identity
                or self.unmodelled_motion is not None or st.diameter or st.polar
                or self.css_surface is not None or self.spindle_stopped or self.watch
                or self.corner is not None or self.capture is not None):
            return self._slow(d)
        motion = st.motion
        if motion == "rapid":
            feed = None
        elif motion == "linear":
            feed = st.feed
            if not feed:
                self._need_feed()
        else:
            return self._slow(d)
        self.moved = True
        if not words:
            return None
        tgt = self.pos.copy()
        scale = st.scale
        inc = st.incremental
        for axis, v, mode, lin in words:
            if lin and scale != 1.0:
                v = v * scale
            cur = tgt.get(axis)
            if cur is None:                  # first use of an axis: the general path adds it
                return self._slow(d)
            if (inc if mode is None else mode == "inc"):
                v += cur
            tgt[axis] = v
        self.last_from = self.pos
        self.last_arc = None
        self.pos = tgt
        tot = self.off.total
        mend = {a: v + tot.get(a, 0.0) for a, v in tgt.items()} if tot else tgt.copy()
        mstart = self.mpos
        self.mpos = mend
        sp = self.span
        if motion == "rapid":           # a feedless G1 stays a feed move (NC202), as on the general path
            rec = ToolpathRecord(0, sp.file, sp.line, "rapid", mstart, mend, None, None, None,
                                 None, None, None, st.spindle_speed, st.tool)
        else:
            rec = ToolpathRecord(0, sp.file, sp.line, "linear", mstart, mend, None, None, None,
                                 None, feed, st.feed_mode, st.spindle_speed, st.tool)
        self.out.append(rec)
        if self.hook is not None:
            self._hookq.append(({a: v - tot.get(a, 0.0) for a, v in mend.items()}, None))
            self.positioned.update(w[0] for w in words)     # what plain motion must write (flatten)
        return None

    def _h_motion(self, d):
        words, center, radius, turns, machine, polar, via, aperture = d
        st = self.st
        if self.unmodelled_motion is not None:
            if self._unmodelled_at is self.span:
                return                  # the code's own block: reported with the code
            if self.__dict__.get("unmodelled_one_block"):
                self.unmodelled_motion = None       # a non-modal code (G31): its block is over
                return self._h_motion(d)
            self.diag("NC220", "warning", f"motion under {self.unmodelled_motion} is not modelled: "
                      "this block's axis words move nothing in the analysed toolpath")
            return
        self.moved = True
        vals = self._eval_words(words)
        self._polar_arc = bool(polar)
        if polar:
            vals = polar_words.end_point(self, vals, polar)
            if vals is None:
                return
        elif st.polar:
            vals = polar_input.cartesian(self, vals, machine)
            if vals is None:
                return
        if self.modal_cycle is not None and st.cycle == "off" and not machine:
            self._motion_plain(vals, d)
            if any(a in PLANE_AXES[st.plane][:2] for a, _, _ in vals):
                self._run_modal_cycle()
            return
        if st.cycle != "off" and not machine:
            self._cycle_hole(vals)
            return
        if machine:
            self._machine_move(vals)
            return
        self._motion_plain(vals, d)

    def _motion_plain(self, vals, d):
        _, center, radius, turns, _, _, via, aperture = d
        st = self.st
        motion = st.motion
        if self.contour_table is not None and motion not in contour_tables.CONTOUR_MOTIONS:
            contour_tables.refuse_motion(self, motion)      # thread, spline .. in a contour table
            return
        used = ARC_WORDS_USED.get(motion)
        if used is not None and (
                (radius is not None and "radius" not in used) or (via and "via" not in used)
                or (turns is not None and "turns" not in used) or (center and "center" not in used)
                or (aperture is not None and "aperture" not in used)):
            self._arc_words_unused(d, used)
        if motion == "rapid":
            if vals:
                self._move("rapid", self._target(vals))
            return
        if motion == "linear":
            if vals:
                self._need_feed()
                self._move("linear", self._target(vals))
            return
        if motion == "thread":
            if vals:
                self._g33_move(vals, center)
            return
        if motion in rigid_tap.MODES:
            if vals:
                rigid_tap.rigid_tap_move(self, vals, center, motion)
            return
        if motion == rigid_tap.RETURNING:
            if vals:
                rigid_tap.returning_tap_move(self, vals, center)
            return
        if motion == rigid_tap.INTERPOLATED:
            if vals:
                rigid_tap.interpolated_tap_move(self, vals)
            return
        if motion in ("arc_cw", "arc_ccw"):
            self._arc(vals, center, radius, turns, motion == "arc_cw", aperture)
            return
        if motion == "arc_3point":
            self._arc_3point(vals, via)
            return
        if motion == "arc_tangent":
            self._arc_tangent(vals)
            return
        if vals:
            self.diag("NC207", "error", "axis words while no motion mode is active")

    def _arc_words_unused(self, d, used: frozenset) -> None:
        """A circle's words where the motion mode does not use them (Sinumerik `G1 X10 CR=5`,
        `CIP .. CR=`, `G2 .. I1=`): the move runs as its mode says and the word does nothing,
        which the programmer did not mean (NC238)."""
        _, center, radius, turns, _, _, via, aperture = d
        what = [name for key, name, v in (
            ("center", "arc centre", center), ("radius", "arc radius", radius is not None),
            ("aperture", "opening angle", aperture is not None),
            ("turns", "extra turns", turns is not None), ("via", "intermediate point", via))
            if v and key not in used]
        mode = MODE_NAMES.get(self.st.motion, self.st.motion)
        self.diag("NC238", "warning", f"{' and '.join(what)} in a {mode} block: that motion does "
                  "not use it, so it has no effect here; the move is analysed as programmed")

    def _need_feed(self) -> None:
        st = self.st
        if self.contour_table is not None:  # a contour table's blocks do not move (contour_tables)
            return
        if not st.feed and not self.feed_reported:
            self.feed_reported = True
            if self.stack or not self._runs_from_a_caller():
                self.diag("NC202", "error", "feed move with no feed rate programmed")
            else:                       # a subprogram file (.SPF) run alone: F is its caller's
                self.diag("NC202", "warning", "feed move with no feed rate programmed in this "
                          "subprogram file: it moves at the feed its caller set, which the analysis "
                          "of the file alone does not know")
        self._spindle_standing("feed move while the spindle is stopped (M5, or a tool change that "
                               "stops it): the tool would rub or break; start the spindle (M3/M4) before cutting")

    def _spindle_standing(self, message: str) -> None:
        """NC209 at the line, once until the spindle is programmed again: a feed move (or a cycle's
        feed, interp/cycle_calls) with the spindle standing."""
        if self.spindle_stopped and not self.spindle_reported:
            self.spindle_reported = True
            self.diag("NC209", "warning", message)

    def _runs_from_a_caller(self) -> bool:
        """The program run is a subprogram file by its dialect's file types (a Sinumerik .SPF)
        or an ISO macro file run alone (interp/macro_alone: its F may be a G65 argument): its
        modes and feed are its caller's (convert.subprogram_file)."""
        from nctrans.convert import subprogram_file
        return subprogram_file(self.program) or bool(getattr(self, "_macro_alone", False))

    def _g33_move(self, vals, center) -> None:
        """G33: a feed synchronised with the spindle, `lead` mm per revolution: the feed is
        lead x S and the record carries the lead (pitch). The lead is the I/J/K word of the
        block (Sinumerik, LinuxCNC, Fagor: the one of the axis that travels furthest when
        several are given), else the F word in a dialect whose table says F is the lead
        (`[options] thread_lead = "feed"`: ISO seed 4.5 `G33 Z.. F<lead>`)."""
        st = self.st
        target = self._target(vals)
        leads = {a: abs(v) for a, v, _ in self._eval_words(center)} if center else {}
        lead = None
        if leads:
            travel = {w: abs(target.get(a, 0.0) - self.pos.get(a, 0.0))
                      for w, a in (("I", "X"), ("J", "Y"), ("K", "Z"))}
            lead = leads[max(leads, key=lambda w: travel.get(w, 0.0))]
        elif self._thread_lead_is_feed():
            lead = st.feed if st.feed and st.feed_mode != "inverse_time" else None   # mm
        if not lead:
            self.diag("NC206", "error", "thread move (G33) without a lead: the move is not made")
            return
        if not st.spindle_speed:
            self.diag("NC209", "warning", "thread move (G33) with no spindle speed: the feed "
                      "(lead x S) is unknown")
        mark = len(self.out)
        self._lead_move(target, lead)
        thread_starts.stamp(self, mark)

    def _lead_move(self, target, lead: float) -> None:
        """A feed move synchronised with the spindle (G33, G331/G332): `lead` mm per revolution,
        so the feed is lead x S (unknown without S); the records carry the lead as pitch and the
        programmed feed comes back afterwards."""
        st = self.st
        saved, saved_mode = st.feed, st.feed_mode
        st.feed = lead * st.spindle_speed if st.spindle_speed else None
        st.feed_mode = "per_min"
        mark = len(self.out)
        try:
            self._move("linear", target)
        finally:
            st.feed, st.feed_mode = saved, saved_mode
        for rec in self.out[mark:]:
            rec.pitch = lead

    def _thread_lead_is_feed(self) -> bool:
        v = getattr(self, "_lead_is_feed", None)
        if v is None:
            from nctrans.rules import option
            v = option(self.program.dialect, "thread_lead") == "feed"
            self._lead_is_feed = v
        return v

    def _h_pole(self, s: n.PolarPole) -> None:
        polar_words.set_pole(self, s)

    def _machine_move(self, vals) -> None:
        """G53: the words are machine coordinates of the controlled point, this block only."""
        if self.corner is not None:     # a held move first: G53 starts from where it ends
            corner_elements.flush(self, "the next move is in machine coordinates (G53)")
        for a, _, _ in vals:
            if a not in self.mpos:
                self._new_axis(a)   # first use: from machine 0, as any other move (not a jump)
        mend = dict(self.mpos)
        for a, v, _ in vals:
            mend[a] = v
        kind = "linear" if self.st.motion == "linear" else "rapid"
        if kind == "linear":
            self._need_feed()
        tot = self.off.total
        end = self.frame.to_program({a: v - tot.get(a, 0.0) for a, v in mend.items()})
        self._move(kind, end)

    def _arc_3point(self, vals, via) -> None:
        """Sinumerik CIP: the circle through start, intermediate point and end."""
        a1, a2, _ = PLANE_AXES[self.st.plane]
        start = self.pos
        end = self._target(vals)
        mid = self._target(self._eval_words(via)) if via else None
        self._need_feed()
        if mid is None:
            self.diag("NC203", "error", "3-point arc without an intermediate point")
            return
        p = [(q.get(a1, 0.0), q.get(a2, 0.0)) for q in (start, mid, end)]
        (x1, y1), (x2, y2), (x3, y3) = p
        den = 2 * (x1 * (y2 - y3) + x2 * (y3 - y1) + x3 * (y1 - y2))
        if abs(den) < 1e-12:
            self.diag("NC203", "error", "3-point arc through collinear points")
            return
        s1, s2, s3 = x1 * x1 + y1 * y1, x2 * x2 + y2 * y2, x3 * x3 + y3 * y3
        cx = (s1 * (y2 - y3) + s2 * (y3 - y1) + s3 * (y1 - y2)) / den
        cy = (s1 * (x3 - x2) + s2 * (x1 - x3) + s3 * (x2 - x1)) / den
        cw = ((x2 - x1) * (y3 - y2) - (y2 - y1) * (x3 - x2)) < 0
        self._move("arc", end, (cx, cy), cw, 0)

    def _tangent(self) -> Optional[tuple[float, float]]:
        a1, a2, _ = PLANE_AXES[self.st.plane]
        e1, e2 = self.pos.get(a1, 0.0), self.pos.get(a2, 0.0)
        if self.last_arc is not None:
            (c1, c2), cw = self.last_arc
            r1, r2 = e1 - c1, e2 - c2
            t = (r2, -r1) if cw else (-r2, r1)
        elif self.last_from is not None:
            t = (e1 - self.last_from.get(a1, 0.0), e2 - self.last_from.get(a2, 0.0))
        else:
            return None
        ln = math.hypot(*t)
        return None if ln < 1e-12 else (t[0] / ln, t[1] / ln)

    def _arc_tangent(self, vals) -> None:
        """Sinumerik CT: an arc leaving tangentially from the previous path."""
        a1, a2, _ = PLANE_AXES[self.st.plane]
        t = self._tangent()
        end = self._target(vals)
        self._need_feed()
        s1, s2 = self.pos.get(a1, 0.0), self.pos.get(a2, 0.0)
        d1, d2 = end.get(a1, 0.0) - s1, end.get(a2, 0.0) - s2
        if t is None:
            self.diag("NC203", "error", "tangential arc without a previous direction")
            return
        nl = (-t[1], t[0])                       # left normal
        dn = d1 * nl[0] + d2 * nl[1]
        if abs(dn) < 1e-12:                      # end straight ahead: a line
            self._move("linear", end)
            return
        k = (d1 * d1 + d2 * d2) / (2 * dn)
        self._move("arc", end, (s1 + k * nl[0], s2 + k * nl[1]), k < 0, 0)

    def _arc(self, vals, center, radius, turns, cw, aperture=None) -> None:
        st = self.st
        plane = st.plane
        a1, a2, an = PLANE_AXES[plane]
        start = self.pos
        end = self._target(vals)
        s1, s2 = start.get(a1, 0.0), start.get(a2, 0.0)
        e1, e2 = end.get(a1, 0.0), end.get(a2, 0.0)
        inch = st.scale != 1.0
        if center:
            self._rc_arc(center)
        nturns = 0
        if turns is not None:
            t = self._value(turns, "turns")
            if t is not None:
                nturns = max(int(round(t)), 0)
        self._need_feed()
        try:
            if aperture is not None:
                ang = self._value(aperture, "opening angle")
                if ang is None or not 0 < ang < 360:
                    raise arcs.ArcError(f"arc opening angle {ang} outside 0..360")
                cvals = self._eval_words(center)
                if cvals and not any(a in (a1, a2) for a, _, _ in vals):
                    # centre + angle: the end is the start turned about the centre
                    cd = {a: v for a, v, _ in cvals}
                    ci = {"I": "X", "J": "Y", "K": "Z"}
                    c1, c2 = s1, s2
                    for a, v in cd.items():
                        ax = ci.get(a, a)
                        absolute = dict((w, m == "abs") for w, _, m in cvals)[a] or st.arc_absolute
                        if ax == a1:
                            c1 = v if absolute else s1 + v
                        elif ax == a2:
                            c2 = v if absolute else s2 + v
                    phi = math.radians(-ang if cw else ang)
                    r1, r2 = s1 - c1, s2 - c2
                    end = dict(end)
                    end[a1] = c1 + r1 * math.cos(phi) - r2 * math.sin(phi)
                    end[a2] = c2 + r1 * math.sin(phi) + r2 * math.cos(phi)
                    self._move("arc", end, (c1, c2), cw, nturns)
                    return
                half = math.hypot(e1 - s1, e2 - s2) / 2
                r = half / math.sin(math.radians(ang) / 2)
                c1, c2 = arcs.center_from_radius(s1, s2, e1, e2, r if ang <= 180 else -r, cw, inch)
            elif radius is not None:
                r = self._value(radius, "arc radius")
                if r is None:
                    raise arcs.ArcError("arc radius is vacant")
                c1, c2 = arcs.center_from_radius(s1, s2, e1, e2, r * st.scale, cw, inch)
            else:
                cvals = self._eval_words(center)
                if not cvals and self.__dict__.get("_polar_arc"):
                    # G2/G3 with a polar end point turns about the pole (Sinumerik G110-G112,
                    # Fagor G30) [GK: Siemens Fundamentals, polar coordinates]
                    c1, c2 = self.pole or (0.0, 0.0)
                    err = arcs.check_center(s1, s2, e1, e2, c1, c2, inch)
                    if err:
                        raise arcs.ArcError(err)
                    self._move("arc", end, (c1, c2), cw, nturns)
                    return
                if not cvals:
                    raise arcs.ArcError("arc without centre or radius")
                c1, c2 = s1, s2
                cd = {a: v for a, v, _ in cvals}
                absolute = {a: (m == "abs") if m else st.arc_absolute for a, _, m in cvals}
                ci = {"X": "X", "Y": "Y", "Z": "Z", "I": "X", "J": "Y", "K": "Z"}
                for a, v in cd.items():
                    ax = ci.get(a, a)
                    if ax == a1:
                        c1 = v if absolute[a] else s1 + v
                    elif ax == a2:
                        c2 = v if absolute[a] else s2 + v
                err = arcs.check_center(s1, s2, e1, e2, c1, c2, inch)
                if err:
                    raise arcs.ArcError(err)
        except arcs.ArcError as ex:
            self.diag("NC203", "error", str(ex))    # the controller alarms: no motion
            if st.diameter:
                self._radius_x_check(vals, center, radius, cw)
            return
        self._move("arc", end, (c1, c2), cw, nturns)

    def _h_home(self, s: n.HomeReturn):
        """G28/G30: rapid to the intermediate point, then to the reference point (machine 0 for
        every reference point, as LinuxCNC's default #5161.. / #5181..) on the named axes;
        with no axis words every axis goes home directly."""
        vals = self._eval_words(self._words(s.via))
        if polar_input.guard(self, vals, "a home return through an intermediate point"):
            return
        if vals:
            self._move("rapid", self._target(vals))
            axes = [a for a, _, _ in vals]
        else:
            axes = list(self.mpos)
        tot = self.off.total
        mend = dict(self.mpos)
        for a in axes:
            mend[a] = 0.0
        self._move("rapid", self.frame.to_program({a: v - tot.get(a, 0.0) for a, v in mend.items()}))
