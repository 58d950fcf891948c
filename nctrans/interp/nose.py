"""Tool-nose radius compensation on a lathe: G41/G42 with the tool tip direction (0-9).

A turning tool is set (touched off) at its imaginary tool tip, the corner of the square around its
nose radius, not at the nose centre: with compensation off, that point runs on the programmed path.
With G41/G42 the nose centre runs at the radius from the contour (CutterCompensator, the same
geometry as on a mill) and the control moves the imaginary tip, which lies at a fixed offset from
the centre given by the tip direction stored with the offset (Fanuc/Haas "tip", Sinumerik cutting
edge position, LinuxCNC orientation with X mirrored):

    tip 1: +X +Z   2: +X -Z   3: -X -Z   4: -X +Z   5: +Z   6: +X   7: -Z   8: -X   0, 9: centre

(the vector from the nose centre to the imaginary tip, radius times the unit components). So on a
Z-parallel or X-parallel cut the tip runs on the programmed line, and only tapers and arcs differ.
The toolpath records hold the imaginary tip, the point the offsets (and the machine) refer to.

Points that are not compensated keep the programmed position: the start of the entry move, the
end of the exit move (G40), and a move the compensator leaves uncompensated (an entry shorter than
the radius).
"""
from __future__ import annotations

from dataclasses import replace

from nctrans.interp.cutter_comp import CutterCompensator, PlannedMove, _Held

# tip direction -> (X, Z) unit components of the vector nose centre -> imaginary tip
TIP_VECTORS = {1: (1, 1), 2: (1, -1), 3: (-1, -1), 4: (-1, 1), 5: (0, 1), 6: (1, 0), 7: (0, -1),
               8: (-1, 0)}
TIP_DIRECTIONS = range(10)


def tip_offset(tip: int, radius: float) -> tuple[float, float]:
    """(dX, dZ) from the nose centre to the imaginary tip; (0, 0) for tip 0 and 9 (the centre)."""
    vx, vz = TIP_VECTORS.get(tip, (0, 0))
    return vx * radius, vz * radius


class NoseCompensator(CutterCompensator):
    """CutterCompensator in the ZX plane whose output points are the imaginary tip."""

    def __init__(self, side: str, radius: float, tip: int, plane: str = "ZX"):
        super().__init__(side, radius, plane)
        self.tip = tip
        self.dx, self.dz = tip_offset(tip, self.radius)
        self._entry_move = None             # the entry move: its start is not compensated

    def push(self, item) -> list:
        was_first = self._first
        out = super().push(item)
        if was_first and not self._first:
            held = [q for q in self._queue if isinstance(q, _Held)]
            if held:
                self._entry_move = held[-1].move
        # the item itself comes back only when it stays uncompensated (an entry shorter than the
        # radius): it moves as programmed
        return [m if m is item else self._shift(m, start=m is not self._entry_move) for m in out]

    def finish(self, item=None) -> list:
        compensated = self._cur is not None
        out = super().finish(item)
        last = out[-1] if isinstance(item, PlannedMove) and out else None
        res = []
        for m in out:
            if m is last:
                res.append(self._shift(m, start=compensated and m is not self._entry_move, end=False)
                           if isinstance(m, PlannedMove) else m)
            else:
                res.append(self._shift(m, start=m is not self._entry_move))
        self._entry_move = None
        return res

    def _shift(self, m, start: bool = True, end: bool = True):
        if not isinstance(m, PlannedMove) or (self.dx == 0 and self.dz == 0):
            return m
        return replace(m, start=self._moved(m.start) if start else dict(m.start),
                       end=self._moved(m.end) if end else dict(m.end),
                       center=None if m.center is None else self._moved(m.center))

    def _moved(self, p: dict) -> dict:
        out = dict(p)
        if "X" in out:
            out["X"] += self.dx
        if "Z" in out:
            out["Z"] += self.dz
        return out
