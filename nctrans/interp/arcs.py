"""Arc geometry: the centre of an arc programmed by centre words or by radius, checked the way
LinuxCNC's rs274ngc checks it (it is the reference for the toolpath numbers).

Everything here is in the plane's own 2-D coordinates (first, second axis of PLANE_AXES) in mm.
"""
from __future__ import annotations

import math
from typing import Optional

# LinuxCNC interp: TOLERANCE_MM/INCH for radius-format end points, and the centre-format
# radius-mismatch test: error if |r1-r2| > 100*abs_tol, or (|r1-r2| > abs_tol and relative > 0.1 %)
TOLERANCE_MM = 0.002
TOLERANCE_INCH = 0.0002 * 25.4
CENTER_TOL_MM = 2 * 0.01 * math.sqrt(2)
CENTER_TOL_INCH = 2 * 0.001 * math.sqrt(2) * 25.4
REL_TOL = 0.001


class ArcError(ValueError):
    """Geometry that no controller can run; the interpreter reports it as NC203."""


def center_from_radius(s1: float, s2: float, e1: float, e2: float, radius: float, cw: bool,
                       inch: bool = False) -> tuple[float, float]:
    """Centre of the arc from (s1,s2) to (e1,e2) with signed radius (negative: the long arc)."""
    if radius == 0:
        raise ArcError("arc radius is zero")
    d1, d2 = e1 - s1, e2 - s2
    chord = math.hypot(d1, d2)
    if chord < 1e-12:
        raise ArcError("arc by radius with start point equal to end point (full circle "
                       "cannot be programmed with a radius)")
    half = chord / 2
    r = abs(radius)
    tol = TOLERANCE_INCH if inch else TOLERANCE_MM
    if half - r > tol:
        raise ArcError(f"arc radius {r:g} too small to reach the end point "
                       f"(half chord {half:.4f})")
    h = math.sqrt(max(r * r - half * half, 0.0))
    # short cw arc: centre to the right of the chord direction; long arc or ccw flips it
    right = cw == (radius > 0)
    u1, u2 = d1 / chord, d2 / chord
    if right:
        n1, n2 = u2, -u1
    else:
        n1, n2 = -u2, u1
    m1, m2 = (s1 + e1) / 2, (s2 + e2) / 2
    return m1 + h * n1, m2 + h * n2


def check_center(s1: float, s2: float, e1: float, e2: float, c1: float, c2: float,
                 inch: bool = False) -> Optional[str]:
    """None when the end lies on the circle through the start within LinuxCNC's tolerance,
    else the error message."""
    r1 = math.hypot(s1 - c1, s2 - c2)
    r2 = math.hypot(e1 - c1, e2 - c2)
    if r1 < 1e-12:
        return "arc radius is zero (centre on the start point)"
    err = abs(r1 - r2)
    tol = CENTER_TOL_INCH if inch else CENTER_TOL_MM
    rel = err / max(r1, r2)
    if err > 100 * tol or (rel > REL_TOL and err > tol):
        return (f"radius to end of arc differs from radius to start: r1={r1:.4f} r2={r2:.4f} "
                f"(difference {err:.4f} mm)")
    return None


def sweep(s1: float, s2: float, e1: float, e2: float, c1: float, c2: float, cw: bool,
          turns: int = 0) -> float:
    """Swept angle in radians (positive), full circle when start == end, plus extra turns."""
    a0 = math.atan2(s2 - c2, s1 - c1)
    a1 = math.atan2(e2 - c2, e1 - c1)
    d = (a0 - a1) if cw else (a1 - a0)
    d %= 2 * math.pi
    if d < 1e-9:
        d = 2 * math.pi
    return d + 2 * math.pi * max(turns, 0)
