"""Sinumerik milling cycles (rules/cycles.toml [[milling]]) expanded into plain rapid, feed and arc moves.

A call such as `POCKET1(10, 0, 2, -6, , 40, 20, 5, 50, 50, 0, 100, 300, 3, 3, 0.5, 0, 2, 200)` reaches
the interpreter as a CycleCall of kind "milling"; `run_milling_cycle` binds its arguments by the
table's positions, plans the moves here (pure geometry, testable without an interpreter) and plays
them through the interpreter's ordinary `_move`, so frames, limits, backplot, cycle time and the
per-construct lowering into other dialects see nothing but rapids, feeds and arcs.

Facts [GK] (Siemens SINUMERIK 840D/810D cycles manual; the seeds are silent):
- the cycle approaches the pocket centre at the retraction plane RTP with G0, then RFP+SDIS with G0;
- the depth is cut in equal infeeds of at most MID (finishing: MIDF), each fed at FFD vertically at
  the pocket centre (POCKET1/POCKET2 need a centre-cutting end mill); DPR wins over DP;
- roughing clears the pocket from the inside outwards at FFP1 and leaves FAL on the edge; finishing
  goes round the edge at FFP2; VARI 0 = roughing then finishing, 1 = roughing, 2 = finishing;
- CDIR 2 mills clockwise (G2), 3 counterclockwise (G3);
- the tool radius comes from the active offset; without one the control stops (alarm 61000 "no
  tool offset active"), and a cutter too large for the pocket stops it too (alarm 61105).
Modelling choices [NC] where the manual leaves the path to the control:
- roughing rings are concentric copies of the finishing contour, equally spaced from the centre out,
  at most `ring_step` (rules: 0.8) x the tool diameter apart; the innermost "ring" of a rectangle
  is the centre line along its longer side; every ring starts and ends on the length axis (+u);
- each depth cut and the finishing contour are entered from the pocket centre by a straight feed
  (the control's tangential quarter-circle approach is not modelled) and left back to the centre;
- the cycle ends with G0 from the pocket centre to RTP.
Finishing spindle speed SSF has no effect on the path and is not modelled.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

from nctrans.interp.cycles import DRILL_AXIS, PLANE_AXES, cycle_table, milling_cycle

# A planned step, in plane coordinates (abscissa, ordinate, height along the tool axis):
# ("rapid" | "linear", (p1, p2, h)) | ("arc", (p1, p2, h), (c1, c2), cw) | ("feed", f)
Step = tuple
_EPS = 1e-9


class MillingError(Exception):
    """The call cannot run as the control would run it: rule, severity and message."""

    def __init__(self, rule: str, severity: str, message: str):
        super().__init__(message)
        self.rule, self.severity, self.message = rule, severity, message


@dataclass
class Levels:
    """Heights along the tool axis: retract (RTP), reference (RFP), approach (RFP+SDIS), bottom."""
    rtp: float
    rfp: float
    approach: float
    bottom: float
    up: float                    # +1 when the tool axis points out of the material (RTP above RFP)


def levels_of(p: dict[str, float], current: float) -> Levels:
    """RTP, RFP, SDIS and DP/DPR (DPR wins) as heights; a missing RTP is the current height."""
    rfp = p.get("RFP", 0.0)
    rtp = p.get("RTP", current)
    up = 1.0 if rtp >= rfp else -1.0
    if p.get("DPR"):
        bottom = rfp - up * abs(p["DPR"])
    elif "DP" in p:
        bottom = p["DP"]
    else:
        raise MillingError("NC206", "error", "without a depth (DP or DPR)")
    if (rfp - bottom) * up <= _EPS:
        raise MillingError("NC225", "error", "with its depth not below the reference plane RFP")
    return Levels(rtp, rfp, rfp + up * abs(p.get("SDIS", 0.0)), bottom, up)


def depth_levels(top: float, bottom: float, mid: float, up: float) -> list[float]:
    """Equal infeeds of at most `mid` from `top` down to `bottom` (mid 0: one cut to the bottom)."""
    total = (top - bottom) * up
    if total <= _EPS:
        return [bottom]
    n = max(1, math.ceil(total / mid - 1e-9)) if mid and mid > 0 else 1
    return [top - up * total * k / n for k in range(1, n)] + [bottom]


def rect_ring(hu: float, hv: float, rc: float, ccw: bool) -> list[tuple]:
    """A closed rectangle of half sizes (hu, hv), corner radius rc, centred on the origin, from
    (hu, 0) back to it: [(end (u, v), arc centre or None)], counterclockwise when `ccw`."""
    rc = max(0.0, min(rc, hu, hv))
    pts: list[tuple] = [((hu, hv - rc), None)]
    for (cu, cv), (eu, ev), (nu, nv) in (
            ((hu - rc, hv - rc), (hu - rc, hv), (-hu + rc, hv)),
            ((-hu + rc, hv - rc), (-hu, hv - rc), (-hu, -hv + rc)),
            ((-hu + rc, -hv + rc), (-hu + rc, -hv), (hu - rc, -hv)),
            ((hu - rc, -hv + rc), (hu, -hv + rc), (hu, 0.0))):
        if rc > _EPS:
            pts.append(((eu, ev), (cu, cv)))
        pts.append(((nu, nv), None))
    segs, prev = [], (hu, 0.0)
    for end, centre in pts:
        if centre is None and math.dist(prev, end) <= _EPS:
            continue
        segs.append((prev, end, centre))
        prev = end
    if not ccw:
        segs = [(e, s, c) for s, e, c in reversed(segs)]
    return [(e, c) for _, e, c in segs]


def circle_ring(r: float) -> list[tuple]:
    """A full circle of radius r about the origin from (r, 0), as two half circles."""
    return [((-r, 0.0), (0.0, 0.0)), ((r, 0.0), (0.0, 0.0))]


class _Plan:
    """Collects steps in plane coordinates; local pocket coordinates (u, v) are turned by the
    pocket angle and moved to its centre."""

    def __init__(self, start: tuple[float, float, float]):
        self.at = start
        self.steps: list[Step] = []
        self.feed: Optional[float] = None

    def rapid(self, p1: float, p2: float, h: float) -> None:
        self._go("rapid", (p1, p2, h))

    def linear(self, p1: float, p2: float, h: float, feed: float) -> None:
        self.set_feed(feed)
        self._go("linear", (p1, p2, h))

    def arc(self, p1: float, p2: float, h: float, centre: tuple[float, float], cw: bool, feed: float) -> None:
        self.set_feed(feed)
        self.steps.append(("arc", (p1, p2, h), centre, cw))
        self.at = (p1, p2, h)

    def set_feed(self, feed: float) -> None:
        if feed != self.feed:
            self.steps.append(("feed", feed))
            self.feed = feed

    def _go(self, kind: str, to: tuple[float, float, float]) -> None:
        if max(abs(a - b) for a, b in zip(to, self.at)) <= _EPS:
            return
        self.steps.append((kind, to))
        self.at = to


@dataclass
class _Frame:
    """Local pocket coordinates (u along the length, v across) -> plane coordinates."""
    cpa: float
    cpo: float
    angle_deg: float = 0.0

    def __call__(self, u: float, v: float) -> tuple[float, float]:
        a = math.radians(self.angle_deg)
        c, s = math.cos(a), math.sin(a)
        return self.cpa + u * c - v * s, self.cpo + u * s + v * c


def _approach(plan: _Plan, centre: tuple[float, float], lv: Levels) -> None:
    """G0 to the centre at RTP (rising to RTP first when below it), then G0 to RFP+SDIS."""
    p1, p2, h = plan.at
    if (h - lv.rtp) * lv.up < 0:
        plan.rapid(p1, p2, lv.rtp)
        h = lv.rtp
    plan.rapid(centre[0], centre[1], h)
    plan.rapid(centre[0], centre[1], lv.approach)


def _ring_moves(plan: _Plan, frame: _Frame, segs: list[tuple], h: float, cw: bool, feed: float) -> None:
    for (u, v), centre in segs:
        p1, p2 = frame(u, v)
        if centre is None:
            plan.linear(p1, p2, h, feed)
        else:
            plan.arc(p1, p2, h, frame(*centre), cw, feed)


def pocket_steps(shape: str, p: dict[str, float], radius: float,
                 start: tuple[float, float, float], feed: float) -> list[Step]:
    """The steps of POCKET1 (shape "rect_pocket") or POCKET2 ("circ_pocket") from `start`.

    `p` holds the call's values by Siemens name (lengths and feeds already in mm); `radius` is the
    tool radius; `feed` the active feed, used for any feed the call leaves out. MillingError when
    the control would refuse the call."""
    lv = levels_of(p, start[2])
    rect = shape == "rect_pocket"
    fal = abs(p.get("FAL", 0.0))
    if rect:
        a, b = p.get("LENG", 0.0) / 2, p.get("WID", 0.0) / 2
        if a <= 0 or b <= 0:
            raise MillingError("NC225", "error", "with no pocket length LENG or width WID")
        crad = max(0.0, p.get("CRAD", 0.0))
        if crad > min(a, b) + _EPS:
            raise MillingError("NC225", "error", f"with a corner radius CRAD {crad:g} larger than half "
                               f"the pocket width {2 * min(a, b):g}")
        room = min(a, b) - radius
    else:
        a = b = p.get("PRAD", 0.0)
        if a <= 0:
            raise MillingError("NC225", "error", "with no pocket radius PRAD")
        crad = a
        room = a - radius
    vari = int(p.get("VARI", 0.0)) % 10
    if vari not in (0, 1, 2):
        raise MillingError("NC225", "error", f"with VARI {vari} (0 complete, 1 roughing, 2 finishing)")
    if room <= _EPS or (vari != 2 and room - fal <= _EPS):
        raise MillingError("NC225", "error", f"with a tool (radius {radius:g}) too large for the pocket"
                           f"{' and its finishing allowance' if fal and room > _EPS else ''} "
                           "(the control stops with alarm 61105)")
    cdir = int(p.get("CDIR", 3.0))
    if cdir not in (2, 3):
        raise MillingError("NC225", "error", f"with CDIR {cdir} (2 = G2, 3 = G3)")
    cw = cdir == 2
    ffd = p.get("FFD") or feed
    ffp1 = p.get("FFP1") or feed
    ffp2 = p.get("FFP2") or ffp1
    frame = _Frame(p.get("CPA", 0.0), p.get("CPO", 0.0), p.get("STA1", 0.0) if rect else 0.0)
    centre = frame(0.0, 0.0)
    step = cycle_table().milling_model.get("ring_step", 0.8) * 2 * radius

    plan = _Plan(start)
    _approach(plan, centre, lv)

    def down_at_centre(level: float) -> None:
        plan.linear(centre[0], centre[1], level, ffd)

    if vari in (0, 1):
        limit_u, limit_v = a - radius - fal, b - radius - fal
        m = min(limit_u, limit_v)
        rings = max(1, math.ceil(m / step - 1e-9))
        for level in depth_levels(lv.rfp, lv.bottom, abs(p.get("MID", 0.0)), lv.up):
            down_at_centre(level)
            if rect:
                core_u, core_v = limit_u - m, limit_v - m        # the centre line (one is 0)
                if core_u > _EPS:
                    _ring_moves(plan, frame, [((-core_u, 0.0), None), ((core_u, 0.0), None)], level, cw, ffp1)
                elif core_v > _EPS:
                    _ring_moves(plan, frame, [((0.0, -core_v), None), ((0.0, core_v), None),
                                              ((0.0, 0.0), None)], level, cw, ffp1)
            for j in range(1, rings + 1):
                inset = m * (rings - j) / rings
                hu, hv = limit_u - inset, limit_v - inset
                _ring_moves(plan, frame, [((hu, 0.0), None)], level, cw, ffp1)
                if rect:
                    segs = rect_ring(hu, hv, crad - radius - fal - inset, not cw)
                else:
                    segs = circle_ring(hu)
                _ring_moves(plan, frame, segs, level, cw, ffp1)
            plan.linear(centre[0], centre[1], level, ffp1)
    if vari in (0, 2):
        hu, hv = a - radius, b - radius
        segs = rect_ring(hu, hv, crad - radius, not cw) if rect else circle_ring(hu)
        for level in depth_levels(lv.rfp, lv.bottom, abs(p.get("MIDF", 0.0)), lv.up):
            down_at_centre(level)
            _ring_moves(plan, frame, [((hu, 0.0), None)], level, cw, ffp2)
            _ring_moves(plan, frame, segs, level, cw, ffp2)
            plan.linear(centre[0], centre[1], level, ffp2)
    retract = lv.rtp if (lv.rtp - lv.approach) * lv.up > 0 else lv.approach
    plan.rapid(centre[0], centre[1], retract)
    return plan.steps


PLANNERS = {"rect_pocket": pocket_steps, "circ_pocket": pocket_steps}


# ---------------------------------------------------------------------------------------------
# Running a call in the interpreter

def _tool_radius(interp) -> Optional[float]:
    """The active tool's radius (mm), or None when no offset is active or the machine model
    does not know it. A Sinumerik D number is an edge of the active tool, so the tool table's
    radius of the active tool comes first, then the offset register."""
    st = interp.st
    edge = st.radius_index or (interp.default_edge if st.tool else None)
    if not edge:
        return None                      # no D, and no tool to bring its default edge D1
    tool = interp.machine.tool(int(st.tool)) if st.tool else None
    r = tool.radius if tool is not None and tool.radius > 0 else interp.machine.radius_offset(int(edge))
    return r if r > 0 else None


def call_values(interp, cyc, s) -> dict[str, float]:
    """The call's arguments by Siemens name, lengths and feeds in mm (rules: milling_param units)."""
    table = cycle_table()
    scales = {"length": interp.st.scale, "feed": interp.st.feed_scale}   # G70: inch lengths, mm feeds
    out: dict[str, float] = {}
    for name in cyc.params:
        e = s.params.get(table.neutral(name))
        if e is None:
            continue
        v = interp._value(interp.ev.compile(e), f"{cyc.name} {name}")
        if v is None:
            continue
        unit = table.milling_param[name].unit if name in table.milling_param else "code"
        out[name] = v * scales.get(unit, 1.0)
    return out


def run_milling_cycle(interp, s) -> None:
    """Plan the milling cycle call `s` and play its moves through the interpreter (see module doc)."""
    cyc = milling_cycle(s.name)
    if cyc is None:
        interp.diag("NC103", "warning", f"milling cycle {s.name} is not known")
        return
    if s.modal:
        interp.diag("NC224", "warning", f"MCALL {cyc.name}: a modal call of a milling cycle is not "
                    "modelled; the call is ignored and the following positions do not run it")
        return
    radius = _tool_radius(interp)
    if radius is None:
        interp.diag("NC224", "warning", f"{cyc.name} ({cyc.meaning}) needs the tool radius: no tool "
                    "offset (D) is active, or the machine model does not give the active tool's radius; "
                    "the call is skipped and moves nothing in the analysed toolpath")
        return
    st = interp.st
    plane = st.plane
    a1, a2 = PLANE_AXES[plane]
    ax = DRILL_AXIS[plane]
    pos = interp.pos
    start = (pos.get(a1, 0.0), pos.get(a2, 0.0), pos.get(ax, 0.0))
    try:
        steps = PLANNERS[cyc.shape](cyc.shape, call_values(interp, cyc, s), radius, start, st.feed or 0.0)
    except MillingError as err:
        interp.diag(err.rule, err.severity, f"{cyc.name} {err.message}; the call is skipped and "
                    "moves nothing in the analysed toolpath")
        return
    saved = st.feed
    try:
        for step in steps:
            kind = step[0]
            if kind == "feed":
                st.feed = step[1]
                if not st.feed:
                    interp._need_feed()
                continue
            end = dict(interp.pos)
            end[a1], end[a2], end[ax] = step[1]
            if kind == "arc":
                interp._move("arc", end, step[2], step[3], 0)
            else:
                interp._move(kind, end)
    finally:
        st.feed = saved
