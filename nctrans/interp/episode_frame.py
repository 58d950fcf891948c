"""The programmable frame of a cutter radius compensation episode.

Why: the compensator works in the program coordinates of its episode (records.py `_comp_move`):
the move held before a change waits for the next move's corner, so it must keep the frame it was
programmed in, and the next move, programmed in the new frame, is brought back into the
episode's coordinates so that the corner between them is computed on the path the machine runs.
An offset change (tool length, work offset, G92) was done that way (issue 9); a frame change
(Sinumerik TRANS/ATRANS/ROT/AROT, ISO G52/G68, a settable frame's rotation) is the same where the
change is rigid (a shift and a turn): offsets at right angles to the path stay at right angles and
keep their length, so compensating in the episode's coordinates is compensating on the machine's
path. A change that scales or mirrors (SCALE, MIRROR, G51, G51.1 ...) is not: the seeds say only
that a mirror that is in force swaps G41 and G42 (ISO seed L1712), not what a change in the middle of
a compensated contour does. It is NC119 at its line (warning): the analysed compensated path after
it is not the machine's, and conversions refuse it.
"""
from __future__ import annotations

from nctrans.interp.frames import mat_mul

RULE = "NC119"


def snapshot(interp) -> None:
    """At the first move of an episode: its frame."""
    from nctrans.interp.offsets import copy_frame
    interp.comp_frame = copy_frame(interp.frame)


def frame(interp):
    """The frame the episode's program coordinates are in (the current one outside an episode)."""
    fr = interp.__dict__.get("comp_frame")
    return interp.frame if fr is None else fr


def changed(interp) -> bool:
    ep = interp.__dict__.get("comp_frame")
    now = interp.frame
    return ep is not None and (ep.affine != now.affine or ep.local != now.local
                               or ep.extra_trans != now.extra_trans)


def to_episode(interp, p: dict[str, float], episode_total: dict[str, float],
               total: dict[str, float]) -> dict[str, float]:
    """Program point `p` of the current frame and offsets in the episode's program coordinates:
    the same machine point."""
    work = interp.frame.to_work(p)
    machine = {a: v + total.get(a, 0.0) for a, v in work.items()}
    return frame(interp).to_program({a: v - episode_total.get(a, 0.0) for a, v in machine.items()})


def rigid(interp) -> bool:
    """Whether the change from the episode's frame to the current one is a shift and a turn."""
    ep = frame(interp)
    if ep.inverse is None:
        return False
    m = mat_mul(ep.inverse, interp.frame.affine[0])
    mtm = mat_mul(tuple(zip(*m)), m)        # type: ignore[arg-type]
    det = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
           - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
           + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
    return det > 0 and all(abs(mtm[i][j] - (1.0 if i == j else 0.0)) < 1e-9
                           for i in range(3) for j in range(3))


def frame_changed_under_comp(interp) -> None:
    """After a frame instruction: under an active compensation episode, a change that is not a
    shift and a turn is NC119 at its line."""
    if interp.comp is None or not changed(interp) or rigid(interp):
        return
    interp.diag(RULE, "warning", "a frame change that scales or mirrors under cutter radius "
                "compensation is not modelled: the analysed compensated path after it is not the "
                "machine's (end the compensation with G40 before it)")
