"""Sinumerik CYCLE95, stock removal along a contour subprogram, on the iso-t roughing geometry.

`CYCLE95(NPP, MID, FALZ, FALX, FAL, FF1, FF2, FF3, VARI, DT, DAM, _VRT)` roughs and/or finishes the
contour named by NPP: a subprogram ("KONTUR") or a section of the calling program between two
labels ("ANF:END"). The geometry is the one of nctrans.interp.turning (the ISO G71/G72 engine):
points are (d, p) in radius, `p` the axis a pass runs along and `d` the axis the passes step across
(longitudinal: d = X, p = Z; face: d = Z, p = X), and moves are turning.py's (kind, end, centre, cw).

Facts [GK] (Siemens 840D/810D turning cycles manual; the seeds do not document CYCLE95):
- VARI 1..12: (VARI-1) // 4 is roughing (0), finishing (1) or complete (2); (VARI-1) % 4 is
  longitudinal outside (0), face outside (1), longitudinal inside (2), face inside (3);
- MID is the largest infeed (radius); the depth is cut in equal infeeds of at most MID;
- FALZ / FALX are the finishing allowances along Z and X (X as a radius), FAL along the contour;
- roughing cuts are paraxial at FF1; after each cut the tool follows the contour (plus allowance)
  back to the previous infeed level, so no residual corners remain, lifts off by _VRT in both axes
  (_VRT 0: 1 mm) and goes back with G0; undercuts are entered at FF2;
- the cycle start point is computed from the contour: its outermost point plus allowance plus
  _VRT across, its free end plus allowance plus _VRT along; it is approached with G0 in both axes
  and the cycle ends there;
- finishing runs the contour at FF3, lifts off by _VRT and returns to the start point with G0;
- DT is a dwell and DAM a path length for chip breaking while roughing.
Modelling choices [NC] (the manual leaves them to the control, or nctrans does not model them):
- the contour must be monotonic in both axes (no undercut): one with undercuts is refused at its
  line (NC113) and moves nothing; so are DAM/DT chip breaking and a contour with fewer than two
  moves;
- FAL offsets the contour along its normal (convex corners rounded with radius FAL, as a tool of
  that radius would run round them); FALX/FALZ then shift it along the axes (the two add up);
- longitudinal machining steps towards the axis outside, away from it inside; face machining
  steps towards -Z; the passes run from the contour's deep end (the end furthest in the infeed
  direction) towards its other end, whichever way the contour is written;
- the lift-off is a G0 by _VRT in both axes; finishing enters the contour start along the pass
  axis with G1 from the start point's level, runs the contour from its deep end, lifts off by
  _VRT across and returns across first, then along;
- the tool path is the tool tip on the contour: the cycle's own tool-nose compensation is not
  modelled (a known nose radius is reported, NC113, and the path is still the tip's).
"""
from __future__ import annotations

import math
from typing import Optional

from nctrans.interp import turning
from nctrans.interp.milling_cycles import MAX_MOVES, MAX_PASSES, MillingError

EPS = 1e-9


def _sign(v: float) -> float:
    return -1.0 if v < 0 else 1.0


def unmodelled(message: str) -> MillingError:
    return MillingError("NC113", "warning", message)


def impossible(message: str) -> MillingError:
    return MillingError("NC114", "error", message)


def variant(vari: float) -> tuple[str, bool, bool]:
    """VARI -> (machining "rough" | "finish" | "complete", face, inside)."""
    v = int(vari) if math.isfinite(vari) else 0
    if v != vari or not 1 <= v <= 12:
        raise impossible(f"with VARI {vari:g} (1..12: roughing, finishing or complete; longitudinal or "
                         "face; outside or inside)")
    what, form = divmod(v - 1, 4)
    return ("rough", "finish", "complete")[what], form in (1, 3), form >= 2


def reversed_contour(start, moves):
    """The contour run backwards: (new start, moves)."""
    points = [start] + [m[1] for m in moves]
    out = []
    for i in range(len(moves) - 1, -1, -1):
        kind, _, centre, cw = moves[i]
        out.append((kind, points[i], centre, None if cw is None else not cw))
    return points[-1], out


def _on_move(cur, move, level: float) -> Optional[tuple]:
    """The point of `move` (from `cur`) at d = level, or None (a monotonic move has at most one)."""
    kind, end, centre, cw = move
    if abs(cur[0] - level) < EPS:
        return cur
    if abs(end[0] - level) < EPS:
        return end
    if (cur[0] - level) * (end[0] - level) > 0:
        return None
    if kind == "arc" and centre is not None:
        ps = turning.hits(cur, [move], level)
        if not ps:
            return None
        lo, hi = sorted((cur[1], end[1]))
        inside = [p for p in ps if lo - 1e-7 <= p <= hi + 1e-7] or ps
        return (level, min(inside, key=lambda p: abs(p - cur[1])))
    t = (level - cur[0]) / (end[0] - cur[0])
    return (level, cur[1] + t * (end[1] - cur[1]))


def first_at(start, moves, level: float) -> tuple[int, tuple]:
    """(index, point): the first point of a monotonic contour at d = level (index -1: the start)."""
    if abs(start[0] - level) < EPS:
        return -1, start
    cur = start
    for i, m in enumerate(moves):
        pt = _on_move(cur, m, level)
        if pt is not None:
            return i, pt
        cur = m[1]
    return len(moves) - 1, cur


def last_at(start, moves, level: float) -> tuple[int, tuple]:
    """(index, point): the last point of a monotonic contour at d = level."""
    points = [start] + [m[1] for m in moves]
    for i in range(len(moves) - 1, -1, -1):
        if abs(points[i + 1][0] - level) < EPS:
            return i, points[i + 1]
        pt = _on_move(points[i], moves[i], level)
        if pt is not None:
            return i, pt
    return -1, start


def between(start, moves, a: tuple[int, tuple], b: tuple[int, tuple]) -> list:
    """The contour's moves from point a to point b (both (index, point) as first_at/last_at give,
    the point lying on move `index`; index -1 is the start point)."""
    ia, pa = a
    ib, pb = b
    out = []
    if ib < ia:
        return out
    here = pa
    for i in range(max(ia, 0), ib + 1):
        kind, end, centre, cw = moves[i]
        target = pb if i == ib else end
        if abs(target[0] - here[0]) > EPS or abs(target[1] - here[1]) > EPS:
            out.append(("linear" if kind == "rapid" else kind, target, centre, cw))
            here = target
    return out


def _extreme(start, moves, direction: float, axis: int) -> float:
    best = start[axis]
    cur = start
    for kind, end, centre, cw in moves:
        pts = turning.arc_points(cur, end, centre, cw, 64) if kind == "arc" and centre is not None else [end]
        for pt in pts:
            if direction * (pt[axis] - best) > 0:
                best = pt[axis]
        cur = end
    return best


def _tangent(start, move) -> tuple[float, float]:
    """Unit direction (d, p) in which `move` leaves `start`."""
    kind, end, centre, cw = move
    if kind == "arc" and centre is not None:
        # in the (p, d) frame an arc runs clockwise when `cw`; its tangent is the radius turned
        rp, rd = start[1] - centre[1], start[0] - centre[0]
        tp, td = (rd, -rp) if cw else (-rd, rp)
    else:
        tp, td = end[1] - start[1], end[0] - start[0]
    n = math.hypot(tp, td) or 1.0
    return td / n, tp / n


def equidistant(start, moves, fal: float, sd: float, sp: float):
    """The contour offset by `fal` along its normal, away from the part (towards -sd): the
    compensated path of a tool of radius FAL (nctrans.interp.cutter_comp: convex corners get an arc
    round the corner, concave ones end at the intersection). (start, moves) in (d, p)."""
    if fal <= EPS:
        return start, list(moves)
    from nctrans.interp.cutter_comp import LEFT, RIGHT, CutterCompensator, PlannedMove

    def pt(q):                      # (d, p) -> the plane (X = p, Y = d)
        return {"X": q[1], "Y": q[0]}

    side = LEFT if sp == -sd else RIGHT     # travelling +sp, the part lies on the sd side
    comp = CutterCompensator(side, fal, "XY")
    td, tp = _tangent(start, moves[0])
    lead = 4 * fal + 1.0                    # an entry move longer than the radius (LinuxCNC's rule)
    before = (start[0] - lead * td, start[1] - lead * tp)
    out = comp.push(PlannedMove("linear", pt(before), pt(start)))
    cur = start
    for kind, end, centre, cw in moves:
        if kind == "arc" and centre is not None:
            out += comp.push(PlannedMove("arc", pt(cur), pt(end), pt(centre), "cw" if cw else "ccw"))
        else:
            out += comp.push(PlannedMove("linear", pt(cur), pt(end)))
        cur = end
    out += comp.finish()
    if comp.problems:
        raise unmodelled(f"with FAL {fal:g} along a contour it cannot follow at that distance "
                         f"({comp.problems[0][1]}): not modelled")
    o_start = (out[0].end["Y"], out[0].end["X"])
    o_moves = []
    for m in out[1:]:
        e = (m.end["Y"], m.end["X"])
        if m.kind == "arc":
            o_moves.append(("arc", e, (m.center["Y"], m.center["X"]), m.direction == "cw"))
        else:
            o_moves.append(("linear", e, None, None))
    # the filter checks corners locally; a step of the contour smaller than FAL can still bring the
    # offset closer than FAL: then the allowance is not modelled rather than cut into
    near = min(_distance(q, _polyline(start, moves)) for q in _polyline(o_start, o_moves, 8))
    if near < fal - 1e-3 or turning.first_non_monotonic(o_start, o_moves) is not None or \
            turning.first_non_monotonic((o_start[1], o_start[0]), turning.swapped(o_moves)) is not None:
        raise unmodelled(f"with FAL {fal:g} larger than a step of the contour: the contour offset by FAL "
                         "is not modelled there")
    return o_start, o_moves


def _polyline(start, moves, n_line: int = 1) -> list:
    """Points along the moves: arcs finely sampled, lines split in n_line pieces."""
    pts = [start]
    cur = start
    for kind, end, centre, cw in moves:
        if kind == "arc" and centre is not None:
            pts.extend(turning.arc_points(cur, end, centre, cw, 256)[1:])
        else:
            pts.extend((cur[0] + (end[0] - cur[0]) * k / n_line, cur[1] + (end[1] - cur[1]) * k / n_line)
                       for k in range(1, n_line + 1))
        cur = end
    return pts


def _distance(q, pts) -> float:
    """Distance from q to the polyline through pts."""
    best = math.inf
    for a, b in zip(pts, pts[1:]):
        dx, dy = b[0] - a[0], b[1] - a[1]
        L = dx * dx + dy * dy
        t = 0.0 if L == 0 else max(0.0, min(1.0, ((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / L))
        best = min(best, math.hypot(q[0] - a[0] - t * dx, q[1] - a[1] - t * dy))
    return best if len(pts) > 1 else math.hypot(q[0] - pts[0][0], q[1] - pts[0][1])


def plan(start, moves, p: dict[str, float], face: bool, inside: bool, what: str):
    """CYCLE95 in (d, p): the contour `start` + `moves` as the subprogram programs it (radius,
    axes already in (d, p) order, allowances not applied). Returns (cycle start point, steps):
    steps are turning-style moves and ("feed", value, None, None). MillingError when refused."""
    for k, v in p.items():
        if not math.isfinite(v):
            raise impossible(f"with {k} not a finite number")
    if len(moves) < 1:
        raise impossible("with a contour of fewer than two points")
    if abs(p.get("DAM", 0.0)) > EPS or abs(p.get("DT", 0.0)) > EPS:
        raise unmodelled("with chip breaking while roughing (DT/DAM): not modelled")
    if turning.first_non_monotonic(start, moves) is not None or \
            turning.first_non_monotonic((start[1], start[0]), turning.swapped(moves)) is not None:
        raise unmodelled("with a contour that turns back (an undercut, entered at FF2): not modelled; "
                         "nctrans models contours monotonic in both axes")
    sd = -1.0 if face else (1.0 if inside else -1.0)   # the infeed direction in d
    ends = [start, moves[-1][1]]
    deep = max(ends, key=lambda q: sd * q[0])
    if deep is not start:
        start, moves = reversed_contour(start, moves)
    shallow = moves[-1][1]
    sp = _sign(shallow[1] - start[1]) if abs(shallow[1] - start[1]) > EPS else -1.0
    fal_d = abs(p.get("FALZ" if face else "FALX", 0.0))
    fal_p = abs(p.get("FALX" if face else "FALZ", 0.0))
    vrt = abs(p.get("VRT", 0.0)) or 1.0
    dd, dp = -sd * fal_d, -sp * fal_p
    o_start, o_moves = equidistant(start, moves, abs(p.get("FAL", 0.0)), sd, sp)
    s_start = (o_start[0] + dd, o_start[1] + dp)
    s_moves = turning.shifted(o_moves, dd, dp)
    top = _extreme(s_start, s_moves, -sd, 0)
    front = _extreme(s_start, s_moves, -sp, 1)
    a = (top - sd * vrt, front - sp * vrt)             # the cycle start point
    steps: list = [("rapid", a, None, None)]
    if what in ("rough", "complete"):
        mid = p.get("MID", 0.0)
        if mid <= EPS:
            raise impossible("roughing without an infeed depth MID")
        total = sd * (s_start[0] - top)
        n = math.ceil(total / mid - 1e-9) if total > EPS else 0
        if n > MAX_PASSES:
            raise impossible(f"with more than {MAX_PASSES} roughing cuts (MID too small)")
        if n:
            steps.append(("feed", p.get("FF1", 0.0), None, None))
        prev = top
        for k in range(1, n + 1):
            level = s_start[0] if k == n else top + sd * total * k / n
            stop = last_at(s_start, s_moves, level)
            reach = first_at(s_start, s_moves, prev)
            steps.append(("rapid", (level, a[1]), None, None))
            steps.append(("linear", stop[1], None, None))
            follow = between(s_start, s_moves, stop, reach)
            steps.extend(follow)
            here = follow[-1][1] if follow else stop[1]
            steps.append(("rapid", (here[0] - sd * vrt, here[1] - sp * vrt), None, None))
            steps.append(("rapid", (here[0] - sd * vrt, a[1]), None, None))
            prev = level
            if len(steps) > MAX_MOVES:
                raise impossible(f"with more than {MAX_MOVES} moves (MID too small for the contour)")
        steps.append(("rapid", a, None, None))
    if what in ("finish", "complete"):
        steps.append(("rapid", (start[0], a[1]), None, None))
        steps.append(("feed", p.get("FF3", 0.0), None, None))
        steps.append(("linear", start, None, None))
        steps.extend(("linear" if m[0] == "rapid" else m[0], m[1], m[2], m[3]) for m in moves)
        end = moves[-1][1]
        steps.append(("rapid", (end[0] - sd * vrt, end[1]), None, None))
        steps.extend(turning.return_to(a, (end[0] - sd * vrt, end[1])))
    out = []
    for s in steps:                                     # drop moves that go nowhere
        if s[0] in ("rapid", "linear") and out:
            last = next((o for o in reversed(out) if o[0] != "feed"), None)
            if last is not None and abs(last[1][0] - s[1][0]) < EPS and abs(last[1][1] - s[1][1]) < EPS:
                continue
        out.append(s)
    return a, out


# ---------------------------------------------------------------------------------------------
# In the interpreter

def _values(interp, cyc, s) -> dict[str, float]:
    """The numeric arguments by Siemens name: lengths in mm (G70: inch), feeds in mm."""
    lengths = ("MID", "FALZ", "FALX", "FAL", "DAM", "VRT")
    feeds = ("FF1", "FF2", "FF3")
    from nctrans.interp.cycles import cycle_table
    table = cycle_table()
    out: dict[str, float] = {}
    for name in cyc.params:
        e = s.params.get(table.neutral(name))
        if e is None or name == "NPP":
            continue
        v = interp._value(interp.ev.compile(e), f"{cyc.name} {name}")
        if v is None:
            continue
        scale = interp.st.scale if name in lengths else interp.st.feed_scale if name in feeds else 1.0
        out[name] = v * scale
    return out


def capture_at_cycle_feed(interp, blocks) -> Optional[list]:
    """The contour's moves (interp._capture_contour), read under any feed: the contour's own F is
    not needed, the cycle feeds at its own parameters."""
    st = interp.st
    feed = st.feed
    st.feed = feed or 1.0
    try:
        return interp._capture_contour(blocks)
    finally:
        st.feed = feed


def _contour_blocks(interp, npp: str, unit, pc):
    """The blocks of the contour NPP names: a subprogram, or "START:END" labels of the calling
    program (both label blocks included). Blocks after a RET/M17/M30 of the subprogram are not
    part of it; the ending statement is dropped."""
    import copy
    from nctrans.interp.compiled import BLOCK, label_key
    from nctrans.ir import nodes as n
    if ":" in npp:
        first, _, last = (x.strip() for x in npp.partition(":"))
        a = interp._find_label(unit, label_key(first), "any", pc)
        if a is None:
            raise impossible(f"with its contour start label {first} not found in the program")
        b = interp._find_label(unit, label_key(last), "forward", a - 1)
        if b is None:
            raise impossible(f"with its contour end label {last} not found after {first}")
        code = unit.code[a:b + 1]
    else:
        sub = interp._find_unit(npp)
        if sub is None:
            raise impossible(f"with its contour subprogram {npp} not found beside the program or on "
                             "the search path")
        code = sub.code
    blocks = []
    for ins in code:
        if ins[0] != BLOCK:
            raise unmodelled("with control flow inside its contour: not modelled")
        blk = ins[2]
        ends = [st for st in blk.body if type(st) in (n.Return, n.ProgramEnd)]
        if ends:
            blk = copy.copy(blk)
            blk.body = [st for st in blk.body if type(st) not in (n.Return, n.ProgramEnd)]
            blocks.append(blk)
            break
        blocks.append(blk)
    return blocks


def run_cycle95(interp, s, unit, pc) -> None:
    """CYCLE95 in the interpreter: read the contour without moving, plan, play the moves through
    the lathe's turning emitter (X radius, Z along the axis)."""
    from nctrans.interp.cycles import milling_cycle
    from nctrans.interp.milling_cycles import _tool_radius
    from nctrans.ir import nodes as n
    cyc = milling_cycle(s.name)
    st = interp.st
    try:
        if s.modal:
            raise unmodelled("called modally (MCALL): not modelled")
        npp = s.params.get("npp")
        if type(npp) is not n.Str or not npp.value.strip():
            raise unmodelled("with NPP not a string constant naming the contour: not modelled")
        p = _values(interp, cyc, s)
        what, face, inside = variant(p.get("VARI", 0.0))
        blocks = _contour_blocks(interp, npp.value.strip(), unit, pc)
        captured = capture_at_cycle_feed(interp, blocks)
        if captured is None:
            return                                  # the capture said why (NC133)
        if len(captured) < 2:
            raise impossible(f"with a contour {npp.value} of fewer than two points")

        def dp(pt):
            return (pt["Z"], pt["X"]) if face else (pt["X"], pt["Z"])

        moves = []
        for kind, _start, end, centre, cw, _span, _blk in captured[1:]:
            c = None
            if centre is not None:                  # (Z, X) in the ZX plane
                c = (centre[0], centre[1]) if face else (centre[1], centre[0])
            moves.append(("linear" if kind == "rapid" else kind, dp(end), c,
                          (not cw) if (face and cw is not None) else cw))
        _, steps = plan(dp(captured[0][2]), moves, p, face, inside, what)
    except MillingError as err:
        interp.diag(err.rule, err.severity, f"{s.name} {err.message}; the call is skipped and moves "
                    "nothing in the analysed toolpath")
        return
    radius = _tool_radius(interp)
    if radius:
        interp.diag("NC113", "warning", f"{s.name}: the cycle's own tool-nose radius compensation "
                    f"(nose radius {radius:g}) is not modelled; the analysed path is the tool tip on "
                    "the contour")
    saved = st.feed
    try:
        for step in steps:
            if step[0] == "feed":
                st.feed = step[1]
                continue
            interp._emit_turning([step], swap=face)
    finally:
        st.feed = saved
