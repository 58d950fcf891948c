"""LIMS= in the block that starts constant surface speed clamps it from that block on (the
Siemens LIMS acts with G96 in its block): `G96 S200 LIMS=3000 M4` at X0 started the spindle at the
machine's 24000 rpm first and clamped it to 3000 only after, a record that a conversion to ISO
turning wrote as `S24000 M4` (a lathe spindle at its top speed for a block)."""
from __future__ import annotations

from nctrans.dialects.base import get
from nctrans.interp.interpreter import interpret
from nctrans.machine import default_lathe


def spindle_records(text):
    res = get("sinumerik").parse(text, "t.mpf")
    diags = list(res.diagnostics)
    return [(r.line, r.spindle) for r in interpret(res.program, default_lathe(), diagnostics=diags)
            if r.kind == "spindle"]


def test_lims_in_the_g96_block_clamps_its_first_speed():
    # at X0 the surface speed needs an infinite rpm: the block's own limit 3000 is the speed;
    # then X52 (diameter, radius 26 mm): 200 / (2 pi 0.026) = 1224.268793 rpm
    text = "G18 G90 G95 G71 DIAMON\nT1 D1 M6\nG96 S200 LIMS=3000 M4\nG0 X52 Z2\nM30\n"
    assert spindle_records(text) == [(3, 3000.0), (4, 1224.268793)]


def test_lims_written_before_or_after_s_reads_the_same():
    a = "G18 DIAMON\nT1 D1 M6\nG0 X20 Z2\nG96 S100 LIMS=1000 M3\nG1 X10 F0.1\nM30\n"
    b = "G18 DIAMON\nT1 D1 M6\nG0 X20 Z2\nG96 LIMS=1000 S100 M3\nG1 X10 F0.1\nM30\n"
    # X20 (radius 10): 100 / (2 pi 0.010) = 1591.5 -> clamped 1000; X10 the same
    assert spindle_records(a) == spindle_records(b) == [(4, 1000.0)]
