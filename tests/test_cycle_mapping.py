"""Canned cycles converted as cycles (rules/cycle-mapping.toml), proven by `equiv` over generated
parameter sets: an ISO G8x series written as MCALL CYCLE8x must make the same toolpath in the
interpreter as the ISO source, and each mapping the table calls inexact must be refused, never
written as a near miss."""
from __future__ import annotations

import pytest
from hypothesis import assume, given, settings, strategies as st

from nctrans import api
from nctrans.cyclemap import DERIVED, mapping_table
from nctrans.interp.cycles import named_cycles
from nctrans.ir.vocabulary import CYCLE_PARAMS, MODAL_GROUPS

# ISO G code of each modal kind whose mapping the table calls exact
EXACT = {"drill": "G81", "drill_dwell": "G82", "peck": "G83", "bore_feed_out": "G85",
         "bore_dwell_feed_out": "G89"}
INEXACT = {"chip_break": "G73", "tap": "G84", "tap_left": "G74", "fine_bore": "G76",
           "back_bore": "G87", "bore_manual": "G88", "bore_stop_rapid_out": "G86"}

coord = st.integers(-5000, 5000).map(lambda v: v / 100)      # +-50 mm, 0.01 steps


def _to_sinumerik(text: str) -> api.Conversion:
    return api.transpile(text, read="iso-m", write="sinumerik")


def _structural(conv: api.Conversion) -> bool:
    return conv.text is not None and not any(
        "lowered to plain motion" in d.message for d in conv.diagnostics)


@st.composite
def cycle_series(draw, kind: str):
    """An ISO program drilling 1..3 holes with one canned cycle; the levels as a shop writes them
    (initial level at or above R, R above the bottom)."""
    bottom = draw(st.integers(-4000, -100)) / 100
    r = bottom + draw(st.integers(50, 3000)) / 100
    initial = r + draw(st.integers(0, 3000)) / 100
    words = [f"Z{bottom:.2f}", f"R{r:.2f}"]
    if kind == "peck":
        q = draw(st.integers(10, 1500)) / 100
        # the pecks' last depth exactly at the bottom is a float tie between the two models
        # (LinuxCNC compares depth > bottom, CYCLE83 stroke + 1e-9): keep clear of it
        ratio = (r - bottom) / q
        assume(abs(ratio - round(ratio)) > 1e-6)
        words.append(f"Q{q:.2f}")
    if kind in ("drill_dwell", "bore_dwell_feed_out"):
        words.append(f"P{draw(st.integers(0, 3000))}")
    retract = draw(st.sampled_from(["G98", "G99"]))
    feed = draw(st.integers(10, 2000))
    holes = draw(st.lists(st.tuples(coord, coord), min_size=1, max_size=3))
    x0, y0 = holes[0]
    lines = ["G17 G21 G90 G54", "T1 M6", "S1200 M3", f"G0 X0 Y0 Z{initial:.2f}",
             f"{retract} {EXACT[kind]} X{x0:.2f} Y{y0:.2f} {' '.join(words)} F{feed}"]
    lines += [f"X{x:.2f} Y{y:.2f}" for x, y in holes[1:]]
    lines += ["G80", f"G0 Z{initial + 10:.2f}", "M30"]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("kind", sorted(EXACT))
def test_exact_cycles_convert_as_cycles_with_the_same_toolpath(kind):
    @settings(max_examples=25, deadline=None)
    @given(cycle_series(kind))
    def check(program):
        conv = _to_sinumerik(program)
        assert _structural(conv), [d.format_text() for d in conv.diagnostics]
        named = mapping_table().for_modal(kind).named
        assert f"MCALL {named}(" in conv.text
        same = api.equiv(program, conv.text, read_a="iso-m", read_b="sinumerik")
        assert same, f"{same.message}\n--- iso\n{program}--- sinumerik\n{conv.text}"
    check()


def test_g83_writes_the_peck_as_first_depth_and_degression_with_the_iso_clearance():
    # hand-computed: R2 Z-20 under G98 from Z20; Q5 is the first infeed (FDPR) and every later one
    # (DAM), VARI=1 (swarf removal), _DIS1 = 0.254 mm (the G83 re-approach distance)
    conv = _to_sinumerik("G17 G21 G90\nS1000 M3\nG0 X0 Y0 Z20.\nG98 G83 X10. Y10. Z-20. R2. Q5. "
                         "F100.\nG80\nM30\n")
    assert "MCALL CYCLE83(20, 2, 0, -20,,, 5., 5.,,,, 1,,,,, 0.254)" in conv.text.splitlines()


def test_g83_in_inch_takes_the_clearance_in_inch():
    program = "G17 G20 G90\nS1000 M3\nG0 X0 Y0 Z1.\nG99 G83 X1. Y1. Z-1. R.1 Q.25 F10.\nG80\nM30\n"
    conv = _to_sinumerik(program)
    line = next(x for x in conv.text.splitlines() if x.startswith("MCALL CYCLE83"))
    assert line == "MCALL CYCLE83(0.1, 0.1, 0, -1,,, .25, .25,,,, 1,,,,, 0.01)"     # G99: RTP = R
    assert api.equiv(program, conv.text, read_a="iso-m", read_b="sinumerik")


@pytest.mark.parametrize("kind", sorted(INEXACT))
def test_cycles_without_an_exact_standard_cycle_are_refused_at_their_line(kind):
    program = (f"G17 G21 G90\nS1000 M3\nG0 X0 Y0 Z20.\n"
               f"G99 {INEXACT[kind]} X10. Y10. Z-5. R2. Q1. P100 F100.\nG80\nM30\n")
    from nctrans.dialects.base import get
    out = get("sinumerik").emit(get("iso-m").parse(program, "a.nc").program)
    refusals = [d for d in out.diagnostics if d.rule == "NC402"]
    assert refusals and all(d.line == 4 for d in refusals)
    mapping = mapping_table().for_modal(kind)
    assert (mapping.none or mapping.differs) in refusals[0].message


def test_the_table_names_known_kinds_cycles_and_parameters():
    kinds = MODAL_GROUPS["cycle"]
    table = mapping_table()
    assert {c.modal for c in table.cycle} == set(kinds) - {"off"}
    named = named_cycles()
    for c in table.cycle:
        assert bool(c.named) != bool(c.none), c.modal        # a cycle, or the reason there is none
        if not c.named:
            continue
        params = named[c.named].params
        for p, source in c.args.items():
            assert p in params, (c.named, p)
            assert isinstance(source, float) or source in CYCLE_PARAMS or source in DERIVED
        assert set(c.absent) <= set(params) and not set(c.absent) & set(c.args)
        assert c.exact or c.differs, c.modal
