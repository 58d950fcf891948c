"""Sinumerik CYCLE93, grooving on a lathe, planned as plain rapids, feeds, arcs and dwells.

`CYCLE93(SPD, SPL, WIDG, DIAG, STA1, ANG1, ANG2, RCO1, RCO2, RCI1, RCI2, FAL1, FAL2, IDEP, DTB,
VARI, _VRT, _DN)` cuts a groove WIDG wide and DIAG deep into a straight contour with a grooving
tool of two cutting edges. The plan is pure geometry (`groove_steps`, testable without an
interpreter) in X (radius) and Z; `run_cycle93` plays it through the lathe's turning emitter, so
conversion, equiv and check see nothing but rapids, feeds, arcs and dwells.

Facts [GK] (Siemens 840D/810D turning cycles manual; the seeds do not document CYCLE93):
- SPD is the groove's starting point in the facing axis X (a diameter under DIAMON, as X is
  programmed), SPL in the longitudinal axis Z; WIDG and DIAG are unsigned, DIAG a radius;
- VARI ones digit 1..8: longitudinal (odd) or face (even), outside (1, 2, 5, 6) or inside (3, 4,
  7, 8), the starting point on the left (1..4) or on the right (5..8); tens digit 0: a chamfer's
  value is its length along the chamfer (CHF), 1: the length of its legs (CHR);
- the three choices say where the starting point lies against the groove: left = on the groove's
  -Z side (the groove lies towards +Z from SPL), right = on its +Z side; outside = on its +X side
  (the groove lies towards the axis from SPD), inside = on its -X side. A longitudinal groove runs
  along Z (WIDG) and goes into X (DIAG); a face groove runs along X and goes into Z: VARI 6 is
  the usual face groove in a right-hand end face, entered from +Z and running from SPD towards
  the axis (the Siemens VARI picture read this way [GK]; the seeds have no picture);
- RCO1/RCO2 round or chamfer the groove's outer corners (on the contour), RCI1/RCI2 its corners
  at the base, 1 on the starting point's side: a positive value is a radius, a negative one a
  chamfer;
- roughing plunges paraxially into the groove in infeeds of at most IDEP, backs off for chip
  breaking after each, dwells DTB at the bottom, and steps across the groove by at most the tool's
  width, leaving FAL1 on the base and FAL2 on the flanks; finishing then runs the profile from each
  edge to the middle of the base (the starting point's side with the first cutting edge, the other
  side with the second); the feed is the one programmed before the call;
- the tool's width is the distance between its two cutting edges (D and D+1, or _DN);
  a tool wider than the groove less its allowances makes the control stop with an alarm.
Modelling choices [NC] (the manual leaves them to the control):
- the path is that of the first cutting edge (the D active at the call): where the second edge
  cuts, the first runs the tool's width behind it, which moves the slide exactly as the control's
  switch to the second edge's offset does; the width comes from the machine model (a tool's
  `width`); without it the call is refused at its line (NC113) and moves nothing;
- the cycle's start point is the groove's edge on the starting point's side, _VRT (1 mm when 0)
  outside the contour; it is reached with G0 in both axes, and the cycle ends there;
- plunges are equally spaced at most the tool's width apart, from the starting point's side
  across; infeeds are equal, of at most IDEP (IDEP 0: one infeed); the chip-breaking back-off is
  _VRT (1 mm when 0) with G0; between plunges the tool goes out to the start point's level;
- roughing leaves the allowances measured paraxially, and a plunge never reaches into a rounded or
  chamfered base corner (it stops above the corner where the tool spans it);
- not modelled, refused at the call's line and moving nothing (NC113): an inclined contour
  (STA1 not 0: the sense in which the angle turns the groove is not documented in the seeds),
  flank angles ANG1/ANG2 (whether WIDG is the width at the base or on the contour is not
  documented in the seeds), MCALL;
- a groove or clearance that would take the path across the turning axis (X below 0) alarms
  (NC114).
"""
from __future__ import annotations

import math
from typing import Optional

from nctrans.interp.milling_cycles import MAX_MOVES, MAX_PASSES, MillingError

EPS = 1e-9
# A planned step in (X radius, Z): ("rapid" | "linear", (x, z)) | ("arc", (x, z), (cx, cz), cw)
# | ("dwell", seconds)
Step = tuple


def unmodelled(message: str) -> MillingError:
    return MillingError("NC113", "warning", message)


def impossible(message: str) -> MillingError:
    return MillingError("NC114", "error", message)


def variant(vari: float) -> tuple[bool, bool, bool, bool]:
    """VARI -> (face, inside, starting point on the right, chamfers as leg length CHR); the ones
    digit from rules/cycles.toml [cycle93_vari]."""
    from nctrans.interp.cycles import cycle_table
    v = int(vari) if math.isfinite(vari) else 0
    ones, tens = v % 10, v // 10
    row = cycle_table().cycle93_vari.get(str(ones))
    if v != vari or row is None or tens not in (0, 1):
        raise impossible(f"with VARI {vari:g} (1..8 and 11..18: longitudinal or face, outside or inside, "
                         "starting point left or right; tens digit the chamfer measure)")
    return row.face, row.inside, row.right, tens == 1


def _leg(value: float, chr_: bool) -> tuple[str, float]:
    """A corner value -> (kind, how far it reaches along each side of the corner)."""
    if abs(value) <= EPS:
        return "none", 0.0
    if value > 0:
        return "radius", value
    return "chamfer", -value if chr_ else -value / math.sqrt(2.0)


class _Outline:
    """The finished groove in local coordinates: u along the contour from the starting point's
    edge (0) to the other edge (W), w the depth into the part (0 on the contour, D at the base)."""

    def __init__(self, width: float, depth: float, o1, o2, i1, i2):
        self.W, self.D = width, depth
        self.o1, self.o2, self.i1, self.i2 = o1, o2, i1, i2

    def floor(self, u: float) -> float:
        """The depth of the finished base at u (less where a base corner is rounded or chamfered)."""
        for (kind, leg), v in ((self.i1, u), (self.i2, self.W - u)):
            if kind != "none" and v < leg:
                if kind == "radius":
                    return self.D - leg + math.sqrt(max(leg * leg - (leg - v) ** 2, 0.0))
                return self.D - leg + v
        return self.D


def groove_steps(p: dict[str, float], tool_width: float) -> list[Step]:
    """CYCLE93 as steps in (X radius, Z). `p` holds the call's values by Siemens name, lengths in
    mm and SPD already a radius; `tool_width` is the distance between the tool's two cutting edges.
    MillingError when the call cannot run as nctrans models it."""
    roughing, finishing = groove_passes(p, tool_width)
    out: list[Step] = []
    for st in roughing + finishing:                # drop moves that go nowhere
        if st[0] in ("rapid", "linear") and out:
            last = next((o for o in reversed(out) if o[0] != "dwell"), None)
            if last is not None and math.dist(last[1], st[1]) <= EPS:
                continue
        out.append(st)
    return out


def groove_passes(p: dict[str, float], tool_width: float) -> tuple[list[Step], list[Step]]:
    """The roughing steps (from the start point's approach) and the finishing steps (back to the
    start point) of `groove_steps`."""
    for k, v in p.items():
        if not math.isfinite(v):
            raise impossible(f"with {k} not a finite number")
    face, inside, right, chr_ = variant(p.get("VARI", 0.0))
    if abs(p.get("STA1", 0.0)) > EPS:
        raise unmodelled(f"on an inclined contour (STA1 {p['STA1']:g}): not modelled (the sense in which the "
                         "angle turns the groove is not documented in the seeds); nctrans models grooves in a "
                         "contour parallel (longitudinal) or square (face) to the axis, STA1 0")
    for name in ("ANG1", "ANG2"):
        if abs(p.get(name, 0.0)) > EPS:
            raise unmodelled(f"with flank angle {name} {p[name]:g}: not modelled (whether WIDG is the width at "
                             "the base or on the contour is not documented in the seeds); nctrans models "
                             "flanks square to the contour")
    W, D = abs(p.get("WIDG", 0.0)), abs(p.get("DIAG", 0.0))
    if W <= EPS or D <= EPS:
        raise impossible("without a groove width WIDG or depth DIAG")
    tw = tool_width
    if not math.isfinite(tw) or tw <= EPS:
        raise impossible(f"with a tool width of {tw:g}")
    fal1, fal2 = abs(p.get("FAL1", 0.0)), abs(p.get("FAL2", 0.0))
    idep, dtb = abs(p.get("IDEP", 0.0)), max(p.get("DTB", 0.0), 0.0)
    vrt = abs(p.get("VRT", 0.0)) or 1.0
    o1, o2 = _leg(p.get("RCO1", 0.0), chr_), _leg(p.get("RCO2", 0.0), chr_)
    i1, i2 = _leg(p.get("RCI1", 0.0), chr_), _leg(p.get("RCI2", 0.0), chr_)
    if o1[1] + i1[1] > D + EPS or o2[1] + i2[1] > D + EPS or i1[1] + i2[1] > W + EPS:
        raise impossible("with radii or chamfers larger than the groove's flanks or base")
    if tw > W - i1[1] - i2[1] + EPS:
        raise impossible(f"with a tool {tw:g} wide for a groove whose flat base is "
                         f"{W - i1[1] - i2[1]:g} wide (the control stops with a tool width alarm)")
    if tw > W - 2 * fal2 + EPS or fal1 >= D - EPS:
        raise impossible(f"with a tool {tw:g} wide, or allowances FAL1/FAL2, that leave nothing to rough "
                         "(the control stops with an alarm)")
    groove = _Outline(W, D, o1, o2, i1, i2)
    s = 1.0 if not right else -1.0                 # the groove lies towards +Z of SPL when the starting point is left
    e = -1.0 if inside else 1.0                    # ... towards the axis (-X) of SPD when it is outside
    r0, spl = p.get("SPD", 0.0), p.get("SPL", 0.0)
    # (u, w) -> (X radius, Z): longitudinal grooves run along Z (u) and go into X (w); face grooves
    # run along X (u) and go into Z (w)
    u_dir, w_dir = ((-e, 0.0), (0.0, s)) if face else ((0.0, s), (-e, 0.0))
    reach = D if not face else W + o2[1]
    if not inside and reach > r0 + EPS:
        raise impossible(f"with a groove reaching {reach:g} towards the axis from a radius of {r0:g} (past the axis)")

    def at(u: float, w: float) -> tuple[float, float]:
        return (r0 + u * u_dir[0] + w * w_dir[0], spl + u * u_dir[1] + w * w_dir[1])

    steps: list[Step] = []
    roughing: list[Step] = []

    def go(kind: str, u: float, w: float) -> None:
        steps.append((kind, at(u, w)))
        if len(steps) + len(roughing) > MAX_MOVES:
            raise impossible(f"with more than {MAX_MOVES} moves (IDEP too small for the depth)")

    def arc(u: float, w: float, centre: tuple[float, float], here: tuple[float, float]) -> None:
        a, b, c = at(*here), at(u, w), at(*centre)
        # clockwise in the (Z, X) picture, as the turning emitter reads it
        cross = (a[1] - c[1]) * (b[0] - c[0]) - (a[0] - c[0]) * (b[1] - c[1])
        steps.append(("arc", b, c, cross < 0))

    # roughing: plunges from the starting point's side across
    lo, hi = fal2, W - fal2 - tw
    n = max(0, math.ceil((hi - lo) / tw - 1e-9)) if hi > lo + EPS else 0
    if n > MAX_PASSES:
        raise impossible(f"with more than {MAX_PASSES} plunges")
    go("rapid", 0.0, -vrt)
    for k in range(n + 1):
        a = lo + (hi - lo) * k / n if n else lo
        depth = min(groove.floor(a), groove.floor(a + tw)) - fal1
        if depth <= EPS:
            continue
        m = max(1, math.ceil(depth / idep - 1e-9)) if idep > EPS else 1
        if m > MAX_PASSES:
            raise impossible(f"with more than {MAX_PASSES} infeeds (IDEP too small)")
        go("rapid", a, -vrt)
        for j in range(1, m + 1):
            level = depth * j / m
            go("linear", a, level)
            if j < m:
                go("rapid", a, level - vrt)
        if dtb > EPS:
            steps.append(("dwell", dtb))
        go("rapid", a, -vrt)

    roughing, steps = steps, []
    # finishing: the first edge down the starting point's flank to the middle of the base
    u1 = min(W / 2, W - i2[1] - tw)                # the tool stays off the other base corner
    go("rapid", -o1[1], -vrt)
    go("linear", -o1[1], 0.0)
    if o1[0] == "radius":
        arc(0.0, o1[1], (-o1[1], o1[1]), (-o1[1], 0.0))
    elif o1[0] == "chamfer":
        go("linear", 0.0, o1[1])
    go("linear", 0.0, D - i1[1])
    if i1[0] == "radius":
        arc(i1[1], D, (i1[1], D - i1[1]), (0.0, D - i1[1]))
    elif i1[0] == "chamfer":
        go("linear", i1[1], D)
    if u1 > i1[1] + EPS:
        go("linear", u1, D)
    here = max(u1, i1[1])
    go("rapid", here, -vrt)
    # the second edge (tw ahead of the first) down the other flank to the middle
    u2 = max(W / 2, i1[1] + tw)
    go("rapid", W + o2[1] - tw, -vrt)
    go("linear", W + o2[1] - tw, 0.0)
    if o2[0] == "radius":
        arc(W - tw, o2[1], (W + o2[1] - tw, o2[1]), (W + o2[1] - tw, 0.0))
    elif o2[0] == "chamfer":
        go("linear", W - tw, o2[1])
    go("linear", W - tw, D - i2[1])
    if i2[0] == "radius":
        arc(W - i2[1] - tw, D, (W - i2[1] - tw, D - i2[1]), (W - tw, D - i2[1]))
    elif i2[0] == "chamfer":
        go("linear", W - i2[1] - tw, D)
    if u2 < W - i2[1] - EPS:
        go("linear", u2 - tw, D)
    here = min(u2, W - i2[1]) - tw
    go("rapid", here, -vrt)
    go("rapid", 0.0, -vrt)
    if any(st[0] != "dwell" and st[1][0] < -EPS for st in roughing + steps):
        raise impossible(f"with a path that crosses the turning axis (X below 0): the groove or its "
                         f"clearance _VRT {vrt:g} does not fit the radius {r0:g}")
    return roughing, steps


# ---------------------------------------------------------------------------------------------
# In the interpreter

def _tool_width(interp) -> Optional[float]:
    """The active tool's cutting width from the machine model, or None. A lathe's turret tool is
    active from its T word (no M6), so the selected tool counts when none was changed."""
    st = interp.st
    number = st.tool or st.tool_selected
    tool = interp.machine.tool(int(number)) if number else None
    width = getattr(tool, "width", None) if tool is not None else None
    return width if width is not None and width > 0 else None


def run_cycle93(interp, cyc, s) -> None:
    """CYCLE93 in the interpreter: plan, then play the steps through the lathe's turning emitter
    (X radius, Z along the axis) at the feed programmed before the call."""
    from nctrans.interp.milling_cycles import call_values
    st = interp.st
    try:
        if s.modal:
            raise unmodelled("called modally (MCALL): not modelled")
        p = call_values(interp, cyc, s)
        width = _tool_width(interp)
        if width is None:
            raise unmodelled("needs the grooving tool's width (the distance between its two cutting "
                             "edges): no tool is active, or the machine model (--machine) gives no "
                             "`width` for it")
        if "SPD" in p and st.diameter:
            p["SPD"] /= 2.0                         # X programmed as a diameter (DIAMON)
        steps = groove_steps(p, width)
    except MillingError as err:
        interp.diag(err.rule, err.severity, f"{s.name} {err.message}; the call is skipped and moves "
                    "nothing in the analysed toolpath")
        return
    for step in steps:
        if step[0] == "dwell":
            interp._record("dwell", dwell_s=float(step[1]))
        elif step[0] == "arc":
            interp._emit_turning([("arc", step[1], step[2], step[3])])
        else:
            interp._emit_turning([(step[0], step[1], None, None)])
