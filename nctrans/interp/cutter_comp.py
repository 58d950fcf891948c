"""Cutter radius compensation (G41/G42, Sinumerik G450 corners) as a streaming filter over planned moves.

The interpreter pushes every planned move and every other event while compensation is on; the
filter returns what is ready to emit. Each move is held back until the next plane move shows the
corner, so events that arrive meanwhile queue behind the held move and the order is kept. Memory
is bounded: the queue holds one plane move plus the non-plane moves and events that follow it.

Behaviour is LinuxCNC 2.9 rs274 (the judge; tests/test_cutter_comp.py compares with it):

- Entry (first move after G41/G42): a G0/G1 ends at the programmed end offset by the radius along
  the normal of the entry move itself; the entry move starts at the uncompensated position. The
  corner with the next move is then treated like any other corner. An arc as the first move is
  allowed by LinuxCNC (its centre is moved so that the arc starts at the current point); the ISO
  spec (iso.md §4.20, L2098-2102) forbids it, which the interpreter reports itself (NC212).
- Convex corners (angle > 0.05 rad, LinuxCNC TOLERANCE_CONCAVE_CORNER) get an arc of the tool
  radius around the programmed corner (like Sinumerik G450); for a rapid the arc is replaced by a
  straight rapid to the arc's end. The corner arc carries the later move's rotary-axis ends and the
  earlier move's height.
- Concave corners end at the intersection of the offset paths (line-line, line-arc, arc-line,
  arc-arc): the held move (and the non-plane moves after it) get that end point.
- Arcs keep their centre and get radius R -/+ r (tool inside / outside the arc).
- Exit (G40): the held move keeps its normal offset end; the exit move runs uncompensated from there
  to its programmed end (LinuxCNC has no exit corner). An arc as exit move is a LinuxCNC error.
- A move without motion in the plane keeps the compensated plane position.

Where LinuxCNC raises an error the filter records (payload, message) in `self.problems` (the
interpreter turns them into NC204) and carries on with the nearest sensible geometry, so the path
stays continuous. Coordinates are program coordinates; other axes pass through unchanged.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Optional

PLANE_AXES = {"XY": ("X", "Y"), "ZX": ("Z", "X"), "YZ": ("Y", "Z")}
THIRD_AXIS = {"XY": "Z", "ZX": "Y", "YZ": "X"}
ROTARY_AXES = ("A", "B", "C", "U", "V", "W")
TOLERANCE_CONCAVE_CORNER = 0.05      # rad, LinuxCNC
TOLERANCE_EQUAL = 0.0001             # LinuxCNC

LEFT, RIGHT = "left", "right"


@dataclass
class PlannedMove:
    kind: str                                   # "rapid" | "linear" | "arc"
    start: dict[str, float]
    end: dict[str, float]
    center: Optional[dict[str, float]] = None
    direction: Optional[str] = None             # "cw" | "ccw"
    turns: int = 0                              # extra full turns
    payload: object = None


@dataclass
class _Held:
    move: PlannedMove
    dir: tuple[float, float] = (0.0, 0.0)       # straight: direction used by LinuxCNC's reversal check
    sweep: float = 0.0                          # arc: programmed sweep (0 = unchecked)
    turn: int = 0                               # arc: signed LinuxCNC turn


def find_turn(x1: float, y1: float, cx: float, cy: float, turn: int, x2: float, y2: float) -> float:
    """Signed sweep (rad, ccw positive) of an arc with LinuxCNC's `turn` convention (+-1 = less than a turn)."""
    if turn == 0:
        return 0.0
    a = math.atan2(y1 - cy, x1 - cx)
    b = math.atan2(y2 - cy, x2 - cx)
    if turn > 0:
        if b <= a:
            b += 2 * math.pi
        return (b - a) + (turn - 1) * 2 * math.pi
    if a <= b:
        a += 2 * math.pi
    return (b - a) + (turn + 1) * 2 * math.pi


class CutterCompensator:
    """One G41/G42 episode: push() moves and events while it is on, finish() at G40."""

    def __init__(self, side: str, radius: float, plane: str = "XY"):
        side = side.lower()
        if side not in (LEFT, RIGHT):
            raise ValueError(f"cutter comp side must be 'left' or 'right', not {side!r}")
        if radius < 0:                          # a negative stored radius swaps the side (iso.md §4.20)
            side = RIGHT if side == LEFT else LEFT
        self.side = side
        self.radius = abs(radius)
        self.plane = plane
        self.a1, self.a2 = PLANE_AXES[plane]
        self.problems: list[tuple[object, str]] = []
        self._queue: list = []                  # _Held moves and plain events, in order
        self._first = True
        self._prog: tuple[float, float] | None = None   # programmed end of the last move
        self._cur: dict[str, float] | None = None       # compensated end of the last move
        self._endpoint: tuple[float, float] | None = None
        self._warned_plane = False

    # -- public ---------------------------------------------------------------------------------
    def push(self, item) -> list:
        if not isinstance(item, PlannedMove):
            if self._queue:
                self._queue.append(item)
                return []
            return [item]
        if self.plane == "YZ" and not self._warned_plane:
            self._warned_plane = True
            self._problem(item, "cutter radius compensation in the YZ plane is not supported by LinuxCNC")
        if self._first:
            return self._entry(item)
        if item.kind == "arc":
            return self._arc(item)
        return self._straight(item)

    def finish(self, item=None) -> list:
        out = self._flush()
        if isinstance(item, PlannedMove):
            # an arc here is reported by the interpreter (NC212, run_checks), radius known or not
            start = dict(self._cur) if self._cur is not None else dict(item.start)
            out.append(replace(item, start=start, end=dict(item.end)))
        elif item is not None:
            out.append(item)
        self._first, self._prog, self._cur, self._endpoint = True, None, None, None
        return out

    # -- helpers --------------------------------------------------------------------------------
    def _problem(self, payload, message: str) -> None:
        self.problems.append((payload, message))

    def _p(self, point: dict[str, float], fallback: dict[str, float] | None = None) -> tuple[float, float]:
        fb = fallback or {}
        return (point.get(self.a1, fb.get(self.a1, 0.0)), point.get(self.a2, fb.get(self.a2, 0.0)))

    def _at(self, base: dict[str, float], xy: tuple[float, float]) -> dict[str, float]:
        out = dict(base)
        out[self.a1], out[self.a2] = xy
        return out

    def _flush(self) -> list:
        out = [q.move if isinstance(q, _Held) else q for q in self._queue]
        self._queue = []
        return out

    def _front(self) -> _Held | None:
        for q in self._queue:
            if isinstance(q, _Held):
                return q
        return None

    def _turn(self, item: PlannedMove) -> int:
        n = (item.turns or 0) + 1
        return n if item.direction == "ccw" else -n

    def _inside(self, turn: int) -> bool:
        return (self.side == LEFT and turn > 0) or (self.side == RIGHT and turn < 0)

    def _hold(self, move: PlannedMove, **kw) -> None:
        self._queue.append(_Held(move, **kw))
        self._cur = dict(move.end)

    def _corner_point(self, item: PlannedMove, xy: tuple[float, float]) -> dict[str, float]:
        """Corner arc end: earlier move's height, later move's rotary axes (LinuxCNC)."""
        pt = self._at(self._cur, xy)
        for ax in ROTARY_AXES:
            if ax in item.end:
                pt[ax] = item.end[ax]
        return pt

    def _move_endpoint_and_flush(self, xy: tuple[float, float], payload) -> list:
        """Concave corner: every held move now ends at xy (LinuxCNC checks none is reversed)."""
        ex, ey = self._endpoint if self._endpoint is not None else xy
        held = [q for q in self._queue if isinstance(q, _Held)]
        for i, h in enumerate(held):
            m = h.move
            if m.kind == "arc":
                cx, cy = self._p(m.center)
                l2 = find_turn(ex, ey, cx, cy, h.turn, *xy)
                if h.sweep and abs(l2) > abs(h.sweep) + 0.001:
                    self._problem(payload, "Arc move in concave corner cannot be reached by the tool "
                                           "without gouging")
            else:
                x1, y1 = h.dir
                if x1 * (xy[0] - ex) + y1 * (xy[1] - ey) < 0:
                    what = "traverse" if m.kind == "rapid" else "feed"
                    self._problem(payload, f"Straight {what} in concave corner cannot be reached by "
                                           "the tool without gouging")
            m.end = self._at(m.end, xy)
            if i:
                m.start = self._at(m.start, xy)
        if self._cur is not None:
            self._cur = self._at(self._cur, xy)
        self._endpoint = xy
        return self._flush()

    # -- entry ----------------------------------------------------------------------------------
    def _entry(self, item: PlannedMove) -> list:
        r = self.radius
        cx, cy = self._p(item.start)
        px, py = self._p(item.end, item.start)
        out = self._flush()
        if math.hypot(px - cx, py - cy) <= r:
            what = "arc" if item.kind == "arc" else "move"
            self._problem(item.payload, f"Length of cutter compensation entry {what} is not greater "
                                        "than the tool radius")
            return out + [item]                 # stays uncompensated; the next move is the entry
        if item.kind != "arc":
            alpha = math.atan2(py - cy, px - cx) + (math.pi / 2 if self.side == LEFT else -math.pi / 2)
            end = (px + r * math.cos(alpha), py + r * math.sin(alpha))
            move = PlannedMove(item.kind, dict(item.start), self._at(item.end, end), payload=item.payload)
            self._endpoint = (cx, cy)
            self._hold(move, dir=(math.cos(alpha), math.sin(alpha)))
        else:
            turn = self._turn(item)
            ccx, ccy = self._p(item.center)
            if self._inside(turn):
                gamma = math.atan2(ccy - py, ccx - px)
            else:
                gamma = math.atan2(py - ccy, px - ccx)
            ex, ey = px + r * math.cos(gamma), py + r * math.sin(gamma)
            b_len = math.hypot(cy - ey, cx - ex) / 2.0
            ab_ang = math.atan2(ccy - ey, ccx - ex)
            a_ang = math.atan2(cy - ey, cx - ex) - ab_ang
            if abs(math.cos(a_ang)) < TOLERANCE_EQUAL:
                self._problem(item.payload, "Tool radius not less than arc radius with comp")
                return out + [item]
            c_len = b_len / math.cos(a_ang)
            ncx, ncy = ex + c_len * math.cos(ab_ang), ey + c_len * math.sin(ab_ang)
            move = PlannedMove("arc", dict(item.start), self._at(item.end, (ex, ey)),
                               center=self._at(item.center or {}, (ncx, ncy)),
                               direction=item.direction, turns=item.turns, payload=item.payload)
            self._endpoint = (cx, cy)
            self._hold(move, sweep=find_turn(cx, cy, ncx, ncy, turn, ex, ey), turn=turn)
        self._first = False
        self._prog = (px, py)
        return out

    # -- straight moves -------------------------------------------------------------------------
    def _straight(self, item: PlannedMove) -> list:
        r, small = self.radius, TOLERANCE_CONCAVE_CORNER
        opx, opy = self._prog
        cx, cy = self._p(self._cur)
        px, py = self._p(item.end, self._cur)
        if px == opx and py == opy:             # no motion in the plane: keep the offset position
            move = PlannedMove(item.kind, dict(self._cur), self._at(item.end, (cx, cy)),
                               payload=item.payload)
            self._hold(move)
            return []
        theta = math.atan2(cy - opy, cx - opx)
        alpha = math.atan2(py - opy, px - opx)
        if self.side == LEFT:
            if theta < alpha:
                theta += 2 * math.pi
            beta = theta - alpha - math.pi / 2
            gamma = math.pi / 2
        else:
            if alpha < theta:
                alpha += 2 * math.pi
            beta = alpha - theta - math.pi / 2
            gamma = -math.pi / 2
        end = (px + r * math.cos(alpha + gamma), py + r * math.sin(alpha + gamma))
        mid = (opx + r * math.cos(alpha + gamma), opy + r * math.sin(alpha + gamma))
        front = self._front()
        concave = beta < -small or beta > math.pi + small or (
            beta > math.pi - small and front is not None and front.move.kind == "arc"
            and ((self.side == RIGHT and front.turn > 0) or (self.side == LEFT and front.turn < 0)))
        out: list = []
        if not concave and beta > small:        # convex: go around the programmed corner
            out = self._flush()
            corner_end = self._corner_point(item, mid)
            if item.kind == "rapid":
                corner = PlannedMove("rapid", dict(self._cur), corner_end, payload=item.payload)
            else:
                corner = PlannedMove("arc", dict(self._cur), corner_end,
                                     center=self._at({}, (opx, opy)),
                                     direction="cw" if self.side == LEFT else "ccw",
                                     payload=item.payload)
            out.append(corner)
            self._cur = corner_end
            self._endpoint = mid
        elif concave:
            if front is None or front.move.kind != "arc":        # line -> line
                halfcorner = (beta + math.pi) / 2.0
                if halfcorner == 0.0:
                    self._problem(item.payload, "Zero degree inside corner is invalid for cutter "
                                                "compensation")
                    retreat = 0.0
                else:
                    retreat = r / math.tan(halfcorner)
                cmid = (cx + retreat * math.cos(theta + gamma), cy + retreat * math.sin(theta + gamma))
            else:                                                # arc -> line
                cmid = self._arc_line_corner(front, item, opx, opy, px, py)
            out = self._move_endpoint_and_flush(cmid, item.payload)
        else:                                   # tangent or collinear
            out = self._flush()
            self._endpoint = (cx, cy)
        move = PlannedMove(item.kind, dict(self._cur), self._at(item.end, end), payload=item.payload)
        self._hold(move, dir=(px - opx, py - opy))
        self._prog = (px, py)
        return out

    def _arc_line_corner(self, prev: _Held, item, opx, opy, px, py) -> tuple[float, float]:
        r = self.radius
        pcx, pcy = self._p(prev.move.center)
        pex, pey = self._p(prev.move.end)
        oldrad = math.hypot(pcy - pey, pcx - pex)
        base_dir = math.atan2(py - opy, px - opx)
        theta = base_dir + math.pi / 2 if prev.turn > 0 else base_dir - math.pi / 2
        phi = math.atan2(pcy - opy, pcx - opx)
        inside = self._inside(prev.turn)
        oldrad_uncomp = oldrad + r if inside else oldrad - r
        d = oldrad_uncomp * math.cos(theta - phi)
        d2 = d - r if inside else d + r
        ratio = self._ratio(d2, oldrad, item.payload, "Arc to straight motion makes a corner the "
                                                      "compensated tool can't fit in without gouging")
        sign = -1.0 if (prev.turn > 0) == inside else 1.0
        angle = sign * math.acos(ratio) + theta + math.pi
        return (pcx + oldrad * math.cos(angle), pcy + oldrad * math.sin(angle))

    def _ratio(self, num: float, den: float, payload, message: str) -> float:
        ratio = num / den if den else 2.0
        if ratio > 1.0 or ratio < -1.0:
            self._problem(payload, message)
            ratio = max(-1.0, min(1.0, ratio))
        return ratio

    # -- arcs -----------------------------------------------------------------------------------
    def _arc(self, item: PlannedMove) -> list:
        r, small = self.radius, TOLERANCE_CONCAVE_CORNER
        opx, opy = self._prog
        cx, cy = self._p(self._cur)
        ex, ey = self._p(item.end, self._cur)
        ccx, ccy = self._p(item.center or {}, self._cur)
        turn = self._turn(item)
        ccw = turn > 0
        arc_radius = math.hypot(ccx - ex, ccy - ey)
        theta = math.atan2(cy - opy, cx - opx)
        theta = theta - math.pi / 2 if self.side == LEFT else theta + math.pi / 2
        delta = math.atan2(ccy - opy, ccx - opx)
        alpha = delta - math.pi / 2 if ccw else delta + math.pi / 2
        beta = theta - alpha if self.side == LEFT else alpha - theta
        if beta > 1.5 * math.pi:
            beta -= 2 * math.pi
        elif beta < -math.pi / 2:
            beta += 2 * math.pi
        inside = self._inside(turn)
        if inside:
            gamma = math.atan2(ccy - ey, ccx - ex)
            if arc_radius <= r:
                self._problem(item.payload, "Tool radius not less than arc radius with comp")
        else:
            gamma = math.atan2(ey - ccy, ex - ccx)
            delta += math.pi
        new_end = (ex + r * math.cos(gamma), ey + r * math.sin(gamma))
        front = self._front()
        out: list = []
        if beta < -small or beta > math.pi + small or (abs(beta - math.pi) < small and not inside):
            if front is None or front.move.kind != "arc":        # line -> arc
                cy_ = arc_radius * math.sin(beta - math.pi / 2)
                msg = "Arc move in concave corner cannot be reached by the tool without gouging"
                if inside:
                    dist = arc_radius - r
                    l = self._ratio(cy_ + r, dist, item.payload, msg)
                    angle = theta + math.asin(l) if turn > 0 else theta - math.asin(l)
                else:
                    dist = arc_radius + r
                    l = self._ratio(cy_ - r, dist, item.payload, msg)
                    angle = theta + math.pi - math.asin(l) if turn > 0 else theta + math.pi + math.asin(l)
                cmid = (ccx + dist * math.cos(angle), ccy + dist * math.sin(angle))
            else:                                                # arc -> arc
                pcx, pcy = self._p(front.move.center)
                pex, pey = self._p(front.move.end)
                oldrad = math.hypot(pcy - pey, pcx - pex)
                newrad = arc_radius - r if inside else arc_radius + r
                arc_cc = math.hypot(pcy - ccy, pcx - ccx)
                if oldrad == 0 or arc_cc == 0:
                    self._problem(item.payload, "Arc to arc motion is invalid because the arcs have "
                                                "the same center")
                    cmid = (cx, cy)
                else:
                    a = self._ratio(oldrad ** 2 + arc_cc ** 2 - newrad ** 2, 2 * oldrad * arc_cc,
                                    item.payload, "Arc to arc motion makes a corner the compensated "
                                                  "tool can't fit in without gouging")
                    pullback = math.acos(a)
                    cc_dir = math.atan2(ccy - pcy, ccx - pcx)
                    if self._inside(front.turn):
                        d = cc_dir + pullback if turn > 0 else cc_dir - pullback
                    else:
                        d = cc_dir - pullback if turn > 0 else cc_dir + pullback
                    cmid = (pcx + oldrad * math.cos(d), pcy + oldrad * math.sin(d))
            out = self._move_endpoint_and_flush(cmid, item.payload)
        elif beta > small:                      # convex: corner arc first
            out = self._flush()
            mid = (opx + r * math.cos(delta), opy + r * math.sin(delta))
            corner_end = self._corner_point(item, mid)
            out.append(PlannedMove("arc", dict(self._cur), corner_end, center=self._at({}, (opx, opy)),
                                   direction="cw" if self.side == LEFT else "ccw",
                                   payload=item.payload))
            self._cur = corner_end
            self._endpoint = mid
        else:
            out = self._flush()
            self._endpoint = (cx, cy)
        center = self._at(item.center or {}, (ccx, ccy))
        if inside and arc_radius <= r:          # no arc can be cut: go straight to the offset end
            move = PlannedMove("linear", dict(self._cur), self._at(item.end, new_end), payload=item.payload)
            self._hold(move, dir=(new_end[0] - cx, new_end[1] - cy))
        else:
            move = PlannedMove("arc", dict(self._cur), self._at(item.end, new_end), center=center,
                               direction=item.direction, turns=item.turns, payload=item.payload)
            self._hold(move, sweep=find_turn(opx, opy, ccx, ccy, turn, ex, ey), turn=turn)
        self._prog = (ex, ey)
        return out
