"""Tool and holder against the fixtures, continuously along every move.

A convex part (a cylinder of the cutter or the holder) moved along a straight segment sweeps
exactly the convex hull of its two end positions, so each move is tested as that hull (an fcl
Convex) against each fixture (an fcl BVH of its mesh): nothing between the end points is
skipped, and a fixture wholly inside the swept hull still counts. Arcs are cut into chords that
stay within ARC_TOL of the arc, the part's cross-section grown by the chord's sagitta.

Broad phase: moves are taken in chunks; numpy compares each move's swept box (path box grown by
its tool's box) with every fixture's box at once, and only overlapping pairs reach fcl. Where a
hull touches a fixture, bisection along the move finds where contact begins, which is the
position reported. (trimesh's CollisionManager would turn each swept hull into a BVH of its
triangles; two triangle soups miss a fixture wholly inside the hull, so fcl is called directly.)
"""
from __future__ import annotations

import numpy as np

from nctrans.check.findings import Finding, fmt_point
from nctrans.check.geometry import arc_chords, arc_extremes
from nctrans.check.scene import Solid, ToolCache, ToolSolid
from nctrans.machine import Machine
from nctrans.toolpath import ToolpathRecord

CHUNK = 2048
ARC_TOL = 0.01          # mm
BISECT_STEPS = 12       # first contact found to 1/4096 of the move


def _bvh(mesh):
    import fcl
    m = fcl.BVHModel()
    m.beginModel(len(mesh.vertices), len(mesh.faces))
    m.addSubModel(np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int32))
    m.endModel()
    return fcl.CollisionObject(m, fcl.Transform())


def _hull_object(points: np.ndarray):
    """fcl object for the convex hull of `points`, or None when they span no volume."""
    import fcl
    from scipy.spatial import ConvexHull, QhullError
    try:
        hull = ConvexHull(points)
    except (QhullError, ValueError):
        return None
    faces = np.c_[np.full(len(hull.simplices), 3), hull.simplices].ravel().astype(np.int32)
    return fcl.CollisionObject(fcl.Convex(points, len(hull.simplices), faces), fcl.Transform())


def _point(r: ToolpathRecord, p: dict) -> np.ndarray:
    return np.array([p.get("X", 0.0), p.get("Y", 0.0), p.get("Z", 0.0)])


class CollisionCheck:
    """Feed records in order (`add`), then `finish()`; findings are appended to `out`."""

    def __init__(self, machine: Machine, fixtures: list[Solid], tools: ToolCache, out: list[Finding]):
        import fcl
        self._fcl = fcl
        self.machine = machine
        self.tools = tools
        self.fixtures = fixtures
        self.out = out
        self._objects = [_bvh(f.mesh) for f in fixtures]
        b = np.array([f.bounds for f in fixtures]).reshape(-1, 2, 3)
        self._flo, self._fhi = b[:, 0, :], b[:, 1, :]
        self._chunk: list[ToolpathRecord] = []
        self._request = fcl.CollisionRequest()
        self._reported: set[tuple] = set()
        self.moves = 0
        self.narrow = 0

    def add(self, r: ToolpathRecord) -> None:
        self._chunk.append(r)
        if len(self._chunk) >= CHUNK:
            self._run_chunk()

    def finish(self) -> None:
        if self._chunk:
            self._run_chunk()

    # ------------------------------------------------------------------ broad phase
    def _run_chunk(self) -> None:
        recs, self._chunk = self._chunk, []
        n = len(recs)
        self.moves += n
        ends = np.array([(r.start.get("X", 0.0), r.start.get("Y", 0.0), r.start.get("Z", 0.0),
                          r.end.get("X", 0.0), r.end.get("Y", 0.0), r.end.get("Z", 0.0)) for r in recs])
        lo = np.minimum(ends[:, :3], ends[:, 3:])
        hi = np.maximum(ends[:, :3], ends[:, 3:])
        tools = [self.tools.get(r.tool) for r in recs]
        lo += np.array([t.lo for t in tools]) - ARC_TOL
        hi += np.array([t.hi for t in tools]) + ARC_TOL
        for i, r in enumerate(recs):
            if r.kind == "arc" and r.center is not None:
                for p, _ in arc_extremes(r):
                    q = _point(r, p)
                    lo[i] = np.minimum(lo[i], q + tools[i].lo - ARC_TOL)
                    hi[i] = np.maximum(hi[i], q + tools[i].hi + ARC_TOL)
        hit = ((lo[:, None, :] <= self._fhi[None]) & (hi[:, None, :] >= self._flo[None])).all(axis=2)
        for i, j in zip(*np.nonzero(hit)):
            self._narrow(recs[i], int(j))

    # ------------------------------------------------------------------ narrow phase
    def _segments(self, r: ToolpathRecord) -> tuple[list[np.ndarray], float]:
        if r.kind == "arc" and r.center is not None:
            pts, sag = arc_chords(r, ARC_TOL)
            return [_point(r, p) for p in pts], sag
        return [_point(r, r.start), _point(r, r.end)], 0.0

    def _hits(self, part_pts: np.ndarray, a: np.ndarray, b: np.ndarray, obj) -> bool:
        hull = _hull_object(np.vstack([part_pts + a, part_pts + b]))
        if hull is None:
            return False
        self.narrow += 1
        return self._fcl.collide(hull, obj, self._request, self._fcl.CollisionResult()) > 0

    def _narrow(self, r: ToolpathRecord, j: int) -> None:
        tool = self.tools.get(r.tool)
        fixture, obj = self.fixtures[j], self._objects[j]
        pts, grow = self._segments(r)
        flo, fhi = self._flo[j], self._fhi[j]
        for part in tool.parts:
            key = (r.file, r.line, part.role, j)
            if key in self._reported:
                continue
            ppts = part.points
            if grow > 0:
                d = np.hypot(ppts[:, 0], ppts[:, 1])[:, None]
                scale = np.where(d > 0, (d + grow) / np.maximum(d, 1e-12), 1.0)
                ppts = np.c_[ppts[:, :2] * scale, ppts[:, 2]]
            plo, phi = ppts.min(axis=0), ppts.max(axis=0)
            for k in range(len(pts) - 1):
                a, b = pts[k], pts[k + 1]
                if ((np.minimum(a, b) + plo > fhi + ARC_TOL).any()
                        or (np.maximum(a, b) + phi < flo - ARC_TOL).any()):
                    continue
                if self._hits(ppts, a, b, obj):
                    rest = sum(float(np.linalg.norm(pts[m + 1] - pts[m])) for m in range(k + 1, len(pts) - 1))
                    self._report(r, tool, part.role, fixture, ppts, a, b, obj, key, rest)
                    break

    def _report(self, r, tool: ToolSolid, role: str, fixture: Solid, ppts, a, b, obj, key,
                rest: float) -> None:
        lo_t, hi_t = 0.0, 1.0          # contact begins in (lo_t, hi_t]
        if self._hits(ppts, a, a + 1e-9 * (b - a), obj):
            hi_t = 0.0
        else:
            for _ in range(BISECT_STEPS):
                mid = (lo_t + hi_t) / 2
                if self._hits(ppts, a, a + mid * (b - a), obj):
                    hi_t = mid
                else:
                    lo_t = mid
        p = a + hi_t * (b - a)
        pos = {"X": float(p[0]), "Y": float(p[1]), "Z": float(p[2])}
        beyond = float(np.linalg.norm(b - p)) + rest
        name = f"T{tool.number}" if tool.number is not None else "the tool"
        what = f"holder of {name}" if role == "holder" else (
            name if tool.known else f"{name} (not in the machine's tool table: its tip only)")
        verb = "starts inside" if hi_t == 0.0 else "hits"
        self._reported.add(key)
        self.out.append(Finding(
            "NC311" if role == "holder" else "NC310", r.file, r.line, fixture.name,
            f"{what} {verb} fixture {fixture.name!r} in this {r.kind} move at {fmt_point(pos)}"
            f" (machine coordinates), {beyond:.3f} mm before the move's end",
            pos, beyond))
