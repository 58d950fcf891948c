"""Canned cycles between the modal shape (a cycle mode + positioning blocks) and the named shape
(a standard cycle called once or modally), as data: rules/cycle-mapping.toml.

Emitters use it to convert a cycle without expanding it into motion: which named cycle a modal kind
becomes, which further parameters it takes and from what, and whether the interpreter's two models
of the pair give the same toolpath (`exact`) or what differs (`differs`, reported as NC410).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Optional, Union

from nctrans import tables
from nctrans.rules import RULES_DIR

# Derived values an `args` entry may name besides the neutral cycle parameters.
DERIVED = ("peck_clearance", "pitch", "feed")


@dataclass
class CycleMapping:
    """One modal cycle kind and the named cycle it maps to (or `none`: why there is none)."""
    __pydantic_config__ = {"extra": "forbid"}
    modal: str
    named: str = ""
    args: dict[str, Union[float, str]] = field(default_factory=dict)
    absent: list[str] = field(default_factory=list)
    exact: bool = False
    differs: str = ""
    none: str = ""


@dataclass
class CycleMappingTable:
    """rules/cycle-mapping.toml (schema for pydantic)."""
    __pydantic_config__ = {"extra": "forbid"}
    cycle: list[CycleMapping] = field(default_factory=list)

    @classmethod
    def from_data(cls, d: dict) -> "CycleMappingTable":
        return cls(cycle=[CycleMapping(**c) for c in d["cycle"]])

    def for_modal(self, kind: str) -> Optional[CycleMapping]:
        """The mapping of a modal cycle kind (None: the table does not list it)."""
        return next((c for c in self.cycle if c.modal == kind), None)

    def for_named(self, name: str, kind: str) -> Optional[CycleMapping]:
        """The mapping that writes a named cycle call of neutral `kind` (CYCLE83's kind follows
        its VARI) in the modal shape."""
        return next((c for c in self.cycle if c.named == name.upper() and c.modal == kind), None)


@lru_cache(maxsize=1)
def mapping_table() -> CycleMappingTable:
    """rules/cycle-mapping.toml, validated by pydantic (once per content: see nctrans.tables)."""
    return tables.load(RULES_DIR / "cycle-mapping.toml", CycleMappingTable,
                       CycleMappingTable.from_data)


def peck_clearance(units_mm: bool) -> float:
    """The interpreter's G73/G83 back-off / re-approach distance in program units."""
    from nctrans.interp.cycles import PECK_CLEARANCE_INCH
    return PECK_CLEARANCE_INCH * 25.4 if units_mm else PECK_CLEARANCE_INCH
