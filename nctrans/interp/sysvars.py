"""Numbered system variables (Fanuc/Haas macro B #2001.., #4001.., #5201..) read from the machine
model and the running state, as the dialect's rules table maps them (`[[options.numbered_variables]]`
of rules/<dialect>.toml; sources documented there).

A number the table marks "unknown", or does not list, reads as UNKNOWN: the interpreter then says
NC107 where the value drives motion or a condition. Reads are evaluated when they happen, so a G10
write or a modal change before them is seen.
"""
from __future__ import annotations

from typing import Any, Callable

from nctrans.interp.evaluate import UNKNOWN

AXES = "XYZABC"


def entries(dialect: str) -> list[dict]:
    """The dialect's system-variable map (empty for a dialect without one)."""
    try:
        from nctrans.rules import load_table
        return list(load_table(dialect).options.get("numbered_variables", ()))
    except Exception:            # no table for this dialect
        return []


def register(interp, dialect: str) -> None:
    """Publish every mapped number in `interp.ev.system` (callables read at evaluation time)."""
    system = interp.ev.system
    for e in entries(dialect):
        if not isinstance(e, dict) or "first" not in e:
            continue
        first = int(e["first"])
        last = int(e.get("last", first))
        for k in range(first, last + 1):
            if k in system:
                continue                 # the interpreter's own (positions) win
            f = _reader(interp, e, k - first)
            if f is not None:
                system[k] = f


def _reader(interp, e: dict, offset: int) -> Callable[[], Any] | None:
    src = e["source"]
    st = interp.st
    if src == "modal":
        group, values = e["group"], e["values"]

        def modal():
            v = st.groups.get(group)
            got = values.get(v) if v is not None else None
            if got is None and group == "work_offset" and isinstance(v, str) and v.startswith("G54.1"):
                return 54.1
            return float(got) if got is not None else UNKNOWN
        return modal
    if src == "word":
        word = e["word"]
        attr = {"feed": "feed", "speed": "spindle_speed", "tool": "tool_selected",
                "radius_index": "radius_index", "length_index": "length_index"}[word]

        def modal_word():
            v = getattr(st, attr)
            if v is None:
                return None              # vacant: nothing programmed yet
            # the feed as programmed: in the feed unit (G70 keeps it mm, G700 inch), per minute
            # or per revolution alike; an inverse-time F has no unit
            return float(v) / (st.feed_scale if word == "feed" and st.feed_mode != "inverse_time" else 1.0)
        return modal_word
    if src == "work_offset":
        step = int(e.get("step", 20))
        index, axis = divmod(offset, step)
        offsets = e["offsets"]
        if index >= len(offsets) or axis >= len(AXES):
            return None
        name, a = offsets[index], AXES[axis]

        def work_offset():
            return interp.machine.work_offset(name).get(a, 0.0) / (st.scale if a in "XYZ" else 1.0)
        return work_offset
    if src in ("tool_length", "tool_radius"):
        number = offset + 1
        read = interp.machine.length_offset if src == "tool_length" else interp.machine.radius_offset

        def tool_offset():
            return read(number) / st.scale
        return tool_offset
    if src == "zero":
        return lambda: 0.0
    return None                          # "unknown": UNKNOWN by default
