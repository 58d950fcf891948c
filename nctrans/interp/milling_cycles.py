"""Sinumerik milling cycles (rules/cycles.toml [[milling]]) expanded into plain rapid, feed and arc moves.

A call such as `POCKET1(10, 0, 2, -6, , 40, 20, 5, 50, 50, 0, 100, 300, 3, 3, 0.5, 0, 2, 200)` reaches
the interpreter as a CycleCall of kind "milling"; `run_milling_cycle` binds its arguments by the
table's positions, plans the moves here (pure geometry, testable without an interpreter) and plays
them through the interpreter's ordinary `_move`, so frames, limits, backplot, cycle time and the
per-construct lowering into other dialects see nothing but rapids, feeds and arcs.

Facts [GK] (Siemens SINUMERIK 840D/810D cycles manual; the seeds are silent):
- a cycle approaches its start point at the retraction plane RTP with G0, then RFP+SDIS with G0,
  and ends with G0 to RTP; DPR (depth below RFP) wins over DP;
- the depth is cut in equal infeeds of at most MID (finishing: MIDF), fed at FFD; POCKET1/POCKET2
  and SLOT1/SLOT2 plunge vertically (centre-cutting end mill);
- roughing clears from the inside out at FFP1 leaving FAL on the edge; finishing goes round the edge
  at FFP2; VARI 0 = roughing then finishing, 1 = roughing, 2 = finishing (POCKET3/4, CYCLE76/77:
  ones digit 1 roughing, 2 finishing; FALD is left on the floor by roughing);
- CDIR 2 mills clockwise (G2), 3 counterclockwise (G3); POCKET3/4 and CYCLE76/77 also take 0 climb
  and 1 conventional milling, which depend on the spindle direction (M3, inside a pocket: climb is
  G3; round a spigot: G2);
- the tool radius comes from the active offset; without one the control stops (alarm 61000 "no
  tool offset active"); a cutter too large for the shape stops it too (alarm 61105).
Modelling choices [NC] where the manual leaves the path to the control (or the seeds cannot say):
- roughing rings are concentric copies of the finishing contour, equally spaced, at most
  `ring_step` (rules: 0.8) x the tool diameter apart (MIDA where the cycle has it); the innermost
  "ring" of a pocket is its centre line (a rectangle's along its longer side, a slot's along its
  arc); rings start and end on the length axis (+u), arc slots at their start cap;
- every depth cut and the finishing contour are entered by a straight feed from the plunge point
  (the control's tangential quarter-circle approach is not modelled) and left back to it;
- slots and elongated holes on a circle lie radially with RAD to their middle (as the open plotter
  ncplot7py reads them), LENG their whole length; an elongated hole is as wide as the tool and is cut
  by infeeds alternating at its two ends;
- a spigot is roughed from the blank AP1 x AP2 (one ring when no blank is given), entered outside it
  on +u at RFP+SDIS;
- face milling (CYCLE71) runs paths whose tool edge is flush with the face's sides, equally spaced at
  most MIDA (0.8 x diameter when 0) apart, starting and ending FDP beyond the face;
- thread milling (CYCLE90) climbs one pitch per turn from DP to RFP, entered from the centre
  (internal) or from outside (external) by a straight feed.
MCALL of a milling cycle calls it after every following block that moves in the plane, with the
values its arguments had at the MCALL (`select_modal`).
The lathe's thread cutting cycles CYCLE97 and CYCLE98 (chained threads) are planned here as well
(`thread_turn_steps`, `thread_chain_steps`, their facts and choices in their docstrings). Finishing spindle speed SSF has no effect on the path and is not
modelled. Calls that ask for what
is not modelled (helical or oscillating insertion, a pre-machined blank, a floor allowance in
SLOT1/SLOT2) say so (NC224) and move nothing.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

from nctrans.interp.cycles import DRILL_AXIS, PLANE_AXES, cycle_table, milling_cycle
from nctrans.interp.thread_starts import start_angles
from nctrans.interp.thread_starts import stamp as stamp_thread_start

# A planned step, in plane coordinates (abscissa, ordinate, height along the tool axis):
# ("rapid" | "linear", (p1, p2, h)) | ("arc", (p1, p2, h), (c1, c2), cw) | ("feed", f)
Step = tuple
# A contour segment in local coordinates: (end (u, v), arc centre (u, v) or None, clockwise)
Seg = tuple
_EPS = 1e-9
MAX_PASSES = 10_000
# A call planning more moves than this is refused (NC225): the plan is held in memory, and no
# real pocket needs a tenth of it (a 10-cut pocket of 20 rings is under 2,000 moves).
MAX_MOVES = 200_000


class MillingError(Exception):
    """The call cannot run as nctrans models it: rule, severity and message."""

    def __init__(self, rule: str, severity: str, message: str):
        super().__init__(message)
        self.rule, self.severity, self.message = rule, severity, message


def _impossible(message: str) -> MillingError:
    return MillingError("NC225", "error", message)


def _unmodelled(message: str) -> MillingError:
    return MillingError("NC224", "warning", message)


@dataclass
class Levels:
    """Heights along the tool axis: retract (RTP), reference (RFP), approach (RFP+SDIS), bottom."""
    rtp: float
    rfp: float
    approach: float
    bottom: float
    up: float                    # +1 when the tool axis points out of the material (RTP above RFP)

    @property
    def retract(self) -> float:
        return self.rtp if (self.rtp - self.approach) * self.up > 0 else self.approach


def levels_of(p: dict[str, float]) -> Levels:
    """RTP, RFP, SDIS and DP/DPR (DPR wins) as heights. An omitted RTP, RFP or SDIS is 0, as the
    cycle's PROC sees an omitted argument (seed L4722); the caller warns of an omitted RTP (NC127)."""
    rfp = p.get("RFP", 0.0)
    rtp = p.get("RTP", 0.0)
    up = 1.0 if rtp >= rfp else -1.0
    if p.get("DPR"):
        bottom = rfp - up * abs(p["DPR"])
    elif "DP" in p:
        bottom = p["DP"]
    else:
        raise MillingError("NC206", "error", "without a depth (DP or DPR)")
    if (rfp - bottom) * up <= _EPS:
        raise _impossible("with its depth not below the reference plane RFP")
    return Levels(rtp, rfp, rfp + up * abs(p.get("SDIS", 0.0)), bottom, up)


def depth_levels(top: float, bottom: float, mid: float, up: float) -> list[float]:
    """Equal infeeds of at most `mid` from `top` down to `bottom` (mid 0: one cut to the bottom)."""
    total = (top - bottom) * up
    if total <= _EPS:
        return [bottom]
    n = max(1, math.ceil(total / mid - 1e-9)) if mid and mid > 0 else 1
    if n > MAX_PASSES:
        raise _impossible(f"with more than {MAX_PASSES} depth cuts (MID too small)")
    return [top - up * total * k / n for k in range(1, n)] + [bottom]


def _count(width: float, step: float) -> int:
    n = max(1, math.ceil(width / step - 1e-9)) if width > _EPS else 1
    if n > MAX_PASSES:
        raise _impossible(f"with more than {MAX_PASSES} passes in the plane")
    return n


# ---------------------------------------------------------------------------------------------
# Contours in local coordinates

def rect_ring(hu: float, hv: float, rc: float, ccw: bool) -> list[Seg]:
    """A closed rectangle of half sizes (hu, hv), corner radius rc, centred on the origin, from
    (hu, 0) back to it, counterclockwise when `ccw`."""
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
    return _directed(segs, ccw)


def _directed(ccw_segs: list[tuple], ccw: bool) -> list[Seg]:
    """(start, end, centre) pieces of a closed counterclockwise contour as Segs in direction `ccw`."""
    if ccw:
        return [(e, c, False) for _, e, c in ccw_segs]
    return [(s, c, True) for s, e, c in reversed(ccw_segs)]


def circle_ring(r: float, ccw: bool) -> list[Seg]:
    """A full circle of radius r about the origin from (r, 0), as two half circles."""
    return [((-r, 0.0), (0.0, 0.0), not ccw), ((r, 0.0), (0.0, 0.0), not ccw)]


def _polar(r: float, deg: float) -> tuple[float, float]:
    a = math.radians(deg)
    return r * math.cos(a), r * math.sin(a)


def arc_slot_ring(rad: float, start: float, sweep: float, w: float, ccw: bool) -> tuple[tuple, list[Seg]]:
    """The closed contour at distance w round the arc of radius `rad` about the origin from angle
    `start` through `sweep` > 0 degrees: (its start point, behind the arc's start, and its Segs)."""
    end = start + sweep
    p0, p1 = _polar(rad, start), _polar(rad, end)
    back = (p0[0] + w * math.sin(math.radians(start)), p0[1] - w * math.cos(math.radians(start)))
    pieces = [(back, _polar(rad + w, start), p0), (_polar(rad + w, start), _polar(rad + w, end), (0.0, 0.0)),
              (_polar(rad + w, end), _polar(rad - w, end), p1)]
    inner = [(_polar(rad - w, end), _polar(rad - w, start), (0.0, 0.0)), (_polar(rad - w, start), back, p0)]
    # counterclockwise round the slot: the inner arc runs clockwise about the circle's centre
    segs = [(e, c, False) for _, e, c in pieces] + [(inner[0][1], inner[0][2], True), (back, p0, False)]
    if ccw:
        return back, segs
    starts = [back] + [s[0] for s in segs[:-1]]
    return back, [(s, c, not cw) for s, (e, c, cw) in reversed(list(zip(starts, segs)))]


# ---------------------------------------------------------------------------------------------
# Planning

class _Plan:
    """Collects steps in plane coordinates."""

    def __init__(self, start: tuple[float, float, float]):
        self.at = start
        self.steps: list[Step] = []
        self.feed: Optional[float] = None

    def rapid(self, p1: float, p2: float, h: float) -> None:
        self._go("rapid", (p1, p2, h))

    def linear(self, p1: float, p2: float, h: float, feed: float) -> None:
        if max(abs(a - b) for a, b in zip((p1, p2, h), self.at)) <= _EPS:
            return
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
        if len(self.steps) > MAX_MOVES:
            raise _impossible(f"with more than {MAX_MOVES} moves (infeeds MID/MIDA or a count too small "
                              "for the sizes)")

    def approach(self, p1: float, p2: float, lv: Levels) -> None:
        """G0 to (p1, p2) at RTP (rising to RTP first when below it), then G0 to RFP+SDIS."""
        h = self.at[2]
        if (h - lv.rtp) * lv.up < 0:
            self.rapid(self.at[0], self.at[1], lv.rtp)
            h = lv.rtp
        self.rapid(p1, p2, h)
        self.rapid(p1, p2, lv.approach)


@dataclass
class _Frame:
    """Local coordinates (u along the shape's length, v across) -> plane coordinates."""
    cpa: float
    cpo: float
    angle_deg: float = 0.0

    def __call__(self, u: float, v: float) -> tuple[float, float]:
        a = math.radians(self.angle_deg)
        c, s = math.cos(a), math.sin(a)
        return self.cpa + u * c - v * s, self.cpo + u * s + v * c


def _contour(plan: _Plan, frame: _Frame, start: tuple, segs: list[Seg], h: float, feed: float) -> None:
    """A straight feed to `start`, then the contour, at height h."""
    plan.linear(*frame(*start), h, feed)
    for (u, v), centre, cw in segs:
        p1, p2 = frame(u, v)
        if centre is None:
            plan.linear(p1, p2, h, feed)
        else:
            plan.arc(p1, p2, h, frame(*centre), cw, feed)


@dataclass
class Shape:
    """A closed shape the tool clears (pocket) or goes round (spigot), in local coordinates.

    `rings(offset, step)`: the roughing contours [(start, Segs)] in cutting order for a tool whose
    centre keeps `offset` inside the shape's edge (negative: outside, for a spigot), at most `step`
    apart; `entry`: where the tool plunges."""
    rings: Callable[[float, float], list[tuple]]
    entry: tuple[float, float]
    room: float                  # pocket: how far the edge is from the centre line; spigot: inf


def _rect_pocket(a: float, b: float, crad: float, ccw: bool) -> Shape:
    def rings(offset: float, step: float) -> list[tuple]:
        lu, lv = a - offset, b - offset
        m = min(lu, lv)
        out: list[tuple] = []
        cu, cv = lu - m, lv - m                      # the centre line (one of them is 0)
        if cu > _EPS:
            out.append(((0.0, 0.0), [((-cu, 0.0), None, False), ((cu, 0.0), None, False)]))
        elif cv > _EPS:
            out.append(((0.0, 0.0), [((0.0, -cv), None, False), ((0.0, cv), None, False),
                                     ((0.0, 0.0), None, False)]))
        n = _count(m, step)
        for j in range(1, n + 1):
            inset = m * (n - j) / n
            out.append(((lu - inset, 0.0), rect_ring(lu - inset, lv - inset, crad - offset - inset, ccw)))
        return out
    return Shape(rings, (0.0, 0.0), min(a, b))


def _circ_pocket(prad: float, ccw: bool) -> Shape:
    def rings(offset: float, step: float) -> list[tuple]:
        m = prad - offset
        n = _count(m, step)
        return [((m * j / n, 0.0), circle_ring(m * j / n, ccw)) for j in range(1, n + 1)]
    return Shape(rings, (0.0, 0.0), prad)


def _arc_slot(rad: float, start: float, sweep: float, half_width: float, ccw: bool) -> Shape:
    p0, p1 = _polar(rad, start), _polar(rad, start + sweep)

    def rings(offset: float, step: float) -> list[tuple]:
        m = half_width - offset
        out: list[tuple] = [(p0, [(p1, (0.0, 0.0), False), (p0, (0.0, 0.0), True)])]
        if m > _EPS:
            n = _count(m, step)
            out += [arc_slot_ring(rad, start, sweep, m * j / n, ccw) for j in range(1, n + 1)]
        return out
    return Shape(rings, p0, half_width)


def _outside_offsets(gap: float, radius: float, offset: float, step: float) -> list[float]:
    """Distances of the tool centre from a spigot's edge, outside in: from the blank `gap` away
    down to -offset (offset < 0 for a spigot), at most `step` of material per ring."""
    final = -offset
    width = max(gap + radius - final, 0.0)
    if width <= _EPS:
        return [final]
    n = _count(width, step)
    return [final + width * (n - k) / n for k in range(1, n + 1)]


def _rect_spigot(a: float, b: float, crad: float, blank: tuple[float, float], ccw: bool,
                 clearance: float, radius: float) -> Shape:
    gap = max(blank[0] - a, blank[1] - b, 0.0)

    def rings(offset: float, step: float) -> list[tuple]:
        return [((a + d, 0.0), rect_ring(a + d, b + d, crad + d, ccw))
                for d in _outside_offsets(gap, radius, offset, step)]
    return Shape(rings, (a + gap + radius + clearance, 0.0), math.inf)


def _circ_spigot(prad: float, blank: float, ccw: bool, clearance: float, radius: float) -> Shape:
    gap = max(blank - prad, 0.0)

    def rings(offset: float, step: float) -> list[tuple]:
        return [((prad + d, 0.0), circle_ring(prad + d, ccw)) for d in _outside_offsets(gap, radius, offset, step)]
    return Shape(rings, (prad + gap + radius + clearance, 0.0), math.inf)


@dataclass
class _Cut:
    """What one shape's machining needs besides its geometry."""
    radius: float
    fal: float                   # edge allowance left by roughing
    fald: float                  # floor allowance left by roughing
    rough: bool
    finish: bool
    mid: float                   # roughing infeed
    midf: float                  # finishing infeed
    step: float                  # width between roughing rings
    ffd: float
    ffp1: float
    ffp2: float
    outside: bool = False        # a spigot: the tool stays outside the edge


def _machine_shape(plan: _Plan, frame: _Frame, shape: Shape, lv: Levels, cut: _Cut) -> None:
    """Approach, roughing and finishing of one shape, ending with G0 to RTP over its entry point."""
    r, sign = cut.radius, (-1.0 if cut.outside else 1.0)
    if not cut.outside and shape.room - r <= _EPS:
        raise _impossible(f"with a tool (radius {r:g}) too large for the shape (the control stops "
                          "with alarm 61105)")
    if not cut.outside and cut.rough and shape.room - r - cut.fal <= _EPS:
        raise _impossible(f"with a tool (radius {r:g}) too large for the shape and its finishing "
                          "allowance FAL (the control stops with alarm 61105)")
    entry = frame(*shape.entry)
    plan.approach(*entry, lv)

    def passes(levels: list[float], rings: list[tuple], feed: float) -> None:
        for level in levels:
            plan.linear(*entry, level, cut.ffd)
            for start, segs in rings:
                _contour(plan, frame, start, segs, level, feed)
            plan.linear(*entry, level, feed)

    if cut.rough:
        bottom = lv.bottom + lv.up * cut.fald
        if (lv.rfp - bottom) * lv.up <= _EPS:
            raise _impossible("with its floor allowance FALD not above the depth")
        passes(depth_levels(lv.rfp, bottom, cut.mid, lv.up), shape.rings(sign * (r + cut.fal), cut.step),
               cut.ffp1)
    if cut.finish:
        passes(depth_levels(lv.rfp, lv.bottom, cut.midf, lv.up), shape.rings(sign * r, math.inf)[-1:],
               cut.ffp2)
    plan.rapid(*entry, lv.retract)


def _mill_dir(code: int, outside: bool, spindle_cw: bool) -> bool:
    """CDIR -> counterclockwise? 2 G2, 3 G3; 0 climb, 1 conventional (depends on the spindle)."""
    if code == 2:
        return False
    if code == 3:
        return True
    if code in (0, 1):
        climb_ccw = (not outside) == spindle_cw      # M3: climb is G3 in a pocket, G2 round a spigot
        return climb_ccw if code == 0 else not climb_ccw
    raise _impossible(f"with CDIR {code} (0 climb, 1 conventional, 2 G2, 3 G3)")


def _cut(p: dict[str, float], radius: float, feed: float, vari_codes: tuple, *,
         finish_infeed: Optional[str] = "MIDF", step_key: Optional[str] = None, outside: bool = False) -> _Cut:
    """Roughing/finishing, allowances, infeeds and feeds of a call; `finish_infeed` names the
    finishing infeed parameter (None: finishing takes MID's cuts)."""
    vari = int(p.get("VARI", vari_codes[0]))
    ones, tens = vari % 10, vari // 10 % 10
    if ones not in vari_codes:
        raise _impossible(f"with VARI {vari} (ones digit {'/'.join(map(str, vari_codes))})")
    if tens not in (0, 1):
        raise _unmodelled(f"with VARI {vari}: helical or oscillating insertion is not modelled")
    rough = ones in (0, 1)
    finish = ones in (0, 2)
    step = p.get(step_key, 0.0) if step_key else 0.0
    if step <= 0:
        step = cycle_table().milling_model.get("ring_step", 0.8) * 2 * radius
    mid = abs(p.get("MID", 0.0))
    midf = abs(p.get(finish_infeed, 0.0)) if finish_infeed else mid
    ffd = p.get("FFD") or feed
    ffp1 = p.get("FFP1") or feed
    return _Cut(radius, abs(p.get("FAL", 0.0)), abs(p.get("FALD", 0.0)), rough, finish, mid, midf,
                step, ffd, ffp1, p.get("FFP2") or ffp1, outside)


def _g2_g3(p: dict[str, float]) -> bool:
    """CDIR of POCKET1/2, SLOT1/2 and CYCLE90 (2 = G2, 3 = G3) -> counterclockwise?"""
    cdir = int(p.get("CDIR", 3))
    if cdir not in (2, 3):
        raise _impossible(f"with CDIR {cdir} (2 = G2, 3 = G3)")
    return cdir == 3


def _finite(p: dict[str, float]) -> None:
    """Every value a finite number, every feed not negative (the control stops on either)."""
    for name, v in p.items():
        if not math.isfinite(v):
            raise _impossible(f"with {name} = {v} (not a finite number)")
        if name in ("FFD", "FFP1", "FFP2", "FFR") and v < 0:
            raise _impossible(f"with a negative feed {name} {v:g}")


def _positive(p: dict[str, float], *names: str) -> None:
    for name in names:
        if p.get(name, 0.0) <= 0:
            raise _impossible(f"with no positive {name}")


def _pattern(p: dict[str, float]) -> list[float]:
    """Angles of NUM positions on a circle from STA1, INDA apart (0: evenly round the circle)."""
    num = int(p.get("NUM", 1) or 1)
    if num < 1 or num > MAX_PASSES:
        raise _impossible(f"with NUM {num}")
    inda = p.get("INDA") or 360.0 / num
    return [p.get("STA1", 0.0) + k * inda for k in range(num)]


def _rect_size(p: dict[str, float], what: str) -> tuple[float, float, float]:
    """Half length, half width and corner radius of a rectangular shape (LENG, WID, CRAD)."""
    _positive(p, "LENG", "WID")
    a, b = p["LENG"] / 2, p["WID"] / 2
    crad = max(0.0, p.get("CRAD", 0.0))
    if crad > min(a, b) + _EPS:
        raise _impossible(f"with a corner radius CRAD {crad:g} larger than half the {what} width "
                          f"{2 * min(a, b):g}")
    return a, b, crad


def _pocket(plan: _Plan, p: dict[str, float], lv: Levels, radius: float, feed: float, spindle_cw: bool,
            shape: str) -> None:
    """POCKET1 (rect_pocket) / POCKET2 (circ_pocket): centre CPA/CPO, CDIR 2/3, VARI 0/1/2, MIDF."""
    cut = _cut(p, radius, feed, (0, 1, 2))
    ccw = _g2_g3(p)
    if shape == "rect_pocket":
        a, b, crad = _rect_size(p, "pocket")
        geo, frame = _rect_pocket(a, b, crad, ccw), _Frame(p.get("CPA", 0.0), p.get("CPO", 0.0), p.get("STA1", 0.0))
    else:
        _positive(p, "PRAD")
        geo, frame = _circ_pocket(p["PRAD"], ccw), _Frame(p.get("CPA", 0.0), p.get("CPO", 0.0))
    _machine_shape(plan, frame, geo, lv, cut)


def _pocket34(plan: _Plan, p: dict[str, float], lv: Levels, radius: float, feed: float, spindle_cw: bool,
              shape: str) -> None:
    """POCKET3 (rect_pocket3) / POCKET4 (circ_pocket4): centre PA/PO, CDIR 0-3, MIDA, FALD."""
    if any(p.get(k) for k in ("AP1", "AP2", "AD")):
        raise _unmodelled("with a pre-machined blank (AP1/AP2/AD): not modelled")
    cut = _cut(p, radius, feed, (1, 2), finish_infeed=None, step_key="MIDA")
    ccw = _mill_dir(int(p.get("CDIR", 0)), False, spindle_cw)
    if shape == "rect_pocket3":
        if p.get("LENG", 0.0) < 0 or p.get("WID", 0.0) < 0:
            raise _unmodelled("with a signed LENG/WID (dimensioned from a corner): not modelled")
        a, b, crad = _rect_size(p, "pocket")
        geo, frame = _rect_pocket(a, b, crad, ccw), _Frame(p.get("PA", 0.0), p.get("PO", 0.0), p.get("STA", 0.0))
    else:
        _positive(p, "PRAD")
        geo, frame = _circ_pocket(p["PRAD"], ccw), _Frame(p.get("PA", 0.0), p.get("PO", 0.0))
    _machine_shape(plan, frame, geo, lv, cut)


def _spigot(plan: _Plan, p: dict[str, float], lv: Levels, radius: float, feed: float, spindle_cw: bool,
            shape: str) -> None:
    """CYCLE76 (rect_spigot) / CYCLE77 (circ_spigot): roughed from the blank AP1 (x AP2) in."""
    cut = _cut(p, radius, feed, (1, 2), finish_infeed=None, outside=True)
    ccw = _mill_dir(int(p.get("CDIR", 0)), True, spindle_cw)
    clearance = abs(p.get("SDIS", 0.0))
    if shape == "rect_spigot":
        a, b, crad = _rect_size(p, "spigot")
        blank = (max(p.get("AP1", 0.0), 0.0) / 2 or a, max(p.get("AP2", 0.0), 0.0) / 2 or b)
        geo = _rect_spigot(a, b, crad, blank, ccw, clearance, radius)
        frame = _Frame(p.get("PA", 0.0), p.get("PO", 0.0), p.get("STA", 0.0))
    else:
        _positive(p, "PRAD")
        geo = _circ_spigot(p["PRAD"], max(p.get("AP1", 0.0), 0.0) / 2 or p["PRAD"], ccw, clearance, radius)
        frame = _Frame(p.get("PA", 0.0), p.get("PO", 0.0))
    _machine_shape(plan, frame, geo, lv, cut)


def _slots(plan: _Plan, p: dict[str, float], lv: Levels, radius: float, feed: float, spindle_cw: bool,
           shape: str) -> None:
    """SLOT1 (slots_circle: straight, radial) / SLOT2 (arc_slots: along the circle), each like POCKET1."""
    if p.get("FALD"):
        raise _unmodelled("with a floor allowance FALD: not modelled")
    cut = _cut(p, radius, feed, (0, 1, 2))
    ccw = _g2_g3(p)
    _positive(p, "WID")
    if shape == "slots_circle":
        _positive(p, "LENG")
        if p["LENG"] < p["WID"] - _EPS:
            raise _impossible("with the slot length LENG shorter than its width WID")
    else:
        _positive(p, "AFSL", "RAD")
        if p["WID"] / 2 >= p["RAD"] - _EPS:
            raise _impossible("with the slot width WID reaching the circle's centre")
    cpa, cpo, rad = p.get("CPA", 0.0), p.get("CPO", 0.0), p.get("RAD", 0.0)
    for angle in _pattern(p):
        if shape == "slots_circle":
            c = _polar(rad, angle)
            frame = _Frame(cpa + c[0], cpo + c[1], angle)
            geo = _rect_pocket(p["LENG"] / 2, p["WID"] / 2, p["WID"] / 2, ccw)
        else:
            frame = _Frame(cpa, cpo)
            geo = _arc_slot(rad, angle, p["AFSL"], p["WID"] / 2, ccw)
        _machine_shape(plan, frame, geo, lv, cut)


def _long_holes(plan: _Plan, p: dict[str, float], lv: Levels, radius: float, feed: float,
                spindle_cw: bool, shape: str) -> None:
    """LONGHOLE: holes as wide as the tool, infeeds alternating at their two ends."""
    _positive(p, "LENG")
    if p["LENG"] < 2 * radius - _EPS:
        raise _impossible(f"with LENG {p['LENG']:g} shorter than the tool diameter {2 * radius:g}")
    ffd, ffp1 = p.get("FFD") or feed, p.get("FFP1") or feed
    cpa, cpo, rad = p.get("CPA", 0.0), p.get("CPO", 0.0), p.get("RAD", 0.0)
    half = p["LENG"] / 2 - radius
    for angle in _pattern(p):
        c = _polar(rad, angle)
        frame = _Frame(cpa + c[0], cpo + c[1], angle)
        ends = [frame(-half, 0.0), frame(half, 0.0)]
        plan.approach(*ends[0], lv)
        for k, level in enumerate(depth_levels(lv.rfp, lv.bottom, abs(p.get("MID", 0.0)), lv.up)):
            plan.linear(*ends[k % 2], level, ffd)
            plan.linear(*ends[(k + 1) % 2], level, ffp1)
        plan.rapid(*plan.at[:2], lv.retract)


def milling_steps(shape: str, p: dict[str, float], radius: float, start: tuple[float, float, float],
                  feed: float, spindle_cw: bool = True) -> list[Step]:
    """The steps of one milling cycle call from `start` (plane coordinates).

    `p` holds the call's values by Siemens name (lengths and feeds already in mm); `radius` is the
    tool radius; `feed` the active feed, used for any feed the call leaves out; `spindle_cw` the
    spindle direction (climb and conventional milling depend on it). MillingError when the call
    cannot run (the control would stop, or nctrans does not model what it asks for)."""
    planner = PLANNERS.get(shape)
    if planner is None:
        raise _unmodelled(f"shape {shape!r} is not modelled")
    _finite(p)
    plan = _Plan(start)
    planner(plan, p, levels_of(p), radius, feed, spindle_cw, shape)
    return plan.steps


def _face(plan: _Plan, p: dict[str, float], lv: Levels, radius: float, feed: float, spindle_cw: bool,
          shape: str) -> None:
    """CYCLE71: paths over the rectangle from (PA, PO) over LENG x WID (signed) at angle STA."""
    vari = int(p.get("VARI", 0))
    ones, tens = vari % 10, vari // 10 % 10
    if ones not in (1, 2) or tens not in (1, 2, 3, 4):
        raise _impossible(f"with VARI {vari} (ones 1 roughing / 2 finishing, tens 1-4 the path pattern)")
    if not p.get("LENG") or not p.get("WID"):
        raise _impossible("with no face length LENG or width WID")
    frame = _Frame(p.get("PA", 0.0), p.get("PO", 0.0), p.get("STA", 0.0))
    lu, lw = sorted((0.0, p["LENG"])), sorted((0.0, p["WID"]))
    along_u = tens in (1, 3)
    alternate = tens in (3, 4)
    span, across = (lu, lw) if along_u else (lw, lu)
    width = across[1] - across[0]
    step = p.get("MIDA") or cycle_table().milling_model.get("ring_step", 0.8) * 2 * radius
    if width <= 2 * radius + _EPS:
        centres = [(across[0] + across[1]) / 2]
    else:
        lo, hi = across[0] + radius, across[1] - radius + abs(p.get("FDP1", 0.0))
        n = _count(hi - lo, step)
        centres = [lo + (hi - lo) * k / n for k in range(n + 1)]
    over = radius + abs(p.get("FDP", 0.0))
    ends = (span[0] - over, span[1] + over)
    ffp1 = p.get("FFP1") or feed

    def at(s: float, c: float) -> tuple[float, float]:
        return frame(s, c) if along_u else frame(c, s)

    fald = abs(p.get("FALD", 0.0))
    if ones == 1:
        bottom = lv.bottom + lv.up * fald
        if (lv.rfp - bottom) * lv.up <= _EPS:
            raise _impossible("with its floor allowance FALD not above the depth")
        levels = depth_levels(lv.rfp, bottom, abs(p.get("MID", 0.0)), lv.up)
    else:
        levels = [lv.bottom]
    plan.approach(*at(ends[0], centres[0]), lv)
    for i, level in enumerate(levels):
        if i:                             # back over the first path's start for the next cut
            plan.rapid(*plan.at[:2], lv.approach)
            plan.rapid(*at(ends[0], centres[0]), lv.approach)
        forward = True
        for k, c in enumerate(centres):
            s0, s1 = ends if forward else ends[::-1]
            if k == 0 or not alternate:
                if k:
                    plan.rapid(*plan.at[:2], lv.approach)
                    plan.rapid(*at(s0, c), lv.approach)
                plan.linear(*at(s0, c), level, ffp1)
            else:
                plan.linear(*at(s0, c), level, ffp1)
            plan.linear(*at(s1, c), level, ffp1)
            if alternate:
                forward = not forward
    plan.rapid(*plan.at[:2], lv.retract)


def _thread(plan: _Plan, p: dict[str, float], lv: Levels, radius: float, feed: float,
            spindle_cw: bool, shape: str) -> None:
    """CYCLE90: a helix of pitch PIT from DP up to RFP round (CPA, CPO), inside (TYPTH 0) or outside (1)."""
    _positive(p, "DIATH", "PIT")
    typth = int(p.get("TYPTH", 0))
    if typth not in (0, 1):
        raise _impossible(f"with TYPTH {typth} (0 internal, 1 external thread)")
    cw = not _g2_g3(p)
    outside = typth == 1
    r_path = p["DIATH"] / 2 + (radius if outside else -radius)
    if r_path <= _EPS:
        raise _impossible(f"with a tool (radius {radius:g}) too large for the thread diameter "
                          f"(the control stops with alarm 61105)")
    pit = p["PIT"]
    turns = (lv.rfp - lv.bottom) * lv.up / pit
    if turns > MAX_PASSES:
        raise _impossible(f"with more than {MAX_PASSES} thread turns")
    cpa, cpo = p.get("CPA", 0.0), p.get("CPO", 0.0)
    ffr = p.get("FFR") or feed
    entry = (cpa + r_path + abs(p.get("SDIS", 0.0)), cpo) if outside else (cpa, cpo)
    plan.approach(*entry, lv)
    plan.linear(*entry, lv.bottom, ffr)
    plan.linear(cpa + r_path, cpo, lv.bottom, ffr)
    halves = math.ceil(2 * turns - 1e-9)
    h = lv.bottom
    for k in range(1, halves + 1):
        frac = min(k / 2, turns) / turns if turns > 0 else 1.0
        h = lv.bottom + lv.up * (lv.rfp - lv.bottom) * lv.up * frac
        if k < halves or abs(2 * turns - halves) <= 1e-9:
            end = (cpa - r_path, cpo) if k % 2 else (cpa + r_path, cpo)
        else:                             # the last part turn ends where the pitch brings it
            ang = math.pi * (2 * turns - (halves - 1)) * (-1 if cw else 1)
            base = math.pi if (halves - 1) % 2 else 0.0
            end = (cpa + r_path * math.cos(base + ang), cpo + r_path * math.sin(base + ang))
        plan.arc(*end, h, (cpa, cpo), cw, ffr)
    plan.linear(*entry, h, ffr)
    plan.rapid(*entry, lv.retract)


# shape (rules/cycles.toml [[milling]]) -> planner(plan, values, levels, radius, feed, spindle_cw, shape)
PLANNERS: dict[str, Callable] = {
    "rect_pocket": _pocket, "circ_pocket": _pocket, "rect_pocket3": _pocket34, "circ_pocket4": _pocket34,
    "rect_spigot": _spigot, "circ_spigot": _spigot, "slots_circle": _slots, "arc_slots": _slots,
    "long_holes": _long_holes, "face": _face, "thread_mill": _thread,
}


# ---------------------------------------------------------------------------------------------
# Running a call in the interpreter

def _tool_radius(interp) -> Optional[float]:
    """The active tool's radius (mm), or None when no offset is active or the machine model
    does not know it. A Sinumerik D number is an edge of the active tool, so the tool table's
    radius of the active tool comes first, then the offset register. An explicit D0 selects no
    offset: the control's cycle stops (alarm 61000), where it used to take the default edge D1."""
    st = interp.st
    edge = st.radius_index if st.radius_index is not None else (interp.default_edge if st.tool else None)
    if not edge:
        return None                      # D0 (no offset), or no D and no tool to bring its default edge D1
    if interp.edges is not None and st.tool:     # the edge's data, written or from the tool table
        r = interp.edges.radius(int(st.tool), int(edge))
        return r if r > 0 else None
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
        if e is None or (name in table.milling_param and table.milling_param[name].unit == "name"):
            continue
        v = interp._value(interp.ev.compile(e), f"{cyc.name} {name}")
        if v is None:
            continue
        unit = table.milling_param[name].unit if name in table.milling_param else "code"
        out[name] = v * scales.get(unit, 1.0)
    return out


def select_modal(interp, s) -> None:
    """MCALL of a milling cycle: the control calls it after every following block that moves in
    the plane until MCALL alone (or another MCALL) ends it (seed, advanced manual 2.7: "the
    subprogram is automatically called and executed after every block with path motion";
    "parameters are only passed once with an MCALL"). The arguments are evaluated here, once;
    each call gets the same values, so a pocket given by its centre CPA/CPO (PA/PO) is machined
    there each time, as the cycle's own code would be [seed]. The call runs after a block that
    moves in the plane, as the built-in drilling cycles do under MCALL [NC]."""
    from dataclasses import replace

    from nctrans.interp.evaluate import UNKNOWN
    from nctrans.ir import nodes as n
    values = {}
    for k, e in s.params.items():
        try:
            v = interp.ev.compile(e)()
        except Exception:           # evaluated again (and reported) where the cycle runs
            v = None
        values[k] = n.Num(float(v)) if isinstance(v, (int, float)) and v is not UNKNOWN else e
    interp.modal_call = None         # one modal call at a time: this one replaces a PROC's
    interp.modal_cycle = replace(s, params=values, modal=False)


def run_milling_cycle(interp, s) -> None:
    """Plan the milling cycle call `s` and play its moves through the interpreter (see module doc)."""
    cyc = milling_cycle(s.name)
    if cyc is None:
        interp.diag("NC103", "warning", f"milling cycle {s.name} is not known")
        return
    if cyc.shape == "groove":                   # a turning cycle (nctrans.interp.grooving)
        from nctrans.interp.grooving import run_cycle93
        run_cycle93(interp, cyc, s)
        return
    if cyc.shape in ("undercut", "thread_undercut"):    # turning (nctrans.interp.undercuts)
        from nctrans.interp.undercuts import run_undercut
        run_undercut(interp, cyc, s)
        return
    if s.modal:
        select_modal(interp, s)
        return
    if cyc.shape == "thread_turn":
        _run_thread_turn(interp, cyc, s)
        return
    if cyc.shape == "thread_chain":
        _run_thread_turn(interp, cyc, s, thread_chain_steps)
        return
    radius = _tool_radius(interp)
    if radius is None:
        interp.diag("NC224", "warning", f"{cyc.name} ({cyc.meaning}) needs the tool radius: no tool "
                    "offset (D) is active, or the machine model (--machine) does not give the active tool's radius; "
                    "the call is skipped and moves nothing in the analysed toolpath")
        return
    st = interp.st
    plane = st.plane
    a1, a2 = PLANE_AXES[plane]
    ax = DRILL_AXIS[plane]
    pos = interp.pos
    start = (pos.get(a1, 0.0), pos.get(a2, 0.0), pos.get(ax, 0.0))
    try:
        steps = milling_steps(cyc.shape, call_values(interp, cyc, s), radius, start, st.feed or 0.0,
                             spindle_cw=st.spindle_dir != "ccw")
    except MillingError as err:
        interp.diag(err.rule, err.severity, f"{cyc.name} {err.message}; the call is skipped and "
                    "moves nothing in the analysed toolpath")
        return
    run_steps(interp, steps, a1, a2, ax)


def run_steps(interp, steps, a1: str, a2: str, ax: str) -> None:
    """Move the tool through a planned cycle: ("feed", F) sets the feed for the moves after it,
    (kind, (p1, p2, depth)[, centre, cw]) moves in the plane axes a1/a2 and the tool axis ax. The
    program's feed is restored after the cycle, as the control does."""
    st = interp.st
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


# ---------------------------------------------------------------------------------------------
# CYCLE97: thread cutting on a lathe (X radius, Z along the axis)

def _thread_variant(p: dict[str, float], starts: str) -> int:
    """VARI of CYCLE97/CYCLE98 (1/3 external, 2/4 internal), after the checks both share: finite
    values, a known VARI, a whole number of thread starts (`starts`: the cycle's name for the
    count; the starts are cut in turn by _run_thread_turn)."""
    _finite(p)
    vari = int(p.get("VARI", 1))
    if vari not in (1, 2, 3, 4):
        raise _impossible(f"with VARI {vari} (1/3 external, 2/4 internal thread)")
    thread_starts(p, starts)
    return vari


def thread_starts(p: dict[str, float], starts: str) -> list[float]:
    """The start angles of CYCLE97 (NUMT) / CYCLE98 (NUMTH) threads: `starts` (0: one) spread
    evenly over the turn from NSP, 360 / starts apart [GK, Siemens cycles manual: "the thread
    turns are distributed evenly over the circumference, the first at NSP"]."""
    count = p.get(starts, 1) or 1
    if count != int(count) or not 1 <= count <= MAX_PASSES:
        raise _impossible(f"with {starts} {count:g} (a whole number of thread starts, 1 to {MAX_PASSES})")
    return start_angles(p.get("NSP", 0.0), int(count))


def _thread_pass_depths(vari: int, nrc: int, tdep: float, fal: float, nid: int) -> list[float]:
    """The depth below the crest of each pass of CYCLE97/CYCLE98: NRC roughing cuts to TDEP - FAL,
    of equal infeed (VARI 1/2) or equal chip section (VARI 3/4: depth ~ sqrt(k)), the finishing
    cut at TDEP when FAL > 0, then NID idle passes at TDEP."""
    rough = tdep - fal
    if vari in (1, 2):
        depths = [rough * k / nrc for k in range(1, nrc + 1)]
    else:
        depths = [rough * math.sqrt(k / nrc) for k in range(1, nrc + 1)]
    if fal > 0:
        depths.append(tdep)
    return depths + [tdep] * max(0, nid)


def thread_turn_steps(p: dict[str, float], start: tuple[float, float]) -> list[Step]:
    """CYCLE97 passes from `start` = (X radius, Z): ("rapid", (x, z)) | ("thread", (x, z), lead).

    [GK] Siemens cycles manual: the thread runs from SPL to FPL on the diameters DM1 (at SPL) and
    DM2 (at FPL), lengthened by the run-in APP and the run-out ROP; TDEP deep, the roughing depth
    TDEP - FAL in NRC cuts (VARI 1/2 external/internal with constant infeed, 3/4 with constant
    cross-section: the k-th cut at depth x sqrt(k / NRC)), then FAL in one finishing cut and NID
    idle passes; IANG infeeds along a flank (negative: alternating flanks); the lead is PIT, or
    the metric coarse pitch of MPIT. [NC] DM is the nominal (outer) diameter for both external
    and internal threads; the tool retracts _VRT (1 mm when 0) beyond the crest and goes back to
    the thread's start with G0 after each pass; flank infeed puts each cut (TDEP - depth) x
    tan(IANG) earlier along the thread, the last at the programmed start."""
    vari = _thread_variant(p, "NUMT")
    lead = abs(p.get("PIT", 0.0))
    if not lead and p.get("MPIT"):
        from nctrans.interp.cycles import coarse_pitch
        lead = coarse_pitch(p["MPIT"]) or 0.0
    if lead <= 0:
        raise _impossible("without a thread pitch (PIT) or a known thread size (MPIT)")
    spl, fpl = p.get("SPL", 0.0), p.get("FPL", 0.0)
    if abs(fpl - spl) <= _EPS:
        raise _impossible("with the thread's start SPL at its end FPL")
    tdep = abs(p.get("TDEP", 0.0))
    fal = abs(p.get("FAL", 0.0))
    if tdep <= _EPS or fal >= tdep:
        raise _impossible("with no thread depth TDEP (or a finishing allowance FAL not below it)")
    _positive(p, "DM1")
    dm2 = p.get("DM2") or p["DM1"]
    nrc = max(1, int(p.get("NRC", 1) or 1))
    if nrc > MAX_PASSES:
        raise _impossible(f"with more than {MAX_PASSES} roughing cuts")
    sp = 1.0 if fpl > spl else -1.0
    z0, z1 = spl - sp * abs(p.get("APP", 0.0)), fpl + sp * abs(p.get("ROP", 0.0))

    def nominal(z: float) -> float:
        return (p["DM1"] + (dm2 - p["DM1"]) * (z - spl) / (fpl - spl)) / 2

    external = vari in (1, 3)
    sd = -1.0 if external else 1.0                  # the infeed: towards the axis outside
    crest = (lambda z: nominal(z)) if external else (lambda z: nominal(z) - tdep)
    vrt = abs(p.get("VRT", 0.0)) or 1.0
    clear = (max(crest(z0), crest(z1)) + vrt) if external else (min(crest(z0), crest(z1)) - vrt)
    nid = int(p.get("NID", 0) or 0)
    if nid > MAX_PASSES:
        raise _impossible(f"with more than {MAX_PASSES} idle passes")
    depths = _thread_pass_depths(vari, nrc, tdep, fal, nid)
    iang = p.get("IANG", 0.0)
    tan = math.tan(math.radians(abs(iang))) if iang else 0.0

    steps: list[Step] = []
    x, z = start
    if (x - clear) * sd > 0:                         # first away from the thread, then along it
        steps.append(("rapid", (clear, z)))
    steps.append(("rapid", (clear, z0)))
    for k, depth in enumerate(depths):
        flank = -1.0 if iang < 0 and k % 2 else 1.0
        shift = -sp * (tdep - depth) * tan * flank
        steps.append(("rapid", (clear, z0 + shift)))
        steps.append(("rapid", (crest(z0) + sd * depth, z0 + shift)))
        steps.append(("thread", (crest(z1) + sd * depth, z1 + shift), lead))
        steps.append(("rapid", (clear, z1 + shift)))
    steps.append(("rapid", (clear, z0)))
    return [s for i, s in enumerate(steps) if i == 0 or s[:2] != steps[i - 1][:2]]


# ---------------------------------------------------------------------------------------------
# CYCLE98: chained threads on a lathe (up to three sections in one pass)

def thread_chain_steps(p: dict[str, float], start: tuple[float, float]) -> list[Step]:
    """CYCLE98 passes from `start` = (X radius, Z), as CYCLE97's (`thread_turn_steps`) but each
    pass runs through the chain PO1 -> PO2 -> PO3 -> PO4 on the diameters DM1..DM4, the k-th
    section with the lead PPk [GK, Siemens cycles manual]; APP runs in before PO1 and ROP out after
    PO4. [NC] The run-in continues the first section's taper and the run-out the last one's;
    each pass keeps its depth below the crest at every chain point; the sections must run one way
    along Z and be threads, not faces (each at most 45 degrees steep): a chain that turns back or
    a face section is not modelled (NC224)."""
    vari = _thread_variant(p, "NUMTH")
    zs = [p.get(f"PO{k}", 0.0) for k in range(1, 5)]
    ds = [p.get(f"DM{k}", 0.0) for k in range(1, 5)]
    leads = [abs(p.get(f"PP{k}", 0.0)) for k in range(1, 4)]
    if any(d <= 0 for d in ds):
        raise _impossible("with a diameter DM1..DM4 not above 0")
    if any(lead <= 0 for lead in leads):
        raise _impossible("without a thread pitch PP1, PP2 and PP3 for its three sections")
    sp = 1.0 if zs[1] > zs[0] else -1.0
    for a, b, da, db in zip(zs, zs[1:], ds, ds[1:]):
        if (b - a) * sp <= _EPS:
            raise _unmodelled("with sections that do not run one way along Z: not modelled")
        if abs(db - da) / 2 > abs(b - a) + _EPS:
            raise _unmodelled("with a section steeper than 45 degrees (a face thread): not modelled")
    tdep, fal = abs(p.get("TDEP", 0.0)), abs(p.get("FAL", 0.0))
    if tdep <= _EPS or fal >= tdep:
        raise _impossible("with no thread depth TDEP (or a finishing allowance FAL not below it)")
    nrc = max(1, int(p.get("NRC", 1) or 1))
    nid = int(p.get("NID", 0) or 0)
    if nrc > MAX_PASSES or nid > MAX_PASSES:
        raise _impossible(f"with more than {MAX_PASSES} roughing cuts or idle passes")
    app, rop = abs(p.get("APP", 0.0)), abs(p.get("ROP", 0.0))
    slope0 = (ds[1] - ds[0]) / 2 / (zs[1] - zs[0])
    slope1 = (ds[3] - ds[2]) / 2 / (zs[3] - zs[2])
    chain = [(ds[0] / 2 - slope0 * sp * app, zs[0] - sp * app)] + \
        [(d / 2, z) for d, z in zip(ds, zs)] + [(ds[3] / 2 + slope1 * sp * rop, zs[3] + sp * rop)]
    pitch = [leads[0], leads[0]] + leads + [leads[2]]   # the lead of the move that ends at each point
    external = vari in (1, 3)
    sd = -1.0 if external else 1.0
    crest = [(r if external else r - tdep, z) for r, z in chain]
    vrt = abs(p.get("VRT", 0.0)) or 1.0
    clear = (max(r for r, _ in crest) + vrt) if external else (min(r for r, _ in crest) - vrt)
    depths = _thread_pass_depths(vari, nrc, tdep, fal, nid)
    iang = p.get("IANG", 0.0)
    tan = math.tan(math.radians(abs(iang))) if iang else 0.0
    steps: list[Step] = []
    x, z = start
    z0 = chain[0][1]
    if (x - clear) * sd > 0:
        steps.append(("rapid", (clear, z)))
    steps.append(("rapid", (clear, z0)))
    for k, depth in enumerate(depths):
        flank = -1.0 if iang < 0 and k % 2 else 1.0
        shift = -sp * (tdep - depth) * tan * flank
        steps.append(("rapid", (clear, z0 + shift)))
        steps.append(("rapid", (crest[0][0] + sd * depth, z0 + shift)))
        for i in range(1, len(crest)):
            steps.append(("thread", (crest[i][0] + sd * depth, crest[i][1] + shift), pitch[i]))
        steps.append(("rapid", (clear, crest[-1][1] + shift)))
        if len(steps) > MAX_MOVES:
            raise _impossible(f"with more than {MAX_MOVES} moves")
    steps.append(("rapid", (clear, z0)))
    out = [s for i, s in enumerate(steps) if i == 0 or s[:2] != steps[i - 1][:2]]
    # a run-in or run-out of 0 leaves a thread move that goes nowhere
    return [s for i, s in enumerate(out) if s[0] != "thread" or s[1] != out[i - 1][1]]


def _run_thread_turn(interp, cyc, s, plan: Callable = thread_turn_steps) -> None:
    """CYCLE97 (CYCLE98: plan = thread_chain_steps) in the interpreter: X is the radius, Z the
    thread axis; the thread cuts are spindle-synchronised (feed = lead x S, the records carry the
    lead as G33 moves do)."""
    st = interp.st
    try:
        if not st.spindle_speed:
            raise _impossible("with no spindle speed (the thread feed is the lead x S)")
        p = call_values(interp, cyc, s)
        steps = plan(p, (interp.pos.get("X", 0.0), interp.pos.get("Z", 0.0)))
        angles = thread_starts(p, "NUMTH" if plan is thread_chain_steps else "NUMT")
        if len(steps) * len(angles) > MAX_MOVES:
            raise _impossible(f"with more than {MAX_MOVES} moves")
    except MillingError as err:
        interp.diag(err.rule, err.severity, f"{cyc.name} {err.message}; the call is skipped and "
                    "moves nothing in the analysed toolpath")
        return
    # several starts: each cut completely in turn, the first at NSP [GK: Siemens cycles manual,
    # and CYCLE99's default "one thread after the other"]; [NC] each start is approached as the
    # first one is, from where the one before left the tool, and the start angle in force before
    # the call (SF=) holds again after it
    saved, saved_mode, saved_start = st.feed, st.feed_mode, interp.thread_start
    try:
        for k, angle in enumerate(angles):
            if k:
                steps = plan(p, (interp.pos.get("X", 0.0), interp.pos.get("Z", 0.0)))
            interp.thread_start = angle
            for step in steps:
                end = dict(interp.pos)
                end["X"], end["Z"] = step[1]
                if step[0] == "rapid":
                    if k and max(abs(end[a] - interp.pos.get(a, 0.0)) for a in "XZ") <= _EPS:
                        continue            # the next start begins where the last one ended
                    interp._move("rapid", end)
                    continue
                st.feed, st.feed_mode = step[2] * st.spindle_speed, "per_min"
                mark = len(interp.out)
                interp._move("linear", end)
                for rec in interp.out[mark:]:
                    rec.pitch = step[2]
                stamp_thread_start(interp, mark)
    finally:
        st.feed, st.feed_mode, interp.thread_start = saved, saved_mode, saved_start
