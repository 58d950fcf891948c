"""Where the radius of G41/G42 comes from, and saying so where the program does not know it (NC123).

Two kinds of offset number (rules table option `offsets_of_active_tool`):
- ISO D (Fanuc, LinuxCNC) names a register of the control's offset table, whatever tool is in the
  spindle: the machine file's `radius_offsets`, else tool n's radius. D0 is offset 0; G41 with no D
  at all is NC208 (records.py).
- Sinumerik D ("compensation data for a certain tool T", seed L24265; edges of the active tool,
  L13484-13490) and Fagor D (a corrector of
  the active tool, seed L5711-5803: `T2` then `D2` selects D2 of the still active T1) belong to the
  tool in the spindle. When no tool change precedes the compensation in the run, that tool is the
  one the machine holds from before (in a subprogram file: its caller's), which the program does
  not say. Unless the machine file gives that number as a flat offset (`radius_offsets`, Sinumerik
  flat D numbers, seed L13488), the radius is not known: NC123 at the G41/G42 line, and the
  analysis runs the programmed contour (radius 0, as a control with no tool or D0 compensates)
  instead of taking some tool's radius from the machine file. A conversion that would
  lower the compensation into coordinates refuses it (lower/flatten.takes_unknown_path).
"""
from __future__ import annotations

from typing import Optional


def offsets_of_active_tool(dialect: Optional[str]) -> bool:
    from nctrans.rules import option
    return bool(option(dialect, "offsets_of_active_tool", False))


def radius_of(it, d: int) -> float:
    """The radius of offset number `d` where D numbers are not cutting edges of their own model
    (interp/tool_edges): a register the machine file gives (radius_offsets); a tool-relative D1
    (Fagor: the corrector of the active tool, which the machine file's tool holds) is the active
    tool's radius, as its length is; else register d (tool d's radius). D0: none."""
    if not d:
        return 0.0
    m = it.machine
    if it.offsets_of_tool and it.st.tool and d == 1 and d not in m.radius_offsets:
        tool = m.tool(int(it.st.tool))
        if tool is not None:
            return float(tool.radius)
    return float(m.radius_offset(d))


def loaded_tool_radius(it) -> Optional[float]:
    """G41/G42 with no D where the control profile compensates with the loaded tool's radius
    (rules `[options.profiles.<p>] comp_without_d = "loaded_tool"`, LinuxCNC: "if D is omitted,
    the radius of the tool in the spindle" [GK, LinuxCNC G-code reference]; rs274 2.9 checked by
    hand: T1 of diameter 10 M6, G41 G1 X10 Y0 then Y10 runs X5 Y5), else None (NC208)."""
    from nctrans.rules import option
    profile = (it.program.meta or {}).get("profile") if isinstance(it.program.meta, dict) else None
    if not profile:
        return None
    own = ((option(it.program.dialect, "profiles") or {}).get(profile) or {}).get("comp_without_d")
    if own != "loaded_tool":
        return None
    if it.st.tool is None:
        it.diag("NC123", "warning", f"G41/G42 with no D takes the radius of the tool in the spindle "
                f"({profile}), but no tool change precedes it in the program: that tool is the one the "
                "machine holds, which the program does not say; analysed on the programmed contour "
                "(radius 0)", it.comp_on_span)
        return 0.0
    tool = it.machine.tool(int(it.st.tool))
    return float(tool.radius) if tool is not None else 0.0


def check_entry(it) -> None:
    """Before the first move of a G41/G42 episode: NC123 and radius 0 where the radius is the
    unknown tool's. `it`: the Interpreter (st, machine, comp_radius, default_edge, diag)."""
    folding = getattr(it, "hook", None) is not None
    if folding and it.st.tool is not None:
        folded_at_zero(it)
    if not it.offsets_of_tool:
        if folding and it.st.tool is None:
            register_unknown(it)
        return
    if it.st.tool is not None:
        return
    d = it.st.radius_index
    defaulted = d is None and bool(it.default_edge)
    if defaulted:                               # the edge a tool brings (Sinumerik D1)
        d = it.default_edge
    if not d:
        return                                  # D0 / no D: no offset (NC208 where no D)
    if d in getattr(it.machine, "radius_offsets", {}):
        return                                  # a flat offset number the machine file gives
    side = it.st.comp_side
    code = "G41" if side == "left" else "G42"
    which = f"D{d}" if it.st.radius_index is not None and not defaulted else f"D{d} (the default edge)"
    it.diag("NC123", "warning",
            f"{code} with {which} of the active tool, but no tool change precedes it in the program: the "
            "radius is that of the tool the machine holds (a subprogram's: its caller's), which the "
            "program does not say; analysed on the programmed contour (radius 0). Change the tool "
            "before (T.. M6), or give the offset number in the machine file's radius_offsets",
            it.comp_on_span)
    it.st.radius_index = d
    it.comp_radius = 0.0


def register_unknown(it) -> None:
    """NC125 in a run written as plain motion (a flatten hook: a lowering, --flatten) with no tool
    change before it: G41/G42 by an ISO offset register d (a register of the control's table,
    whatever tool is loaded) that the machine file does not give (no radius_offsets entry d, no
    tool d). The analysis reads it as 0, which is no fact of any machine; plain motion would fold
    that 0 into the coordinates. A lowering nctrans chooses refuses it (lower/flatten.
    takes_unknown_path); --flatten keeps the warning. (With a tool changed before it, the
    lowering of a target that writes that tool's own offset, not the register, is not refused
    here: the built-in machines give no register, and their radius 0 is the analysis' own.)"""
    d = it.st.radius_index
    m = it.machine
    if not d or m is None or d in getattr(m, "radius_offsets", {}) or m.tool(int(d)) is not None:
        return
    code = "G41" if it.st.comp_side == "left" else "G42"
    it.diag("NC125", "warning",
            f"{code} by offset register D{d}, which the machine file does not give (no radius_offsets "
            f"entry {d}, no tool {d}): plain motion would fold a radius of 0 into the coordinates, "
            "and the control's register holds whatever radius was set there. Give the register in "
            "the machine file (--machine)", it.comp_on_span)


def radius_given(it, d: int) -> bool:
    """Whether the machine model (its file, or a write of the program: G10, $TC_DP6) holds a
    radius for offset number `d` of the active tool, as radius_of / ToolEdges read it."""
    m = it.machine
    if d in getattr(m, "radius_offsets", {}):
        return True
    t = int(it.st.tool or 0)
    edges = getattr(it, "edges", None)
    if edges is not None and "radius" in edges.data.get((t, d), {}):
        return True
    if (edges is not None or it.offsets_of_tool) and d == 1 and t and m.tool(t) is not None:
        return True
    return m.tool(int(d)) is not None


def folded_at_zero(it) -> None:
    """NC409 in a run written as plain motion (a lowering, --flatten) with the tool known: the
    register or edge in force gives no radius in the machine model (the built-in machines give
    none), so the tool-centre path written is the programmed contour, right only for a tool of
    radius 0. Said once per offset number per run, at the first G41/G42 that uses it; the
    conversion goes ahead (corpus lathe programs under G42 convert without --machine)."""
    d = it.st.radius_index if it.st.radius_index is not None else it.default_edge
    if not d or radius_given(it, int(d)):
        return
    seen = it.__dict__.setdefault("_folded_at_zero", set())
    if d in seen:
        return
    seen.add(d)
    code = "G41" if it.st.comp_side == "left" else "G42"
    which = f"edge D{d} of tool {it.st.tool}" if (getattr(it, "edges", None) is not None
                                                   or it.offsets_of_tool) else f"offset register {d}"
    it.diag("NC409", "warning",
            f"{code} with {which}: the machine model gives no radius for it, so the compensation "
            "was folded into the coordinates with radius 0; the path written is right only for a "
            "tool of radius 0. Convert with --machine giving the tool's radius (radius_offsets "
            f"{d}, or its [[tools]] entry) for the real path", it.comp_on_span)
