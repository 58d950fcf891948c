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
- ANG1 (the starting point's side) and ANG2 (the other side), 0 <= ANG < 89.999, are flank
  angles: the flanks open outwards from the base by their angles to the contour's normal. WIDG is
  the width at the base: the control alarms when the tool is wider than WIDG (alarm 61602), which
  only says the tool does not fit if WIDG is the groove's narrowest width; SPD/SPL is the edge
  where the starting point's flank meets the contour (the point STA1 draws the contour through).
  The groove is then WIDG + DIAG (tan ANG1 + tan ANG2) wide on the contour;
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
- roughing plunges are spread over the groove's whole opening on the contour; each goes as deep
  as the tool's whole width may: FAL1 off the base, FAL2 square to each flank, never into a
  rounded or chamfered base corner (the rough floor is concave, so its least over the tool's
  width is at one of its ends); a plunge that would not go in at all (at a sloping flank's top)
  is left out;
- a corner on a sloping flank is a rounding tangent to flank and contour (or base), or a chamfer
  with equal legs (nctrans.interp.corners, as RND/CHF/CHR);
- not modelled, refused at the call's line and moving nothing (NC113): an inclined contour
  (STA1 not 0: the manual [GK] turns the groove with the contour, but the tool does not turn, and
  a flat blade tw wide cannot finish a base sloping at STA1: one corner touches it, the other
  stays tw x tan STA1 above it, or the blade cuts below it; whether the control leaves that
  material, finishes the base otherwise, or measures DIAG paraxially is not documented, so any
  model of it would be a guess at the machine's motion), MCALL;
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


BIG = 1e6                                       # the far end of a profile line (the corner geometry's reach)


class _Side:
    """One side of the finished groove in local coordinates (u along the contour from the starting
    point's edge, w the depth into the part): the contour, the flank and the base as lines, and
    the top (RCO) and base (RCI) corner elements between them (nctrans.interp.corners: a rounding
    tangent to both lines, or a chamfer with equal legs)."""

    def __init__(self, top: tuple[float, float], bottom: tuple[float, float], outward: float,
                 rco: float, rci: float, chr_: bool):
        from nctrans.interp import corners
        self.top, self.bottom = top, bottom
        contour = corners.Element("linear", (top[0] + outward * BIG, 0.0), top)
        flank = corners.Element("linear", top, bottom)
        base = corners.Element("linear", bottom, (bottom[0] - outward * BIG, bottom[1]))
        self.o = _corner(contour, flank, rco, chr_)
        self.i = _corner(flank, base, rci, chr_)

    def flank_used(self) -> float:
        """How much of the flank the two corner elements take."""
        return sum(math.dist(c, p) for c, p in ((self.top, self.o.second_start if self.o else self.top),
                                                 (self.bottom, self.i.first_end if self.i else self.bottom)))

    def base_end(self) -> float:
        """u where the flat base begins on this side (the base corner's tangent point)."""
        return self.i.second_start[0] if self.i else self.bottom[0]

    def floor(self, u: float) -> Optional[float]:
        """The depth of the finished base corner at u, where u lies under it; else None."""
        c = self.i
        if c is None:
            return None
        (u0, w0), (u1, w1) = c.first_end, c.second_start
        if not min(u0, u1) - EPS <= u <= max(u0, u1) + EPS:
            return None
        if c.kind == "arc":
            r = math.dist(c.center, c.first_end)
            return c.center[1] + math.sqrt(max(r * r - (u - c.center[0]) ** 2, 0.0))
        return w0 + (w1 - w0) * (u - u0) / (u1 - u0) if abs(u1 - u0) > EPS else max(w0, w1)


def _corner(first, second, value: float, chr_: bool):
    """The corner element RCO/RCI asks for between two profile lines: > 0 a rounding of that
    radius, < 0 a chamfer (tens digit of VARI: 0 its length CHF, 1 its legs CHR); None for 0."""
    from nctrans.interp import corners
    if abs(value) <= EPS:
        return None
    if value > 0:
        c, _ = corners.rounding(first, second, value)
    elif chr_:
        c, _ = corners.chamfer_legs(first, second, -value)
    else:
        c, _ = corners.chamfer_length(first, second, -value)
    if c is None:
        raise impossible(f"with a radius or chamfer {value:g} that does not fit the groove")
    return c


class _Outline:
    """The finished groove in local coordinates: u along the contour from the starting point's
    edge (0) towards the other edge, w the depth into the part (0 on the contour, D at the base).
    [GK] WIDG is the width at the base, the flanks open outwards by ANG1 (starting point's side)
    and ANG2 from the normal of the contour, so the groove is WIDG + DIAG (tan ANG1 + tan ANG2)
    wide on the contour; the starting point is the edge where flank 1 meets the contour."""

    def __init__(self, width: float, depth: float, ang1: float, ang2: float, rco1: float, rco2: float,
                 rci1: float, rci2: float, chr_: bool):
        self.W, self.D = width, depth
        self.t1, self.t2 = math.tan(math.radians(ang1)), math.tan(math.radians(ang2))
        self.c1, self.c2 = math.cos(math.radians(ang1)), math.cos(math.radians(ang2))
        self.b1 = depth * self.t1                   # base corner on the starting point's side
        self.b2 = self.b1 + width                   # ... on the other side
        self.top2 = self.b2 + depth * self.t2       # the other edge on the contour
        self.s1 = _Side((0.0, 0.0), (self.b1, depth), -1.0, rco1, rci1, chr_)
        self.s2 = _Side((self.top2, 0.0), (self.b2, depth), 1.0, rco2, rci2, chr_)

    def floor(self, u: float) -> float:
        """The depth of the finished groove at u (less on a flank or a rounded or chamfered base
        corner); 0 outside the groove's opening."""
        w = self.D
        if self.t1 > EPS:
            w = min(w, u / self.t1)
        elif u < -EPS:
            return 0.0
        if self.t2 > EPS:
            w = min(w, (self.top2 - u) / self.t2)
        elif u > self.top2 + EPS:
            return 0.0
        for side in (self.s1, self.s2):
            f = side.floor(u)
            if f is not None:
                w = min(w, f)
        return max(w, 0.0)

    def rough_floor(self, u: float, fal1: float, fal2: float) -> float:
        """The deepest a roughing plunge may reach at u: the finished floor less FAL1, and FAL2
        off each flank (measured square to the flank)."""
        w = self.floor(u) - fal1
        lo, hi = fal2 / self.c1, self.top2 - fal2 / self.c2
        if u < lo - EPS or u > hi + EPS:
            return 0.0
        if self.t1 > EPS:
            w = min(w, (u - lo) / self.t1)
        if self.t2 > EPS:
            w = min(w, (hi - u) / self.t2)
        return w


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
    sta1 = p.get("STA1", 0.0)
    if abs(sta1) > EPS:
        # A groove turned with the contour has a base sloping at STA1 to the axis, which a grooving
        # tool that does not turn cannot finish: its flat blade tw wide touches the base with one
        # corner only, so either the other corner's end (tw wide, tw x tan STA1 deep) stays or the
        # blade cuts below the base. What the control does there (or whether its groove is turned
        # at all, DIAG square to the contour or paraxial) is in neither the seeds nor [GK]
        raise unmodelled(f"on an inclined contour (STA1 {sta1:g}): not modelled (the seeds do not "
                         "document CYCLE93; the manual [GK] turns the groove with the contour, but a tool "
                         f"that does not turn cannot finish a base sloping at {sta1:g} degrees with its flat "
                         f"blade {tool_width:g} wide (it leaves {tool_width:g} x tan {sta1:g} of material at "
                         "one end of the base, or cuts below it), and how the control's cycle "
                         "resolves it, or whether DIAG is square to the contour at all, is not documented); "
                         "nctrans models grooves in a contour parallel (longitudinal) or square (face) to "
                         "the axis, STA1 0")
    ang1, ang2 = p.get("ANG1", 0.0), p.get("ANG2", 0.0)
    for name, a in (("ANG1", ang1), ("ANG2", ang2)):
        if not 0.0 <= a < 90.0 - 1e-3 + EPS:
            raise impossible(f"with flank angle {name} {a:g} (0 <= {name} < 89.999 degrees [GK])")
    W, D = abs(p.get("WIDG", 0.0)), abs(p.get("DIAG", 0.0))
    if W <= EPS or D <= EPS:
        raise impossible("without a groove width WIDG or depth DIAG")
    tw = tool_width
    if not math.isfinite(tw) or tw <= EPS:
        raise impossible(f"with a tool width of {tw:g}")
    fal1, fal2 = abs(p.get("FAL1", 0.0)), abs(p.get("FAL2", 0.0))
    idep, dtb = abs(p.get("IDEP", 0.0)), max(p.get("DTB", 0.0), 0.0)
    vrt = abs(p.get("VRT", 0.0)) or 1.0
    groove = _Outline(W, D, ang1, ang2, p.get("RCO1", 0.0), p.get("RCO2", 0.0), p.get("RCI1", 0.0),
                      p.get("RCI2", 0.0), chr_)
    s1, s2 = groove.s1, groove.s2
    base1, base2 = s1.base_end(), s2.base_end()    # the flat base runs from base1 to base2
    if (s1.flank_used() > D / groove.c1 + EPS or s2.flank_used() > D / groove.c2 + EPS
            or base2 < base1 - EPS):
        raise impossible("with radii or chamfers larger than the groove's flanks or base")
    if tw > base2 - base1 + EPS:
        raise impossible(f"with a tool {tw:g} wide for a groove whose flat base is "
                         f"{base2 - base1:g} wide (the control stops with a tool width alarm)")
    if tw > W - fal2 / groove.c1 - fal2 / groove.c2 + EPS or fal1 >= D - EPS:
        raise impossible(f"with a tool {tw:g} wide, or allowances FAL1/FAL2, that leave nothing to rough "
                         "(the control stops with an alarm)")
    s = 1.0 if not right else -1.0                 # the groove lies towards +Z of SPL when the starting point is left
    e = -1.0 if inside else 1.0                    # ... towards the axis (-X) of SPD when it is outside
    r0, spl = p.get("SPD", 0.0), p.get("SPL", 0.0)
    # (u, w) -> (X radius, Z): longitudinal grooves run along Z (u) and go into X (w); face grooves
    # run along X (u) and go into Z (w)
    u_dir, w_dir = ((-e, 0.0), (0.0, s)) if face else ((0.0, s), (-e, 0.0))
    o2_reach = s2.o.first_end[0] if s2.o else groove.top2
    reach = D if not face else o2_reach
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

    # roughing: plunges from the starting point's side across the groove's opening; each goes as
    # deep as the tool's whole width may (the rough floor is concave: its least over the tool's
    # width is at one of the tool's ends)
    lo, hi = fal2 / groove.c1, groove.top2 - fal2 / groove.c2 - tw
    n = max(0, math.ceil((hi - lo) / tw - 1e-9)) if hi > lo + EPS else 0
    if n > MAX_PASSES:
        raise impossible(f"with more than {MAX_PASSES} plunges")
    go("rapid", 0.0, -vrt)
    for k in range(n + 1):
        a = lo + (hi - lo) * k / n if n else lo
        depth = min(groove.rough_floor(a, fal1, fal2), groove.rough_floor(a + tw, fal1, fal2))
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

    def profile(side: _Side, shift: float, end_u: float, sense: float) -> None:
        """Finish one side with one edge (the first edge's path is the edge's point less `shift`
        along u): from the contour over the top corner, down the flank, over the base corner and
        along the base (in the sense `sense` of u) to `end_u`, then out."""
        def element(c) -> None:
            if c.kind == "arc":
                arc(c.second_start[0] - shift, c.second_start[1], (c.center[0] - shift, c.center[1]),
                    (c.first_end[0] - shift, c.first_end[1]))
            else:
                go("linear", c.second_start[0] - shift, c.second_start[1])
        o, i = side.o, side.i
        u0 = o.first_end[0] if o else side.top[0]
        go("rapid", u0 - shift, -vrt)
        go("linear", u0 - shift, 0.0)
        if o:
            element(o)
        flank_end = i.first_end if i else side.bottom
        go("linear", flank_end[0] - shift, flank_end[1])
        if i:
            element(i)
        here = side.base_end()
        if (end_u - here) * sense > EPS:
            go("linear", end_u - shift, D)
            here = end_u
        go("rapid", here - shift, -vrt)

    # finishing: the first edge down the starting point's flank to the middle of the base (it
    # stays off the other base corner), then the second edge (tw ahead of the first) down the
    # other flank to the middle
    middle = (groove.b1 + groove.b2) / 2
    profile(s1, 0.0, min(middle, base2 - tw), 1.0)
    profile(s2, tw, max(middle, base1 + tw), -1.0)
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
