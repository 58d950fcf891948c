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


@dataclass
class Spindle:
    __pydantic_config__ = _OPEN
    max_rpm: Optional[float] = None


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


@dataclass
class Mesh:
    __pydantic_config__ = _OPEN
    mesh: Optional[str] = None
    box: Optional[dict[str, list[float]]] = None


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
    # controller and machine-builder system variables the program may read, by the dialect's own
    # name (Fagor "V.MPA.MAXFEED.X", "V.MTB.P1"): what the machine model knows of them
    variables: dict[str, float] = field(default_factory=dict)
    source_dir: Optional[str] = None

    def __post_init__(self) -> None:
        self.axes = {k.upper(): v for k, v in self.axes.items()}
        self.offsets = {k.upper(): {a.upper(): v for a, v in o.items()} for k, o in self.offsets.items()}

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


class MachineError(Exception):
    """A machine file that cannot be read or validated; carries a user-facing message."""


def load(path: str | Path) -> Machine:
    import tomllib

    from pydantic import TypeAdapter, ValidationError
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as e:
        raise MachineError(f"{path}: cannot read machine file: {e.strerror}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise MachineError(f"{path}: invalid TOML: {e}") from None
    try:
        m = TypeAdapter(Machine).validate_python(data)
    except ValidationError as e:   # keep pydantic's readable text
        raise MachineError(f"{path}: invalid machine description:\n{e}") from None
    m.source_dir = str(path.parent)
    return m
