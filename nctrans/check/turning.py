"""Collisions on a lathe: the tool tip against fixtures of revolution (chuck, jaws, tailstock).

The part and everything clamped to the spindle turn, so a fixture given as a cylinder about the
spindle axis (machine `cylinder = { radius, z_min, z_max }`) sweeps the whole ring around it: in
the X-Z plane the tool moves in, that is the rectangle |X| <= radius, z_min <= Z <= z_max. The
tool is its tip, the controlled point of a lathe toolpath, grown by its nose radius; a straight
move is clipped against each rectangle, an arc as chords of at most one degree. Turning tool
bodies and holders, and fixtures given as meshes or boxes, are not modelled: MachineCheck says so
(NC306) once.

Needs no geometry library: plain arithmetic on the records.
"""
from __future__ import annotations

from nctrans.check.findings import Finding
from nctrans.check.limits import arc_points, segment_in_box
from nctrans.machine import Machine
from nctrans.toolpath import ToolpathRecord

AXES = ("X", "Z")


class TurningCheck:
    """Feed motion records in order (`add`); findings go to `found`."""

    def __init__(self, machine: Machine, found: list[Finding]):
        self.machine = machine
        self.found = found
        self.rings = []                 # (name, lo, hi) in machine X/Z
        for i, f in enumerate(machine.fixtures):
            if f.cylinder is None:
                continue
            dz = 0.0
            if f.frame:
                dz += machine.work_offset(f.frame).get("Z", 0.0)
            if f.position:
                dz += f.position[2]
            r = f.cylinder["radius"]
            self.rings.append((f.name or f"fixture {i + 1}", {"X": -r, "Z": f.cylinder["z_min"] + dz},
                               {"X": r, "Z": f.cylinder["z_max"] + dz}))
        self._reported: set[tuple] = set()

    def add(self, r: ToolpathRecord, placed: bool) -> None:
        """One move; `placed` False for the first, whose start is only assumed (its end counts)."""
        tool = self.machine.tool(r.tool) if r.tool is not None else None
        grow = tool.radius if tool is not None else 0.0
        if not placed:
            pts = [r.end, r.end]
        elif r.kind == "arc" and r.center is not None:
            pts = [r.start] + [p for p, _ in arc_points(r)]
        else:
            pts = [r.start, r.end]
        for name, lo, hi in self.rings:
            lo_g = {a: v - grow for a, v in lo.items()}
            hi_g = {a: v + grow for a, v in hi.items()}
            deepest, depth = None, 0.0
            for p, q in zip(pts, pts[1:]):
                hit = segment_in_box(p, q, lo_g, hi_g, AXES)
                if hit is not None:
                    d = min(min(hit[a] - lo_g[a], hi_g[a] - hit[a]) for a in AXES)
                    if deepest is None or d > depth:
                        deepest, depth = hit, d
            key = (r.file, r.line, name)
            if deepest is None or key in self._reported:
                continue
            self._reported.add(key)
            who = f"T{r.tool}" if r.tool is not None else "the tool"
            self.found.append(Finding(
                "NC310", r.file, r.line, name,
                f"{r.kind} move: {who} tip reaches into {name!r} (radius {hi['X']:g}, Z{lo['Z']:g}.."
                f"{hi['Z']:g}, turning about the spindle) by {depth:.3f} mm at "
                f"X{deepest['X']:.3f} Z{deepest['Z']:.3f} (machine coordinates)",
                {a: deepest[a] for a in AXES}, depth))
