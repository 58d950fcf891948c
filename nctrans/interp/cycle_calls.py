"""Running canned cycles: ISO modal drilling cycles (G81..G89 with their hole positions), Sinumerik
cycle calls (CYCLE81.., MCALL), hole patterns (HOLES1/HOLES2/CYCLE801), tapping and deep-hole
infeeds, CYCLE800 swivel planes, and a cycle's own code found beside the program. What a cycle
does, step by step, is nctrans.interp.cycles (and turning cycles lathe.py); this module feeds it
the call's values and turns its steps into moves. A mixin of Interpreter.
"""
from __future__ import annotations

from typing import Any, Optional

from nctrans.interp import contour_tables
from nctrans.interp.compiled import BLOCK, Unit
from nctrans.interp.cycles import (coarse_pitch, cycle_problems, cycle_table, deep_hole_steps,
                                   expand_cycle, hole_pattern, plane_cycle_levels, swivel_plan, tap_steps)
from nctrans.interp.evaluate import UNKNOWN
from nctrans.interp.frames import PLANE_AXES
from nctrans.interp.lathe import TURNING_KINDS
from nctrans.interp.milling_cycles import run_milling_cycle
from nctrans.ir import nodes as n
from nctrans.ir.walk import constant

# refusals of a cycle call at its line: it moved nothing (NC206 a required value missing, NC224 a
# variant not modelled, NC225 a call the control would refuse)
CALL_REFUSED = frozenset(("NC206", "NC224", "NC225"))
CYCLE_LENGTH_KEYS = frozenset(("bottom", "r_plane", "retract_plane", "safety", "peck", "shift",
                               "depth_rel", "first_peck", "decrement", "min_peck", "relief"))


class CycleCallsMixin:
    """Cycle parameters, calls and hole positions."""

    def _cycles_table(self) -> dict:
        """Compilers of cycle parameter and cycle call statements."""
        return {
            n.CycleParams: lambda s: (self._h_cycle_params, s),
            n.CycleCall: lambda s: (self._h_cycle_call, s),
        }

    def _cycle_off(self) -> None:
        self.st.set("cycle", "off")
        self.cycle_params = {}
        self.cycle_initial = None

    def _h_cycle_params(self, s: n.CycleParams):
        scale = self.st.scale
        for k, e in s.values.items():
            v = self._value(self.ev.compile(e), f"cycle {k}")
            if v is None:
                continue
            self.cycle_params[k] = v * scale if k in CYCLE_LENGTH_KEYS else v

    def _cycle_hole(self, vals) -> None:
        st = self.st
        plane = st.plane
        a1, a2, ax = PLANE_AXES[plane]
        p = self.cycle_params
        repeat = p.pop("repeat", 1)
        for a, v, mode in vals:
            if a == ax:
                p["bottom"] = v
        if not vals and "bottom" not in p:
            return
        missing = [k for k in ("bottom", "r_plane") if k not in p]
        if missing:
            self.diag("NC206", "error", f"canned cycle without {' and '.join(missing)}")
            return
        self._rc_cycle()
        initial = self.cycle_initial if self.cycle_initial is not None else self.pos.get(ax, 0.0)
        if st.incremental:
            zr = initial + p["r_plane"]
            zb = zr + p["bottom"]
        else:
            zr, zb = p["r_plane"], p["bottom"]
        retract = initial if st.cycle_retract == "initial" else zr
        plane_vals = [(a, v, m) for a, v, m in vals if a != ax]
        hole = self._target(plane_vals)
        hole[ax] = self.pos.get(ax, 0.0)
        step = None
        if st.incremental:
            step = {a: v for a, v, m in plane_vals if m != "abs"}
        self._questionable_cycle(st.cycle, zr, zb, p, repeat)
        self._expand(st.cycle, hole, zr, zb, retract, p, int(round(repeat)), step)

    def _questionable_cycle(self, kind: str, approach: float, bottom: float, p: dict, repeat) -> None:
        """NC132 at the line: values a control rejects or reads in its own way (an R plane beyond
        the bottom, G83 with no peck depth Q, G76 with no shift Q, G89 with no dwell P, a tap
        against the spindle's direction). The seed does not say what the control does with them
        and LinuxCNC stops with an error; nctrans runs its own reading, so it is said, never
        silent. A stopped spindle is NC209's, at the first feed move."""
        problems = cycle_problems(kind, approach=approach, bottom=bottom, peck=p.get("peck"),
                                  dwell_s=p.get("dwell"), shift=p.get("shift"),
                                  spindle_dir=self.st.spindle_dir, repeat=int(round(repeat)))
        if self.spindle_stopped:
            problems = [x for x in problems if not x.startswith("spindle")]
        if problems:
            self.diag("NC132", "warning", f"canned cycle {kind}: {'; '.join(problems)} (a control may "
                      "alarm here; the analysed motion is nctrans' reading of these values)")

    def _cycle_rule(self, name: str) -> str:
        """A dialect/profile rule of rules/cycles.toml (`position_at`, `tap_end`), looked up once
        per run: the cycle table's method of that name for this program's dialect and profile."""
        rules = self.__dict__.setdefault("_cycle_rules", {})
        if name not in rules:
            rules[name] = getattr(cycle_table(), name)(self.program.dialect,
                                                       self.program.meta.get("profile"))
        return rules[name]

    def _expand(self, kind, hole, approach, bottom, retract, p, repeat=1, step=None,
                steps=None, own: Optional[dict] = None) -> None:
        st = self.st
        seed_tap = steps is None and kind in ("tap", "tap_left") and self._cycle_rule("tap_end") == "stopped"
        if seed_tap:
            # the spindle an earlier hole's tap stopped is turned by this one (rules [tapping]);
            # one the program stopped (M5, a tool change) is not: NC209 at the feed in, and at
            # each later hole while no M3/M4 is programmed (the control's alarm is per call)
            turns = bool(self.spindle_stopped_by_tap and self.spindle_stopped)
            programmed = turns or not self.spindle_stopped
            own = {**(own or {}), "tap_end": "stopped",
                   "tap_turns": True if turns else (False if programmed else None)}
        feed = p.get("feed")
        feed = feed * st.feed_scale if feed is not None else (st.feed or 0.0)
        if not feed:
            self._need_feed()
        if repeat < 1:
            return
        if steps is None:
            steps = expand_cycle(kind, plane=st.plane, position=dict(self.pos), hole=hole,
                                 approach=approach, bottom=bottom, retract=retract,
                                 peck=p.get("peck"), dwell_s=p.get("dwell"), shift=p.get("shift"),
                                 feed=feed, spindle_dir=(own or {}).get("spindle_dir", st.spindle_dir),
                                 units_mm=st.scale == 1.0, repeat=repeat, step=step,
                                 position_at=self._cycle_rule("position_at"),
                                 **{k: v for k, v in (own or {}).items() if k != "spindle_dir"})
        elif callable(steps):
            steps = steps(feed)
        pitch = None
        if kind in ("tap", "tap_left"):
            pitch = p.get("pitch")
            if pitch is None:
                pitch = feed if st.feed_mode == "per_rev" else (
                    feed / st.spindle_speed if st.spindle_speed else None)
        saved = st.feed
        st.feed = feed
        turned = None       # (direction, speed) of a spindle step just recorded, nothing since
        try:
            for s in steps:
                k = s[0]
                if k == "spindle":
                    now = (s[1], s[2] if len(s) > 2 else st.spindle_speed)
                    if now == turned:
                        continue    # CYCLE84: G332's return to cw, then SDAC cw at the same speed
                    turned = now
                else:
                    turned = None
                if k in ("rapid", "linear"):
                    pt = dict(self.pos)
                    pt.update(s[1])
                    if k == "linear":
                        said = self._standing_cut(kind)
                        if seed_tap and self.spindle_stopped and not self.spindle_reported:
                            alarm = cycle_table().tapping_alarm.get(self.program.dialect)
                            said = ("tapping with no spindle direction in force (M5, or a tool change "
                                    "that stops the spindle): the tap is fed in with the spindle "
                                    "standing and breaks; program M3/M4 before the cycle"
                                    + (f"; {alarm}" if alarm else ""))
                        self._spindle_standing(said)
                    mark = len(self.out)
                    self._move(k, pt)
                    if pitch is not None and k == "linear":
                        for rec in self.out[mark:]:
                            rec.pitch = pitch     # tapping: the feed is the spindle's times the lead
                elif k == "feed":
                    st.feed = s[1]
                elif k == "dwell":
                    self._record("dwell", dwell_s=float(s[1] or 0.0))
                elif k == "spindle":         # the cycle turns it (tapping reversal, CYCLE84 SDAC, SST)
                    st.set("spindle", s[1])
                    if len(s) > 2:
                        st.spindle_speed = s[2]
                    stops = s[1] in ("off", "orient")
                    if stops and not self.spindle_stopped:
                        self.spindle_reported = False   # a fresh stop by the cycle (SDAC 5): NC209 again
                    self.spindle_stopped = stops
                    self._record("spindle", spindle_dir=s[1], spindle=st.spindle_speed)
                elif k == "stop":
                    self._record("stop", stop_kind="stop")
        finally:
            st.feed = saved
        if seed_tap:
            self.spindle_stopped_by_tap = self.spindle_stopped and programmed
        if kind == "bore_manual":        # the operator retracted by hand (see cycles.py)
            ax = PLANE_AXES[st.plane][2]
            pos = dict(self.pos)
            pos[ax] = max(retract, approach) if approach >= bottom else min(retract, approach)
            self.pos = pos
            self.mpos = self._to_machine(pos)

    @staticmethod
    def _standing_cut(kind: str) -> str:
        """NC209's text for a cycle model's feed move with the spindle the program (M5, a tool
        change that stops it) or an earlier hole's cycle (CYCLE840 SDAC 5) left standing, said at
        the cycle's line (the call, or the MCALL/modal position). A cycle that turns the spindle
        itself first (CYCLE84: G331, rigid_tap) never gets here; CYCLE840 turns it back at the
        depth and SDAC 5 stops it anew, so each such position is said."""
        if kind in ("tap", "tap_left"):
            return ("tapping with the spindle stopped (M5, a tool change that stops it, or an "
                    "earlier hole's SDAC 5 under MCALL): this tapping cycle feeds the tap in without "
                    "turning the spindle first, so the tap breaks; start the spindle (M3/M4) before "
                    "the cycle, or end the earlier tap with SDAC 3/4")
        return ("cycle feed move while the spindle is stopped (M5, or a tool change that stops it): "
                "the tool would rub or break; start the spindle (M3/M4) before the cycle")

    def _h_cycle_call(self, s: n.CycleCall):
        if self.contour_table is not None:      # a cycle among a contour table's blocks
            contour_tables.refuse_cycle(self, s.name or s.kind)
            return None
        if s.kind in TURNING_KINDS:
            return self._turning_cycle(s)
        if s.name and s.kind != "swivel_plane" and self._find_unit(s.name) is not None:
            return self._cycle_code(s)
        self._omitted_retract_plane(s)
        filled = self._omitted_from_state(s)
        self._unmodelled_params(s)
        self._inch_defaults(s)
        if filled is None:
            return self._dispatch_cycle_call(s)
        # NC128 after the call has run: a call refused at its line (NC206 no depth, NC224/NC225
        # not modelled) moved nothing, so what the analysis took for its omitted values is moot
        span, mark = self.span, len(self.diags)
        line = span.line if span is not None else 0
        result = self._dispatch_cycle_call(s)
        if not any(d.rule in CALL_REFUSED and d.line == line for d in self.diags[mark:]):
            self.diag("NC128", "warning", filled, span)
        return result

    def _dispatch_cycle_call(self, s: n.CycleCall):
        if s.kind in ("holes_line", "holes_circle", "holes_grid"):
            return self._hole_pattern(s)
        if s.kind == "swivel_plane":
            self._swivel_plane(s)
            return
        if s.kind == "milling" and (s.name or "").upper() in ("CYCLE95", "CYCLE72"):
            return ("turning", s)           # reads its contour from the running body (lathe.py)
        if s.kind == "milling":
            return run_milling_cycle(self, s)
        if s.modal:
            self.modal_cycle = s
            return
        self._run_cycle_call(s)

    def _omitted_retract_plane(self, s: n.CycleCall) -> None:
        """A built-in cycle model called with RTP left out: the cycle is a subprogram and sees
        the omitted argument as 0 (seed L4722), so it retracts to 0, as modelled. That is almost
        always a slip (the tool crosses to the next hole at the workpiece zero), so say it at the
        line (NC127), once per call statement (an MCALL's holes are one call)."""
        if "retract_plane" in s.params or not s.name:
            return
        name = s.name.upper()
        spec = ({c.name: c for c in cycle_table().cycle} | {m.name: m for m in cycle_table().milling}).get(name)
        if spec is None or "RTP" not in spec.params:
            return
        axis = PLANE_AXES[self.st.plane][2]
        self.diag("NC127", "warning", f"{name} with RTP (retract plane) omitted: the cycle sees an "
                  f"omitted parameter as 0 (seed L4722), so it retracts to {axis}0 (or to RFP+SDIS "
                  f"where that is higher) as the control does, not to the height it started from "
                  f"({axis}{self.pos.get(axis, 0.0):g}); give RTP")

    def _omitted_from_state(self, s: n.CycleCall) -> Optional[str]:
        """Parameters a built-in model takes from the program's state when the call leaves them
        out or gives 0, where the control's cycle sees 0 (rules/cycles.toml [omitted_from_state]):
        the NC128 message said at the line (once per call statement), or None."""
        table = cycle_table()
        fills = table.omitted_from_state.get((s.name or "").upper())
        if not fills:
            return None
        taken = []
        for name, instead in fills.items():
            e = s.params.get(table.neutral(name))
            c = None if e is None else constant(e)
            if e is None or (c is not None and c == 0):
                taken.append(f"{name} as {instead}")
        if taken:
            return (f"{s.name.upper()} with {', '.join(n_.split(' as ')[0] for n_ in taken)} "
                      f"omitted or 0: the control's cycle sees 0 (seed L4722) and stops or uses a default "
                      f"of its own; the analysis takes {'; '.join(taken)}. The path is the same, its feed, "
                    "time or spindle may not be the machine's; give the value")
        return None

    def _unmodelled_params(self, s: n.CycleCall) -> None:
        """A parameter the built-in model does not read, given a value at which the control's
        cycle moves otherwise (rules/cycles.toml [unmodelled_param]): said at the line (NC239),
        once per call statement; the path is the model's without it."""
        table = cycle_table()
        for name, entry in table.unmodelled_param.get((s.name or "").upper(), {}).items():
            e = s.params.get(table.neutral(name))
            v = None if e is None else self._value(self.ev.compile(e), f"{s.name} {name}")
            when = entry.get("when")
            applicate = "XYZ".index(PLANE_AXES[self.st.plane][2]) + 1
            own_unit = 1 if self.st.scale == 1.0 else 3
            if v is not None and ((when == "nonzero" and v != 0)
                                  or (when == "not_applicate" and v not in (0, applicate))
                                  or (when == "not_program_unit" and v not in (0, own_unit))):
                self.diag("NC239", "warning", f"{s.name.upper()} with {name} {v:g}: {entry['meaning']} is not "
                          f"modelled [GK]; the analysed path is {entry['modelled']}, which the control's "
                          "cycle does not run. Give its PROC beside the program to run it")

    def _inch_defaults(self, s: n.CycleCall) -> None:
        """A built-in distance of a turning model (rules/cycles.toml [inch_default]: "0: 1 mm")
        taken in an inch program: the model keeps 1 mm; whether the control's cycle means 1 inch
        there is not documented [GK], so it is said at the call (NC419), once per call."""
        if self.st.scale == 1.0:
            return
        table = cycle_table()
        name = (s.name or "").upper()
        for param, what in table.inch_default.get(name, {}).items():
            e = s.params.get(table.neutral(param))
            c = None if e is None else constant(e)
            if e is None or c == 0:
                self.diag("NC419", "warning", f"{name} with {param} omitted or 0 in an inch program: "
                          f"the analysis takes {what} (the cycles manual's default [GK]); whether the "
                          "control's cycle takes 1 inch there is not documented, and the path would "
                          f"then be 24.4 mm wider. Give {param}")

    def _cycle_code(self, s: n.CycleCall):
        """A cycle whose own code is in the program or beside it (CYCLE81.SPF on the search
        path): the control runs that code, so the interpreter calls it with the call's
        arguments in their places (omitted ones as the control passes them) instead of the
        built-in model. MCALL makes it a modal call like any subprogram's."""
        table = cycle_table()
        spec = ({c.name: c for c in table.cycle} | {p.name: p for p in table.pattern}
                | {m.name: m for m in table.milling}).get(s.name.upper())
        params = list(spec.params) if spec is not None else []
        args = [s.params.get(table.neutral(p), n.Num(0.0, "")) for p in params]
        unit = self._find_unit(s.name)          # a PROC declaring fewer parameters than the table
        given = [i for i, p in enumerate(params) if table.neutral(p) in s.params]
        keep = max(len(unit.params) if unit is not None and unit.params else len(args),
                   given[-1] + 1 if given else 0)
        args = args[:keep]
        if s.modal:
            call = n.SubCall(s.name, args, modal="after_move", kind="mcall")
            self.modal_cycle = None
            self.modal_call = (call, self._call_args(call), self._depth())
            return None
        return ("call", n.SubCall(s.name, args, kind="proc"))

    def _hole_pattern(self, s: n.CycleCall):
        """Sinumerik HOLES1/HOLES2/CYCLE801: the modally called cycle at each position of the
        pattern (only positioning when no cycle is modal). Under a modal subprogram call (MCALL
        of a PROC, such as a CYCLE81.SPF beside the program) the positions run as blocks of
        their own, so the call follows each of them as it follows any block that moves."""
        pat = {p.name: p for p in cycle_table().pattern}.get((s.name or "").upper())
        if pat is None:
            self.diag("NC103", "warning", f"hole pattern {s.name or s.kind} is not known")
            return
        args = []
        for p in pat.params:
            e = s.params.get(p.lower())
            args.append(None if e is None else self._value(self.ev.compile(e), p))
        a1, a2, _ = PLANE_AXES[self.st.plane]
        sc = self.st.scale
        holes = hole_pattern(pat.name, args)
        if self.modal_call is not None and self.modal_cycle is None and holes:
            positions = Unit(pat.name, self.span.file if self.span else "", [])
            positions.code = [(BLOCK, [(self._h_pattern_position, (a1, a2, p1 * sc, p2 * sc))],
                               None, self.span) for p1, p2 in holes]
            positions.seen = bytearray(b"\x01" * len(holes))
            return ("pattern", positions)
        for p1, p2 in holes:
            hole = dict(self.pos)
            hole[a1], hole[a2] = p1 * sc, p2 * sc
            self._move("rapid", hole)        # the pattern's positioning block, even when there
            if self.modal_cycle is not None:
                self._run_modal_cycle()

    def _h_pattern_position(self, d) -> None:
        """One position of a hole pattern under a modal subprogram call: a rapid in the plane."""
        a1, a2, p1, p2 = d
        hole = dict(self.pos)
        hole[a1], hole[a2] = p1, p2
        self.moved = True
        self._move("rapid", hole)            # a positioning block, even when already there

    def _run_modal_cycle(self) -> None:
        """The modally called cycle (MCALL CYCLE81.., MCALL POCKET1..) at the current position."""
        s = self.modal_cycle
        if s.kind == "milling":
            run_milling_cycle(self, s)
        else:
            self._run_cycle_call(s)

    def _run_cycle_call(self, s: n.CycleCall, hole: Optional[dict] = None) -> None:
        st = self.st
        ax = PLANE_AXES[st.plane][2]
        params = {}
        for k, e in s.params.items():
            v = self._value(self.ev.compile(e), f"cycle {k}")
            if v is not None:
                params[k] = v * st.scale if k in CYCLE_LENGTH_KEYS else v
        if "bottom" not in params and not params.get("depth_rel"):
            self.diag("NC206", "error", f"cycle {s.name or s.kind} without a depth")
            return
        approach, bottom, retract = plane_cycle_levels(params)
        self._rc_cycle()
        steps = None
        if hole is not None and any(abs(hole.get(a, 0.0) - self.pos.get(a, 0.0)) > 0
                                    for a in PLANE_AXES[st.plane][:2]):
            self._move("rapid", {**self.pos, **{a: hole[a] for a in PLANE_AXES[st.plane][:2]}})
        hole = dict(self.pos)
        kind = s.kind
        if kind in ("peck", "chip_break") and "peck" not in params:
            steps = self._deep_hole(params, approach, bottom, retract)
        elif kind in ("tap", "tap_left"):
            kind, steps = self._tap(s, params, approach, bottom, retract)
            if steps is None:
                return
        self._expand(kind, hole, approach, bottom, retract, params, steps=steps,
                     own=self._boring_params(kind, params))

    def _boring_params(self, kind: str, p: dict) -> dict:
        """What Sinumerik's boring cycles do beyond the ISO cycle of their kind [GK, Siemens
        cycles manual]: CYCLE85 dwells DTB at the depth and feeds out at RFF; CYCLE86 lifts off by
        RPA/RPO/RPAP (increments in the abscissa, ordinate and applicate) after the oriented stop;
        CYCLE87/CYCLE88 retract with G0 after NC start. CYCLE86/87/88 bore in SDIR (3: M3, 4: M4,
        "the direction of rotation with which boring is performed") and turn the spindle on in it
        again; SDIR 0 (omitted) takes the direction in force (NC128 for CYCLE86)."""
        st = self.st
        own: dict = {}
        if kind == "bore_feed_out":
            own["dwell_feed_out"] = True
            if p.get("rff"):
                own["feed_out"] = p["rff"] * st.feed_scale
        elif kind == "fine_bore":
            a1, a2, ax = PLANE_AXES[st.plane]
            own["lift"] = {a: (p.get(k) or 0.0) * st.scale for a, k in ((a1, "rpa"), (a2, "rpo"), (ax, "rpap"))}
        elif kind == "bore_manual":
            own["manual_retract"] = True
        direction = {3: "cw", 4: "ccw"}.get(int(p.get("sdir") or 0))
        if direction and kind in ("fine_bore", "bore_manual"):
            own["bore_dir"] = direction
        return own

    def _tap(self, s: n.CycleCall, p: dict, approach: float, bottom: float, retract: float):
        """CYCLE84/CYCLE840: lead from PIT, else from the M size MPIT; its sign gives the hand;
        feed = lead * S (spindle-synchronised)."""
        st = self.st
        lead = p.get("pit") or None
        if lead is None and p.get("mpit"):
            lead = coarse_pitch(p["mpit"])
            if lead is not None and p["mpit"] < 0:
                lead = -lead
        if lead is None:
            self.diag("NC206", "error", f"{s.name or 'tapping cycle'} without a thread pitch "
                      "(PIT) or a known thread size (MPIT)")
            return s.kind, None
        kind = "tap_left" if lead < 0 else "tap"
        lead = abs(lead) * (st.scale if "pit" in p and p.get("pit") else 1.0)
        if not st.spindle_speed:
            self.diag("NC206", "error", f"{s.name or 'tapping cycle'} with no spindle speed")
            return kind, None
        p["pitch"] = lead
        # lead (mm) x S in mm/min, in the program's feed unit as _expand reads p["feed"]: under G70
        # lengths are inch but feeds stay mm/min (feed_scale 1), so it is not lead / scale
        p["feed"] = lead * st.spindle_speed / st.feed_scale
        after = {3: "cw", 4: "ccw", 5: "off"}.get(int(p.get("sdac", 0) or 0))
        before = None
        speeds = None
        if (s.name or "").upper() == "CYCLE84":     # taps with G331/G332 on the control
            from nctrans.interp.rigid_tap import spindle_state
            before = spindle_state(self)
            speeds = self._tap_speeds(p, lead)
        steps = tap_steps(plane=st.plane, approach=approach, bottom=bottom, retract=retract,
                          dwell_s=p.get("dwell"), forward="ccw" if kind == "tap_left" else "cw",
                          after=after, before=before, speeds=speeds)
        return kind, steps

    def _tap_speeds(self, p: dict, lead: float):
        """CYCLE84 SST (tapping speed) and SST1 (retraction speed; 0: SST) [GK, Siemens cycles
        manual]: (tap speed, feed), (retraction speed, feed), the speed before the call, which the
        cycle programs again at its end; None when neither differs from the speed in force (SST 0
        or omitted taps at the speed in force, NC128)."""
        st = self.st
        now = st.spindle_speed
        tap = p.get("sst") or now
        back = p.get("sst1") or tap
        if tap == now and back == now:
            return None

        def feed(speed: float) -> float:      # a ("feed", F) step is mm/min as it stands: lead (mm) x S
            return lead * speed
        return ((None, None) if tap == now else (tap, feed(tap))), (back, feed(back)), now

    def _deep_hole(self, p: dict, approach: float, bottom: float, retract: float):
        """CYCLE83 infeeds from FDEP/FDPR and DAM (cycles.deep_hole_steps)."""
        rfp = p.get("r_plane", 0.0)
        up = 1.0 if approach >= bottom else -1.0
        # FDEP left out is 0, an absolute first depth at 0, as the cycle sees it (seed L4722); FDPR
        # 0 is "not programmed", as DPR
        first = p.get("first_peck", 0.0)
        if p.get("fdpr"):               # FDPR as DPR: 0 is "not programmed" (plane_cycle_levels)
            first = rfp - up * abs(p["fdpr"] * self.st.scale)
        vari = int(p.get("vari", 0) or 0)
        vari = 1 if vari % 10 == 1 else 0
        anticipation = p.get("_dis1")     # _DIS1: re-approach distance (VARI=1), a length
        if anticipation is not None:
            anticipation *= self.st.scale
        # _DTD: dwell at the final depth [GK, Siemens cycles manual]: > 0 seconds, < 0 spindle
        # revolutions, 0 as DTB
        final = p.get("_dtd") or None
        if final is not None and final < 0:
            speed = self.st.spindle_speed
            if not speed:
                self.diag("NC206", "error", "CYCLE83 with a dwell _DTD in spindle revolutions and no "
                          "spindle speed: the dwell at the final depth is taken as DTB")
                final = None
            else:
                final = -final * 60.0 / speed

        def make(feed: float):
            return deep_hole_steps(plane=self.st.plane, vari=vari, approach=approach, rfp=rfp,
                                   bottom=bottom, retract=retract, first=first,
                                   decrement=p.get("decrement", 0.0), dwell_bottom=p.get("dwell"),
                                   dwell_top=p.get("dts"), relief=p.get("relief"), feed=feed,
                                   first_factor=p.get("frf"), anticipation=anticipation,
                                   dwell_final=final)
        return make

    def _swivel_plane(self, s: n.CycleCall) -> None:
        """Sinumerik CYCLE800 [GK]: retract in machine coordinates (_FR), then the programmable
        frame becomes TRANS(_X0..) : AROT(axis by axis) : ATRANS(_X1..) (_ST 1: composed on the
        current frame). Rotary axes are not positioned: that needs the machine's swivel data
        record (kinematics), which the machine model does not hold (NC107 info)."""
        params: dict[str, Any] = {}
        for k, e in s.params.items():
            if k == "swivel_record":
                v = self.ev.compile(e)()
                params[k] = None if v is None or v is UNKNOWN else v
            else:
                v = self._value(self.ev.compile(e), f"CYCLE800 {k}")
                if v is not None:
                    params[k] = v
        plan = swivel_plan(params)
        self._swivel_retract(plan)
        if plan.mode != "axis":
            self.diag("NC107", "warning", f"CYCLE800 swivel mode {plan.mode!r} (_MODE "
                      f"{int(params.get('swivel_mode', 0))}) is not modelled: the plane is not "
                      "swivelled, the moves after it run in the frame that was active before")
            return
        if plan.rotations:
            # The control positions the rotary axes of the swivel data record so that the tool
            # stands normal to the new plane [GK]; the kinematics is not in the machine model
            rec = params.get("swivel_record")
            self.diag("NC107", "warning", f"CYCLE800 swivels the frame, but positioning the rotary "
                      f"axes of swivel data record {str(rec or '')!r} (the tool normal to the new "
                      "plane) is not modelled: the machine's kinematics is not in the machine model. "
                      "The tool tip follows the swivelled path with the tool along machine Z and "
                      "the rotary axes where they were; machine positions, travel and collision "
                      "checks are not the machine's")

        def op(kind: str, vals: dict[str, float], additive: bool) -> None:
            self._h_frame(n.FrameOp(kind, {a: n.Num(v) for a, v in vals.items()}, additive=additive))

        op("trans", plan.ref, plan.additive)
        for axis, angle in plan.rotations:
            op("rot", {axis: angle}, True)
        op("trans", plan.shift, True)

    def _swivel_retract(self, plan) -> None:
        """CYCLE800 _FR: rapid moves in machine Z (then X and Y) to the machine model's max travel."""
        if plan.retract == "none":
            return
        if plan.retract == "unknown":
            self.diag("NC105", "error", "CYCLE800 retract mode _FR must be 0, 1, 2, 4 or 5; no retract")
            return
        steps: list[dict[str, float]] = []
        z = self.mpos.get("Z", 0.0)
        if plan.retract == "tool_inc":
            steps.append({"Z": z + plan.retract_inc * self.st.scale})
        else:
            axes = [("Z",)] + ([("X", "Y")] if plan.retract == "z_xy" else [])
            for group in axes:
                target = {}
                for a in group:
                    ax = self.machine.axes.get(a)
                    if ax is None or ax.max is None:
                        self.diag("NC107", "info", f"the machine model has no max travel for {a}; "
                                  "CYCLE800 does not retract that axis")
                        continue
                    target[a] = float(ax.max)
                if target:
                    steps.append(target)
        tot = self.off.total
        for target in steps:
            mend = dict(self.mpos)
            mend.update(target)
            if all(abs(mend[a] - self.mpos.get(a, 0.0)) < 1e-12 for a in target):
                continue
            self._move("rapid", self.frame.to_program({a: v - tot.get(a, 0.0) for a, v in mend.items()}))
