"""The start angle of a thread: where on the spindle's turn a thread cut begins.

A thread of several starts (a two-start thread of lead 4: two grooves 2 mm apart) is cut as
separate passes over the same path, each begun at another spindle angle. The controls program
that angle as a setting in force for every later thread until it is written again:
- Sinumerik `SF=<deg>` in (or before) a G33 block writes SD 42000 THREAD_START_ANGLE (seed L7546,
  L24380, L24690: 0..359.999 degrees);
- ISO `G33 .. F<lead> Q<angle>` (ISO-M and ISO-T), Q an integer in 0.001 degree (`Q180000` =
  180 deg), writes the same setting data (ISO seed 4.1.16, spec iso.md L3523-3550). [GK] On a
  Fanuc, G32's Q holds for its block only (0 when not written): nctrans's writers therefore write
  Q on every thread block whose angle is not 0, and Q0 after one that was, which is right both ways;
- CYCLE97 (NSP, NUMT) and CYCLE98 (NSP, NUMTH) cut each start in turn (milling_cycles.py).

The toolpath carries the angle on each thread move (`pitch` set) as `thread_start`, in degrees
0..360, and leaves the key out when it is 0, so a single-start thread reads as it always did.
`equiv` compares it (a thread cut at another phase is another thread).
"""
from __future__ import annotations

import dataclasses

from nctrans.ir import nodes as n


def compile_motion(it, s: n.Motion) -> tuple:
    """The compiled form of a Motion that writes a start angle: (angle, the motion's own compiled
    form or None when it has no words besides the angle)."""
    angle = it.ev.compile(s.thread_start)
    bare = dataclasses.replace(s, thread_start=None)
    words = bool(bare.target or bare.center or bare.radius is not None or bare.turns is not None
                 or bare.via or bare.polar or bare.aperture is not None or bare.indirect
                 or bare.machine_coords)
    return (angle, it._c_motion_full(bare) if words else None)


def run_motion(it, d: tuple) -> None:
    """Set the start angle, then run the block's motion (if it has any)."""
    angle, full = d
    v = it._value(angle, "thread start angle")
    if v is not None:
        it.thread_start = v % 360.0
    if full is not None:
        it._h_motion(full)


def stamp(it, mark: int) -> None:
    """Give the thread moves recorded since `mark` the start angle in force (none when 0)."""
    angle = getattr(it, "thread_start", 0.0)
    if angle and abs(angle - 360.0) > 1e-9:
        for rec in it.out[mark:]:
            if rec.pitch:
                rec.thread_start = angle


def start_angles(first: float, starts: int) -> list[float]:
    """The start angles of a thread of `starts` starts, the first at `first` degrees: evenly
    spread over the turn, 360 / starts apart (0..360)."""
    return [(first + 360.0 * k / starts) % 360.0 for k in range(starts)]
