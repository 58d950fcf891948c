"""What a dialect is, and the registry of dialects.

A dialect is a front end (text -> IR) and an emitter (IR -> text) plus its rules table
(`rules/<name>.toml`). Everything dialect-specific lives in `nctrans/dialects/<name>/` and its table;
nothing outside knows a dialect's spelling. Modelled on sqlglot's Dialect: one tree, per-dialect
parser and generator, differences as data.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from typing import Callable, Optional

from nctrans.diagnostics import Diagnostic
from nctrans.ir.nodes import Program


@dataclass
class ParseResult:
    program: Program
    diagnostics: list[Diagnostic] = field(default_factory=list)


@dataclass
class EmitResult:
    text: str
    diagnostics: list[Diagnostic] = field(default_factory=list)


@dataclass
class Dialect:
    """name: contract name (`iso-m`, `sinumerik`, ...). parse(text, file) never raises on bad input:
    it returns the best Program it can with NC0xx diagnostics. emit(program) returns text and NC4xx
    diagnostics for anything the dialect cannot express (lowered or refused)."""
    name: str
    extensions: tuple[str, ...]
    parse: Callable[[str, str], ParseResult]
    emit: Callable[[Program], EmitResult]
    sniff: Callable[[str], float]          # 0..1: how much `text` looks like this dialect
    description: str = ""


# dialect name -> module that defines `DIALECT`
_MODULES = {
    "iso-m": "nctrans.dialects.iso_m",
    "sinumerik": "nctrans.dialects.sinumerik",
}
_loaded: dict[str, Dialect] = {}


def names() -> list[str]:
    return list(_MODULES)


def get(name: str) -> Optional[Dialect]:
    """The dialect called `name`, or None when there is no such dialect."""
    if name not in _MODULES:
        return None
    if name not in _loaded:
        _loaded[name] = importlib.import_module(_MODULES[name]).DIALECT
    return _loaded[name]
