"""LinuxCNC `rs274` as a reference interpreter: run it, read its canonical calls as machine-mm moves.

rs274 (the stand-alone LinuxCNC interpreter) prints one canonical call per line, e.g.
`   34 N0120  STRAIGHT_TRAVERSE(4.0000, -4.0000, 2.0000, 0.0000, 0.0000, 0.0000)`. Positions are
printed in PROGRAM units (the units of the last USE_LENGTH_UNITS) and PROGRAM coordinates, with 4
decimals; offsets are printed separately when they change. Facts established with small programs
(tests/test_rs274_harness.py runs them again):

- machine = rotate_z(program + G92 offset, XY rotation) + G5x offset + tool length offset.
  G52 is reported as SET_G92_OFFSET. The G92 offset is rotated with the program (it lives inside the
  G10 L2 R rotation); the G5x offset and the tool offset are not.
- Each offset call is printed in the units active when it is printed and is not reprinted on G20/G21,
  so it is converted to mm at the time it is read.
- rs274 prints X Y Z A B C (this build has no U V W); nine values are accepted too.
- ARC_FEED(first_end, second_end, first_center, second_center, rotation, axis_end, a, b, c):
  XY plane -> first X, second Y, axis Z; YZ -> Y, Z, axis X; XZ -> Z, X, axis Y.
  rotation > 0 is G3 (ccw), < 0 is G2 (cw); |rotation| - 1 is the number of extra full turns (G2 P2 -> 2).
- The stand-alone rs274 reads tool-table lengths and diameters in INCHES whatever the program units
  (Z10 -> USE_TOOL_LENGTH_OFFSET 254.0000 in a G21 program). `write_tool_table` converts from mm.
- The machine does not move when an offset changes: the next move starts where the last one ended.
  Power-on position is machine 0 with every offset 0.
"""
from __future__ import annotations

import math
import os
import re
import subprocess
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Optional

RS274 = os.environ.get("RS274", "/usr/bin/rs274")   # override to point at another build
MM_PER_INCH = 25.4
HALF_UNIT = 0.00005          # half of the last printed digit (4 decimals), in program units
BASE_TOL_MM = 0.001          # the project's 1 µm position tolerance
ZERO_MOVE_MM = 1e-6          # a rapid/linear move shorter than this on every axis is dropped
LINEAR_AXES = ("X", "Y", "Z")
ROTARY_AXES = ("A", "B", "C")
AXES = LINEAR_AXES + ROTARY_AXES

# canonical plane -> (first axis, second axis, helix axis, contract plane name)
PLANES = {
    "CANON_PLANE_XY": ("X", "Y", "Z", "XY"),
    "CANON_PLANE_YZ": ("Y", "Z", "X", "YZ"),
    "CANON_PLANE_XZ": ("Z", "X", "Y", "ZX"),
}

# "%5d N%-6s" then the call: a 6-digit N word runs straight into the name ("N110795PROGRAM_END()")
_CALL = re.compile(r"^\s*(\d+)\s+(N(?:\.+|\d*))\s*([A-Z_][A-Z_0-9]*)\((.*)\)")
_NUM = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


@dataclass(slots=True)
class Move:
    """One rs274 motion in machine mm, shaped like a nctrans ToolpathRecord for comparison."""
    kind: str                               # rapid | linear | arc
    start: dict[str, float]
    end: dict[str, float]
    center: Optional[dict[str, float]] = None   # plane axes only (plus the helix axis at end height)
    direction: Optional[str] = None
    plane: Optional[str] = None
    turns: Optional[int] = None
    feed: Optional[float] = None            # mm/min (as last set; informational)
    tol: float = BASE_TOL_MM                # position tolerance this record's printed rounding allows
    out_line: int = 0                       # sequence number rs274 printed
    n_word: str = ""
    text: str = ""                          # the canonical call as printed

    def where(self) -> str:
        return f"rs274 out #{self.out_line} {self.n_word}: {self.text}"


@dataclass(slots=True)
class Event:
    """A non-motion canonical call kept for debugging (tool change, dwell, program end...)."""
    name: str
    args: str
    out_line: int


@dataclass
class Run:
    moves: list[Move] = field(default_factory=list)
    events: list[Event] = field(default_factory=list)
    completed: bool = False                 # reached PROGRAM_END
    message: str = ""                       # rs274's own stdout/stderr (its error text when it stopped)


def _nums(args: str) -> list[float]:
    return [float(m) for m in _NUM.findall(args)]


class _State:
    def __init__(self) -> None:
        self.scale = 1.0                    # mm per program unit
        self.g5x = [0.0] * 6                # mm / deg, X Y Z A B C
        self.g92 = [0.0] * 6
        self.tool = [0.0] * 6
        self.g5x_half = self.g92_half = self.tool_half = 0.0   # printed rounding of each, mm
        self.rotation = 0.0                 # degrees
        self.plane = "CANON_PLANE_XY"
        self.pos = {a: 0.0 for a in AXES}   # machine position
        self.feed: Optional[float] = None

    def _offset(self, vals: list[float]) -> list[float]:
        vals = (vals + [0.0] * 6)[:6]
        return [v * self.scale for v in vals[:3]] + vals[3:6]

    def to_machine(self, p: dict[str, float]) -> dict[str, float]:
        """Program point (program units, deg) -> machine mm; see module docstring for the order."""
        x = p["X"] * self.scale + self.g92[0]
        y = p["Y"] * self.scale + self.g92[1]
        z = p["Z"] * self.scale + self.g92[2]
        if self.rotation:
            t = math.radians(self.rotation)
            x, y = x * math.cos(t) - y * math.sin(t), x * math.sin(t) + y * math.cos(t)
        out = {"X": x + self.g5x[0] + self.tool[0],
               "Y": y + self.g5x[1] + self.tool[1],
               "Z": z + self.g5x[2] + self.tool[2]}
        for i, a in enumerate(ROTARY_AXES, start=3):
            out[a] = p[a] + self.g92[i] + self.g5x[i] + self.tool[i]
        return out

    def tolerance(self) -> float:
        """Printed rounding of one coordinate: the point's own digit plus each nonzero offset's."""
        t = HALF_UNIT * self.scale
        if any(self.g5x[:3]):
            t += self.g5x_half
        if any(self.g92[:3]):
            t += self.g92_half
        if any(self.tool[:3]):
            t += self.tool_half
        return max(BASE_TOL_MM, t)


def parse(text: str) -> Run:
    """Read rs274's canonical output into moves in machine mm (PROGRAM_END sets `completed`)."""
    st = _State()
    run = Run()
    for raw in text.splitlines():
        m = _CALL.match(raw)
        if not m:
            continue
        seq, n_word, name, args = int(m.group(1)), m.group(2), m.group(3), m.group(4)
        if name == "USE_LENGTH_UNITS":
            st.scale = MM_PER_INCH if "INCHES" in args else 1.0   # CANON_UNITS_CM never occurs in G-code
        elif name == "SET_G5X_OFFSET":
            st.g5x = st._offset(_nums(args)[1:])
            st.g5x_half = HALF_UNIT * st.scale
        elif name == "SET_G92_OFFSET":
            st.g92 = st._offset(_nums(args))
            st.g92_half = HALF_UNIT * st.scale
        elif name == "SET_XY_ROTATION":
            st.rotation = _nums(args)[0]
        elif name == "USE_TOOL_LENGTH_OFFSET":
            v = _nums(args)                # "x y z, a b c, u v w"
            st.tool = st._offset(v[:6])
            st.tool_half = HALF_UNIT * st.scale
        elif name == "SELECT_PLANE":
            st.plane = args.strip()
        elif name == "SET_FEED_RATE":
            st.feed = _nums(args)[0] * st.scale
        elif name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            v = _nums(args)
            end = st.to_machine(dict(zip(AXES, v[:6])))
            kind = "rapid" if name == "STRAIGHT_TRAVERSE" else "linear"
            run.moves.append(Move(kind, dict(st.pos), end, feed=None if kind == "rapid" else st.feed,
                                  tol=st.tolerance(), out_line=seq, n_word=n_word,
                                  text=f"{name}({args})"))
            st.pos = end
        elif name == "RIGID_TAP":
            # G33.1: synchronised to the point and back to where it began (rs274 prints the point
            # only, in XYZ; the position after it is the start)
            v = _nums(args)
            start = dict(st.pos)
            end = st.to_machine(dict(zip(AXES, v[:3] + [0.0, 0.0, 0.0])))
            for a in ROTARY_AXES:
                end[a] = start.get(a, 0.0)
            for a, b in ((start, end), (end, start)):
                run.moves.append(Move("linear", dict(a), dict(b), feed=st.feed, tol=st.tolerance(),
                                      out_line=seq, n_word=n_word, text=f"{name}({args})"))
        elif name == "ARC_FEED":
            v = _nums(args)
            first, second, axis, plane = PLANES[st.plane]
            rot = int(v[4])
            p_end = {first: v[0], second: v[1], axis: v[5], "A": v[6], "B": v[7], "C": v[8]}
            p_ctr = {first: v[2], second: v[3], axis: v[5], "A": v[6], "B": v[7], "C": v[8]}
            end = st.to_machine(p_end)
            c = st.to_machine(p_ctr)
            run.moves.append(Move("arc", dict(st.pos), end,
                                  center={first: c[first], second: c[second]},
                                  direction="ccw" if rot > 0 else "cw", plane=plane,
                                  turns=abs(rot) - 1, feed=st.feed, tol=st.tolerance(),
                                  out_line=seq, n_word=n_word, text=f"{name}({args})"))
            st.pos = end
        else:
            if name == "PROGRAM_END":
                run.completed = True
            if name in ("CHANGE_TOOL", "DWELL", "PROGRAM_END", "PROGRAM_STOP", "OPTIONAL_PROGRAM_STOP",
                        "STRAIGHT_PROBE", "RIGID_TAP", "NURBS_FEED", "SPLINE_FEED"):
                run.events.append(Event(name, args, seq))
    return run


def linuxcnc():
    """A context in which ISO milling is written for LinuxCNC (as `convert --profile linuxcnc`):
    flattened threads with the lead as K, taps as G33.1, what rs274 runs (rules iso-m
    [options.profiles.linuxcnc]); api.transpile takes profile="linuxcnc" instead."""
    from nctrans.dialects.emit import target_profile
    return target_profile("iso-m", "linuxcnc")


def write_tool_table(path: Path, tools: Iterable[tuple[int, float, float]]) -> Path:
    """Tool table for rs274 from (number, length_mm, radius_mm); rs274 reads it in inches."""
    lines = [f"T{n} P{n} Z{length / MM_PER_INCH:.9f} D{2 * radius / MM_PER_INCH:.9f} ;"
             for n, length, radius in tools]
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    return path


def _private_home(out: Path) -> dict:
    """rs274 keeps its tool table in $HOME/.tool.mmap, truncated on start: two runs at once (pytest
    -n 2) crash each other with a bus error. Each run gets the directory of its output as HOME."""
    home = out.parent / ".rs274-home"
    home.mkdir(parents=True, exist_ok=True)
    return {**os.environ, "HOME": str(home)}


def run_rs274(program: Path, tool_table: Path, out: Path, timeout: float = 120.0) -> Run:
    """Run rs274 in batch mode on `program`; canonical output goes to `out` (reused if present)."""
    message = ""
    if not out.exists():
        proc = subprocess.run([RS274, "-t", str(tool_table), "-g", str(program), str(out)], env=_private_home(out),
                              stdin=subprocess.DEVNULL, capture_output=True, timeout=timeout)
        message = (proc.stdout + proc.stderr).decode("utf-8", "replace")
        out.with_suffix(".msg").write_text(message, encoding="utf-8")
    else:
        msg = out.with_suffix(".msg")
        message = msg.read_text(encoding="utf-8") if msg.exists() else ""
    text = out.read_text(encoding="utf-8", errors="replace") if out.exists() else ""
    run = parse(text)
    run.message = message.replace("executing", "").strip()
    return run


# ---------------------------------------------------------------- comparison with nctrans records

@dataclass(slots=True)
class Motion:
    """The comparable part of a nctrans ToolpathRecord (rapid/linear/arc) plus where it came from."""
    kind: str
    start: dict[str, float]
    end: dict[str, float]
    center: Optional[dict[str, float]]
    direction: Optional[str]
    plane: Optional[str]
    turns: Optional[int]
    where: str

    @classmethod
    def of(cls, rec) -> "Motion":
        return cls(rec.kind, dict(rec.start or {}), dict(rec.end or {}), rec.center and dict(rec.center),
                   rec.direction, rec.plane, rec.turns, f"nctrans {rec.file}:{rec.line} seq {rec.seq}")


def is_zero_move(m) -> bool:
    """A rapid/linear whose start and end coincide (arcs never: equal ends mean a full circle)."""
    if m.kind == "arc":
        return False
    keys = set(m.start) & set(m.end)
    return all(abs(m.end[k] - m.start[k]) <= ZERO_MOVE_MM for k in keys)


def _fmt(d: Optional[dict[str, float]]) -> str:
    if d is None:
        return "-"
    return "{" + ", ".join(f"{k}={v:.4f}" for k, v in d.items()) + "}"


def describe(m) -> str:
    s = f"{m.kind} start {_fmt(m.start)} end {_fmt(m.end)}"
    if m.kind == "arc":
        s += f" center {_fmt(m.center)} {m.direction} {m.plane} turns {m.turns}"
    return s


def _point_diff(ref: dict[str, float], got: dict[str, float], axes: Iterable[str]) -> list[tuple[str, float]]:
    """(axis, |difference|) for axes of `ref` given; an axis `got` lacks counts as 0 there."""
    out = []
    for a in axes:
        if a not in ref:
            continue
        g = got.get(a, 0.0)
        out.append((a, abs(ref[a] - g)))
    return out


def differences(ref: Move, got: Motion, check_start: bool = True) -> list[str]:
    """Why `got` is not the same motion as `ref` (empty list when it is)."""
    problems = []
    if ref.kind != got.kind:
        problems.append(f"kind {got.kind} != {ref.kind}")
        return problems
    tol = ref.tol
    # rotary axes are compared only where nctrans reports them or rs274 has them nonzero
    axes = [a for a in AXES if a in LINEAR_AXES or a in got.end or abs(ref.end.get(a, 0.0)) > tol]
    for label, r, g in (("end", ref.end, got.end),) + ((("start", ref.start, got.start),) if check_start else ()):
        for a, d in _point_diff(r, g, axes):
            if d > tol:
                problems.append(f"{label}.{a} differs by {d:.6f} mm (tol {tol:.6f})")
    if ref.kind == "arc":
        if ref.plane != got.plane:
            problems.append(f"plane {got.plane} != {ref.plane}")
        if ref.direction != got.direction:
            problems.append(f"direction {got.direction} != {ref.direction}")
        if (got.turns or 0) != ref.turns:
            problems.append(f"turns {got.turns} != {ref.turns}")
        for a, d in _point_diff(ref.center or {}, got.center or {}, list((ref.center or {}).keys())):
            if d > tol:
                problems.append(f"center.{a} differs by {d:.6f} mm (tol {tol:.6f})")
    return problems


def compare(ref_moves: list[Move], got: list[Motion], name: str = "") -> Optional[str]:
    """None when both motion sequences agree (zero-length rapid/linear moves dropped on both sides);
    otherwise a readable report of the first difference with rs274's call and nctrans's file:line."""
    ref = [m for m in ref_moves if not is_zero_move(m)]
    mine = [m for m in got if not is_zero_move(m)]
    for i, (r, g) in enumerate(zip(ref, mine)):
        probs = differences(r, g)
        if probs:
            prev = (f"\n  last agreeing: {ref[i - 1].where()}  <->  {mine[i - 1].where}" if i else
                    "\n  (first motion of the program)")
            return (f"{name}: motion #{i} differs: " + "; ".join(probs) +
                    f"\n  rs274:   {r.where()}\n           {describe(r)}"
                    f"\n  nctrans: {g.where}\n           {describe(g)}" + prev)
    if len(ref) != len(mine):
        n = min(len(ref), len(mine))
        extra = (f"first extra rs274 motion: {ref[n].where()}\n           {describe(ref[n])}" if len(ref) > n
                 else f"first extra nctrans motion: {mine[n].where}\n           {describe(mine[n])}")
        return (f"{name}: rs274 has {len(ref)} motions, nctrans {len(mine)} (all of the first {n} agree)"
                f"\n  {extra}")
    return None


_MARKED_CALL = re.compile(r"N\.+\s+([A-Z_]+)\((.*)\)\s*$")


def calls_between_markers(workdir: Path, program: str, tool_table: str) -> tuple[list[tuple[str, str]], str]:
    """Run rs274 on `program` (text) with `tool_table` (text); return the canonical calls printed
    between its `(BEGIN)` and `(END)` comments as (name, argument text), and rs274's own message —
    how the small cycle and cutter-compensation oracles read rs274."""
    prog, tbl, out = workdir / "p.ngc", workdir / "t.tbl", workdir / "out"
    prog.write_text(program)
    tbl.write_text(tool_table)
    proc = subprocess.run([RS274, "-t", str(tbl), "-g", str(prog), str(out)], stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=60, env=_private_home(out))
    calls, inside = [], False
    for line in out.read_text().splitlines() if out.exists() else []:
        m = _MARKED_CALL.search(line)
        if not m:
            continue
        name, args = m.groups()
        if name == "COMMENT":
            inside = {'"BEGIN"': True, '"END"': False}.get(args, inside)
        elif inside:
            calls.append((name, args))
    return calls, proc.stdout + proc.stderr
