"""The 3D backplot as a binary glTF scene (GLB), built with trimesh.

The toolpath is one Path3D per (move kind, tool): each move is one polyline entity (arcs tessellated
to 0.01 mm, or finer than a ten-thousandth of the part), coloured by kind (rapid red, linear blue,
arc green - the glTF material of that geometry). glTF keeps no entity boundaries, so each geometry's
extras list its moves: "moves" (move indices in program order), "lines" (source lines) and
"points" (vertices per move); the GL_LINES buffer holds, move after move, points-1 segments each.
The machine's stock and fixtures (--machine), the start point and tool changes are meshes beside it.
"""
from __future__ import annotations

from pathlib import Path
from typing import Optional

from nctrans.backplot import BackplotError
from nctrans.backplot import project as P
from nctrans.backplot.compare import Comparison
from nctrans.backplot.scene import Scene

KIND_COLOURS = {"rapid": (0.85, 0.15, 0.15, 1.0), "linear": (0.12, 0.47, 0.71, 1.0),
                "arc": (0.17, 0.63, 0.17, 1.0)}
STOCK_COLOUR = (0.75, 0.75, 0.78, 0.35)
FIXTURE_COLOUR = (0.45, 0.45, 0.5, 0.6)
MARKER_COLOURS = {"start": (0.0, 0.67, 0.0, 1.0), "tool_change": (1.0, 0.8, 0.0, 1.0),
                  "difference": (0.82, 0.0, 0.0, 1.0)}


class GlbError(BackplotError):
    """A machine mesh that cannot be loaded (reported by the CLI, exit 2)."""


def _path_geometries(scene: Scene, prefix: str) -> dict:
    """{geometry name: Path3D} grouping moves by (kind, tool), with the per-move extras."""
    import numpy as np
    import trimesh
    from trimesh.path.entities import Line
    tol = max(0.01, scene.diagonal() * 1e-4)
    groups: dict[tuple, dict] = {}
    for m in scene.moves:
        key = (m.kind, m.tool)
        g = groups.get(key)
        if g is None:
            g = groups[key] = {"vertices": [], "entities": [], "moves": [], "lines": [], "points": []}
        pts = [m.start] + (P.arc_polyline(m, tol) if m.kind == "arc" else [m.end])
        first = len(g["vertices"])
        g["vertices"].extend(pts)
        g["entities"].append(Line(points=np.arange(first, first + len(pts))))
        g["moves"].append(m.index)
        g["lines"].append(m.line)
        g["points"].append(len(pts))
    out = {}
    for (kind, tool), g in groups.items():
        name = f"{prefix}{kind}-T{tool if tool is not None else 'none'}"
        meta = {"kind": kind, "tool": tool, "file": scene.label, "moves": g["moves"],
                "lines": g["lines"], "points": g["points"]}
        out[name] = trimesh.path.Path3D(entities=g["entities"], vertices=np.array(g["vertices"], dtype=float),
                                        process=False, metadata=meta)
    return out


def _marker(position, kind: str, size: float):
    import trimesh
    mesh = trimesh.creation.icosphere(subdivisions=1, radius=size)
    mesh.apply_translation(position)
    mesh.visual.vertex_colors = [int(255 * c) for c in MARKER_COLOURS[kind]]
    return mesh


def _machine_meshes(machine) -> list[tuple[str, object]]:
    """Stock (box or mesh) and fixture meshes of a machine, paths relative to its file."""
    import trimesh
    out = []
    if machine is None:
        return out
    base = Path(machine.source_dir or ".")

    def load(spec, what: str):
        if spec.box:
            lo, hi = spec.box.get("min"), spec.box.get("max")
            if not lo or not hi or len(lo) != 3 or len(hi) != 3:
                raise GlbError(f"{what}: box needs min = [x, y, z] and max = [x, y, z]")
            mesh = trimesh.creation.box(extents=[h - l for l, h in zip(lo, hi)])
            mesh.apply_translation([(h + l) / 2 for l, h in zip(lo, hi)])
            return mesh
        if spec.mesh:
            path = base / spec.mesh
            try:
                mesh = trimesh.load(str(path), force="mesh")
            except Exception as e:      # trimesh raises many kinds for unreadable files
                raise GlbError(f"{path}: cannot load {what} mesh: {e}") from None
            return mesh
        return None

    if machine.stock is not None:
        mesh = load(machine.stock, "stock")
        if mesh is not None:
            mesh.visual.vertex_colors = [int(255 * c) for c in STOCK_COLOUR]
            out.append(("stock", mesh))
    for i, fx in enumerate(machine.fixtures or []):
        mesh = load(fx, f"fixture {i + 1}")
        if mesh is not None:
            mesh.visual.vertex_colors = [int(255 * c) for c in FIXTURE_COLOUR]
            out.append((f"fixture-{i + 1}", mesh))
    return out


def render(scene: Scene, machine=None, comparison: Optional[Comparison] = None) -> bytes:
    import trimesh
    sc = trimesh.Scene()
    geoms = _path_geometries(scene, "")
    if comparison is not None:
        geoms.update(_path_geometries(comparison.b, "B-"))
    for name, g in geoms.items():
        sc.add_geometry(g, geom_name=name, node_name=name)
    size = max(scene.diagonal() * 0.006, 0.2)
    for i, mk in enumerate(scene.markers):
        sc.add_geometry(_marker(mk.position, mk.kind, size), geom_name=f"marker-{mk.kind}-{i}")
    if comparison is not None:
        for i, mark in enumerate(comparison.marks):
            for side in (mark.a, mark.b):
                if side is not None:
                    sc.add_geometry(_marker(side.position, "difference", size * 1.5),
                                    geom_name=f"difference-{i}")
    for name, mesh in _machine_meshes(machine):
        sc.add_geometry(mesh, geom_name=name, node_name=name)

    def colour_paths(tree: dict) -> None:
        """trimesh writes every path with one white material: give each its kind's colour."""
        materials = tree.setdefault("materials", [])
        for mesh in tree.get("meshes", []):
            kind = (mesh.get("extras") or {}).get("kind")
            if kind in KIND_COLOURS:
                for prim in mesh["primitives"]:
                    materials.append({"name": kind, "pbrMetallicRoughness": {
                        "baseColorFactor": list(KIND_COLOURS[kind]), "metallicFactor": 0.0,
                        "roughnessFactor": 1.0}})
                    prim["material"] = len(materials) - 1

    from trimesh.exchange.gltf import export_glb
    data = export_glb(sc, tree_postprocessor=colour_paths)
    return data
