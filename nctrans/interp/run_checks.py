"""Lint checks the interpreter makes as the program runs, on its neutral state (plane, cutter
compensation side, spindle, coolant, units): NC210-NC214. No dialect is named here; what a tool
change expects and does is data (the machine file's [tool_change], else the dialect table's
options.tool_change).

- NC210: an arc centre word on the axis normal to the active plane (J in the ZX plane): the
  control rejects the block; the interpreter would drop the word and cut another arc.
- NC211: a drilling cycle outside the XY plane drills along the plane's normal (X or Y), and a Z
  word is then a position in the plane: warned once per plane selection.
- NC212: cutter compensation switched on or off on an arc (the first move in the plane after
  G41/G42 or G40), whether or not the tool radius is known. An entry move no longer than a known
  radius is the compensator's NC204.
- NC213: a tool change while the spindle turns or coolant flows, where the machine's tool change
  requires them stopped. Where it stops the spindle itself, NC209 then reports a feed move made
  before the program starts the spindle again.
- NC214: a feed move after a unit switch, with the feed rate still the one programmed in the
  other unit (F not restated): the same F number means another speed.

A pending check (comp entry or exit, a stale feed) sets `watch`, which keeps moves off the fast
path and the native kernel until the check is settled.
"""
from __future__ import annotations

import math
from typing import Optional

from nctrans.interp.frames import PLANE_AXES
from nctrans.interp.state import INCH

# centre word -> the axis it measures along
_CENTRE_AXIS = {"I": "X", "J": "Y", "K": "Z"}
_AXIS_CENTRE = {a: w for w, a in _CENTRE_AXIS.items()}
_ZERO = 1e-9


def tool_change_rules(machine, table_options: Optional[dict]) -> tuple[frozenset, bool]:
    """(what must be stopped before a tool change, whether the change stops the spindle): the
    machine file's [tool_change] where it says, else the dialect table's options.tool_change."""
    opts = table_options.get("tool_change") if isinstance(table_options, dict) else None
    opts = opts if isinstance(opts, dict) else {}
    required = frozenset(str(x) for x in opts.get("requires_stopped", ()))
    stops = bool(opts.get("stops_spindle", False))
    tc = getattr(machine, "tool_change", None)
    if tc is not None:
        get = tc.get if isinstance(tc, dict) else (lambda k, d=None: getattr(tc, k, d))
        if get("requires_stopped") is not None:
            required = frozenset(str(x) for x in get("requires_stopped"))
        if get("stops_spindle") is not None:
            stops = bool(get("stops_spindle"))
    return required, stops


class RunChecks:
    """Mixed into the Interpreter: it provides st, pos, span, diag, comp_radius, machine, program."""

    def _rc_init(self) -> None:
        self.watch = False
        self._rc_entry = False                 # comp switched on; no move in the plane yet
        self._rc_exit = False                  # comp switched off; no move in the plane yet
        self._rc_feed_units = None             # (feed's unit, its scale, line of the switch)
        self._rc_feed_scale = None             # the units scale the feed in force was read in
        self._rc_cycle_warned = False
        meta = self.program.meta if isinstance(self.program.meta, dict) else {}
        opts = meta.get("options")
        if not isinstance(opts, dict):
            opts = _table_options(self.program.dialect)
        self._rc_required, self._rc_stops_spindle = tool_change_rules(self.machine, opts)

    def _rc_rewatch(self) -> None:
        self.watch = self._rc_entry or self._rc_exit or self._rc_feed_units is not None

    # ---------------------------------------------------------------- modal changes
    def _rc_mode(self, group: str, value: str) -> None:
        """Before the interpreter applies a modal change."""
        st = self.st
        if group == "cutter_comp":
            prev = st.comp_side
            if prev == "off" and value != "off":
                self._rc_entry, self._rc_exit = True, False
            elif prev != "off" and value == "off":
                self._rc_entry, self._rc_exit = False, True
        elif group == "units":
            new = INCH if value == "inch" else 1.0      # the feed unit (inch_geometry: mm)
            fed = self._rc_feed_scale
            if new == st.feed_scale:
                return
            if fed is None or fed == new or not st.feed or st.feed_mode == "inverse_time":
                self._rc_feed_units = None      # no feed, or back in the units it was read in
            else:
                self._rc_feed_units = ("inch" if fed != 1.0 else "mm", fed,
                                       self.span.line if self.span else 0)
        elif group in ("plane", "cycle"):
            self._rc_cycle_warned = False
        else:
            return
        self._rc_rewatch()

    def _rc_feed_set(self) -> None:
        """An F word: the feed in force is programmed in the units in force."""
        self._rc_feed_scale = self.st.feed_scale
        if self._rc_feed_units is not None:
            self._rc_feed_units = None
            self._rc_rewatch()

    # ---------------------------------------------------------------- moves
    def _rc_move(self, kind: str, end: dict) -> None:
        """Before a move from self.pos to `end` (program coordinates), while `watch` is set."""
        if self._rc_feed_units is not None and kind != "rapid":
            unit, scale, line = self._rc_feed_units
            self._rc_feed_units = None
            st = self.st
            number = st.feed / scale
            now = "inch" if st.feed_scale != 1.0 else "mm"
            per = "mm/rev" if st.feed_mode == "per_rev" else "mm/min"
            self.diag("NC214", "warning",
                      f"feed move after the switch to {now} (line {line}) with the feed rate read in {unit}: "
                      f"F{number:g} = {st.feed:g} {per}, but read in {now} the same F is "
                      f"{number * st.scale:g} {per}, and controls differ in which they use; program F "
                      f"after the unit switch")
        if self._rc_entry or self._rc_exit:
            a1, a2, _ = PLANE_AXES[self.st.plane]
            start = self.pos
            length = math.hypot(end.get(a1, 0.0) - start.get(a1, 0.0), end.get(a2, 0.0) - start.get(a2, 0.0))
            if kind == "arc" or length > _ZERO:
                on = self._rc_entry
                self._rc_entry = self._rc_exit = False
                if kind == "arc":
                    self.diag("NC212", "error", f"cutter compensation {'starts' if on else 'ends'} on an "
                              f"arc: the first move in the plane after it is switched {'on' if on else 'off'} "
                              "must be straight (rapid or linear)")
        self._rc_rewatch()

    # ---------------------------------------------------------------- arcs and cycles
    def _rc_arc(self, center: tuple) -> None:
        """An arc's compiled centre words: (word, constant, closure, mode) tuples."""
        plane = self.st.plane
        a1, a2, an = PLANE_AXES[plane]
        for w in center:
            word = w[0]
            if type(word) is str and _CENTRE_AXIS.get(word) == an:
                self.diag("NC210", "error",
                          f"arc centre word {word} lies along {an}, the axis normal to the {plane} plane: "
                          f"an arc in {plane} takes its centre from {_AXIS_CENTRE[a1]} and "
                          f"{_AXIS_CENTRE[a2]}; the control rejects the block (is the plane the one meant?)")

    def _rc_cycle(self) -> None:
        """A drilling cycle is about to drill a hole."""
        if self._rc_cycle_warned:
            return
        plane = self.st.plane
        a1, a2, an = PLANE_AXES[plane]
        if an == "Z":
            return
        self._rc_cycle_warned = True
        self.diag("NC211", "warning",
                  f"drilling cycle in the {plane} plane: it drills along {an}, the axis normal to the "
                  f"plane; its {an} word is the depth and Z a position in the plane; select the XY plane "
                  f"if the holes are meant along Z")

    # ---------------------------------------------------------------- tool change
    def _rc_tool_change(self) -> None:
        st = self.st
        running = []
        if "spindle" in self._rc_required and st.spindle_dir in ("cw", "ccw"):
            running.append("the spindle turns")
        if "coolant" in self._rc_required and st.coolant not in (None, "off"):
            running.append("coolant flows")
        if running:
            self.diag("NC213", "warning", f"tool change while {' and '.join(running)}: this machine's "
                      "tool change needs them stopped first")
        if self._rc_stops_spindle and not self.spindle_stopped:
            # the change leaves the spindle stopped: NC209 reports a cut before it starts again,
            # also where the program had not yet started it (its power-on state): after the
            # change it is known to stand, and a program that changes tools is no fragment
            # (`T20 M06`, `S1254`, then a cut with no M03 linted clean)
            self.spindle_stopped = True
            self.spindle_reported = False
            self.spindle_stopped_by_tap = False


def _table_options(dialect) -> Optional[dict]:
    from nctrans.rules import load_table
    try:
        return dict(load_table(dialect).options)
    except Exception:       # no table of that name (a test dialect): nothing configured
        return None
