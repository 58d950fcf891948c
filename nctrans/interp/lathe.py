"""Lathe semantics of the interpreter: diameter programming, constant surface speed, turning cycles.

A mixin of nctrans.interp.interpreter.Interpreter (the interpreter calls in at a few places: word
evaluation, moves, spindle speed, cycle calls, control flow). The toolpath convention: records hold
the physical X position, the radius, whatever the source's programming mode; diameter programming
(ISO-T X/U, Sinumerik DIAMON) is a property of the source, undone when a word is evaluated.

Constant surface speed (ModeChange spindle_mode css): on a lathe machine, or in diameter mode,
S is a surface speed (m/min, ft/min under inch) and the spindle speed is derived from the X radius
at the end of each move, clamped by the programmed maximum (SpindleLimit: ISO-T G50 S, Sinumerik
LIMS=) and by the machine's max_rpm; each change is a spindle record, and moves carry it.

Turning cycles (CycleCall kinds in TURNING_KINDS) expand into real passes (geometry in
nctrans.interp.turning). G70-G73 read their contour blocks N<P>..N<Q> from the running body: the
first block numbered P after the cycle block, else the first in the body (the controller's sequence
search), then the first block numbered Q from there on. Roughing (G71/G72/G73) then continues after
the Q block, as the control does; G70 runs the contour as programmed (its F, S and tool-nose
compensation apply) and continues after its own block.
"""
from __future__ import annotations

import copy
import math
from typing import Optional

from nctrans.interp import corner_elements, thread_starts, turning
from nctrans.ir import nodes as n

TURNING_KINDS = frozenset(("finish", "rough_turn", "rough_face", "pattern_repeat", "face_peck",
                           "groove_peck", "thread_multi", "box_turn", "box_thread", "box_face"))
CONTOUR_KINDS = frozenset(("finish", "rough_turn", "rough_face", "pattern_repeat"))
# Modal groups a contour's blocks may change while nctrans reads their geometry
_GEOMETRY_GROUPS = frozenset(("motion", "distance", "units", "plane", "diameter", "arc_distance"))
_KIND_CODE = {"finish": "G70", "rough_turn": "G71", "rough_face": "G72", "pattern_repeat": "G73",
              "face_peck": "G74", "groove_peck": "G75", "thread_multi": "G76", "box_turn": "G90",
              "box_thread": "G92", "box_face": "G94"}


class LatheMixin:
    """Lathe state lives in class-level defaults until a lathe program first sets it."""
    capture: Optional[list] = None          # moves collected while a contour is read
    css_surface: Optional[float] = None     # m/min while constant surface speed is on
    css_limit: Optional[float] = None       # rpm (G50 S / LIMS=)
    turning_first: Optional[dict] = None    # kind -> parameters of the two-block form's first block

    # ------------------------------------------------------------------ spindle
    def _css_applies(self) -> bool:
        return getattr(self.machine, "kind", "mill") == "lathe" or self.st.diameter

    def _css_rpm(self, x: float) -> float:
        limit = self.css_limit
        mx = getattr(getattr(self.machine, "spindle", None), "max_rpm", None)
        if mx and (limit is None or mx < limit):
            limit = mx
        r = abs(x) / 1000.0
        rpm = self.css_surface / (2 * math.pi * r) if r > 1e-9 else math.inf
        if limit is not None:
            rpm = min(rpm, limit)
        if math.isinf(rpm):
            self.diag("NC233", "warning", "constant surface speed at X0 with no maximum spindle "
                      "speed (G50 S / LIMS=) and no machine max_rpm: the speed is unbounded; "
                      "analysed as the last speed")
            return self.st.spindle_speed or 0.0
        return round(rpm, 6)

    def _css_speed_word(self, v: float) -> float:
        """S under G96: remember the surface speed, return the spindle speed at the current X."""
        self.css_surface = v * (0.3048 if self.st.scale != 1.0 else 1.0)
        return self._css_rpm(self.pos.get("X", 0.0))

    def _css_mode(self, value: str) -> None:
        st = self.st
        if value == "css" and not self._css_applies():
            self.diag("NC220", "warning", "constant surface speed is not modelled on a mill (no "
                      "radius to derive the speed from): spindle speeds are the programmed S values")
        elif value == "css":
            if st.spindle_speed is not None and self.css_surface is None:
                self.css_surface = st.spindle_speed * (0.3048 if st.scale != 1.0 else 1.0)
        elif value == "rpm":
            self.css_surface = None

    def _css_move(self, end: dict) -> None:
        """Before a move under constant surface speed: the spindle speed at its end point."""
        rpm = self._css_rpm(end.get("X", 0.0))
        st = self.st
        if rpm != st.spindle_speed:
            st.spindle_speed = rpm
            if st.spindle_dir in ("cw", "ccw"):
                self._record("spindle", spindle_dir=st.spindle_dir, spindle=rpm)

    def _h_spindle_limit(self, s: n.SpindleLimit):
        v = self._value(self.ev.compile(s.value), "maximum spindle speed")
        if v is None:
            return
        if v <= 0:
            self.diag("NC105", "error", f"maximum spindle speed {v:g} is not positive")
            return
        self.css_limit = v
        if self.css_surface is not None:
            self._css_move(self.pos)

    # ------------------------------------------------------------------ tool-nose compensation
    def _compensator(self, side: str, r: float):
        """G41/G42: on a lathe in the ZX plane the tool nose (nctrans.interp.nose: the records hold
        the imaginary tip of the offset's tip direction); elsewhere the cutter centre."""
        from nctrans.interp.cutter_comp import CutterCompensator
        plane = self.st.plane
        if plane != "ZX" or not self._css_applies():
            return CutterCompensator(side, r, plane)
        from nctrans.interp.nose import NoseCompensator
        index = self.st.radius_index or 0
        finder = getattr(self.machine, "tip_direction", None)
        tip = finder(index) if finder is not None else None
        if tip is None:
            self.diag("NC235", "warning", f"tool-nose radius compensation with offset {index} "
                      f"(nose radius {r:g}) and no tip direction in the machine's tool table: "
                      "the nose centre is taken as the programmed point (tip 0)")
            tip = 0
        return NoseCompensator(side, r, tip, plane)

    # ------------------------------------------------------------------ radius among diameters
    def _radius_x_check(self, vals, center, radius, cw) -> None:
        """An arc that fails in diameter mode but closes with its X word read as a radius: the
        word was most likely written as a radius among diameters (NC234, with the evidence)."""
        from nctrans.interp import arcs
        xs = [(a, v, m) for a, v, m in vals if a == "X"]
        if not xs or xs[0][2] == "inc":
            return
        as_radius = [(a, v * 2 if a == "X" else v, m) for a, v, m in vals]
        end = self._target(as_radius)
        s1, s2 = self.pos.get("Z", 0.0), self.pos.get("X", 0.0)
        e1, e2 = end.get("Z", 0.0), end.get("X", 0.0)
        inch = self.st.scale != 1.0
        try:
            if radius is not None:
                r = self._value(radius, "arc radius")
                if r is None:
                    return
                arcs.center_from_radius(s1, s2, e1, e2, r * self.st.scale, cw, inch)
            else:
                cd = {a: v for a, v, _ in self._eval_words(center)}
                c1, c2 = s1 + cd.get("K", 0.0), s2 + cd.get("I", 0.0)
                if arcs.check_center(s1, s2, e1, e2, c1, c2, inch):
                    return
        except arcs.ArcError:
            return
        written = xs[0][1] * 2 / self.st.scale
        self.diag("NC234", "warning", f"X{written:g} reads as a radius among diameters: the arc closes "
                  f"with X{2 * written:g} (diameter), not with X{written:g}")

    # ------------------------------------------------------------------ cycles
    def _turning_cycle(self, s: n.CycleCall):
        """A turning cycle: parameters of a first block are stored; the rest is control (it needs
        the running body to find its contour), see _turning_control."""
        if s.name == "parameters":
            vals = self._turning_values(s)
            if self.turning_first is None:
                self.turning_first = {}
            self.turning_first.setdefault(s.kind, {}).update(vals)
            return None
        return ("turning", s)

    def _turning_values(self, s: n.CycleCall) -> dict:
        out = {}
        for k, e in s.params.items():
            v = self._value(self.ev.compile(e), f"{_KIND_CODE.get(s.kind, s.kind)} {k}")
            if v is not None:
                out[k] = v
        return out

    def _turning_control(self, s: n.CycleCall, unit, pc, sidx):
        """Run a turning cycle; returns where the interpreter continues (unit, code, pc, sidx)."""
        resume = (unit, unit.code, pc, sidx)
        if s.kind == "milling":                 # Sinumerik cycles along a contour subprogram
            if s.name.upper() == "CYCLE72":
                from nctrans.interp.contour_milling import run_cycle72
                run_cycle72(self, s, unit, pc)
            else:
                from nctrans.interp.stock_removal import run_cycle95
                run_cycle95(self, s, unit, pc)
            return resume
        vals = self._turning_values(s)
        first = (self.turning_first or {}).get(s.kind, {})
        if s.kind in CONTOUR_KINDS:
            found = self._contour_blocks(vals, unit, pc)
            if found is None:
                return resume
            blocks, q_pc = found
            if s.kind == "finish":
                self._finish(blocks)
                return resume
            done = self._rough(s.kind, vals, first, blocks)
            return (unit, unit.code, q_pc + 1, 0) if done else resume
        opts = self._options()
        L = self.st.scale
        start = (self.pos.get("X", 0.0), self.pos.get("Z", 0.0))
        target = self._cycle_target(vals)
        if s.kind in ("box_turn", "box_thread", "box_face"):
            taper = vals.get("taper", 0.0) * L
            if s.kind == "box_face":
                moves = turning.box_turn(start[::-1], target[::-1], taper)
                self._emit_turning(moves, swap=True)
            elif s.kind == "box_thread" and "start_angle" in vals:
                # Q: the start angle of the cycle's thread, in 0.001 degree (Fanuc G92 [GK], as
                # G32's Q, seed 4.1.16), kept with the modal cycle's data as F and R are [NC];
                # the setting in force (SF=) again after it
                saved = self.thread_start
                self.thread_start = vals["start_angle"] / 1000.0 % 360.0
                try:
                    self._emit_turning(turning.box_thread(start, target, taper))
                finally:
                    self.thread_start = saved
            else:
                fn = turning.box_turn if s.kind == "box_turn" else turning.box_thread
                self._emit_turning(fn(start, target, taper))
            return resume
        if s.kind in ("face_peck", "groove_peck"):
            retract = first.get("retract")
            retract = retract * L if retract is not None else float(opts.get("peck_retract_mm", 0.5))
            px, pz = vals.get("peck_x", 0.0) * L, vals.get("peck_z", 0.0) * L
            if vals.get("relief"):
                self.diag("NC232", "warning", f"{_KIND_CODE[s.kind]} bottom relief is not modelled")
            if s.kind == "groove_peck":
                self._emit_turning(turning.peck_passes(start, target, px, pz, retract))
            else:
                self._emit_turning(turning.peck_passes(start[::-1], target[::-1], pz, px, retract),
                                   swap=True)
            return resume
        if s.kind == "thread_multi":
            self._thread(vals, first, start, target, opts)
        return resume

    def _options(self) -> dict:
        meta = self.program.meta if isinstance(self.program.meta, dict) else {}
        return meta.get("options") or {}

    def _cycle_target(self, vals: dict) -> tuple[float, float]:
        L = self.st.scale
        fx = 0.5 if self.st.diameter else 1.0
        x, z = self.pos.get("X", 0.0), self.pos.get("Z", 0.0)
        if "x" in vals:
            x = vals["x"] * L * fx
        elif "x_inc" in vals:
            x += vals["x_inc"] * L * fx
        if "z" in vals:
            z = vals["z"] * L
        elif "z_inc" in vals:
            z += vals["z_inc"] * L
        return x, z

    def _thread(self, vals, first, start, target, opts) -> None:
        L = self.st.scale
        passes = int(opts.get("thread_finish_passes", 0))
        angle = float(opts.get("thread_angle", 0.0))
        mode = first.get("mode")
        chamfer = 0
        if mode is not None:                  # Fanuc P mmrraa: rr = pull-out in tenths of the lead
            m = int(round(mode))
            passes, chamfer, angle = m // 10000, (m // 100) % 100, float(m % 100)
        if "angle" in vals:
            angle = vals["angle"]
        height = vals.get("height", 0.0) * L
        depth1 = vals.get("first_depth", 0.0) * L
        if height <= 0 or depth1 <= 0:
            self.diag("NC130", "error", "G76 needs a thread height and a first depth of cut")
            return
        depths = turning.thread_depths(height, depth1, first.get("min_depth", 0.0) * L,
                                       first.get("finish_allow", 0.0) * L, passes)
        pull = chamfer * 0.1 * (self.st.feed or 0.0)
        rise = math.tan(math.radians(float(opts.get("thread_chamfer_angle", 45.0))))
        self._emit_turning(turning.thread_passes(start, target, height, depths,
                                                 vals.get("taper", 0.0) * L, angle, pull, rise))

    # ------------------------------------------------------------------ contours
    def _contour_blocks(self, vals: dict, unit, pc):
        from nctrans.interp.compiled import BLOCK, label_key
        code_name = "G70-G73"
        if "start" not in vals or "end" not in vals:
            self.diag("NC130", "error", f"{code_name} without P and Q (first and last contour block)")
            return None
        p_label, q_label = label_key(int(vals["start"])), label_key(int(vals["end"]))
        p_pc = self._find_label(unit, p_label, "any", pc)
        if p_pc is None:
            self.diag("NC102", "error", f"contour start N{p_label} (P) not found")
            return None
        q_pc = self._find_label(unit, q_label, "forward", p_pc - 1)
        if q_pc is None:
            self.diag("NC102", "error", f"contour end N{q_label} (Q) not found after N{p_label}")
            return None
        blocks = []
        for i in range(p_pc, q_pc + 1):
            ins = unit.code[i]
            if ins[0] != BLOCK:
                self.diag("NC133", "error", f"control flow inside the contour N{p_label}..N{q_label}")
                return None
            blocks.append(ins[2])
        return blocks, q_pc

    def _capture_contour(self, blocks) -> Optional[list]:
        """The moves of the contour blocks in program coordinates, read without moving the tool:
        (kind, start, end, centre, cw, span, block)."""
        saved = (self.pos, self.mpos, self.st, self.span, self.last_from, self.last_arc,
                 self.css_surface)
        st = copy.copy(self.st)
        st.groups = dict(self.st.groups)
        self.st = st
        self.css_surface = None
        self.capture = []
        ok = True
        try:
            for blk in blocks:
                self.span = blk.span
                before = len(self.capture)
                for s in blk.body:
                    t = type(s)
                    if t is n.Motion:
                        self._h_motion(self._c_motion_full(s))
                    elif t is n.ModeChange and s.group in _GEOMETRY_GROUPS:
                        self._h_mode(s)
                    elif t in (n.CycleCall, n.SubCall, n.Goto, n.Return, n.ProgramEnd):
                        self.diag("NC133", "error", "a cycle, call, jump or end inside a P..Q "
                                  "contour: the control alarms")
                        ok = False
                for i in range(before, len(self.capture)):
                    self.capture[i] = self.capture[i] + (blk,)
        finally:
            moves, self.capture = self.capture, None
            if ok and moves:                # RND / CHR / ,R / ,C in the contour (corner_elements)
                moves = corner_elements.apply_to_contour(self, blocks, moves)
            (self.pos, self.mpos, self.st, self.span, self.last_from, self.last_arc,
             self.css_surface) = saved
        return moves if ok else None

    def _finish(self, blocks) -> None:
        """G70: the contour as programmed, then back to the start point."""
        start = dict(self.pos)
        here = self.span
        for blk in blocks:
            self.span = blk.span
            for h, data in self._compile_block(blk):
                if type(data) is n.CycleCall or type(data) is n.SubCall:
                    self.diag("NC133", "error", "a cycle or call inside a G70 contour")
                    continue
                h(data)
        self.span = here
        self._emit_turning(turning.return_to((start["X"], start["Z"]),
                                             (self.pos.get("X", 0.0), self.pos.get("Z", 0.0))))

    def _rough(self, kind, vals, first, blocks) -> bool:
        """G71 / G72 / G73 roughing. False when the cycle alarms (nothing moved)."""
        moves = self._capture_contour(blocks)
        if not moves:
            if moves is not None:
                self.diag("NC130", "error", "the P..Q contour has no moves")
            return False
        st = self.st
        L = st.scale
        fx = 0.5 if st.diameter else 1.0
        opts = self._options()
        code = _KIND_CODE[kind]
        swap = kind == "rough_face"
        allow_x = vals.get("allow_x", 0.0) * L * fx
        allow_z = vals.get("allow_z", 0.0) * L
        if vals.get("rough_allow_x") or vals.get("rough_allow_z"):
            self.diag("NC232", "warning", f"{code} I/K rough-pass allowance is not modelled")

        def dp(pt):
            return (pt[2], pt[0]) if swap else (pt[0], pt[2])

        def conv(m):
            kind_, start, end, center, cw, span, blk = m
            e = (end["Z"], end["X"]) if swap else (end["X"], end["Z"])
            c = None
            if center is not None:                  # (Z, X) in the ZX plane
                c = (center[0], center[1]) if swap else (center[1], center[0])
            return (kind_, e, c, (not cw) if (swap and cw is not None) else cw)

        a = (self.pos.get("X", 0.0), self.pos.get("Z", 0.0))
        a = a[::-1] if swap else a
        approach, rest = moves[0], moves[1:]
        first_blk = approach[6]
        if approach[6] is not blocks[0]:             # the P block itself does not move
            self.diag("NC130", "error", f"{code}: the first contour block (P) has no move")
            return False
        app = conv(approach)
        contour = [conv(m) for m in rest]
        type2 = vals.get("type") == 1.0 or _both_axes(first_blk)
        bad = turning.first_non_monotonic(app[1], contour)
        axis, along = ("Z", "X") if swap else ("X", "Z")
        if type2 and kind != "pattern_repeat":
            inner = turning.inside_stock(a, app[1], contour)
            back = turning.first_non_monotonic((app[1][1], app[1][0]), turning.swapped(inner))
            if back is not None:
                self.diag("NC230", "error", f"{code} type II contour turns back in {along} here: "
                          f"the profile must be monotonic in {along}; the control alarms",
                          rest[back][5])
                return False
        if bad is not None and kind != "pattern_repeat":
            where = rest[bad][5]
            if not type2:
                self.diag("NC230", "error", f"{code} type I contour is not monotonic in {axis} "
                          "here: the control alarms (type II needs both X and Z in the P block)",
                          where)
                return False
            self.diag("NC231", "info", f"{code} type II contour with pockets: each pocket is roughed "
                      "level by level after the outer levels; the moves between pockets are nctrans's "
                      "model", where)
        dd, dp_ = (allow_z, allow_x) if swap else (allow_x, allow_z)
        shifted_contour = turning.shifted(contour, dd, dp_)
        app_end = (app[1][0] + dd, app[1][1] + dp_)
        out = []
        if kind == "pattern_repeat":
            n_pass = vals.get("passes", first.get("passes", 1.0))
            n_pass = max(1, int(round(n_pass)))
            rx = vals.get("relief_x", first.get("relief_x", 0.0)) * L
            rz = vals.get("relief_z", first.get("relief_z", 0.0)) * L
            rd, rp = (rz, rx) if swap else (rx, rz)
            for j in range(n_pass):
                frac = (n_pass - 1 - j) / (n_pass - 1) if n_pass > 1 else 0.0
                od, op = dd + rd * frac, dp_ + rp * frac
                out.append((app[0] if app[0] != "arc" else "linear",
                            (app[1][0] + od, app[1][1] + op), None, None))
                out.extend(turning.shifted(contour, od, op))
                out.extend(turning.return_to(a, out[-1][1]))
        else:
            depth = vals.get("depth", first.get("depth"))
            if depth is None or depth <= 0:
                self.diag("NC130", "error", f"{code} without a depth of cut (D, or U/W of the first "
                          "block)")
                return False
            retract = first.get("retract")
            retract = retract * L if retract is not None else float(opts.get("rough_retract_mm", 0.5))
            if bad is not None:                     # type II with pockets
                inner = turning.inside_stock(a, app_end, shifted_contour)
                out.extend(turning.rough_pockets(a, app_end, inner, depth * L, retract))
            else:
                out.extend(turning.rough_levels(a, app_end, shifted_contour, depth * L, retract))
            out.append((app[0] if app[0] != "arc" else "linear", app_end, None, None))
            out.extend(shifted_contour)
            out.extend(turning.return_to(a, out[-1][1]))
        self._emit_turning(out, swap=swap)
        return True

    def _emit_turning(self, moves, swap: bool = False) -> None:
        """Moves in (d, p) radius coordinates -> toolpath records (through the normal move path)."""
        st = self.st
        for kind, end_dp, center, cw in moves:
            x, z = (end_dp[1], end_dp[0]) if swap else end_dp
            end = dict(self.pos)
            end["X"], end["Z"] = x, z
            if kind == "rapid":
                self._move("rapid", end)
            elif kind == "linear":
                self._need_feed()
                self._move("linear", end)
            elif kind == "thread":
                mode = st.feed_mode
                st.feed_mode = "per_rev"            # F is the lead
                self._need_feed()
                mark = len(self.out)
                self._move("linear", end)
                st.feed_mode = mode
                # a thread cut: spindle-synchronised (the record carries the lead, as G32's do),
                # never a plain feed per revolution (--flatten writes it as a thread move)
                for rec in self.out[mark:]:
                    rec.pitch = st.feed
                thread_starts.stamp(self, mark)
            else:
                cx, cz = (center[1], center[0]) if swap else center
                self._move("arc", end, (cz, cx), (not cw) if swap else cw, 0)


def _both_axes(block) -> bool:
    """Type II stock removal: the P block names both X(U) and Z(W)."""
    for s in block.body:
        if type(s) is n.Motion and "X" in s.target and "Z" in s.target:
            return True
    return False
