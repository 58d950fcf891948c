"""Dialect code tables (`rules/<dialect>.toml`) loaded and validated with pydantic (nctrans.tables).

A table lists every G/M (or keyword) code a dialect knows: its neutral (group, value) meaning from
`nctrans.ir.vocabulary`, its own modal-group number, whether it is modal, whether it is the power-on
default, a one-line meaning and the seed reference. Front ends look codes up here; emitters look the
reverse way; the lint catalogue documents from here. No G-code tables in if-chains.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any, Optional

from nctrans import resources, tables

RULES_DIR = resources.root("rules")


def normalise_code(letter: str, number: str | float | int) -> str:
    """Canonical spelling of a numbered code: G00 -> G0, G01.0 -> G1, g54.1 -> G54.1."""
    text = str(number).strip()
    if "." in text:
        whole, frac = text.split(".", 1)
        frac = frac.rstrip("0")
        whole = str(int(whole or "0"))
        return f"{letter.upper()}{whole}.{frac}" if frac else f"{letter.upper()}{whole}"
    return f"{letter.upper()}{int(text)}"


@dataclass
class CodeRule:
    __pydantic_config__ = {"extra": "forbid"}
    code: str                       # canonical spelling, e.g. "G0", "G54.1", "M3", "TRANS"
    group: str                      # neutral group ("motion", "plane", ...) or a statement kind
    value: str = ""                 # neutral value within the group
    modal: bool = True
    default: bool = False           # power-on/reset default of its group
    dialect_group: Optional[int | str] = None   # the manual's own group number/name
    meaning: str = ""
    ref: str = ""                   # seed line reference
    args: dict[str, str] = field(default_factory=dict)   # address letter -> neutral parameter
    spelling: str = ""              # how emitters write it when not as `code` (Fagor G00, M02)


@dataclass
class RulesTable:
    __pydantic_config__ = {"extra": "forbid"}
    dialect: str
    description: str = ""
    options: dict[str, Any] = field(default_factory=dict)
    addresses: dict[str, str] = field(default_factory=dict)   # letter -> what it is
    codes: list[CodeRule] = field(default_factory=list)
    # system variable as spelled ("#5001", "$AA_IW") -> neutral meaning (vocabulary.SYSTEM_VARIABLES)
    system_variables: dict[str, str] = field(default_factory=dict)
    # how the dialect spells expressions: operators, precedence, brackets, function names
    # (nctrans.dialects.emit.ExpressionSyntax reads it)
    expressions: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self._by_code = {c.code.upper(): c for c in self.codes}
        self._by_meaning: dict[tuple[str, str], CodeRule] = {}
        for c in self.codes:
            self._by_meaning.setdefault((c.group, c.value), c)

    @classmethod
    def from_data(cls, data: dict) -> "RulesTable":
        """The table from validated data (tables.load): the rules become CodeRule objects."""
        return cls(**{**data, "codes": [CodeRule(**c) for c in data.get("codes", ())]})

    def lookup(self, code: str) -> Optional[CodeRule]:
        """The rule for a canonical code spelling (see normalise_code), or None if unknown."""
        return self._by_code.get(code.upper())

    def code_for(self, group: str, value: str) -> Optional[CodeRule]:
        """The first code (table order = preferred spelling) that selects (group, value)."""
        return self._by_meaning.get((group, value))

    def defaults(self) -> dict[str, str]:
        """Power-on modal state {group: value}, handed to the interpreter via Program.meta."""
        return {c.group: c.value for c in self.codes if c.default}


@lru_cache(maxsize=1)
def _system_spellings() -> dict[str, str]:
    """Every registered dialect's system-variable spellings (upper case) -> neutral meaning. All
    dialects at once: a program may hold a section of another dialect (Sinumerik ISO mode)."""
    from nctrans.dialects import base
    out: dict[str, str] = {}
    for d in base.dialects():
        if resources.path("rules", f"{d.table_name}.toml").is_file():
            for spelling, meaning in load_table(d.table_name).system_variables.items():
                out.setdefault(spelling.upper(), meaning)
    return out


def system_meaning(key: str | int) -> Optional[str]:
    """The neutral meaning of a system variable as the IR holds it: a name ("$P_EP") or a number
    (ISO #5001 is the int 5001); None when no table knows it."""
    return _system_spellings().get(f"#{key}" if isinstance(key, int) else str(key).upper())


def system_spelling(table_name: str, key: str | int, axis: Optional[str] = None
                    ) -> Optional[tuple[str, Optional[str]]]:
    """How the table `table_name` spells the system variable another dialect spells `key` (with an
    axis index `axis`, as Sinumerik $AA_IM[X]): (spelling, axis index or None), through their
    neutral meaning; None when the table has no spelling of that meaning. A per-axis meaning
    ("axis_position_machine.X") finds either its own number (ISO #5021) or the axis-indexed
    spelling ($AA_IM with index X)."""
    meaning = system_meaning(key)
    if meaning is None:
        return None
    if axis is not None:
        meaning = f"{meaning}.{axis}"
    own = load_table(table_name).system_variables
    found = next((sp for sp, m in own.items() if m == meaning), None)
    if found is not None:
        return found, None
    base, _, per_axis = meaning.partition(".")
    if per_axis:
        found = next((sp for sp, m in own.items() if m == base), None)
        if found is not None:
            return found, per_axis
    return None


@lru_cache(maxsize=None)
def load_table(dialect: str) -> RulesTable:
    """rules/<dialect>.toml, validated by pydantic (once per content: see nctrans.tables)."""
    return tables.load(RULES_DIR / f"{dialect}.toml", RulesTable, RulesTable.from_data)


def option(dialect: Optional[str], key: str, default: Any = None) -> Any:
    """`[options] key` of rules/<dialect>.toml, or `default` when the table does not set it or the
    dialect has no table of its own (a dialect a test registers). A shipped table that does not
    load still fails loudly: a broken rules file must not read as "option unset"."""
    if not dialect or not (RULES_DIR / f"{dialect}.toml").is_file():
        return default
    return load_table(dialect).options.get(key, default)
