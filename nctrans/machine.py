"""The machine model (MACHINE.toml), validated by pydantic, and the built-in default machines.

The interpreter reads work offsets and the tool table from here; `check` reads axis limits,
feeds and geometry. Dialects map their own offset names onto the ISO names used as keys here.
"""
from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Literal, Optional

from pydantic import BaseModel, ConfigDict, Field, model_validator


class Axis(BaseModel):
    model_config = ConfigDict(extra="allow")
    kind: Literal["linear", "rotary"] = "linear"
    min: Optional[float] = None
    max: Optional[float] = None
    max_feed: Optional[float] = None
    rapid: Optional[float] = None


class Spindle(BaseModel):
    model_config = ConfigDict(extra="allow")
    max_rpm: Optional[float] = None


class Tool(BaseModel):
    model_config = ConfigDict(extra="allow")
    number: int
    length: float = 0.0
    radius: float = 0.0
    holder_radius: Optional[float] = None
    holder_length: Optional[float] = None
    cutting_length: Optional[float] = None


class Mesh(BaseModel):
    model_config = ConfigDict(extra="allow")
    mesh: Optional[str] = None
    box: Optional[dict[str, list[float]]] = None


class Machine(BaseModel):
    model_config = ConfigDict(extra="allow")
    name: str = "default"
    kind: Literal["mill", "lathe"] = "mill"
    axes: dict[str, Axis] = Field(default_factory=dict)
    spindle: Spindle = Field(default_factory=Spindle)
    offsets: dict[str, dict[str, float]] = Field(default_factory=dict)
    tools: list[Tool] = Field(default_factory=list)
    fixtures: list[Mesh] = Field(default_factory=list)
    stock: Optional[Mesh] = None
    # tool-offset registers addressed by number (ISO H/D words): index -> value in mm.
    # When empty, H n / D n read tool n's length / radius from the tool table.
    length_offsets: dict[int, float] = Field(default_factory=dict)
    radius_offsets: dict[int, float] = Field(default_factory=dict)
    source_dir: Optional[str] = None

    @model_validator(mode="after")
    def _upper_axes(self):
        self.axes = {k.upper(): v for k, v in self.axes.items()}
        self.offsets = {k.upper(): {a.upper(): v for a, v in o.items()} for k, o in self.offsets.items()}
        return self

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

    def work_offset(self, name: str) -> dict[str, float]:
        """Offset of work coordinate system `name` (ISO name, e.g. "G54", "G54.1P3"); zeros if unset."""
        return self.offsets.get(name.upper(), {})


def default_mill() -> Machine:
    """The built-in 3-axis mill: generous travel, zero offsets, no tool geometry (zero-size tools)."""
    return Machine(
        name="default-mill", kind="mill",
        axes={"X": Axis(min=-1000, max=1000, max_feed=10000, rapid=30000),
              "Y": Axis(min=-1000, max=1000, max_feed=10000, rapid=30000),
              "Z": Axis(min=-1000, max=1000, max_feed=10000, rapid=30000)},
        spindle=Spindle(max_rpm=24000),
    )


def default_lathe() -> Machine:
    return Machine(
        name="default-lathe", kind="lathe",
        axes={"X": Axis(min=-500, max=500, max_feed=5000, rapid=15000),
              "Z": Axis(min=-1000, max=1000, max_feed=5000, rapid=15000)},
        spindle=Spindle(max_rpm=4000),
    )


class MachineError(Exception):
    """A machine file that cannot be read or validated; carries a user-facing message."""


def load(path: str | Path) -> Machine:
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as e:
        raise MachineError(f"{path}: cannot read machine file: {e.strerror}") from None
    except tomllib.TOMLDecodeError as e:
        raise MachineError(f"{path}: invalid TOML: {e}") from None
    try:
        m = Machine.model_validate(data)
    except Exception as e:  # pydantic.ValidationError: keep its readable text
        raise MachineError(f"{path}: invalid machine description:\n{e}") from None
    m.source_dir = str(path.parent)
    return m
