"""Polar motion words (Motion.polar: angle and radius about the pole) and the pole itself
(PolarPole: Sinumerik G110/G111/G112, Fagor G30).

Why a module of its own: what a left-out word stands for is state the control keeps between
blocks, and it differs between controls; the table says which (rules option `polar_memory`):
- "programmed": the control stores the polar angle and radius last programmed, and a block that
  leaves one out (or adds to the angle, AP=IC) uses the stored value. Seed L13315-13317: a plane
  change (and GEOAX) sets the modal polar coordinates to 0; [GK] Siemens Fundamentals, polar
  coordinates: the angle stays stored until a new pole or plane, the radius must be written again
  after a new pole, AP=IC adds to the last programmed angle, RP is always an absolute value.
  Where the stored value is not known (no polar block since the start or since the last pole)
  the block is refused at its line (NC118) instead of guessed.
- "position" (the default): a left-out word is read from where the tool is, seen from the pole.

Refused at the line (NC118, the block moves nothing): RP=IC(..) (no incremental radius [GK]); a
pole given in polar words with IC(..) (the seeds give no reference); a polar word about a pole
that was refused (until a pole is set again).
"""
from __future__ import annotations

import math
from typing import Optional

from nctrans.interp.frames import PLANE_AXES
from nctrans.ir import nodes as n

RULE = "NC118"


def _rules(interp) -> tuple[str, str, str]:
    """(polar_memory, polar_incremental, pole_on_plane_change) of the program's table."""
    v = interp.__dict__.get("_polar_rules")
    if v is None:
        from nctrans.rules import option
        d = interp.program.dialect
        v = interp._polar_rules = (str(option(d, "polar_memory") or "position"),
                                   str(option(d, "polar_incremental") or "never"),
                                   str(option(d, "pole_on_plane_change") or "kept"))
    return v


MOVES_NOTHING = "the block moves nothing in the analysed toolpath"


def refuse(interp, message: str) -> None:
    interp.diag(RULE, "warning", message)


def compile_words(interp, polar: dict) -> dict:
    """Compiled polar words; `IC(..)` marks the angle (`angle_inc`) or radius (`radius_inc`)
    incremental, `AC(..)` is the plain word."""
    out = {}
    for k, v in polar.items():
        if type(v) is n.Func and v.name.upper() in ("IC", "AC") and len(v.args) == 1:
            k, v = (k + "_inc" if v.name.upper() == "IC" else k), v.args[0]
        out[k] = interp.ev.compile(v)
    return out


def plane_changed(interp) -> None:
    """Sinumerik seed L13317: a plane change sets the modal polar coordinates to 0; where the
    table says so (Fagor 8065 manual L3244-3247) the pole goes back to the work zero."""
    interp.polar_stored = (0.0, 0.0)
    if _rules(interp)[2] == "zero":
        interp.pole, interp.pole_refused = None, None


def end_point(interp, vals: list, polar: dict) -> Optional[list]:
    """The block's words [(axis, value, mode)] with the polar end point as absolute plane words;
    None when the block is refused (NC118)."""
    st = interp.st
    a1, a2, _ = PLANE_AXES[st.plane]
    if "radius_inc" in polar:
        refuse(interp, "an incremental polar radius (IC(..)) is not modelled: the polar radius is "
               f"an absolute value [GK]; {MOVES_NOTHING}")
        return None
    r = interp._value(polar["radius"], "polar radius") if "radius" in polar else None
    ang = interp._value(polar["angle"], "polar angle") if "angle" in polar else None
    inc = interp._value(polar["angle_inc"], "polar angle") if "angle_inc" in polar else None
    if r is None and ang is None and inc is None:
        return vals
    if interp.pole_refused is not None:
        refuse(interp, f"a polar end point about the pole of line {interp.pole_refused} is not "
               f"modelled (that pole was refused): {MOVES_NOTHING}")
        return None
    c1, c2 = interp.pole or (0.0, 0.0)
    if r is not None:
        r *= st.scale
    memory, incremental, _ = _rules(interp)
    if memory == "programmed":
        stored = interp.polar_stored
        if (r is None or ang is None) and stored is None:
            left = "radius" if r is None else "angle"
            refuse(interp, f"a polar block without its {left} "
                   + ("after a new pole" if interp.pole_set else "before any polar block")
                   + f" is not modelled: the control takes its stored {left}, not known here; "
                   + MOVES_NOTHING)
            return None
        if r is None:
            r = stored[1]
        if ang is None:
            ang = stored[0] + (inc or 0.0)
    else:
        p1, p2 = interp.pos.get(a1, 0.0) - c1, interp.pos.get(a2, 0.0) - c2
        here_r, here_ang = math.hypot(p1, p2), math.degrees(math.atan2(p2, p1))
        if incremental == "distance" and st.incremental:
            # increments of the current point's radius and angle (Fagor L3229-3232)
            r = here_r + (r or 0.0)
            ang = here_ang + (ang or 0.0)
        if r is None:
            r = here_r
        if ang is None:
            # the last polar angle: where the tool is, seen from the pole
            ang = here_ang + (inc or 0.0)
    interp.polar_stored = (ang, r)
    rest = [w for w in vals if w[0] not in (a1, a2)]
    return rest + [(a1, c1 + r * math.cos(math.radians(ang)), "abs"),
                   (a2, c2 + r * math.sin(math.radians(ang)), "abs")]


def set_pole(interp, s: n.PolarPole) -> None:
    """G110/G111/G112: the pole relative to the last programmed point, the workpiece zero or
    the last pole, whatever G90/G91 (spec 9.2); given by plane axis words or by polar words
    about that point. Nothing moves. The stored polar angle and radius are no longer known."""
    a1, a2, _ = PLANE_AXES[interp.st.plane]
    line = interp.span.line if interp.span else 0
    if s.relative_to == "last_point":
        ref = (interp.pos.get(a1, 0.0), interp.pos.get(a2, 0.0))
    elif s.relative_to == "pole":
        if interp.pole_refused is not None:
            refuse(interp, f"a pole relative to the pole of line {interp.pole_refused} is not modelled "
                   "(that pole was refused): polar end points about it are refused too")
            interp.pole_refused = line
            return
        ref = interp.pole or (0.0, 0.0)
    else:
        ref = (0.0, 0.0)
    interp.pole_set = True
    interp.polar_stored = None
    if s.polar:
        polar = compile_words(interp, s.polar)
        if "angle_inc" in polar or "radius_inc" in polar:
            refuse(interp, "a pole given with an incremental polar word (IC(..)) is not modelled: "
                   "the seeds give it no reference; polar end points about it are refused until "
                   "a pole is set again")
            interp.pole_refused = line
            return
        r = interp._value(polar["radius"], "pole radius") if "radius" in polar else None
        ang = interp._value(polar["angle"], "pole angle") if "angle" in polar else None
        r = (r or 0.0) * interp.st.scale
        ang = math.radians(ang or 0.0)
        interp.pole = (ref[0] + r * math.cos(ang), ref[1] + r * math.sin(ang))
        interp.pole_refused = None
        return
    d = {a1: 0.0, a2: 0.0}
    for axis, v, _ in interp._eval_words(interp._words(s.target)):
        if axis in d:
            d[axis] = v
    interp.pole = (ref[0] + d[a1], ref[1] + d[a2])
    interp.pole_refused = None
