"""Numbered system variables (Fanuc/Haas macro B #2001.., #4001.., #5201..) read from the machine
model and the running state, as the dialect's rules table maps them (`[[options.numbered_variables]]`
of rules/<dialect>.toml; sources documented there).

A number the table marks "unknown", or does not list, reads as UNKNOWN: the interpreter then says
NC107 where the value drives motion or a condition. Reads are evaluated when they happen, so a G10
write or a modal change before them is seen.

Writes to offset numbers (sources "work_offset", "tool_length", "tool_radius" and the wear ranges,
"zero" with `wear_of`) change the machine data as G10 does, so the moves after them use the new
offset: `#2001=.004` then `G41 D1` compensates by .004. (Before, such a write was kept as a plain
variable and the moves silently ran with the old offset.) The wear of an offset adds to its
geometry, as on the control: the register the interpreter applies holds geometry + wear.
"""
from __future__ import annotations

from typing import Any, Callable

from nctrans.interp.evaluate import UNKNOWN

AXES = "XYZABC"


def entries(dialect: str) -> list[dict]:
    """The dialect's system-variable map (empty for a dialect without one)."""
    from nctrans.rules import option
    return list(option(dialect, "numbered_variables", ()))


def _ranges(dialect: str, key: str) -> tuple[tuple[int, int], ...]:
    from nctrans.rules import option
    spans = option(dialect, key, ())
    return tuple((int(a), int(b)) for a, b in spans)


def register(interp, dialect: str) -> None:
    """Publish every mapped number in `interp.ev.system` (callables read at evaluation time), and
    the read-only and running (timer) numbers the evaluator's writes check."""
    system = interp.ev.system
    interp.ev.write_policy = write_policy(dialect)
    interp.ev.read_only_numbers = _ranges(dialect, "read_only_numbers")
    interp.ev.running_numbers = _ranges(dialect, "running_numbers")
    from nctrans.rules import option
    first = option(dialect, "system_numbers_from", None)
    interp.ev.system_numbers_from = int(first) if first is not None else None
    meta = getattr(getattr(interp, "program", None), "meta", None) or {}
    chosen = (option(dialect, "profiles", {}) or {}).get(meta.get("profile") or "", {})
    # a profile's common variables, and the numbers the table maps (a parts counter #3901 is the
    # program's to set): a write to them is no unmodelled system write
    listed = [(int(e["first"]), int(e.get("last", e["first"]))) for e in entries(dialect)
              if isinstance(e, dict) and "first" in e]
    interp.ev.common_numbers = tuple((int(a), int(b)) for a, b in chosen.get("common_variables", ())) \
        + tuple(listed)
    _register_indexed(interp, dialect)
    setters = interp.ev.system_setters
    # (kind, offset number) -> wear written; shared with G10 L11/L13 (offsets._h_data)
    wear: dict[tuple[str, int], float] = interp.__dict__.setdefault("offset_wear", {})
    for e in entries(dialect):
        if not isinstance(e, dict) or "first" not in e:
            continue
        first = int(e["first"])
        last = int(e.get("last", first))
        for k in range(first, last + 1):
            if k in system:
                continue                 # the interpreter's own (positions) win
            f = _reader(interp, e, k - first, wear)
            if f is not None:
                system[k] = f
            w = _writer(interp, e, k - first, wear)
            if w is not None:
                setters.setdefault(k, w)


# meanings whose spellings a program may only read (the control's alarm on a write: NC228)
READ_ONLY_MEANINGS = frozenset((
    "axis_position_work", "axis_position_machine", "active_tool", "active_tool_edge", "feed",
    "spindle_speed", "spindle_direction", "active_tool_radius", "plane_axis_1", "plane_axis_2",
    "plane_axis_3", "programmed_tool",
    "argument_programmed", "settable_frame_number"))


def write_policy(dialect: str) -> Callable[[str], str]:
    """What writing a named system variable nothing models is (`[options.system_variable_writes]`
    of the rules table): "read_only" (the control refuses it, NC228), "no_effect" (stored, quiet)
    or "unmodelled" (stored, NC237)."""
    from nctrans.rules import option, system_meaning
    spec = option(dialect, "system_variable_writes") or {}

    def match(names) -> Callable[[str], bool]:
        exact = {str(x).upper() for x in names if not str(x).endswith("*")}
        prefixes = tuple(str(x).upper()[:-1] for x in names if str(x).endswith("*"))
        return lambda name: name in exact or (bool(prefixes) and name.startswith(prefixes))
    read_only, quiet = match(spec.get("read_only", ())), match(spec.get("no_motion_effect", ()))

    def policy(name: str) -> str:
        up = name.upper()
        if read_only(up) or system_meaning(up) in READ_ONLY_MEANINGS:
            return "read_only"
        return "no_effect" if quiet(up) else "unmodelled"
    return policy


def _register_indexed(interp, dialect: str) -> None:
    """Indexed system variables read by neutral meaning: "argument_programmed" (Sinumerik
    $P_SUBPAR[i]) from the running call level's programmed parameter positions."""
    try:
        from nctrans.rules import load_table
        spellings = load_table(dialect).system_variables
    except Exception:            # no table for this dialect
        return
    for spelling, meaning in spellings.items():
        if meaning == "argument_programmed":
            def programmed(idx, ev=interp.ev):
                done = ev.scope.programmed
                if done is None or not idx or len(idx) != 1:
                    return UNKNOWN
                return 1.0 if int(idx[0]) in done else 0.0
            interp.ev.indexed_system[spelling.upper()] = programmed


def _machine(interp):
    """The interpreter's own copy of the machine, made before its first write (as G10 does)."""
    if not getattr(interp, "_machine_copied", False):
        interp.machine = interp.machine.copy()
        interp._machine_copied = True
    return interp.machine


def _value(k: str, v: Any) -> float:
    from nctrans.interp.evaluate import EvalError
    if v is UNKNOWN:
        raise EvalError("NC107", f"{k} is written with a value the analysis cannot know: the "
                        "offset keeps its old value in the analysed toolpath", "warning")
    return 0.0 if v is None else float(v)


def _work_offset_slot(e: dict, offset: int) -> tuple[str, str] | None:
    """The work offset and axis a number of a work-offset range names (`step` numbers per
    offset, one per axis), or None past the offsets or axes the table lists."""
    index, axis = divmod(offset, int(e.get("step", 20)))
    offsets = e["offsets"]
    if index >= len(offsets) or axis >= len(AXES):
        return None
    return offsets[index], AXES[axis]


def _writer(interp, e: dict, offset: int, wear: dict) -> Callable[[Any], None] | None:
    """How writing the number changes the machine data; None for a number without machine data."""
    src = e["source"]
    st = interp.st
    name = f"#{int(e['first']) + offset}"
    if src == "work_offset":
        slot = _work_offset_slot(e, offset)
        if slot is None:
            return None
        which, a = slot

        def work_offset(v):
            value = _value(name, v) * (st.scale if a in "XYZ" else 1.0)
            m = _machine(interp)
            m.offsets[which] = {**m.offsets.get(which, {}), a: value}
            interp._work_offset_changed(which)
        return work_offset
    kind = {"tool_length": "length", "tool_radius": "radius"}.get(src) or e.get("wear_of")
    if kind not in ("length", "radius"):
        return None
    number = offset + 1
    is_wear = src == "zero"

    def tool_offset(v):
        value = _value(name, v) * st.scale
        m = _machine(interp)
        store = m.length_offsets if kind == "length" else m.radius_offsets
        read = m.length_offset if kind == "length" else m.radius_offset
        old_wear = wear.get((kind, number), 0.0)
        if is_wear:
            store[number] = read(number) - old_wear + value
            wear[(kind, number)] = value
        else:
            store[number] = value + old_wear
    return tool_offset


def _reader(interp, e: dict, offset: int, wear: dict) -> Callable[[], Any] | None:
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
    if src == "extended_offset":
        def extended_offset():          # G54.1 P<n> (Haas G154 P<n>) -> n; G54..G59 -> 0
            v = st.groups.get("work_offset")
            if isinstance(v, str) and v.startswith("G54.1P"):
                return float(v[len("G54.1P"):])
            return 0.0 if v is not None else UNKNOWN
        return extended_offset
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
        slot = _work_offset_slot(e, offset)
        if slot is None:
            return None
        name, a = slot

        def work_offset():
            return interp.machine.work_offset(name).get(a, 0.0) / (st.scale if a in "XYZ" else 1.0)
        return work_offset
    if src in ("tool_length", "tool_radius"):
        number = offset + 1
        kind = "length" if src == "tool_length" else "radius"

        def tool_offset():              # the machine copy of the moment (a G10 may have made one)
            m = interp.machine
            read = m.length_offset if kind == "length" else m.radius_offset
            return (read(number) - wear.get((kind, number), 0.0)) / st.scale
        return tool_offset
    if src == "zero":
        if e.get("wear_of") in ("length", "radius"):
            key = (e["wear_of"], offset + 1)
            return lambda: wear.get(key, 0.0) / st.scale
        return lambda: 0.0
    return None                          # "unknown": UNKNOWN by default
