"""Sinumerik CYCLE94 (undercut form E/F, DIN 509) and CYCLE96 (thread undercut, DIN 76) on a lathe,
planned as plain feeds, arcs and rapids.

`CYCLE94(SPD, SPL, FORM, VARI)` cuts a DIN 509 undercut of form E or F into the corner between a
cylinder of diameter SPD and a shoulder face at SPL; `CYCLE96(DIATH, SPL, FORM, VARI)` cuts a DIN 76
thread undercut (form A normal, B short external; C normal, D short internal) into a thread of nominal diameter DIATH at the shoulder at
SPL. The undercut's dimensions are looked up in tables (rules/cycles.toml [undercut], each fact with
where it comes from); the plan is pure geometry (`undercut_steps`, testable without an interpreter)
in X (radius) and Z; `run_undercut` plays it through the lathe's turning emitter, so conversion,
equiv and check see nothing but rapids, feeds and arcs.

Facts [GK] (Siemens 840D/810D turning cycles manual; the seeds do not document these cycles):
- SPD is the finished diameter (a diameter under DIAMON, as X is programmed), DIATH the thread's
  nominal diameter (always a diameter), SPL the shoulder's position on the longitudinal axis Z;
- FORM "E" (DIN 509 form E: only the cylinder is relieved) or "F" (form F: cylinder and face);
  CYCLE96: "A"/"B" external thread normal/short, "C"/"D" internal thread normal/short;
- the dimensions follow from the diameter (CYCLE94: the DIN 509 row of SPD) or from the thread's
  pitch (CYCLE96: the metric coarse pitch of DIATH, rules/cycles.toml [metric_coarse_pitch]);
- VARI 0 takes the undercut's position from the active tool's cutting edge position, 1..8 give it;
- the undercut is cut in one pass along the finished contour, at the feed programmed before the
  call; the tool's nose radius compensation of the cycle is not modelled (the path is the tip's).
Modelling choices [NC] (what the manual leaves to the control, or what is not established here):
- the position digits 1..4 are the cutting edge positions of the tool tip (nctrans.interp.nose):
  the tip points into the corner, so 3 (-X -Z) is an outside undercut whose shoulder lies towards
  -Z, 4 (-X +Z) outside with the shoulder towards +Z, 2 (+X -Z) and 1 (+X +Z) the inside ones;
  5..8 (a tip along an axis) name no corner and are refused (NC115);
- the cycle starts and ends at the clearance point, 1 mm (`clearance`) beyond the undercut's end on
  the thread/cylinder side and 1 mm outside the surface, reached with G0; it feeds from there onto
  the surface, down the run-out flank, along the base, round the radius and up the face, lifts off
  the face by the clearance, and returns to the start with G0;
- form F: the face recess t2 runs from the radius straight up to the face at the DIN angle of 8°
  (the radius meets it with a small kink instead of tangentially);
- CYCLE96 forms C and D (internal threads): the DIN 76 internal table [GK, to confirm against
  the standard; rules/cycles.toml says where it comes from] gives dg = d + 0.3/0.5, g2 and r by
  the pitch; the undercut is cut into the core hole, whose surface is taken as the basic minor
  diameter D1 = d - 1.082532 P (ISO 724) [NC: where the control's cycle starts an internal
  undercut is not documented here]: depth (dg - D1) / 2, the clearance point 1 mm inside the core
  hole. A form and a position that disagree (C/D outside, A/B inside) are NC116;
- not modelled, refused at the call's line with no motion (NC115): VARI 5..8, VARI 0 without a
  tip direction in the machine model, MCALL.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

from nctrans.interp.milling_cycles import MillingError

EPS = 1e-9
Step = tuple    # ("rapid" | "linear", (x, z)) | ("arc", (x, z), (cx, cz), cw), X a radius


def unmodelled(message: str) -> MillingError:
    return MillingError("NC115", "warning", message)


def impossible(message: str) -> MillingError:
    return MillingError("NC116", "error", message)


@dataclass(frozen=True)
class Undercut:
    """An undercut's outline in local coordinates: u along the axis from the shoulder face (0) away
    from the shoulder, w the depth below the finished surface (into the part). The base lies at
    depth `depth` from u = `radius` - `face_depth`, rises along the run-out flank at `run_out` degrees
    to the surface at u = `width`; the corner to the face is rounded with `radius`; form F recesses
    the face by `face_depth`, its wall at `face_angle` degrees to the radial direction."""
    depth: float
    width: float
    radius: float
    run_out: float
    face_depth: float = 0.0
    face_angle: float = 8.0

    @property
    def run_out_start(self) -> float:
        """u where the base ends and the run-out flank begins."""
        return self.width - self.depth / math.tan(math.radians(self.run_out))


def din509(diameter: float, form: str) -> Undercut:
    """The DIN 509 undercut of form E/F for a finished diameter (rules/cycles.toml [undercut])."""
    from nctrans.interp.cycles import cycle_table
    table = cycle_table().undercut
    for row in table.din509:
        if diameter <= row.max_diameter + EPS:
            return Undercut(row.depth, row.width, row.radius, table.din509_run_out,
                            row.face_depth if form == "F" else 0.0, table.din509_face_angle)
    raise AssertionError("the last DIN 509 row has no upper limit")     # the table ends with inf


def din76(pitch: float, form: str) -> Undercut:
    """The DIN 76 external thread undercut (A normal, B short) for a pitch."""
    from nctrans.interp.cycles import cycle_table
    table = cycle_table().undercut
    for row in table.din76:
        if abs(row.pitch - pitch) <= EPS:
            width = row.width_normal if form == "A" else row.width_short
            return Undercut(row.diameter_less / 2.0, width, row.radius, table.din76_run_out)
    raise impossible(f"for a pitch of {pitch:g} mm, which the DIN 76 table does not list")


def din76_internal(pitch: float, form: str, diameter: float) -> tuple[Undercut, float]:
    """The DIN 76 internal thread undercut (C normal, D short) for a pitch and nominal diameter,
    and the radius of the surface it is cut into: the core hole at the basic minor diameter
    D1 = d - 1.082532 P [GK ISO 724; where the cycle starts it is nctrans' choice, NC]. The depth
    below that surface is (dg - D1) / 2 with dg = d + diameter_more."""
    from nctrans.interp.cycles import cycle_table
    table = cycle_table().undercut
    for row in table.din76_internal:
        if abs(row.pitch - pitch) <= EPS:
            width = row.width_normal if form == "C" else row.width_short
            minor = diameter - table.minor_diameter_factor * pitch
            depth = (diameter + row.diameter_more - minor) / 2.0
            return Undercut(depth, width, row.radius, table.din76_run_out), minor / 2.0
    raise impossible(f"for a pitch of {pitch:g} mm, which the DIN 76 internal table does not list")


def position(vari: float, tip: Optional[int]) -> tuple[bool, bool]:
    """VARI (or, for 0, the tool's tip direction) -> (inside, shoulder towards +Z)."""
    v = int(vari) if math.isfinite(vari) and vari == int(vari) else -1
    if not 0 <= v <= 8:
        raise impossible(f"with VARI {vari:g} (0: the tool's cutting edge position, 1..8: the position)")
    if v == 0:
        if tip is None:
            raise unmodelled("with VARI 0 (the position from the tool's cutting edge position) needs the "
                             "active tool's tip direction in the machine model (`tip` of [[tools]])")
        v = tip
    if not 1 <= v <= 4:
        raise unmodelled(f"with the position {v} (a cutting edge along an axis names no corner): not "
                         "modelled; nctrans models positions 1..4")
    from nctrans.interp.nose import TIP_VECTORS
    tx, tz = TIP_VECTORS[v]
    return tx > 0, tz > 0


def undercut_steps(cut: Undercut, radius0: float, spl: float, inside: bool, shoulder_plus_z: bool,
                   clearance: float) -> list[Step]:
    """The moves of one undercut in (X radius, Z), from and back to the clearance point."""
    r, t, W, t2 = cut.radius, cut.depth, cut.width, cut.face_depth
    if min(r, t, W) <= EPS or cut.run_out_start < r - t2 - EPS:
        raise impossible("with an undercut whose table dimensions do not fit together")
    e = -1.0 if inside else 1.0                    # +w towards the axis outside, away from it inside
    s = -1.0 if shoulder_plus_z else 1.0           # +u away from the shoulder
    if not inside and t > radius0 + EPS:
        raise impossible(f"{t:g} deep in a radius of {radius0:g} (past the axis)")

    def at(u: float, w: float) -> tuple[float, float]:
        return (radius0 - e * w, spl + s * u)

    def arc_to(u: float, w: float, cu: float, cw_: float, here: tuple[float, float]) -> Step:
        a, b, c = at(*here), at(u, w), at(cu, cw_)
        cross = (a[1] - c[1]) * (b[0] - c[0]) - (a[0] - c[0]) * (b[1] - c[1])
        return ("arc", b, c, cross < 0)           # clockwise in the (Z, X) picture

    c = clearance
    steps: list[Step] = [("rapid", at(W + c, -c)), ("linear", at(W, 0.0)),
                         ("linear", at(cut.run_out_start, t)), ("linear", at(r - t2, t))]
    steps.append(arc_to(-t2, t - r, r - t2, t - r, (r - t2, t)))
    top = t - r                                    # where the radius meets the face (or its recess)
    if t2 > EPS:                                   # form F: the recess wall up to the face
        top = t - r - t2 / math.tan(math.radians(cut.face_angle))
        steps.append(("linear", at(0.0, top)))
    elif top > EPS:                                # the face below the surface
        steps.append(("linear", at(0.0, 0.0)))
        top = 0.0
    lift = min(top, 0.0) - c
    steps += [("linear", at(0.0, lift)), ("rapid", at(W + c, lift))]
    if abs(lift + c) > EPS:
        steps.append(("rapid", at(W + c, -c)))
    return steps


# ---------------------------------------------------------------------------------------------
# In the interpreter

def _active_tip(interp) -> Optional[int]:
    st = interp.st
    number = st.tool or st.tool_selected
    tool = interp.machine.tool(int(number)) if number else None
    return getattr(tool, "tip", None) if tool is not None else None


def _form(interp, s, allowed: str) -> str:
    from nctrans.ir import nodes as n
    e = s.params.get("form")
    if e is None:
        raise impossible(f"without FORM (one of {', '.join(allowed)})")
    v = e.value if type(e) is n.Str else interp._value(interp.ev.compile(e), f"{s.name} FORM")
    form = v.strip().upper() if isinstance(v, str) else ""
    if form not in allowed:
        raise impossible(f"with FORM {v!r} (one of {', '.join(allowed)})")
    return form


def plan(interp, cyc, s) -> list[Step]:
    """Read the call, look the undercut up and plan its moves; MillingError when it cannot run."""
    from nctrans.interp.cycles import coarse_pitch, cycle_table
    from nctrans.interp.milling_cycles import call_values
    if s.modal:
        raise unmodelled("called modally (MCALL): not modelled")
    p = call_values(interp, cyc, s)
    for k, v in p.items():
        if not math.isfinite(v):
            raise impossible(f"with {k} not a finite number")
    clearance = cycle_table().undercut.clearance
    if cyc.shape == "undercut":
        form = _form(interp, s, "EF")
        if "SPD" not in p:
            raise impossible("without the diameter SPD")
        diameter = abs(p["SPD"]) if interp.st.diameter else 2 * abs(p["SPD"])
        cut = din509(diameter, form)
    else:
        form = _form(interp, s, "ABCD")
        diameter = abs(p.get("DIATH", 0.0))
        pitch = coarse_pitch(diameter)
        if pitch is None:
            raise impossible(f"with DIATH {diameter:g}: no metric coarse thread of that diameter "
                             "([metric_coarse_pitch]) gives the pitch")
        inside, plus_z = position(p.get("VARI", 0.0), _active_tip(interp))
        if inside != (form in "CD"):
            raise impossible(f"with FORM {form} ({'an internal' if form in 'CD' else 'an external'} "
                             f"thread's undercut) at an {'inside' if inside else 'outside'} position")
        if form in "CD":
            cut, surface = din76_internal(pitch, form, diameter)
        else:
            cut, surface = din76(pitch, form), diameter / 2.0
        return undercut_steps(cut, surface, p.get("SPL", 0.0), inside, plus_z, clearance)
    inside, plus_z = position(p.get("VARI", 0.0), _active_tip(interp))
    return undercut_steps(cut, diameter / 2.0, p.get("SPL", 0.0), inside, plus_z, clearance)


def run_undercut(interp, cyc, s) -> None:
    """CYCLE94 / CYCLE96 in the interpreter: plan, then play the steps through the lathe's turning
    emitter at the feed programmed before the call."""
    try:
        steps = plan(interp, cyc, s)
    except MillingError as err:
        interp.diag(err.rule, err.severity, f"{s.name} {err.message}; the call is skipped and moves "
                    "nothing in the analysed toolpath")
        return
    _diagonal_approach(interp, s, steps)
    for step in steps:
        if step[0] == "arc":
            interp._emit_turning([("arc", step[1], step[2], step[3])])
        else:
            interp._emit_turning([(step[0], step[1], None, None)])


def _diagonal_approach(interp, s, steps: list[Step]) -> None:
    """NC418 where the cycle's first G0, straight from wherever the tool is to the clearance
    point, crosses the radius of the surface it undercuts: the tool started on the part's side of
    that surface (an internal undercut started outside the bore, an external one inside the
    diameter). How the control's cycle approaches is not documented in the seeds; the model runs
    the G0 in both axes at once (as the turning cycles' start points), so say it where that line
    would pass through the part, with where it crosses."""
    (_, (xc, zc)), (_, (surface, _z1)) = steps[0][:2], steps[1][:2]
    x0, z0 = interp.pos.get("X", 0.0), interp.pos.get("Z", 0.0)
    if (x0 - surface) * (xc - surface) >= -EPS or abs(x0 - surface) <= 1e-6:
        return                                  # the start is on the free side of the surface
    z = z0 + (zc - z0) * (x0 - surface) / (x0 - xc)
    inside = xc < surface
    interp.diag("NC418", "warning",
                f"{s.name} approaches its clearance point (radius {xc:.6g}, Z{zc:.6g}) with one G0 "
                f"in X and Z from radius {x0:.6g}, Z{z0:.6g}: that line crosses the "
                f"{'bore' if inside else 'diameter'} it undercuts (radius {surface:.6g}, diameter "
                f"{2 * surface:.6g}) at Z{z:.6g}, through the part wherever the part is there. "
                f"How the control approaches is not documented here; position the tool "
                f"{'inside the bore' if inside else 'outside the diameter'} before the call")
