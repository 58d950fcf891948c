"""A tap in plain motion, written in the target control's own tapping form (issue 8).

The toolpath holds a tap as records: the synchronised move into the hole, the spindle reversed,
the synchronised move back out, the spindle turned the first way again. Plain motion could write
them one by one as G33 moves with spindle words between them, which LinuxCNC runs, but a Fanuc
taps with its rigid tapping cycle, and LinuxCNC has a rigid tap of its own. The target's rules
table says which (`[options.flat_motion] tapping`, a profile overriding it:
nctrans.dialects.emit.flat_forms):
- "g84" (a Fanuc, ISO seed 4.1.11): the records of a G84 tap (in, spindle stopped, reversed,
  dwell, out to where it began, stopped, forward; where the target's G84 ends with the spindle
  stopped, rules/cycles.toml [tapping]: in, stopped, dwell, reversed, out, dwell, stopped) as `M29 S..` then `G99 G84 X.. Y.. Z<bottom>
  R<start> F<feed> [P<dwell>]` and G80 (G74 when the spindle turns M4); the tool stands at R, so
  the cycle's positioning moves nowhere;
- "g33.1" (LinuxCNC): the records of a tap that reverses without stopping (in, reversed, out,
  forward: CYCLE84, G331/G332) as one `G33.1 Z<bottom> K<lead>`.

Each form is written only where the records are exactly what the form runs, so the output
reads back to the same toolpath (`equiv`); any other tap keeps the G33 moves. The records of a
possible tap are held (at most seven) until the pattern is whole or broken: memory stays flat.
"""
from __future__ import annotations

from typing import Callable, Optional

from nctrans.ir import nodes as n
from nctrans.toolpath import ToolpathRecord

_EPS = 1e-9
REVERSE = {"cw": "ccw", "ccw": "cw"}
# the records each form runs, after the move in: ("spindle", off|reverse|forward) | ("dwell",) | ("out",)
TEMPLATES = {
    "g84": (("spindle", "off"), ("spindle", "reverse"), ("dwell",), ("out",), ("spindle", "off"),
            ("spindle", "forward")),
    "g33.1": (("spindle", "reverse"), ("out",), ("spindle", "forward")),
}
# a G84 that ends with the spindle stopped (the target's rules/cycles.toml [tapping] "stopped": the
# Siemens ISO seed L3179): stopped, dwell, reversed, out to R, dwell, stopped
STOPPED_G84 = (("spindle", "off"), ("dwell",), ("spindle", "reverse"), ("out",), ("dwell",),
               ("spindle", "off"))


class TapWriter:
    """Watches the flattener's records for taps and writes each whole one in the target's form.
    `replay(rec, work_end, work_center)` writes a record as plain motion; `state()` tells the
    interpreter's offsets state, which must not change within a tap."""

    def __init__(self, fl, forms: dict, replay: Callable, state: Callable):
        self.fl = fl
        self.forms = forms
        self.template = TEMPLATES[forms["tapping"]]
        if forms["tapping"] == "g84" and forms.get("tap_end") == "stopped":
            self.template = STOPPED_G84
        self.replay = replay
        self.state = state
        self.held: list[tuple] = []
        self.held_state = None
        self.forward: Optional[str] = None

    def offer(self, rec: ToolpathRecord, work_end, work_center) -> bool:
        """True when `rec` is taken (held, or the end of a tap now written)."""
        if not self.held:
            if not self._begins(rec):
                return False
            self.held, self.held_state = [(rec, work_end, work_center)], self.state()
            self.forward = self.fl.spindle_dir
            return True
        k = len(self.held) - 1
        if self.state() == self.held_state and self._fits(self.template[k], rec):
            self.held.append((rec, work_end, work_center))
            if len(self.held) == len(self.template) + 1:
                self._write()
            return True
        self.flush()
        return self.offer(rec, work_end, work_center)

    def flush(self) -> None:
        """Write what is held as plain motion (it was not a tap of the target's form)."""
        held, self.held = self.held, []
        for item in held:
            self.replay(*item, state=self.held_state)

    def _begins(self, rec: ToolpathRecord) -> bool:
        s, e = rec.start or {}, rec.end or {}
        return (rec.kind == "linear" and bool(rec.pitch) and rec.thread_start is None
                and self.fl.spindle_dir in REVERSE and self.fl.plane == "XY"
                and set(s) == set(e) and abs(e.get("Z", 0.0) - s.get("Z", 0.0)) > _EPS
                and all(abs(e[a] - s[a]) <= _EPS for a in s if a != "Z"))

    def _fits(self, step: tuple, rec: ToolpathRecord) -> bool:
        down = self.held[0][0]
        if step[0] == "spindle":
            want = {"off": "off", "reverse": REVERSE[self.forward], "forward": self.forward}[step[1]]
            return rec.kind == "spindle" and rec.spindle_dir == want and rec.spindle in (None, down.spindle)
        if step[0] == "dwell":         # one P dwells at both ends of a stopped G84
            earlier = [r.dwell_s for r, *_ in self.held if r.kind == "dwell"]
            return (rec.kind == "dwell" and rec.dwell_s is not None and rec.dwell_s >= 0
                    and all(abs(d - rec.dwell_s) <= _EPS for d in earlier))
        return (rec.kind == "linear" and rec.pitch == down.pitch and rec.feed == down.feed
                and rec.thread_start is None and rec.spindle == down.spindle
                and _same(rec.start, down.end) and _same(rec.end, down.start))

    def _write(self) -> None:
        fl = self.fl
        down = self.held[0][0]
        span = n.Span(down.file, down.line)
        held, self.held = self.held, []
        body: list = []
        fl._sync_offsets(body, span)
        bottom = _prog(down.end, fl.off)
        start = _prog(down.start, fl.off)
        if self.forms["tapping"] == "g33.1":
            fl.info_once("tap_form", "--flatten: taps written as LinuxCNC's rigid tap G33.1 Z.. K<lead> "
                         "(first at this line)", span)
            if fl.motion != "tap_return":
                body.append(n.ModeChange("motion", "tap_return"))
                fl.motion = "tap_return"
            body.append(n.Motion({"Z": n.AxisValue(n.Num(bottom["Z"]))},
                                 center={"K": n.AxisValue(n.Num(down.pitch))}))
            fl.blocks.append(n.Block(span, body))
            return
        fl.info_once("tap_form", f"--flatten: taps written as the control's rigid tapping cycle "
                     f"({self.forms.get('rigid_tap_mode', 'M29')} S.. then G84/G74 .. G80, ISO seed 4.1.11; "
                     "--profile linuxcnc writes G33.1) (first at this line)", span)
        dwell = next((r.dwell_s for r, *_ in held if r.kind == "dwell"), None)
        fl.blocks.append(n.Block(span, body + [
            n.SpindleSpeed(n.Num(down.spindle)),
            n.Passthrough(self.forms.get("rigid_tap_mode", "M29"), "rigid tapping mode before G84",
                          self.forms["dialect"])]))
        if fl.feed_mode != "per_min":
            fl.blocks.append(n.Block(span, [n.ModeChange("feed_mode", "per_min")]))
            fl.feed_mode = "per_min"
        params = {"r_plane": n.Num(start["Z"])}
        if dwell:
            params["dwell"] = n.Num(dwell)
        fl.blocks.append(n.Block(span, [
            n.Feed(n.Num(down.feed)), n.ModeChange("cycle_retract", "r_plane"),
            n.ModeChange("cycle", "tap" if self.forward == "cw" else "tap_left"), n.CycleParams(params),
            n.Motion({a: n.AxisValue(n.Num(v)) for a, v in bottom.items() if a in ("X", "Y", "Z")})]))
        fl.blocks.append(n.Block(span, [n.ModeChange("cycle", "off")]))
        fl.feed = down.feed
        fl.motion = None                # G80: the next move writes its motion code again
        if self.template is STOPPED_G84:
            fl.spindle_dir = "off"      # the cycle left the spindle stopped: the next M3 is written


def _same(a: Optional[dict], b: Optional[dict]) -> bool:
    a, b = a or {}, b or {}
    return set(a) == set(b) and all(abs(a[k] - b[k]) <= _EPS for k in a)


def _prog(point: Optional[dict], off: dict) -> dict:
    """A machine point in the flattened program's coordinates (rounded as flatten writes them)."""
    return {a: round(v - off.get(a, 0.0), 6) + 0.0 for a, v in (point or {}).items()}
