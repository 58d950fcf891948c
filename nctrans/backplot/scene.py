"""What a backplot shows, gathered from the toolpath stream once: the moves, the markers and findings.

Every renderer (svg, png, glb, html) reads a Scene, never the toolpath, the IR or the source: the
scene is built from ToolpathRecords alone, so a backplot works the same for every dialect (the
interpreter has already expanded cycles, subprograms, loops and cutter compensation).

Only the linear axes X, Y and Z are drawn. A program that also moves a rotary axis gets a warning in
the scene (shown by every renderer), because its plot shows the tool positions without the rotation.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterable, Optional

from nctrans.toolpath import ToolpathRecord

MOTION_KINDS = ("rapid", "linear", "arc")
LINEAR_AXES = ("X", "Y", "Z")
XYZ = tuple[float, float, float]


def xyz(point: Optional[dict]) -> XYZ:
    p = point or {}
    return (float(p.get("X", 0.0)), float(p.get("Y", 0.0)), float(p.get("Z", 0.0)))


@dataclass(slots=True)
class Move:
    """One rapid, linear or arc record, as drawn. `index` counts moves only (0-based)."""
    index: int
    record: ToolpathRecord
    start: XYZ
    end: XYZ

    @property
    def kind(self) -> str:
        return self.record.kind

    @property
    def tool(self) -> Optional[int]:
        return self.record.tool

    @property
    def line(self) -> int:
        return self.record.line

    @property
    def file(self) -> str:
        return self.record.file


@dataclass(slots=True)
class Marker:
    """A point worth a symbol: where the program starts, where a tool change happens."""
    kind: str                  # "start" | "tool_change"
    position: XYZ
    move_index: int            # the first move drawn after the marker (== number of moves before it)
    file: str
    line: int
    tool: Optional[int] = None


@dataclass(slots=True)
class Finding:
    """A lint or check finding to mark on the plot (the interface `check` feeds as well).
    position: where to draw it; when None the scene places it on the first move of its line."""
    line: int
    severity: str
    code: str
    message: str
    file: Optional[str] = None
    position: Optional[XYZ] = None

    @classmethod
    def from_mapping(cls, d: dict) -> "Finding":
        """From a plain {line, severity, code, message, position?, file?} dict (check, the API)."""
        pos = d.get("position")
        if isinstance(pos, dict):
            pos = xyz(pos)
        elif pos is not None:
            pos = tuple(float(v) for v in pos)[:3]
        return cls(int(d["line"]), str(d.get("severity", "warning")), str(d.get("code", d.get("rule", ""))),
                   str(d.get("message", "")), d.get("file"), pos)

    @classmethod
    def from_diagnostic(cls, diag) -> "Finding":
        return cls(diag.line, diag.severity, diag.rule, diag.message, diag.file)


@dataclass
class Scene:
    """The moves of one toolpath, in program order, and what to mark on them."""
    label: str
    moves: list[Move] = field(default_factory=list)
    markers: list[Marker] = field(default_factory=list)
    findings: list[Finding] = field(default_factory=list)
    tools: list[Optional[int]] = field(default_factory=list)    # in order of first use
    warnings: list[str] = field(default_factory=list)
    lo: list[float] = field(default_factory=lambda: [math.inf] * 3)
    hi: list[float] = field(default_factory=lambda: [-math.inf] * 3)
    # moves past limits.MAX_PLOTTED_MOVES: how many, and the first one's record (not drawn)
    left_out: int = 0
    first_left_out: Optional[ToolpathRecord] = None

    @property
    def empty(self) -> bool:
        return not self.moves

    def extend_bounds(self, p: XYZ) -> None:
        lo, hi = self.lo, self.hi
        for k in range(3):
            v = p[k]
            if v < lo[k]:
                lo[k] = v
            if v > hi[k]:
                hi[k] = v

    def bounds(self) -> tuple[XYZ, XYZ]:
        """Bounding box of the drawn moves (arcs by their end points and extreme points)."""
        if self.empty:
            return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        return tuple(self.lo), tuple(self.hi)

    def default_view(self) -> str:
        """Top, unless nothing moves in Y (a lathe's X/Z program): then front, which shows X and Z."""
        lo, hi = self.bounds()
        if hi[1] - lo[1] < 1e-6 and hi[2] - lo[2] > 1e-6:
            return "front"
        return "top"

    def diagonal(self) -> float:
        lo, hi = self.bounds()
        return math.dist(lo, hi)

    def files(self) -> list[str]:
        """Source files the moves come from, in order of first appearance."""
        seen: dict[str, None] = {}
        for m in self.moves:
            seen.setdefault(m.file, None)
        for mk in self.markers:
            seen.setdefault(mk.file, None)
        return list(seen)

    def place_findings(self) -> None:
        """Give every finding without a position the position of its line: the end of the first
        move at or after that line in the same file (so a finding on a modal line sits where the
        tool is when it takes effect), else the last drawn point."""
        if not self.findings:
            return
        by_file: dict[str, list[tuple[int, XYZ]]] = {}
        for m in self.moves:
            lst = by_file.setdefault(m.file, [])
            lst.append((m.line, m.end))
        for lst in by_file.values():
            lst.sort(key=lambda t: t[0])
        import bisect
        last = self.moves[-1].end if self.moves else (0.0, 0.0, 0.0)
        for f in self.findings:
            if f.position is not None:
                continue
            lst = by_file.get(f.file or self.label) or next(iter(by_file.values()), [])
            i = bisect.bisect_left(lst, f.line, key=lambda t: t[0])
            f.position = lst[i][1] if i < len(lst) else (lst[-1][1] if lst else last)


def arc_extremes(r: ToolpathRecord):
    """Points where an arc crosses a quadrant boundary of its plane (for the bounding box)."""
    from nctrans.toolpath_io import arc_sweep
    t0, sweep, radius, (a1, a2) = arc_sweep(r)
    c = r.center or {}
    k0 = math.floor(min(t0, t0 + sweep) / (math.pi / 2)) + 1
    k1 = math.floor(max(t0, t0 + sweep) / (math.pi / 2))
    s = xyz(r.start)
    for k in range(k0, min(k1, k0 + 4) + 1):
        ang = k * math.pi / 2
        p = dict(zip(LINEAR_AXES, s))
        p[a1] = c.get(a1, 0.0) + radius * math.cos(ang)
        p[a2] = c.get(a2, 0.0) + radius * math.sin(ang)
        yield (p["X"], p["Y"], p["Z"])


def build_scene(records: Iterable[ToolpathRecord], label: str,
                findings: Iterable = ()) -> Scene:
    """Read the toolpath once. findings: Finding objects, diagnostics or plain dicts. Moves past
    limits.MAX_PLOTTED_MOVES are counted, not drawn (the scene warns; `left_out`)."""
    from nctrans import limits
    most = limits.setting("MAX_PLOTTED_MOVES", limits.MAX_PLOTTED_MOVES)
    scene = Scene(label)
    moves = scene.moves
    seen_tools: set = set()
    hidden: set[str] = set()      # axes other than X, Y, Z that move
    skipped: list[int] = []       # lines of moves with a non-finite coordinate
    pending_change: Optional[ToolpathRecord] = None
    last_pos: Optional[XYZ] = None
    for r in records:
        kind = r.kind
        if kind in MOTION_KINDS and len(moves) >= most:
            if not scene.left_out:
                scene.first_left_out = r
            scene.left_out += 1
            continue
        if kind in MOTION_KINDS:
            start, end = xyz(r.start), xyz(r.end)
            if not math.isfinite(sum(start) + sum(end) + sum((r.center or {}).values())):
                skipped.append(r.line)      # said below; a NaN would break every renderer
                continue
            if not moves:       # a tool change before the first move is told by the start marker
                scene.markers.append(Marker("start", start, 0, r.file, r.line, r.tool))
                scene.extend_bounds(start)
                pending_change = None
            if pending_change is not None:
                scene.markers.append(Marker("tool_change", start, len(moves), pending_change.file,
                                            pending_change.line, pending_change.tool))
                pending_change = None
            if r.tool not in seen_tools:
                seen_tools.add(r.tool)
                scene.tools.append(r.tool)
            s_pt, e_pt = r.start or {}, r.end or {}
            for a, v in e_pt.items():
                if a not in LINEAR_AXES and abs(v - s_pt.get(a, v)) > 1e-9:
                    hidden.add(a)
            scene.extend_bounds(end)
            if kind == "arc":
                for p in arc_extremes(r):
                    scene.extend_bounds(p)
            moves.append(Move(len(moves), r, start, end))
            last_pos = end
        elif kind == "tool_change":
            pending_change = r      # marked where the next move starts
    if pending_change is not None and moves:
        scene.markers.append(Marker("tool_change", last_pos or moves[-1].end, len(moves),
                                    pending_change.file, pending_change.line, pending_change.tool))
    if hidden:
        scene.warnings.append(f"the program moves {', '.join(sorted(hidden))}: the plot shows X, Y and Z "
                              f"only, without {'that axis' if len(hidden) == 1 else 'those axes'}")
    if scene.left_out:
        first = scene.first_left_out
        scene.warnings.append(f"the plot shows the first {len(moves):,} moves of {len(moves) + scene.left_out:,} "
                              f"(NCTRANS_MAX_PLOTTED_MOVES); the first not drawn is at line {first.line}")
    if skipped:
        scene.warnings.append(f"{len(skipped)} move(s) with a non-finite coordinate not drawn "
                              f"(first at line {skipped[0]})")
    for f in findings:
        if isinstance(f, Finding):
            scene.findings.append(f)
        elif isinstance(f, dict):
            scene.findings.append(Finding.from_mapping(f))
        else:
            scene.findings.append(Finding.from_diagnostic(f))
    for f in scene.findings:
        if f.file is None:
            f.file = label
    scene.place_findings()
    return scene
