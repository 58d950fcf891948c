"""The solids of a check: fixtures and stock from the machine model (mesh files through trimesh,
or boxes), and each tool as the convex parts the collision check sweeps (cutter and holder).

Placement: a solid is in machine coordinates, or relative to the work offset named by its
`frame`, and moved by its `position`. A tool hangs from the controlled point the toolpath gives
(the gauge line, after tool-length compensation): its tip is `length` below it, along -Z.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

from nctrans.machine import Machine, MachineError, Mesh, Tool

SIDES = 24              # polygon sides of a cylinder; circumscribed, so the polygon contains it
MIN_SIZE = 0.01         # mm: a tool with no geometry is checked as a thin pin at its tip


@dataclass
class Solid:
    name: str
    mesh: object                # a trimesh.Trimesh (trimesh is imported lazily: the check extra)
    is_box: bool = False

    @property
    def bounds(self) -> np.ndarray:
        return self.mesh.bounds


def _offset(m: Mesh, machine: Machine) -> np.ndarray:
    off = np.zeros(3)
    if m.frame:
        wo = machine.work_offset(m.frame)
        if not wo and m.frame.upper() not in machine.offsets:
            raise MachineError(f"{m.frame}: no such work offset in the machine (placing {m.name or m.mesh or 'a box'})")
        off += [wo.get("X", 0.0), wo.get("Y", 0.0), wo.get("Z", 0.0)]
    if m.position:
        off += m.position
    return off


def mesh_path(file: str, machine: Machine) -> Path:
    p = Path(file)
    if not p.is_absolute() and machine.source_dir:
        p = Path(machine.source_dir) / p
    return p


def load_mesh(file: str, machine: Machine):
    """A mesh file (STL/OBJ/PLY) as one trimesh; MachineError with the path if it cannot be read."""
    import trimesh
    path = mesh_path(file, machine)
    if not path.is_file():
        raise MachineError(f"{path}: mesh file not found")
    try:
        loaded = trimesh.load(str(path), force="mesh")
    except Exception as e:      # trimesh raises many kinds on a bad file
        raise MachineError(f"{path}: cannot read mesh: {e}") from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise MachineError(f"{path}: no triangles in the mesh")
    return loaded


def load_solid(m: Mesh, machine: Machine, default_name: str) -> Solid:
    import trimesh
    if m.box is not None:
        lo, hi = np.array(m.box["min"], float), np.array(m.box["max"], float)
        mesh = trimesh.creation.box(bounds=np.array([lo, hi]))
        name = m.name or default_name
    elif m.cylinder is not None:
        c = m.cylinder
        mesh = trimesh.creation.cylinder(radius=c["radius"], height=c["z_max"] - c["z_min"], sections=48)
        mesh.apply_translation([0.0, 0.0, (c["z_min"] + c["z_max"]) / 2])
        name = m.name or default_name
    else:
        mesh = load_mesh(m.mesh, machine).copy()
        name = m.name or Path(m.mesh).name
    mesh.apply_translation(_offset(m, machine))
    return Solid(name, mesh, m.box is not None)


def fixtures(machine: Machine) -> list[Solid]:
    return [load_solid(f, machine, f"fixture {i + 1}") for i, f in enumerate(machine.fixtures)]


# --------------------------------------------------------------------------- tools

@dataclass
class ToolPart:
    """A convex part of a tool, as points relative to the controlled point (gauge line)."""
    role: str                   # "tool" (cutter) or "holder"
    points: np.ndarray          # (n, 3)
    radius: float               # in XY, for the stock's Z-map
    bottom: float               # height of its lowest point above the tool tip


def _cylinder(radius: float, z0: float, z1: float) -> np.ndarray:
    a = np.linspace(0.0, 2 * math.pi, SIDES, endpoint=False)
    rr = radius / math.cos(math.pi / SIDES)
    ring = np.stack([rr * np.cos(a), rr * np.sin(a)], axis=1)
    return np.vstack([np.c_[ring, np.full(SIDES, z0)], np.c_[ring, np.full(SIDES, z1)]])


@dataclass
class ToolSolid:
    number: Optional[int]
    length: float               # tip is this far below the controlled point
    radius: float
    parts: list[ToolPart]
    known: bool                 # the machine's tool table describes it

    def __post_init__(self) -> None:
        # the box around every part, relative to the controlled point
        self.lo = np.min([p.points.min(axis=0) for p in self.parts], axis=0)
        self.hi = np.max([p.points.max(axis=0) for p in self.parts], axis=0)


def tool_solid(machine: Machine, number: Optional[int]) -> ToolSolid:
    t: Optional[Tool] = machine.tool(number) if number is not None else None
    if t is None:
        parts = [ToolPart("tool", _cylinder(MIN_SIZE, 0.0, MIN_SIZE), MIN_SIZE, 0.0)]
        return ToolSolid(number, 0.0, 0.0, parts, False)
    length = t.length
    radius = max(t.radius, MIN_SIZE)
    cut = max(t.cutter_height(), MIN_SIZE)
    parts = [ToolPart("tool", _cylinder(radius, -length, -length + cut), radius, 0.0)]
    for r, z0, z1 in t.holder_cylinders():
        parts.append(ToolPart("holder", _cylinder(r, z0 - length, z1 - length), r, z0))
    if t.holder_mesh:
        hm = load_mesh(t.holder_mesh, machine)
        pts = np.asarray(hm.convex_hull.vertices, float) + [0.0, 0.0, -length]
        parts.append(ToolPart("holder", pts, float(np.hypot(pts[:, 0], pts[:, 1]).max()),
                              float(hm.bounds[0][2])))
    return ToolSolid(number, length, radius, parts, True)


class ToolCache:
    """Tool solids by number, built once; holder meshes are read when the cache is made, so a
    missing file is reported before the run."""

    def __init__(self, machine: Machine):
        self.machine = machine
        self._solids: dict[Optional[int], ToolSolid] = {}
        for t in machine.tools:
            if t.holder_mesh:
                self.get(t.number)

    def get(self, number: Optional[int]) -> ToolSolid:
        t = self._solids.get(number)
        if t is None:
            t = self._solids[number] = tool_solid(self.machine, number)
        return t
