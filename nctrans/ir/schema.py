"""The IR's JSON form and its schema.

The internal IR is slotted dataclasses (cheap per block); this module maps it to plain JSON data
with a `"node"` tag naming each node class, back again, and publishes the JSON Schema pydantic
derives from the same dataclasses (so the schema cannot drift from the code).
"""
from __future__ import annotations

import dataclasses
import json
from functools import lru_cache
from typing import Any

from nctrans.ir import nodes

_CLASSES: dict[str, type] = {
    name: obj for name, obj in vars(nodes).items()
    if isinstance(obj, type) and dataclasses.is_dataclass(obj) and obj.__module__ == nodes.__name__
}


def to_data(obj: Any) -> Any:
    """IR object -> JSON-ready data. Optional fields equal to None are left out to keep documents
    small; a required field that is None (Var.key of R[expr] / #[expr]) is written as null."""
    if dataclasses.is_dataclass(obj):
        out: dict[str, Any] = {"node": type(obj).__name__}
        for f in dataclasses.fields(obj):
            v = getattr(obj, f.name)
            if v is None and (f.default is not dataclasses.MISSING
                              or f.default_factory is not dataclasses.MISSING):
                continue
            out[f.name] = to_data(v)
        return out
    if isinstance(obj, dict):
        return {str(k): to_data(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_data(v) for v in obj]
    return obj


def from_data(data: Any) -> Any:
    """JSON data -> IR objects (inverse of to_data). Raises ValueError on an unknown node tag."""
    if isinstance(data, dict):
        tag = data.get("node")
        if tag is None:
            return {k: from_data(v) for k, v in data.items()}
        cls = _CLASSES.get(tag)
        if cls is None:
            raise ValueError(f"unknown IR node {tag!r}")
        kwargs = {k: from_data(v) for k, v in data.items() if k != "node"}
        if cls is nodes.Case and "branches" in kwargs:
            kwargs["branches"] = [tuple(b) for b in kwargs["branches"]]
        return cls(**kwargs)
    if isinstance(data, list):
        return [from_data(v) for v in data]
    return data


def dumps(program: nodes.Program, indent: int | None = None) -> str:
    return json.dumps(to_data(program), indent=indent, ensure_ascii=False)


def loads(text: str) -> nodes.Program:
    return from_data(json.loads(text))


@lru_cache(maxsize=1)
def json_schema() -> dict:
    """JSON Schema (draft 2020-12) of a Program document, derived by pydantic from the dataclasses,
    with the `node` tag added to every node definition."""
    from pydantic import TypeAdapter

    schema = TypeAdapter(nodes.Program).json_schema()
    defs = schema.setdefault("$defs", {})
    targets = [schema] + [d for name, d in defs.items() if name in _CLASSES]
    for d in targets:
        name = d.get("title")
        if name not in _CLASSES:
            continue
        d.setdefault("properties", {})["node"] = {"const": name}
        d.setdefault("required", [])
        if "node" not in d["required"]:
            d["required"].append("node")
    return schema
