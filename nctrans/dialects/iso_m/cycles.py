"""Named standard cycles (IR CycleCall: Sinumerik CYCLE81..89, HOLES1/HOLES2) written as ISO canned
cycles, from rules/cycle-mapping.toml.

A named cycle drills where the call finds the tool (one-shot) or after every block that moves in the
plane (MCALL); the ISO cycle drills at each positioning block of its mode. So a one-shot call
becomes a G8x block without plane words followed by G80, and a modal call a G8x mode whose first
hole is the first positioning block after it. The ISO levels come from the named ones: R = RFP+SDIS,
Z = DP (or RFP-DPR), G99 when the cycle ends at R (RTP not above it), else G98 with the tool at RTP
where the cycle starts (the ISO initial level). Everything the ISO cycle cannot make exactly (another
re-approach distance, a degression, a feed move to the hole, a tool not at RTP ...) is refused naming
it (NC402), never written as a near miss.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from nctrans.cyclemap import mapping_table, peck_clearance
from nctrans.ir import nodes as n
from nctrans.ir.walk import constant

DRILL_AXIS = {"XY": "Z", "ZX": "Y", "YZ": "X"}
PLANE_AXES = {"XY": ("X", "Y"), "ZX": ("Z", "X"), "YZ": ("Y", "Z")}
_TOL = 1e-9


class CycleRefused(Exception):
    """The named cycle has no exact ISO form; the message says why."""


@dataclass
class IsoCycle:
    """An ISO canned cycle ready to write: G code, retract mode and the cycle words."""
    code: str                      # G81 ...
    retract: str                   # G98 | G99
    words: list                    # [(key, text)] Z, R, Q, P
    feed: Optional[n.Expr] = None  # a feed the cycle programs (CYCLE85 FFR): F in the G8x block
    rtp: Optional[float] = None    # G98: where the tool must be when the cycle starts
    name: str = ""


def _num(e) -> Optional[float]:
    return None if e is None else constant(e)


def _given(params: dict, key: str) -> bool:
    """An argument that is programmed and not 0 (an empty or 0 argument means 'not used')."""
    v = params.get(key)
    if v is None:
        return False
    c = constant(v)
    return c is None or abs(c) > _TOL


def iso_cycle(call: n.CycleCall, emitter) -> IsoCycle:
    """The ISO form of a named drilling cycle call, or CycleRefused."""
    from nctrans.interp.cycles import cycle_table, named_cycles
    name = (call.name or "").upper()
    mapping = mapping_table().for_named(name, call.kind) if name else None
    if mapping is None:
        other = mapping_table().for_modal(call.kind)
        why = (other.differs or other.none) if other is not None else "no ISO canned cycle"
        raise CycleRefused(f"{name or call.kind}: {why}")
    if not mapping.exact:
        raise CycleRefused(f"{name}: {mapping.differs}")
    table = cycle_table()
    p = call.params
    for arg in mapping.absent:
        if _given(p, table.neutral(arg)):
            raise CycleRefused(f"{name} with {arg}: the ISO cycle has no equivalent")
    known = set(named_cycles()[name].params)
    pecks = mapping.modal in ("peck", "chip_break")
    # FDEP is FDPR's absolute spelling (_peck reads either)
    used = {"RTP", "RFP", "SDIS", "DP", "DPR", *mapping.args, *mapping.absent, *(("FDEP",) if pecks else ())}
    for arg in known - used:
        if _given(p, table.neutral(arg)):
            raise CycleRefused(f"{name} with {arg}: the ISO cycle has no equivalent")
    rfp, sdis = p.get("r_plane", n.Num(0.0)), p.get("safety", n.Num(0.0))
    if _num(sdis) == 0:
        approach = rfp
    elif _num(rfp) is not None and _num(sdis) is not None:
        approach = n.Num(_num(rfp) + _num(sdis))
    else:
        approach = n.Binary("+", rfp, sdis)
    if _given(p, "depth_rel"):
        dpr = _num(p["depth_rel"])
        bottom = n.Num(_num(rfp) - abs(dpr)) if _num(rfp) is not None and dpr is not None \
            else n.Binary("-", rfp, n.Func("abs", [p["depth_rel"]]))
    elif "bottom" in p:
        bottom = p["bottom"]
    else:
        raise CycleRefused(f"{name} without a depth (DP or DPR)")
    words = [("Z", emitter.addr("Z", bottom)), ("R", emitter.addr("R", approach))]
    out = IsoCycle("", emitter.code_for("cycle_retract", "r_plane"), words, name=name)
    values: dict[str, n.Expr] = {}
    for arg, source in mapping.args.items():
        value = p.get(table.neutral(arg))
        if isinstance(source, float):
            c = _num(value)
            if c is None or abs(c - source) > _TOL:
                raise CycleRefused(f"{name} with {arg} other than {source:g}")
        elif source == "peck_clearance":
            c = _num(value)
            want = peck_clearance(emitter.units_mm)
            if c is None or abs(c - want) > _TOL:
                raise CycleRefused(f"{name}: the ISO cycle backs off / re-approaches by {want:g}, "
                                   f"{arg} asks for {'the automatic distance' if c is None else f'{c:g}'}")
        elif source == "feed":
            if value is not None:
                if out.feed is not None and emitter.val(out.feed) != emitter.val(value):
                    raise CycleRefused(f"{name} with different feeds in and out")
                out.feed = value
        elif source == "pitch":
            raise CycleRefused(f"{name}: {arg} has no ISO canned-cycle word")
        elif pecks and source == "peck":
            continue                   # first infeed and degression: _peck
        elif value is not None:
            if source in values and emitter.val(values[source]) != emitter.val(value):
                raise CycleRefused(f"{name}: the ISO cycle needs "
                                   f"{'/'.join(k for k, v in mapping.args.items() if v == source)} equal")
            values[source] = value
    if pecks:
        values["peck"] = _peck(name, p, p.get("decrement"), rfp, sdis)
    kind = mapping.modal
    if kind == "drill_dwell" and "dwell" not in values:
        kind = "drill"                 # CYCLE82 without DTB dwells nothing: G81
    rule = emitter.table.code_for("cycle", kind)
    if rule is None:
        raise CycleRefused(f"{name}: no ISO code for {kind}")
    out.code = rule.code
    if values:
        saved = dict(emitter.pos)
        words += emitter.w_CycleParams(n.CycleParams(values))       # P (ms) and Q as ISO spells them
        emitter.pos = saved
    # where the cycle ends: RTP when it is above the approach level (G98 from RTP), else R (G99)
    rtp, app = _num(p.get("retract_plane")), _num(approach)
    if p.get("retract_plane") is None:
        raise CycleRefused(f"{name} without RTP")
    if rtp is None or app is None:
        raise CycleRefused(f"{name} with a computed RTP or approach level: G98/G99 cannot be chosen")
    up = 1.0 if (_num(bottom) is None or app >= _num(bottom)) else -1.0
    if (rtp - app) * up > _TOL:
        out.retract, out.rtp = emitter.code_for("cycle_retract", "initial"), rtp
    return out


def _peck(name: str, p: dict, dam, rfp, sdis) -> n.Expr:
    """G83/G73 Q from CYCLE83: ISO pecks Q at a time from R = RFP+SDIS, CYCLE83 first to FDEP
    (or RFP-FDPR), then DAM at a time (rules/cycle-mapping.toml: DAM is the peck). The same depths
    need DAM given and first depth = RFP+SDIS-DAM."""
    q = _num(dam)
    if q is None or q <= 0:
        raise CycleRefused(f"{name} without a constant degression DAM (the ISO peck depth Q)")
    r, s = _num(rfp), _num(sdis) or 0.0
    if _given(p, "first_peck"):
        first, fd = _num(p["first_peck"]), None
        if first is None or r is None:
            raise CycleRefused(f"{name} with a computed first drilling depth")
        fd = r - first
    else:
        fd = _num(p.get("fdpr"))
        if fd is None:
            raise CycleRefused(f"{name} without a constant first drilling depth")
    if abs(abs(fd) + s - q) > 1e-6:
        raise CycleRefused(f"{name}: first infeed {abs(fd) + s:g} from R and degression {q:g} differ "
                           "(ISO pecks the same depth Q every time)")
    return n.Num(q)


def pattern_positions(call: n.CycleCall) -> Optional[list[tuple[float, float]]]:
    """HOLES1/HOLES2 positions when every argument is a constant, else None."""
    from nctrans.interp.cycles import cycle_table, hole_pattern
    pat = {x.name: x for x in cycle_table().pattern}.get((call.name or "").upper())
    if pat is None:
        return None
    args = []
    for prm in pat.params:
        e = call.params.get(prm.lower())
        c = None if e is None else constant(e)
        if e is not None and c is None:
            return None
        args.append(c)
    return hole_pattern(pat.name, args)
