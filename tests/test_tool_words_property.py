"""Random tool selections, changes, offsets and compensation, converted every way: the converted
run is the source's (equiv, on machines with real radii), or the conversion is refused at a line
(NC402), or the difference is said at its line (NC401 for a repeated M6 of the loaded tool, which a
T-changing control cannot make; NC412 for Sinumerik's alarm in place). A fuzz of this shape found
Sinumerik/Fagor D with no tool change written as an ISO register, a Sinumerik lathe T of the tool
in place written as its own offset, and a Fagor T change with the D number of the last tool."""
from __future__ import annotations

from hypothesis import HealthCheck, given, settings, strategies as st

import nctrans
from nctrans.machine import Axis, Machine, Tool

_AX = Axis(min=-500.0, max=500.0)
MILL = Machine(name="mill", kind="mill", axes={"X": _AX, "Y": _AX, "Z": _AX},
               tools=[Tool(number=t, length=0.0, radius=r) for t, r in ((1, 5.0), (2, 3.0), (3, 2.0))])
LATHE = Machine(name="lathe", kind="lathe", axes={"X": _AX, "Z": _AX},
                tools=[Tool(number=t, length=0.0, radius=r, tip=3) for t, r in ((1, 0.8), (2, 0.4), (3, 1.2))])

# (source dialect, machine, head, targets)
SHAPES = {
    "iso-m": ("iso-m", MILL, "G21 G90 G17\nG0 X-20 Y-20 Z5", ("sinumerik", "fagor", "iso-t")),
    "sinumerik": ("sinumerik", MILL, "G17 G90 G71\nG0 X-20 Y-20 Z5", ("iso-m", "fagor", "iso-t")),
    "fagor": ("fagor", MILL, "G17 G90 G71\nG00 X-20 Y-20 Z5", ("iso-m", "sinumerik", "iso-t")),
    "iso-t": ("iso-t", LATHE, "G21 G18 G99\nG0 X60. Z5.", ("iso-m", "sinumerik", "fagor")),
    "sinumerik lathe": ("sinumerik", LATHE, "G18 G90 G95 DIAMON\nG0 X60 Z5", ("iso-t", "iso-m", "fagor")),
    "fagor lathe": ("fagor", LATHE, "G18 G90 G95 G151\nG0 X60 Z5", ("iso-t", "iso-m", "sinumerik")),
}
_STEP = st.tuples(st.integers(1, 3), st.sampled_from(["T M6", "T ... M6", "T", "T D"]),
                  st.integers(0, 2), st.booleans(), st.sampled_from(["G41", "G42"]), st.booleans())


def _program(shape: str, steps) -> str:
    dialect, machine, head, _ = SHAPES[shape]
    lathe = machine is LATHE
    cut = (["{side} G1 X40 Z0 F0.2", "Z-20", "X50 Z-30", "G40 G0 X60 Z5"] if lathe else
           ["{side} {d}G1 X0 Y0 F100", "X30", "Y20", "G40 G1 X-20 Y-20"])
    out = [head]
    for k, how, d, extra_d, side, comp in steps:
        if dialect == "iso-t":
            out.append(f"T0{k}0{d or k}")
        elif how == "T M6":
            out.append(f"T{k} M6")
        elif how == "T ... M6":
            out += [f"T{k}", "G0 X60 Z5" if lathe else "G0 X-20 Y-20", "M6"]
        elif how == "T D" and dialect != "iso-m":
            out.append(f"T{k} D{d or 1}")
        else:
            out.append(f"T{k}")
        if extra_d and dialect != "iso-t":
            out.append(f"G43 H{d or k}" if dialect == "iso-m" else f"D{d}")
        if comp:
            dword = f"D{d or k} " if dialect == "iso-m" else ""
            out += [ln.format(side=side, d=dword) for ln in cut]
    out.append("M30")
    return "\n".join(out) + "\n"


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(shape=st.sampled_from(sorted(SHAPES)), steps=st.lists(_STEP, min_size=1, max_size=4))
def test_tool_words_convert_to_the_same_run_or_say_why(shape, steps):
    dialect, machine, _, targets = SHAPES[shape]
    text = _program(shape, steps)
    for target in targets:
        conv = nctrans.transpile(text, read=dialect, write=target, machine=machine)
        if conv.text is None:
            assert [d for d in conv.diagnostics if d.rule == "NC402"], (target, text)
            continue
        result = nctrans.equiv(text, conv.text, read_a=dialect, read_b=target, machine=machine)
        if not result.equivalent:
            said = [d for d in conv.diagnostics if d.rule == "NC412" or "already loaded" in d.message]
            assert said, (target, text, conv.text, result.message)
