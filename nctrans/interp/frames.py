"""Coordinate systems: programmable frame (local shift, mirror, scale, rotation) and the offsets
(G92 shift, work offset, tool length) that take a program point to machine coordinates.

    program point --programmable frame--> work point --+G92 +work offset +tool length--> machine

The programmable frame is kept as ISO-style components (each replaced on its own, so G52 does
not cancel G68) plus an `extra` affine for additive operations (Sinumerik ATRANS/AROT ...), which
act first on the program point. The components compose into one affine map over X/Y/Z; the
other axes (A B C U V W) only translate. `identity` lets the hot path skip the matrix.
All values are mm (the interpreter converts units before they get here).
"""
from __future__ import annotations

import math
from typing import Optional

Matrix = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]
IDENT: Matrix = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
XYZ = ("X", "Y", "Z")
_IDX = {"X": 0, "Y": 1, "Z": 2}
# axes of each plane (first, second, normal), in right-handed order
PLANE_AXES = {"XY": ("X", "Y", "Z"), "ZX": ("Z", "X", "Y"), "YZ": ("Y", "Z", "X")}


def mat_mul(a: Matrix, b: Matrix) -> Matrix:
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3))  # type: ignore
                 for i in range(3))


def mat_vec(m: Matrix, v) -> tuple[float, float, float]:
    return (m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
            m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
            m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2])


def mat_inv(m: Matrix) -> Optional[Matrix]:
    a, b, c = m
    det = (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
           + a[2] * (b[0] * c[1] - b[1] * c[0]))
    if abs(det) < 1e-15:
        return None
    inv = [[0.0] * 3 for _ in range(3)]
    for i in range(3):
        for j in range(3):
            rows = [r for r in range(3) if r != j]
            cols = [q for q in range(3) if q != i]
            minor = (m[rows[0]][cols[0]] * m[rows[1]][cols[1]]
                     - m[rows[0]][cols[1]] * m[rows[1]][cols[0]])
            inv[i][j] = ((-1) ** (i + j)) * minor / det
    return tuple(tuple(r) for r in inv)  # type: ignore


# A rotation about several axes in one instruction (ROT X.. Y.. Z.., CROT(..), a frame's RT
# components) is roll-pitch-yaw: R = Rz(c)·Ry(b)·Rx(a) whatever order the axes are written in,
# i.e. the chain Z, then Y about the new Y, then X about the new X.
RPY_ORDER = ("Z", "Y", "X")


def rpy_ordered(pairs):
    """(axis, angle) pairs in the order the RPY chain applies them; other axes keep their place
    after the geometry axes."""
    rank = {a: i for i, a in enumerate(RPY_ORDER)}
    return sorted(pairs, key=lambda kv: rank.get(str(kv[0]).upper(), len(RPY_ORDER)))


def rotation(axis: str, deg: float) -> Matrix:
    """Rotation by `deg` about `axis` (counter-clockwise looking down the axis)."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    if abs(c) < 1e-16:
        c = 0.0
    if abs(s) < 1e-16:
        s = 0.0
    if axis == "Z":
        return ((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0))
    if axis == "X":
        return ((1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c))
    return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))     # about Y


def _about(m: Matrix, pivot: dict[str, float]) -> tuple[Matrix, tuple[float, float, float]]:
    """Affine x -> m (x - p) + p."""
    p = (pivot.get("X", 0.0), pivot.get("Y", 0.0), pivot.get("Z", 0.0))
    mp = mat_vec(m, p)
    return m, (p[0] - mp[0], p[1] - mp[1], p[2] - mp[2])


Affine = tuple[Matrix, tuple[float, float, float]]
ID_AFFINE: Affine = (IDENT, (0.0, 0.0, 0.0))


def compose(outer: Affine, inner: Affine) -> Affine:
    """outer ∘ inner (inner applied first)."""
    mo, to = outer
    mi, ti = inner
    m = mat_mul(mo, mi)
    t = mat_vec(mo, ti)
    return m, (t[0] + to[0], t[1] + to[1], t[2] + to[2])


class ProgrammableFrame:
    """The frame between program and work coordinates."""

    __slots__ = ("local", "mirror", "mirror_axes", "scale", "rot", "extra", "extra_trans",
                 "affine", "inverse", "identity", "mirror_swap", "settable", "mirror_first")

    def __init__(self, mirror_first: bool = False) -> None:
        # the control's order of mirror and rotation (rules options.frame_order): False = the point
        # is rotated, then scaled and mirrored (ISO, Sinumerik); True = scaled, mirrored, then
        # rotated about a centre the mirror in force mirrored too (Fagor manual L10157-10160)
        self.mirror_first = mirror_first
        self.local: dict[str, float] = {}                   # G52 / TRANS, every axis
        self.mirror: Optional[Affine] = None
        self.mirror_axes: dict[str, float] = {}           # mirrored axis -> pivot
        self.scale: Optional[Affine] = None
        self.rot: Optional[Affine] = None
        self.extra: Affine = ID_AFFINE                      # additive ops, applied first
        self.extra_trans: dict[str, float] = {}            # additive shifts of non-XYZ axes
        self.mirror_swap = False
        # rotation, scale and mirror of the active settable frame (Sinumerik G54 with RT/SC/MI):
        # applied after the programmable frame, about the work origin; its translation is the
        # work offset (nctrans.interp.settable_frames). Kept when the programmable frame clears.
        self.settable: Optional[Matrix] = None
        self._rebuild()

    # ---------------------------------------------------------------- edits
    def set_local(self, shift: dict[str, float], additive: bool = False) -> None:
        if additive:
            # an additive shift is expressed in the current (rotated, scaled) program system
            self.extra = compose(self.extra, (IDENT, tuple(shift.get(a, 0.0) for a in XYZ)))
            for a, v in shift.items():
                if a not in _IDX:
                    self.extra_trans[a] = self.extra_trans.get(a, 0.0) + v
        else:
            self.local = {a: v for a, v in shift.items() if v != 0.0}
        self._rebuild()

    def set_mirror(self, axes: dict[str, float]) -> None:
        """Mirror about the given positions (axis -> pivot) on each axis named; {} cancels."""
        self.mirror_axes = dict(axes)
        if not axes:
            self.mirror = None
        else:
            m = [list(r) for r in IDENT]
            for a in axes:
                if a in _IDX:
                    m[_IDX[a]][_IDX[a]] = -1.0
            self.mirror = _about(tuple(tuple(r) for r in m), axes)  # type: ignore
        self._rebuild()

    def add_in_current_system(self, kind: str, values: dict[str, float]) -> None:
        """Sinumerik AMIRROR / ASCALE (spec 7.3: P := P . Mi, P := P . S): the mirror or scale acts
        in the system the frame so far produced (after a rotation, about the rotated axes), so it
        is composed after the additive ops; a mirror twice on one axis is none."""
        m = [list(r) for r in IDENT]
        for a, v in values.items():
            if a in _IDX:
                m[_IDX[a]][_IDX[a]] = -1.0 if kind == "mirror" else v
        self.extra = compose(self.extra, (tuple(tuple(r) for r in m), (0.0, 0.0, 0.0)))  # type: ignore
        self._rebuild()

    def set_scale(self, factors: dict[str, float], pivot: dict[str, float]) -> None:
        if not factors:
            self.scale = None
        else:
            m = ((factors.get("X", 1.0), 0.0, 0.0), (0.0, factors.get("Y", 1.0), 0.0),
                 (0.0, 0.0, factors.get("Z", 1.0)))
            self.scale = _about(m, pivot)
        self._rebuild()

    def set_rotation(self, axis: Optional[str], deg: float, pivot: dict[str, float],
                     additive: bool = False, cancel_added: bool = False) -> None:
        """Rotation about `axis` (the normal of the active plane); axis None cancels, and with
        `cancel_added` the rotations added so far go too."""
        if axis is None:
            self.rot = None
            if cancel_added and self.extra[0] != IDENT:
                # (Fagor `G73` alone cancels the G73 Q it accumulated, spec 10.5; ISO G69 keeps
                # a Sinumerik AROT); only rotations put a matrix into the additive part
                self.extra = ID_AFFINE
        elif additive:
            if self.mirror_first and self.mirror is not None and pivot:
                # "I and J are affected by the active mirror images" (Fagor, at the G73)
                m, t = self.mirror
                c = mat_vec(m, tuple(pivot.get(a, 0.0) for a in XYZ))
                pivot = {a: c[i] + t[i] for i, a in enumerate(XYZ)}
            self.extra = compose(self.extra, _about(rotation(axis, deg), pivot))
        elif self.rot is not None and pivot.get("_chain"):
            self.rot = compose(self.rot, _about(rotation(axis, deg), pivot))
        else:
            self.rot = _about(rotation(axis, deg), pivot)
        self._rebuild()

    def clear(self) -> None:
        """The neutral programmable frame; the settable frame's part stays."""
        keep = self.settable
        self.__init__(self.mirror_first)
        if keep is not None:
            self.set_settable(keep)

    def set_settable(self, m: Optional[Matrix]) -> None:
        self.settable = None if m is None or m == IDENT else m
        self._rebuild()

    # ---------------------------------------------------------------- use
    def _rebuild(self) -> None:
        aff = (IDENT, tuple(self.local.get(a, 0.0) for a in XYZ))
        order = ((self.rot, self.extra, self.mirror, self.scale) if self.mirror_first
                 else (self.mirror, self.scale, self.rot, self.extra))
        for part in order:
            if part is not None:
                aff = compose(aff, part)
        if self.settable is not None:
            aff = compose((self.settable, (0.0, 0.0, 0.0)), aff)
        self.affine = aff
        self.identity = aff == ID_AFFINE and not any(
            v for a, v in self.local.items() if a not in _IDX) and not self.extra_trans
        inv = mat_inv(aff[0])
        self.inverse = inv
        m = aff[0]
        det = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
               - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
               + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))
        self.mirror_swap = det < 0

    def to_work(self, p: dict[str, float]) -> dict[str, float]:
        """Program point (all axes) -> work point."""
        if self.identity:
            return dict(p)
        m, t = self.affine
        out = dict(p)
        v = (p.get("X", 0.0), p.get("Y", 0.0), p.get("Z", 0.0))
        w = mat_vec(m, v)
        for i, a in enumerate(XYZ):
            if a in p:
                out[a] = w[i] + t[i]
        for a in out:
            if a not in _IDX:
                out[a] = out[a] + self.local.get(a, 0.0) + self.extra_trans.get(a, 0.0)
        return out

    def to_program(self, w: dict[str, float]) -> dict[str, float]:
        """Work point -> program point (inverse of to_work; singular frames leave XYZ as is)."""
        if self.identity:
            return dict(w)
        out = dict(w)
        m, t = self.affine
        if self.inverse is not None:
            v = (w.get("X", 0.0) - t[0], w.get("Y", 0.0) - t[1], w.get("Z", 0.0) - t[2])
            p = mat_vec(self.inverse, v)
            for i, a in enumerate(XYZ):
                if a in w:
                    out[a] = p[i]
        for a in out:
            if a not in _IDX:
                out[a] = out[a] - self.local.get(a, 0.0) - self.extra_trans.get(a, 0.0)
        return out


class Offsets:
    """Additive shifts between work and machine coordinates: G92, work offset, tool length."""

    __slots__ = ("work", "g92", "tool_z", "total")

    def __init__(self) -> None:
        self.work: dict[str, float] = {}
        self.g92: dict[str, float] = {}
        self.tool_z = 0.0
        self.total: dict[str, float] = {}
        self._rebuild()

    def _rebuild(self) -> None:
        tot = dict(self.work)
        for a, v in self.g92.items():
            tot[a] = tot.get(a, 0.0) + v
        if self.tool_z:
            tot["Z"] = tot.get("Z", 0.0) + self.tool_z
        self.total = tot

    def set_work(self, off: dict[str, float]) -> None:
        self.work = {a.upper(): float(v) for a, v in off.items()}
        self._rebuild()

    def set_g92(self, off: dict[str, float]) -> None:
        self.g92 = off
        self._rebuild()

    def set_tool(self, z: float) -> None:
        self.tool_z = z
        self._rebuild()
