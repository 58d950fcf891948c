"""The machine model (MACHINE.toml), validated by pydantic, and the built-in default machines.

The interpreter reads work offsets and the tool table from here; `check` reads axis limits,
feeds and geometry. Dialects map their own offset names onto the ISO names used as keys here.
The model is plain dataclasses, which pydantic validates a MACHINE.toml against (`load`); the
built-in machines need no validation, so a run without --machine never imports pydantic (~60 ms).
Keys the model does not know are kept as attributes (the contract lets machines grow keys).
"""
from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal, Optional

_OPEN = {"extra": "allow"}


@dataclass
class Axis:
    __pydantic_config__ = _OPEN
    kind: Literal["linear", "rotary"] = "linear"
    min: Optional[float] = None
    max: Optional[float] = None
    max_feed: Optional[float] = None
    rapid: Optional[float] = None
    accel: Optional[float] = None           # mm/s² (deg/s² rotary): cycle time only

    def __post_init__(self) -> None:
        _check_range(self.min, self.max, "min", "max")
        for name in ("max_feed", "rapid", "accel"):
            _check_positive(getattr(self, name), name)


def _check_range(lo: Optional[float], hi: Optional[float], lo_name: str, hi_name: str) -> None:
    if lo is not None and hi is not None and lo > hi:
        raise ValueError(f"{lo_name} ({lo:g}) is above {hi_name} ({hi:g})")


def _check_positive(v: Optional[float], name: str) -> None:
    if v is not None and not v > 0:
        raise ValueError(f"{name} must be a positive number, not {v:g}")


@dataclass
class Spindle:
    __pydantic_config__ = _OPEN
    max_rpm: Optional[float] = None

    def __post_init__(self) -> None:
        _check_positive(self.max_rpm, "max_rpm")


@dataclass
class Cylinder:
    """One cylinder of a tool holder, coaxial with the tool."""
    __pydantic_config__ = {"extra": "forbid"}
    radius: float
    length: float

    def __post_init__(self) -> None:
        _check_positive(self.radius, "radius")
        _check_positive(self.length, "length")


@dataclass
class Tool:
    __pydantic_config__ = _OPEN
    number: int
    length: float = 0.0
    radius: float = 0.0
    holder_radius: Optional[float] = None
    holder_length: Optional[float] = None
    cutting_length: Optional[float] = None
    name: Optional[str] = None              # Sinumerik tools are selected by name (T="DRILL")
    # More holder geometry than holder_radius/holder_length: cylinders stacked upward from where
    # the holder starts (see holder_cylinders), or a mesh with its origin at the tool tip and +Z
    # pointing up the tool axis towards the spindle.
    holder: list[Cylinder] = field(default_factory=list)
    holder_mesh: Optional[str] = None
    # turning tool: tip direction 0-9 of the nose radius (Fanuc/Haas imaginary tool tip, Sinumerik
    # cutting edge position); `radius` is then the nose radius (nctrans.interp.nose)
    tip: Optional[int] = None
    # grooving tool: its cutting width, the distance between its two cutting edges (the Siemens
    # grooving cycle CYCLE93 cuts with both; nctrans.interp.grooving)
    width: Optional[float] = None

    def __post_init__(self) -> None:
        for name in ("length", "radius", "cutting_length", "holder_radius", "holder_length", "width"):
            v = getattr(self, name)
            if v is not None and v < 0:
                raise ValueError(f"{name} must not be negative, not {v:g}")
        if (self.holder_radius is None) != (self.holder_length is None):
            raise ValueError("holder_radius and holder_length go together")
        if self.tip is not None and not 0 <= self.tip <= 9:
            raise ValueError(f"tip (tool-nose tip direction) must be 0..9, not {self.tip}")

    def holder_cylinders(self) -> list[tuple[float, float, float]]:
        """(radius, bottom, top) of each holder cylinder, heights above the tool tip. The holder
        starts above the cutting length; without a cutting length, where the stack's top meets
        the gauge line (tool length above the tip)."""
        stack = ([Cylinder(self.holder_radius, self.holder_length)]
                 if self.holder_radius is not None else []) + list(self.holder)
        if not stack:
            return []
        total = sum(c.length for c in stack)
        z = self.cutting_length if self.cutting_length is not None else max(self.length - total, 0.0)
        out = []
        for c in stack:
            out.append((c.radius, z, z + c.length))
            z += c.length
        return out

    def cutter_height(self) -> float:
        """Height above the tip of the part that may touch material: the cutting length, else the
        whole tool up to its holder (or its length)."""
        if self.cutting_length is not None:
            return self.cutting_length
        cyl = self.holder_cylinders()
        return cyl[0][1] if cyl else self.length


@dataclass
class Mesh:
    """A fixture or the stock: a mesh file (STL/OBJ/PLY, path relative to the machine file), a
    box, or a cylinder about the Z axis (`cylinder = { radius, z_min, z_max }`: on a lathe a
    solid of revolution about the spindle, a chuck, its jaws or a tailstock quill), in machine
    coordinates, or relative to work offset `frame` (e.g. "G54") when given; `position` moves it
    further."""
    __pydantic_config__ = _OPEN
    mesh: Optional[str] = None
    box: Optional[dict[str, list[float]]] = None
    cylinder: Optional[dict[str, float]] = None
    name: Optional[str] = None
    position: Optional[list[float]] = None
    frame: Optional[str] = None
    cell: Optional[float] = None            # stock: Z-map cell size in mm (default from its size)

    def __post_init__(self) -> None:
        if [self.mesh, self.box, self.cylinder].count(None) != 2:
            raise ValueError("give one of mesh = \"file\", box = { min = [x, y, z], max = [x, y, z] } or "
                             "cylinder = { radius = R, z_min = Z0, z_max = Z1 }")
        if self.cylinder is not None:
            if set(self.cylinder) != {"radius", "z_min", "z_max"}:
                raise ValueError("cylinder needs exactly the keys radius, z_min and z_max")
            _check_positive(self.cylinder["radius"], "cylinder radius")
            if not self.cylinder["z_min"] < self.cylinder["z_max"]:
                raise ValueError(f"cylinder z_min ({self.cylinder['z_min']:g}) must be below z_max "
                                 f"({self.cylinder['z_max']:g})")
        if self.box is not None:
            if set(self.box) != {"min", "max"}:
                raise ValueError("box needs exactly the keys min and max")
            lo, hi = self.box["min"], self.box["max"]
            if len(lo) != 3 or len(hi) != 3:
                raise ValueError("box min and max are [x, y, z]")
            for a, l, h in zip("xyz", lo, hi):
                if not l < h:
                    raise ValueError(f"box min {a} ({l:g}) must be below max {a} ({h:g})")
        if self.position is not None and len(self.position) != 3:
            raise ValueError("position is [x, y, z]")
        _check_positive(self.cell, "cell")


@dataclass
class ToolChange:
    """What the machine's tool change (its M6 macro) expects and does: lint NC213 reports a change
    while something in `requires_stopped` runs; `stops_spindle` (None: the dialect's default) makes
    a feed move before the spindle is started again NC209; `by_t_word`: whether T changes the tool
    without M6."""
    __pydantic_config__ = {"extra": "forbid"}
    requires_stopped: list[Literal["spindle", "coolant"]] = field(default_factory=list)
    stops_spindle: Optional[bool] = None
    # a T word changes the tool at once (True) or only M6 does (False); None: the dialect's
    # default for the machine's kind (nctrans.interp.tool_change)
    by_t_word: Optional[bool] = None


@dataclass
class Machine:
    __pydantic_config__ = _OPEN
    name: str = "default"
    kind: Literal["mill", "lathe"] = "mill"
    axes: dict[str, Axis] = field(default_factory=dict)
    spindle: Spindle = field(default_factory=Spindle)
    offsets: dict[str, dict[str, float]] = field(default_factory=dict)
    tools: list[Tool] = field(default_factory=list)
    fixtures: list[Mesh] = field(default_factory=list)
    stock: Optional[Mesh] = None
    # tool-offset registers addressed by number (ISO H/D words): index -> value in mm.
    # When empty, H n / D n read tool n's length / radius from the tool table.
    length_offsets: dict[int, float] = field(default_factory=dict)
    radius_offsets: dict[int, float] = field(default_factory=dict)
    # tool-nose tip directions (0-9) by offset register, stored with the radius on a lathe;
    # when empty, offset n reads tool n's `tip`
    tip_directions: dict[int, int] = field(default_factory=dict)
    # controller and machine-builder system variables the program may read, by the dialect's own
    # name (Fagor "V.MPA.MAXFEED.X", "V.MTB.P1"): what the machine model knows of them
    variables: dict[str, float] = field(default_factory=dict)
    source_dir: Optional[str] = None
    tool_change_s: Optional[float] = None   # seconds per tool change (cycle time)
    tool_change: Optional[ToolChange] = None

    def __post_init__(self) -> None:
        self.axes = {k.upper(): v for k, v in self.axes.items()}
        self.offsets = {k.upper(): {a.upper(): v for a, v in o.items()} for k, o in self.offsets.items()}
        for i, tip in self.tip_directions.items():
            if not 0 <= tip <= 9:
                raise ValueError(f"tip_directions[{i}] must be 0..9, not {tip}")

    def copy(self) -> "Machine":
        """A deep copy (the interpreter's G10 writes offsets into its own copy)."""
        return copy.deepcopy(self)

    def tool(self, number: int) -> Optional[Tool]:
        for t in self.tools:
            if t.number == number:
                return t
        return None

    def length_offset(self, index: int) -> float:
        """Value of length-offset register `index` (ISO H); 0 when nothing is known."""
        if index in self.length_offsets:
            return self.length_offsets[index]
        t = self.tool(index)
        return t.length if t else 0.0

    def radius_offset(self, index: int) -> float:
        """Value of radius-offset register `index` (ISO D); 0 when nothing is known."""
        if index in self.radius_offsets:
            return self.radius_offsets[index]
        t = self.tool(index)
        return t.radius if t else 0.0

    def tip_direction(self, index: int) -> Optional[int]:
        """Tool-nose tip direction of offset register `index` (0-9); None when nothing is known."""
        if index in self.tip_directions:
            return self.tip_directions[index]
        t = self.tool(index)
        return t.tip if t else None

    @classmethod
    def from_toml(cls, path: "str | Path") -> "Machine":
        """The machine described by a MACHINE.toml (CONTRACT.md); MachineError names what is wrong."""
        return load(path)

    def work_offset(self, name: str) -> dict[str, float]:
        """Offset of work coordinate system `name` (ISO name, e.g. "G54", "G54.1P3"); zeros if unset."""
        return self.offsets.get(name.upper(), {})


def default_mill() -> Machine:
    """The built-in 3-axis mill: generous travel, zero offsets, no tool geometry (zero-size tools)."""
    return Machine(
        name="default-mill", kind="mill",
        axes={"X": Axis(min=-1000.0, max=1000.0, max_feed=10000.0, rapid=30000.0),
              "Y": Axis(min=-1000.0, max=1000.0, max_feed=10000.0, rapid=30000.0),
              "Z": Axis(min=-1000.0, max=1000.0, max_feed=10000.0, rapid=30000.0)},
        spindle=Spindle(max_rpm=24000.0),
    )


def default_lathe() -> Machine:
    return Machine(
        name="default-lathe", kind="lathe",
        axes={"X": Axis(min=-500.0, max=500.0, max_feed=5000.0, rapid=15000.0),
              "Z": Axis(min=-1000.0, max=1000.0, max_feed=5000.0, rapid=15000.0)},
        spindle=Spindle(max_rpm=4000.0),
    )


def _explain(e) -> str:
    """One line per problem: the key path as it is written in the TOML file, then what is wrong."""
    lines = []
    for err in e.errors():
        loc = ""
        for part in err["loc"]:
            loc += f"[{part}]" if isinstance(part, int) else (f".{part}" if loc else str(part))
        msg = err["msg"].removeprefix("Value error, ")
        lines.append(f"  {loc or '(top level)'}: {msg}")
    return "\n".join(lines)


class MachineError(Exception):
    """A machine file that cannot be read or validated; carries a user-facing message."""


def load(path: str | Path) -> Machine:
    """The validated machine of a MACHINE.toml. Validation (tomllib and pydantic: ~0.1 s of CPU,
    most of a short lint's start-up) runs once per content: the validated machine is remembered
    in the table cache (nctrans.tables) and rebuilt from it while the file and this module are
    unchanged."""
    from nctrans import tables
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as e:
        raise MachineError(f"{path}: cannot read machine file: {e.strerror}") from None
    m = tables.remembered("machine", raw, Machine, lambda: _validate(path, raw), _dump, _build_machine)
    m.source_dir = str(path.parent)
    return m


def _validate(path: Path, raw: bytes) -> Machine:
    import tomllib

    from pydantic import TypeAdapter, ValidationError
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise MachineError(f"{path}: invalid TOML: {e}") from None
    try:
        return TypeAdapter(Machine).validate_python(data)
    except ValidationError as e:
        raise MachineError(f"{path}: invalid machine description:\n{_explain(e)}") from None


# A validated machine as marshal data: each dataclass instance becomes (_DC, class name, its
# attributes), keys the model does not know included (pydantic keeps them as attributes).
_DC = "\x00dataclass"


def _dump(obj):
    if type(obj) in _CLASSES.values():
        return (_DC, type(obj).__name__, {k: _dump(v) for k, v in vars(obj).items()})
    if isinstance(obj, dict):
        return {k: _dump(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_dump(v) for v in obj]
    if obj is None or isinstance(obj, (str, int, float, bool)):
        return obj
    raise TypeError(f"not remembered: {type(obj).__name__}")


def _build_machine(data) -> Machine:
    m = _build(data)
    if not isinstance(m, Machine):
        raise ValueError("not a remembered machine")
    return m


def _build(data):
    if isinstance(data, tuple):
        if len(data) != 3 or data[0] != _DC:
            raise ValueError("not a remembered machine")
        obj = object.__new__(_CLASSES[data[1]])       # validated already: no __post_init__
        vars(obj).update({k: _build(v) for k, v in data[2].items()})
        return obj
    if isinstance(data, dict):
        return {k: _build(v) for k, v in data.items()}
    if isinstance(data, list):
        return [_build(v) for v in data]
    return data


_CLASSES = {c.__name__: c for c in (Machine, Axis, Spindle, Cylinder, Tool, Mesh, ToolChange)}
