"""Polar coordinate input (the ISO mode G16, group `polar`): while it is on, the first axis word
of the selected plane is a radius and the second an angle (ISO seed L3707-3747, spec iso 4.9).

Why a module of its own: the mode rereads every dimension word of a block, so the motion, the
set-position, frame and home-return handlers all ask it first.

What the seed defines, and so what is modelled:
- The pole: with the radius under G90, the workpiece zero (L3723); with the radius under G91, the
  current position (L3724); with no radius word, the workpiece zero (the example's N20 comment: "No X
  in block, pole is at workpiece zero"), and the radius is then the current distance from it (L3730:
  sqrt(170.711^2 + 70.711^2) = 184.776).
- The radius is absolute (L3747): the distance from the pole.
- The angle follows G90/G91 (L3747). With the pole at the current point it is measured from the
  first axis (the example's N15 `G91 X100 Y0` from (70.711, 70.711) ends at (170.711, 70.711), not
  on at 45 degrees). About the zero, an angle left out (G90) or added to (G91: `G91 Y30` alone, the
  bolt circle) is the current point's angle, where that is the angle last programmed about the zero.
- Words of other axes (the plane's third axis) are Cartesian as always.
- Hole positions of canned cycles (G73..G89) where the rules option `polar_cycle_positions` is
  "polar" (iso-m, a Fanuc [GK]: its manual's bolt hole circle, `G16` then `G81 X100 Y30 Z-20 R-5`,
  `Y150`, `Y270`): the plane words of a cycle block are radius and angle as in a motion block; the
  cycle then drills at that point, its drilling-axis words (Z, R) as always.

What it does not define, and so is refused at its line (NC117, the block moves nothing):
- G91 with a radius and no angle (no angle about the new pole);
- an angle left out or added to about the zero where the current point's angle is not the one last
  programmed (after a Cartesian move, a move about another pole, or as the first polar block):
  keeping one or the other is not the seed's to say;
- a circle (G2/G3) with a polar end point (the seed gives no centre rule);
- a canned cycle position under G16 where the dialect's rules say the control alarms
  (`polar_cycle_positions` not "polar": the seed's Sinumerik ISO mode alarms 61814 unless the
  setting `_ZSFI[3]` is 1, L2427, L6385), or one repeated by K;
- G53, G28/G30, G92, G52, G68 or G51 with plane axis words under G16 (the seed names motion only).
"""
from __future__ import annotations

import math
from typing import Optional

from nctrans.interp.frames import PLANE_AXES
from nctrans.rules import option

RULE = "NC117"


def active(interp) -> bool:
    return interp.st.groups.get("polar") == "on"


def refuse(interp, what: str) -> None:
    code = interp.spelt_codes.get("polar") or "polar mode"
    interp.diag(RULE, "warning", f"{what} under polar coordinate input ({code}) is not modelled: "
                "the block moves nothing in the analysed toolpath (the seed does not define it)")


def plane_words(interp, words) -> bool:
    """Whether evaluated or compiled axis words name an axis of the active plane."""
    a1, a2, _ = PLANE_AXES[interp.st.plane]
    return any(w[0] in (a1, a2) for w in words)


def guard(interp, words, what: str) -> bool:
    """A non-motion statement with plane axis words under G16: refused (True) at its line."""
    if active(interp) and plane_words(interp, words):
        refuse(interp, what)
        return True
    return False


def cartesian(interp, vals: list, machine: bool = False) -> Optional[list]:
    """The block's evaluated words [(axis, value, mode)] with the plane's radius and angle
    replaced by absolute Cartesian end coordinates; None when the block is refused (NC117)."""
    st = interp.st
    a1, a2, _ = PLANE_AXES[st.plane]
    radius = angle = None
    inc_radius = inc_angle = st.incremental
    for axis, v, mode in vals:
        if axis == a1:
            radius = v
            inc_radius = mode == "inc" if mode else st.incremental
        elif axis == a2:
            angle = v / st.scale            # _eval_words scaled it as a length
            inc_angle = mode == "inc" if mode else st.incremental
    if radius is None and angle is None:
        return vals
    if machine:
        refuse(interp, "a move in machine coordinates")
        return None
    if st.motion not in ("rapid", "linear"):
        refuse(interp, "a circle or other non-linear motion with polar words")
        return None
    if st.cycle != "off" or interp.modal_cycle is not None:
        if interp.modal_cycle is not None or option(interp.program.dialect, "polar_cycle_positions") != "polar":
            refuse(interp, "a canned cycle position (alarm 61814 unless _ZSFI[3] = 1)")
            return None
        if int(round(interp.cycle_params.get("repeat", 1) or 1)) != 1:
            # K repeats the hole by the block's increments; whether an angle step repeats about
            # the pole is not documented in the seed or [GK]
            refuse(interp, "a repeated (K) canned cycle position")
            return None
    cur1, cur2 = interp.pos.get(a1, 0.0), interp.pos.get(a2, 0.0)
    if radius is not None and inc_radius:
        if angle is None:
            refuse(interp, "an incremental (G91) radius without an angle (the angle about the new "
                   "pole is not defined)")
            return None
        pole = (cur1, cur2)             # the pole is the current point
        # the angle from the first axis: N15 `G91 X100 Y0` goes along +X, not on at 45 degrees
    else:
        pole = (0.0, 0.0)               # G90 radius, or no radius: the workpiece zero
        if radius is None:
            radius = math.hypot(cur1, cur2)
        if angle is None or inc_angle:
            # the angle the block keeps or adds to: the current point's about the zero, or the
            # angle last programmed; the seed does not say which, so only where they agree
            here = math.degrees(math.atan2(cur2, cur1))
            last = interp.__dict__.get("polar_input_last")
            if last is None or not last[1] or abs((here - last[0] + 180.0) % 360.0 - 180.0) > 1e-6:
                refuse(interp, ("an angle left out" if angle is None else "an incremental (G91) angle")
                       + " where the current point's angle about the zero is not the angle last "
                       "programmed about it (the seed does not say which one counts)")
                return None
            angle = here if angle is None else here + angle
    interp.polar_input_last = (angle, pole == (0.0, 0.0))
    rad = math.radians(angle)
    rest = [w for w in vals if w[0] not in (a1, a2)]
    return rest + [(a1, pole[0] + radius * math.cos(rad), "abs"),
                   (a2, pole[1] + radius * math.sin(rad), "abs")]
