"""Sinumerik CYCLE72, contour milling along a contour subprogram, as plain rapid, feed and arc moves.

`CYCLE72(KNAME, RTP, RFP, SDIS, DP, MID, FAL, FALD, FFP1, FFD, VARI, RL, AS1, LP1, FF3, AS2, LP2)`
mills along the contour KNAME names (a subprogram, or "START:END" labels of the calling program,
read as CYCLE95 reads its contour: nctrans.interp.stock_removal) with the tool centre on it (RL 40)
or beside it at the tool radius (RL 41 left, 42 right: the offset path of
nctrans.interp.cutter_comp, convex corners rounded, concave ones cut at the intersection).

Facts [GK] (Siemens 840D/810D milling cycles manual; the seeds do not document CYCLE72):
- RTP, RFP, SDIS, DP as in every milling cycle; the depth is cut in equal infeeds of at most MID
  (0: at once), fed at FFD; roughing leaves FAL beside the contour and FALD on the floor;
- VARI ones digit 1 roughing, 2 finishing; tens digit: intermediate paths with G0 (0) or G1 at
  FF3 (1); hundreds digit: retraction after the contour to RTP (0), to RFP+SDIS (1), by SDIS
  (2), none (3);
- AS1 / AS2 ones digit: approach / retraction along a straight line tangential to the contour (1),
  a quarter circle (2) or a semicircle (3) of length / radius LP1 / LP2; tens digit 0 in the plane
  (the depth infeed comes first), 1 along a spatial path; the contour is milled at FFP1.
Modelling choices [NC]:
- each depth level: G0 over the approach start at RTP (first) or the retraction height, G0 to
  RFP+SDIS when above it, FFD down to the level, the approach path and the contour at FFP1, the
  retraction path at FFP1, then the hundreds digit's retraction with G0; between levels the
  intermediate path back to the approach start with G0 or G1 FF3 at that height; at the end G0 to
  RTP;
- finishing takes the same infeeds as roughing (MID) down to DP, at the tool radius without FAL;
- spatial approach (tens digit 1), RL 40 with a circular approach, FAL with RL 40, and a contour
  that moves along the tool axis are not modelled (NC224, nothing moves).
"""
from __future__ import annotations

import math

from nctrans.interp.milling_cycles import MillingError, _Plan, _finite, _impossible, _unmodelled, depth_levels, levels_of

EPS = 1e-9


def _unit(v):
    n = math.hypot(*v)
    return (v[0] / n, v[1] / n) if n > EPS else (0.0, 0.0)


def _tangent_out(start, move) -> tuple[float, float]:
    """Unit direction in which `move` (kind, end, centre, cw) leaves `start` (plane coordinates)."""
    kind, end, centre, cw = move
    if kind == "arc" and centre is not None:
        r = (start[0] - centre[0], start[1] - centre[1])
        return _unit((r[1], -r[0]) if cw else (-r[1], r[0]))
    return _unit((end[0] - start[0], end[1] - start[1]))


def _tangent_in(start, move) -> tuple[float, float]:
    """Unit direction in which `move` arrives at its end."""
    kind, end, centre, cw = move
    if kind == "arc" and centre is not None:
        r = (end[0] - centre[0], end[1] - centre[1])
        return _unit((r[1], -r[0]) if cw else (-r[1], r[0]))
    return _unit((end[0] - start[0], end[1] - start[1]))


def offset_path(start, moves, side: str, radius: float):
    """The contour offset by `radius` to `side` ("left"/"right"; radius 0: the contour itself)."""
    if radius <= EPS:
        return start, list(moves)
    from nctrans.interp.cutter_comp import CutterCompensator, PlannedMove

    def pt(q):
        return {"X": q[0], "Y": q[1]}

    comp = CutterCompensator(side, radius, "XY")
    t = _tangent_out(start, moves[0])
    lead = 4 * radius + 1.0                 # an entry move longer than the radius (LinuxCNC's rule)
    out = comp.push(PlannedMove("linear", pt((start[0] - lead * t[0], start[1] - lead * t[1])), pt(start)))
    cur = start
    for kind, end, centre, cw in moves:
        if kind == "arc" and centre is not None:
            out += comp.push(PlannedMove("arc", pt(cur), pt(end), pt(centre), "cw" if cw else "ccw"))
        else:
            out += comp.push(PlannedMove("linear", pt(cur), pt(end)))
        cur = end
    out += comp.finish()
    if comp.problems:
        raise _unmodelled(f"with a contour the tool (offset {radius:g}) cannot follow ({comp.problems[0][1]})")
    o_moves = []
    for m in out[1:]:
        e = (m.end["X"], m.end["Y"])
        if m.kind == "arc":
            o_moves.append(("arc", e, (m.center["X"], m.center["Y"]), m.direction == "cw"))
        else:
            o_moves.append(("linear", e, None, None))
    return (out[0].end["X"], out[0].end["Y"]), o_moves


def _lead(point, t, side: str, how: int, length: float, entering: bool):
    """Approach (entering) to / retraction from `point` with tangent t: (far point, arc or None);
    arc = (centre, cw). `side` is where the tool lies beside the contour (None: on it)."""
    if how == 1:
        s = -1.0 if entering else 1.0
        return (point[0] + s * length * t[0], point[1] + s * length * t[1]), None
    n = (-t[1], t[0]) if side == "left" else (t[1], -t[0])     # towards the tool's side
    centre = (point[0] + length * n[0], point[1] + length * n[1])
    cw = side == "right"
    if how == 2:
        s = -1.0 if entering else 1.0
        return (centre[0] + s * length * t[0], centre[1] + s * length * t[1]), (centre, cw)
    return (point[0] + 2 * length * n[0], point[1] + 2 * length * n[1]), (centre, cw)


def plan72(start, moves, p: dict[str, float], radius: float, here: tuple[float, float, float],
           feed: float) -> list:
    """CYCLE72 steps (milling_cycles' Step format) for the contour `start` + `moves` (plane
    coordinates, the contour as programmed), tool `radius`, from `here`."""
    _finite(p)
    if not moves:
        raise _impossible("with a contour of fewer than two points")
    lv = levels_of(p)
    vari = int(p.get("VARI", 1))
    ones, tens, hundreds = vari % 10, vari // 10 % 10, vari // 100 % 10
    if ones not in (1, 2) or tens not in (0, 1) or hundreds > 3 or vari >= 1000:
        raise _impossible(f"with VARI {vari} (ones 1 roughing / 2 finishing, tens 0/1, hundreds 0-3)")
    rl = int(p.get("RL", 40))
    if rl not in (40, 41, 42):
        raise _impossible(f"with RL {rl} (40 on the contour, 41 left, 42 right)")
    side = {40: None, 41: "left", 42: "right"}[rl]
    how = {}
    for key, length_key in (("AS1", "LP1"), ("AS2", "LP2")):
        code = int(p.get(key, 1) or 1)
        if code % 10 not in (1, 2, 3) or code >= 100:
            raise _impossible(f"with {key} {code} (1 straight line, 2 quarter circle, 3 semicircle)")
        if code // 10:
            raise _unmodelled(f"with {key} {code}: approach or retraction along a spatial path is not modelled")
        if side is None and code % 10 != 1:
            raise _unmodelled(f"with {key} {code} on the contour (RL 40): a circular approach needs a side")
        length = abs(p.get(length_key, 0.0))
        if code % 10 != 1 and length <= EPS:
            raise _impossible(f"with a circular {key} of radius {length_key} 0")
        how[key] = (code % 10, length)
    fal, fald = abs(p.get("FAL", 0.0)), abs(p.get("FALD", 0.0))
    rough = ones == 1
    if side is None and fal > EPS:
        raise _unmodelled("with FAL on the contour (RL 40): an allowance needs a side")
    ffp1 = p.get("FFP1") or feed
    ffd = p.get("FFD") or ffp1
    ff3 = p.get("FF3") or ffp1
    bottom = lv.bottom + lv.up * (fald if rough else 0.0)
    if (lv.rfp - bottom) * lv.up <= EPS:
        raise _impossible("with its floor allowance FALD not above the depth")
    o_start, o_moves = offset_path(start, moves, side or "left", (radius + (fal if rough else 0.0)) if side else 0.0)
    t_in = _tangent_out(o_start, o_moves[0])
    before = o_moves[-2][1] if len(o_moves) > 1 else o_start
    t_out = _tangent_in(before, o_moves[-1])
    o_end = o_moves[-1][1]
    a_far, a_arc = _lead(o_start, t_in, side, *how["AS1"], entering=True)
    r_far, r_arc = _lead(o_end, t_out, side, *how["AS2"], entering=False)
    levels = depth_levels(lv.rfp, bottom, abs(p.get("MID", 0.0)), lv.up)
    plan = _Plan(here)
    plan.approach(a_far[0], a_far[1], lv)
    for k, level in enumerate(levels):
        if k:                                            # intermediate path back to the approach start
            if tens:
                plan.linear(a_far[0], a_far[1], plan.at[2], ff3)
            else:
                plan.rapid(a_far[0], a_far[1], plan.at[2])
            if (plan.at[2] - lv.approach) * lv.up > EPS:
                plan.rapid(a_far[0], a_far[1], lv.approach)
        plan.linear(a_far[0], a_far[1], level, ffd)
        if a_arc is None:
            plan.linear(o_start[0], o_start[1], level, ffp1)
        else:
            plan.arc(o_start[0], o_start[1], level, a_arc[0], a_arc[1], ffp1)
        for kind, end, centre, cw in o_moves:
            if kind == "arc":
                plan.arc(end[0], end[1], level, centre, cw, ffp1)
            else:
                plan.linear(end[0], end[1], level, ffp1)
        if r_arc is None:
            plan.linear(r_far[0], r_far[1], level, ffp1)
        else:
            plan.arc(r_far[0], r_far[1], level, r_arc[0], r_arc[1], ffp1)
        up = {0: lv.rtp, 1: lv.approach, 2: level + lv.up * abs(p.get("SDIS", 0.0)), 3: level}[hundreds]
        plan.rapid(r_far[0], r_far[1], up)
    plan.rapid(r_far[0], r_far[1], lv.rtp)           # the cycle ends at RTP (its docstring, [NC])
    return plan.steps


# ---------------------------------------------------------------------------------------------
# In the interpreter

def run_cycle72(interp, s, unit, pc) -> None:
    """CYCLE72 in the interpreter: read the contour without moving, plan, play the steps."""
    from nctrans.interp.cycles import DRILL_AXIS, PLANE_AXES, milling_cycle
    from nctrans.interp.milling_cycles import _tool_radius, call_values, run_steps
    from nctrans.interp.stock_removal import _contour_blocks, capture_at_cycle_feed
    from nctrans.ir import nodes as n
    cyc = milling_cycle(s.name)
    st = interp.st
    a1, a2 = PLANE_AXES[st.plane]
    ax = DRILL_AXIS[st.plane]
    try:
        if s.modal:
            raise _unmodelled("called modally (MCALL): not modelled")
        radius = _tool_radius(interp)
        if radius is None:
            raise MillingError("NC224", "warning", f"({cyc.meaning}) needs the tool radius: no tool "
                               "offset (D) is active, or the machine model (--machine) does not give "
                               "the active tool's radius")
        name = s.params.get("kname")
        if type(name) is not n.Str or not name.value.strip():
            raise _unmodelled("with KNAME not a string constant naming the contour: not modelled")
        try:
            blocks = _contour_blocks(interp, name.value.strip(), unit, pc)
        except MillingError as err:
            raise MillingError("NC225" if err.rule == "NC114" else "NC224", err.severity, err.message)
        captured = capture_at_cycle_feed(interp, blocks)
        if captured is None:
            return                                  # the capture said why (NC133)
        if len(captured) < 2:
            raise _impossible(f"with a contour {name.value} of fewer than two points")
        heights = {round(m[2].get(ax, 0.0), 9) for m in captured}
        if len(heights) > 1:
            raise _unmodelled("with a contour that moves along the tool axis: not modelled")
        moves = [("linear" if k == "rapid" else k, (e[a1], e[a2]), c, cw)
                 for k, _s, e, c, cw, _sp, _b in captured[1:]]
        start = (captured[0][2][a1], captured[0][2][a2])
        here = (interp.pos.get(a1, 0.0), interp.pos.get(a2, 0.0), interp.pos.get(ax, 0.0))
        values = call_values(interp, cyc, s)
        steps = plan72(start, moves, values, radius, here, st.feed or 0.0)
    except MillingError as err:
        interp.diag(err.rule, err.severity, f"{s.name} {err.message}; the call is skipped and moves "
                    "nothing in the analysed toolpath")
        return
    run_steps(interp, steps, a1, a2, ax)
