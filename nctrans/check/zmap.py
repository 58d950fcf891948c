"""The stock as a Z-map: the height of material over a grid of cells (numpy), lowered by every move
the cutter makes, so the check knows what is already cut.

A rapid whose cutter passes below the material left in a cell is a rapid into uncut stock; the
holder below the material in a cell within its radius is the holder against the stock. A cell is
under the tool when its centre is within the tool's radius of the tool-tip path; cutting and
checking use the same test, so a rapid out of a slot the tool has just cut (the same cells, at
the same depth) finds nothing. The cutter is flat-bottomed (the height it leaves in a cell is the
lowest tip height while the cell is under it), 3-axis (tool along Z). The grid is fixed by the
stock's size, so memory does not grow with the program.
"""
from __future__ import annotations

import math
from typing import Optional

import numpy as np

from nctrans.check.findings import Finding, fmt_point
from nctrans.check.geometry import arc_chords
from nctrans.check.scene import Solid, ToolCache, ToolSolid
from nctrans.machine import Machine
from nctrans.toolpath import ToolpathRecord

NONE = -1e30            # height of a cell with no material
TOL = 0.01              # mm of material a move may graze before it is reported
MAX_CELLS = 1_000_000   # 16 MB of heights and bottoms
ARC_TOL = 0.005


def default_cell(lo: np.ndarray, hi: np.ndarray, smallest_radius: Optional[float]) -> float:
    """A sixteenth of the smallest cutter radius (0.25 mm without one), not below 0.05 mm, and
    coarser for a large stock so the grid stays within MAX_CELLS. What a move cuts or meets is
    judged at cell centres, so the cell sets how finely edges are placed, not depths."""
    area = float((hi[0] - lo[0]) * (hi[1] - lo[1]))
    fine = smallest_radius / 16 if smallest_radius else 0.25
    return max(0.05, fine, math.sqrt(area / MAX_CELLS))


class ZMap:
    def __init__(self, lo: np.ndarray, hi: np.ndarray, cell: float):
        self.cell = cell
        self.x0, self.y0 = float(lo[0]), float(lo[1])
        self.nx = max(1, math.ceil((hi[0] - lo[0]) / cell))
        self.ny = max(1, math.ceil((hi[1] - lo[1]) / cell))
        self.cx = self.x0 + (np.arange(self.nx) + 0.5) * cell
        self.cy = self.y0 + (np.arange(self.ny) + 0.5) * cell
        self.h = np.full((self.ny, self.nx), NONE)       # top of the material in each cell
        self.b = np.full((self.ny, self.nx), -NONE)      # its bottom (material only where h > b)
        self.top = NONE

    @classmethod
    def from_solid(cls, solid: Solid, cell: Optional[float], smallest_radius: Optional[float] = None) -> "ZMap":
        lo, hi = solid.bounds
        z = cls(lo, hi, cell or default_cell(lo, hi, smallest_radius))
        if solid.is_box:
            inside = ((z.cx[None, :] <= hi[0]) & (z.cy[:, None] <= hi[1]))
            z.h[inside] = hi[2]
            z.b[inside] = lo[2]
        else:
            z._raster(np.asarray(solid.mesh.triangles, float))
        z.top = float(z.h.max())
        return z

    def _raster(self, tris: np.ndarray) -> None:
        """Highest and lowest surface over each cell centre, triangle by triangle (vertical faces add
        nothing): the material of a cell is taken as one column between them."""
        for t in tris:
            (x1, y1, z1), (x2, y2, z2), (x3, y3, z3) = t
            det = (y2 - y3) * (x1 - x3) + (x3 - x2) * (y1 - y3)
            if abs(det) < 1e-12:
                continue
            win = self._window(min(x1, x2, x3), max(x1, x2, x3), min(y1, y2, y3), max(y1, y2, y3))
            if win is None:
                continue
            X, Y, sl = win
            l1 = ((y2 - y3) * (X - x3) + (x3 - x2) * (Y - y3)) / det
            l2 = ((y3 - y1) * (X - x3) + (x1 - x3) * (Y - y3)) / det
            l3 = 1.0 - l1 - l2
            inside = (l1 >= -1e-9) & (l2 >= -1e-9) & (l3 >= -1e-9)
            z = l1 * z1 + l2 * z2 + l3 * z3
            sub = self.h[sl]
            self.h[sl] = np.where(inside, np.maximum(sub, z), sub)
            sub = self.b[sl]
            self.b[sl] = np.where(inside, np.minimum(sub, z), sub)

    def _window(self, xlo, xhi, ylo, yhi):
        """Cell-centre coordinates (X row, Y column) and the slice of cells whose centres may lie in
        the box; None outside the grid."""
        c = self.cell
        i0 = max(0, math.floor((xlo - self.x0) / c - 0.5))
        i1 = min(self.nx, math.ceil((xhi - self.x0) / c - 0.5) + 1)
        j0 = max(0, math.floor((ylo - self.y0) / c - 0.5))
        j1 = min(self.ny, math.ceil((yhi - self.y0) / c - 0.5) + 1)
        if i0 >= i1 or j0 >= j1:
            return None
        return self.cx[None, i0:i1], self.cy[j0:j1, None], (slice(j0, j1), slice(i0, i1))

    def _under(self, a: np.ndarray, b: np.ndarray, r: float):
        """Cells whose centres come within r of the segment a-b (XY), with the lowest height of the
        segment while they do: (slice, mask, lowest z, parameter where the disk first covers the
        cell), or None."""
        win = self._window(min(a[0], b[0]) - r, max(a[0], b[0]) + r, min(a[1], b[1]) - r, max(a[1], b[1]) + r)
        if win is None:
            return None
        X, Y, sl = win
        dx, dy, dz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        ux, uy = X - a[0], Y - a[1]
        l2 = dx * dx + dy * dy
        r2 = r * r
        if l2 < 1e-18:
            mask = ux * ux + uy * uy <= r2
            enter = np.zeros_like(ux * uy)
            t = enter if dz >= 0 else np.ones_like(enter)
        else:
            tc = (ux * dx + uy * dy) / l2
            perp2 = (ux * dy - uy * dx) ** 2 / l2
            half = np.sqrt(np.maximum(r2 - perp2, 0.0) / l2)
            mask = (perp2 <= r2) & (tc + half >= 0.0) & (tc - half <= 1.0)
            enter = np.clip(tc - half, 0.0, 1.0)
            t = enter if dz >= 0 else np.clip(tc + half, 0.0, 1.0)
        return sl, mask, a[2] + t * dz, enter

    def cut(self, a: np.ndarray, b: np.ndarray, r: float) -> None:
        if min(a[2], b[2]) >= self.top:
            return
        if a[2] == b[2]:
            # level move (most of a CAM program): one height, cells within r of the segment
            win = self._window(min(a[0], b[0]) - r, max(a[0], b[0]) + r,
                               min(a[1], b[1]) - r, max(a[1], b[1]) + r)
            if win is None:
                return
            X, Y, sl = win
            dx, dy = b[0] - a[0], b[1] - a[1]
            ux, uy = X - a[0], Y - a[1]
            l2 = dx * dx + dy * dy
            t = np.clip((ux * dx + uy * dy) / l2, 0.0, 1.0) if l2 > 1e-18 else 0.0
            ex, ey = ux - t * dx, uy - t * dy
            np.minimum(self.h[sl], a[2], out=self.h[sl], where=ex * ex + ey * ey <= r * r)
            return
        u = self._under(a, b, r)
        if u is None:
            return
        sl, mask, z, _enter = u
        np.minimum(self.h[sl], z, out=self.h[sl], where=mask)

    def intrusion(self, a: np.ndarray, b: np.ndarray, r: float) -> tuple[float, float]:
        """(deepest material above the swept bottom of a flat disk of radius r moved a-b, the
        parameter along a-b where the disk first meets material deeper than TOL); depth <= 0 when
        clear."""
        if min(a[2], b[2]) >= self.top:
            return 0.0, 0.0
        u = self._under(a, b, r)
        if u is None:
            return 0.0, 0.0
        sl, mask, z, enter = u
        h, bottom = self.h[sl], self.b[sl]
        depth = np.where(mask & (h > bottom), h - np.maximum(z, bottom), -np.inf)
        deepest = float(depth.max())
        if deepest <= TOL:
            return deepest, 0.0
        # where the disk first goes TOL deep into each cell: on entering the cell, or on a way
        # down, where its height passes the material's top
        dz = b[2] - a[2]
        first = enter if dz >= 0 else np.maximum(enter, (a[2] - h + TOL) / -dz)
        deep = depth > TOL
        return deepest, float(min(np.broadcast_to(first, depth.shape)[deep].min(), 1.0))


class StockCheck:
    """Feed records in order (`add`); findings are appended to `out`."""

    def __init__(self, machine: Machine, stock: Solid, cell: Optional[float], tools: ToolCache,
                 out: list[Finding]):
        self.machine = machine
        self.tools = tools
        radii = [t.radius for t in machine.tools if t.radius > 0]
        self.zmap = ZMap.from_solid(stock, cell, min(radii) if radii else None)
        self.name = stock.name
        self.out = out
        self._reported: set[tuple] = set()

    def add(self, r: ToolpathRecord) -> None:
        tool = self.tools.get(r.tool)
        if r.kind == "arc" and r.center is not None:
            pts, sag = arc_chords(r, ARC_TOL)
        else:
            pts, sag = [r.start, r.end], 0.0
        tip = [np.array([p.get("X", 0.0), p.get("Y", 0.0), p.get("Z", 0.0) - tool.length]) for p in pts]
        zm = self.zmap
        radius = max(tool.radius, 1e-3)
        for a, b in zip(tip, tip[1:]):
            if r.kind == "rapid":
                # a hair narrower than the cut: a cell on the edge of what was cut stays cut
                depth, t = zm.intrusion(a, b, radius * (1 - 1e-9) - 1e-6)
                if depth > TOL:
                    self._report(r, "NC313", tool, a + t * (b - a), depth,
                                 f"rapid moves {self._who(tool)} {depth:.3f} mm into uncut stock")
            zm.cut(a, b, radius + sag)
            for part in tool.parts:
                if part.role != "holder":
                    continue
                off = np.array([0.0, 0.0, part.bottom])
                depth, t = zm.intrusion(a + off, b + off, part.radius + sag)
                if depth > TOL:
                    self._report(r, "NC312", tool, a + t * (b - a), depth,
                                 f"holder of {self._who(tool)} runs {depth:.3f} mm into the stock")

    @staticmethod
    def _who(tool: ToolSolid) -> str:
        return f"T{tool.number}" if tool.number is not None else "the tool"

    def _report(self, r: ToolpathRecord, rule: str, tool: ToolSolid, tip: np.ndarray, depth: float,
                what: str) -> None:
        key = (r.file, r.line, rule)
        if key in self._reported:
            return
        self._reported.add(key)
        pos = {"X": float(tip[0]), "Y": float(tip[1]), "Z": float(tip[2] + tool.length)}
        self.out.append(Finding(rule, r.file, r.line, self.name,
                                f"{what} ({self.name!r}) at {fmt_point(pos)} (machine coordinates)",
                                pos, depth))
