"""`nctrans check`: the machine check, a consumer of the toolpath stream only.

It reads toolpath records (never the IR or the source), so every dialect is checked the same way.
Limits, feeds and spindle speed are checked on every machine; collisions when the machine (or the
command line) gives fixtures, the stock check when it gives stock; on a lathe, the tool tip against
fixtures of revolution (check/turning.py). The cycle-time estimate comes
from the same pass. Records stream through: nothing holds the whole toolpath.

Collision and stock checks need the `check` extra (numpy, scipy, trimesh, python-fcl); they are
imported only when the machine has fixtures or stock.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Iterable, Optional

from nctrans.check.cycletime import CycleTime
from nctrans.check.findings import RULES, Finding
from nctrans.check.limits import LimitCheck
from nctrans.machine import Machine, MachineError
from nctrans.toolpath import ToolpathRecord

__all__ = ["Finding", "RULES", "CheckResult", "MachineCheck", "check_records", "MachineError"]

ROTARY = ("A", "B", "C")


@dataclass
class CheckResult:
    findings: list[Finding]
    cycle: CycleTime
    moves: int = 0
    notes: list[str] = field(default_factory=list)


class MachineCheck:
    """Feed toolpath records in order with `add`, then call `finish`."""

    def __init__(self, machine: Machine):
        self.machine = machine
        self.found: list[Finding] = []
        self.limits = LimitCheck(machine)
        self.cycle = CycleTime(machine)
        self.collisions = None
        self.stock = None
        self.moves = 0
        self._rotary_noted = False
        self._placed = False        # has a move put the machine somewhere known yet?
        self.turning = None
        self._not_modelled = None
        if machine.kind == "lathe":
            from nctrans.check.turning import TurningCheck
            if any(f.cylinder is not None for f in machine.fixtures):
                self.turning = TurningCheck(machine, self.found)
            if machine.stock is not None or any(f.cylinder is None for f in machine.fixtures):
                self._not_modelled = ("on a lathe only fixtures given as cylinders about the spindle "
                                      "(chuck, jaws, tailstock) are checked: fixtures given as meshes or "
                                      "boxes, and the stock, are not")
        elif machine.fixtures or machine.stock is not None:
            self._geometry()

    def _geometry(self) -> None:
        try:
            from nctrans.check import collide, scene, zmap
        except ImportError as e:
            raise MachineError(f"fixtures and stock need the check extra (pip install 'nctrans[check]'): {e}") from None
        tools = scene.ToolCache(self.machine)
        solids = scene.fixtures(self.machine)
        if solids:
            self.collisions = collide.CollisionCheck(self.machine, solids, tools, self.found)
        if self.machine.stock is not None:
            stock = scene.load_solid(self.machine.stock, self.machine, "stock")
            self.stock = zmap.StockCheck(self.machine, stock, self.machine.stock.cell, tools, self.found)

    def add(self, r: ToolpathRecord) -> None:
        self.limits.add(r)
        self.cycle.add(r)
        if r.kind not in ("rapid", "linear", "arc") or r.start is None or r.end is None:
            return
        self.moves += 1
        if self._not_modelled is not None:
            self.found.append(Finding("NC306", r.file, r.line, "machine", self._not_modelled))
            self._not_modelled = None
        if self.turning is not None:
            self.turning.add(r, self._placed)
            self._placed = True
            return
        if self.collisions is None and self.stock is None:
            return
        if not self._placed:
            # The first move starts where the interpreter assumes the machine is (machine zero),
            # not where it really is: only where it ends is checked.
            self._placed = True
            r = dataclasses.replace(r, kind="linear", start=r.end, center=None)
        if any(r.end.get(a, 0.0) != 0.0 or r.start.get(a, 0.0) != 0.0 for a in ROTARY if a in r.end):
            if not self._rotary_noted:
                self._rotary_noted = True
                self.found.append(Finding(
                    "NC306", r.file, r.line, "rotary axes",
                    "moves with rotary axes are not checked for collisions (the tool is taken "
                    "along Z; 4- and 5-axis geometry is not modelled)", dict(r.end)))
            return
        if self.collisions is not None:
            self.collisions.add(r)
        if self.stock is not None:
            self.stock.add(r)

    def finish(self) -> CheckResult:
        if self.collisions is not None:
            self.collisions.finish()
        self.cycle.finish()
        found = self.limits.findings() + self.found
        found.sort(key=lambda f: (f.file, f.line, f.rule))
        return CheckResult(found, self.cycle, self.moves)


def check_records(records: Iterable[ToolpathRecord], machine: Machine) -> CheckResult:
    """Check a toolpath (any iterable of records, consumed once) on `machine`."""
    mc = MachineCheck(machine)
    for r in records:
        mc.add(r)
    return mc.finish()


def with_extra_solids(machine: Machine, fixtures: Iterable[str] = (), stock: Optional[str] = None) -> Machine:
    """The machine with mesh files from the command line added as fixtures / as the stock
    (paths relative to the working directory, in machine coordinates)."""
    from pathlib import Path

    from nctrans.machine import Mesh
    fixtures = list(fixtures)
    if not fixtures and stock is None:
        return machine
    m = machine.copy()
    for f in fixtures:
        m.fixtures.append(Mesh(mesh=str(Path(f).resolve())))
    if stock is not None:
        m.stock = Mesh(mesh=str(Path(stock).resolve()))
    return m


def check_loaded(ld, machine: Machine) -> tuple[list, Optional[CheckResult]]:
    """Run the toolpath of a loaded file (pipeline.Loaded) through the check: (the file's own
    diagnostics followed by the findings as diagnostics, the result; None if it did not parse).
    MachineError (a mesh that cannot be read) becomes pipeline.PipelineError."""
    from nctrans import pipeline
    try:
        mc = MachineCheck(machine)
    except MachineError as e:
        raise pipeline.PipelineError(str(e)) from None
    if ld.program is None:
        return list(ld.diagnostics), None
    for r in pipeline.toolpath_of(ld, machine):     # a drained stream completes ld.diagnostics
        mc.add(r)
    res = mc.finish()
    return list(ld.diagnostics) + [f.to_diagnostic() for f in res.findings], res
