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
    mode = "G90"
    if draw(st.booleans()):
        # G91: R from the initial level, Z from R, holes as steps, K repeats this block only
        mode = "G91"
        words = [f"Z{bottom - r:.2f}", f"R{r - initial:.2f}", *words[2:],
                 f"K{draw(st.integers(1, 3))}"]
    lines = ["G17 G21 G90 G54", "T1 M6", "S1200 M3", f"G0 X0 Y0 Z{initial:.2f}",
             f"{mode} {retract} {EXACT[kind]} X{x0:.2f} Y{y0:.2f} {' '.join(words)} F{feed}"]
    lines += [f"X{x:.2f} Y{y:.2f}" for x, y in holes[1:]]
    lines += ["G80", f"G90 G0 Z{initial + 10:.2f}", "M30"]
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


# ------------------------------------------------------------------ named -> modal (Sinumerik -> ISO)

NAMED_EXACT = {"CYCLE81": "G81", "CYCLE82": "G82", "CYCLE83": "G83", "CYCLE85": "G85",
               "CYCLE89": "G89"}


@st.composite
def named_series(draw, name: str):
    """A Sinumerik program calling `name` modally at 1..3 holes (or once, at the current point):
    the tool waits at RTP (G98) or RTP is the approach level RFP+SDIS (G99)."""
    rfp = draw(st.integers(-1000, 1000)) / 100
    sdis = draw(st.integers(0, 500)) / 100
    depth = draw(st.integers(50, 3000)) / 100
    rtp_at_approach = draw(st.booleans())
    start = rfp + sdis + draw(st.integers(0 if rtp_at_approach else 1, 3000)) / 100
    rtp = rfp + sdis if rtp_at_approach else start
    rel = draw(st.booleans())
    args = [f"{rtp:.2f}", f"{rfp:.2f}", f"{sdis:.2f}", "" if rel else f"{rfp - depth:.2f}",
            f"{depth:.2f}" if rel else ""]
    if name in ("CYCLE82", "CYCLE89"):
        args.append(f"{draw(st.integers(1, 3000)) / 1000:.3f}")
    if name == "CYCLE83":
        q = draw(st.integers(int(sdis * 100) + 10, int(sdis * 100) + 1500)) / 100
        ratio = (rfp + sdis - (rfp - depth)) / q
        assume(abs(ratio - round(ratio)) > 1e-6)
        # FDEP, FDPR, DAM, DTB, DTS, FRF, VARI, _AXN, _MDEP, _VRT, _DTD, _DIS1
        args += ["", f"{q - sdis:.2f}", f"{q:.2f}", "", "", "", "1", "", "", "", "", "0.254"]
    if name == "CYCLE85":
        feed = draw(st.integers(10, 900))
        args += ["", f"{feed}", f"{feed}"]
    holes = draw(st.lists(st.tuples(coord, coord), min_size=0, max_size=3))
    call = f"{name}({','.join(args)})"
    lines = ["G17 G71 G90", "T1 D1 M6", "S1200 M3 F500", f"G0 X0 Y0 Z{start:.2f}"]
    if holes:
        lines.append("MCALL " + call)
        lines += [f"X{x:.2f} Y{y:.2f}" for x, y in holes]
        lines += ["MCALL", "G1 X1 Y1"]
    else:
        lines += [call, "G1 X1 Y1"]
    lines.append("M30")
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("name", sorted(NAMED_EXACT))
def test_named_cycles_convert_to_iso_cycles_with_the_same_toolpath(name):
    @settings(max_examples=25, deadline=None)
    @given(named_series(name))
    def check(program):
        conv = api.transpile(program, read="sinumerik", write="iso-m")
        assert _structural(conv), [d.format_text() for d in conv.diagnostics]
        assert NAMED_EXACT[name] in conv.text or (name == "CYCLE82" and "G81" in conv.text)
        same = api.equiv(program, conv.text, read_a="sinumerik", read_b="iso-m")
        assert same, f"{same.message}\n--- sinumerik\n{program}--- iso\n{conv.text}"
    check()


def _iso_refusal(program: str, line: int = 2) -> str:
    from nctrans.dialects.base import get
    out = get("iso-m").emit(get("sinumerik").parse(program, "a.mpf").program)
    errors = [d for d in out.diagnostics if d.rule == "NC402"]
    assert errors and all(d.line == line for d in errors), [d.format_text() for d in out.diagnostics]
    return errors[0].message


def test_named_cycles_the_iso_cycle_cannot_make_are_refused_naming_why():
    head = "G0 X0 Y0 Z20\n"
    # CYCLE83 re-approaching by the automatic distance (no _DIS1): G83 re-approaches by 0.254 mm
    assert "_DIS1" in _iso_refusal(head + "MCALL CYCLE83(20,0,2,-20,,,5,5,,,,1)\nX10\nMCALL\nM30\n")
    # a degression: strokes 10, 7, 4, 3 ... are no single Q
    assert "differ" in _iso_refusal(head + "CYCLE83(20,0,0,-30,,-10,,3,,,,1,,,,,0.254)\nM30\n")
    # RTP above the approach level while the tool is elsewhere: G98 would return there instead
    assert "RTP" in _iso_refusal(head + "CYCLE81(50,0,2,-5)\nM30\n")
    # rigid tapping: the strokes differ in detail (rules/cycle-mapping.toml differs)
    assert mapping_table().for_modal("tap").differs.split(" ")[0] in _iso_refusal(
        head + "S500 M3\nCYCLE84(20,0,2,-10,,,,,1.5)\nM30\n", line=3)


def test_a_move_of_the_drilling_axis_under_mcall_is_refused():
    program = "G0 X0 Y0 Z20\nMCALL CYCLE81(20,0,2,-5)\nG0 X10 Z30\nMCALL\nM30\n"
    from nctrans.dialects.base import get
    out = get("iso-m").emit(get("sinumerik").parse(program, "a.mpf").program)
    assert any(d.rule == "NC402" and d.line == 3 and "plane" in d.message for d in out.diagnostics)


def test_hole_patterns_become_hole_lists():
    # HOLES2: 4 holes on a circle of radius 10 about (0, 0) from 0 degrees (hand-computed)
    program = ("G17 G71 G90\nS1000 M3 F200\nG0 X0 Y0 Z20\nMCALL CYCLE81(20,0,2,-5)\n"
               "HOLES2(0,0,10,0,0,4)\nMCALL\nM30\n")
    conv = api.transpile(program, read="sinumerik", write="iso-m")
    lines = conv.text.splitlines()
    first = lines.index("G98 G81 X10. Y0. Z-5. R2.")
    assert lines[first + 1:first + 5] == ["X0. Y10.", "X-10. Y0.", "X0. Y-10.", "G80"]
    assert api.equiv(program, conv.text, read_a="sinumerik", read_b="iso-m")


@pytest.mark.rs274
def test_named_cycles_as_iso_run_in_rs274_with_the_sinumerik_moves(rs274, tmp_path):
    import rs274 as h
    program = ("G17 G71 G90\nT1 M6\nS1000 M3 F300\nG0 X0 Y0 Z15\n"
               "MCALL CYCLE83(15,0,2,-17,,,3,5,,,,1,,,,,0.254)\nX10 Y10\nX20\nMCALL\n"
               "CYCLE82(3,0,3,,4,0.25)\nMCALL CYCLE85(3,0,3,-6,,,150,150)\nHOLES1(0,0,90,5,5,2)\n"
               "MCALL\nG1 X0 Y0\nM30\n")
    conv = api.transpile(program, read="sinumerik", write="iso-m")
    assert _structural(conv), [d.format_text() for d in conv.diagnostics]
    assert all(code in conv.text for code in ("G83", "G82", "G85"))
    out = tmp_path / "named.ngc"
    out.write_text(conv.text, encoding="utf-8")
    table = h.write_tool_table(tmp_path / "zero.tbl", [(1, 0.0, 0.0)])
    run = h.run_rs274(out, table, tmp_path / "named.out")
    assert run.completed, run.message
    ours = [h.Motion.of(r) for r in api.toolpath(program, "sinumerik")
            if r.kind in ("rapid", "linear", "arc")]
    problem = h.compare(run.moves, ours, "named.ngc")
    assert problem is None, problem


def test_a_one_shot_call_under_mcall_leaves_the_modal_cycle_in_force():
    # as the sinumerik emitter writes an ISO G81 block that drills where the tool is
    program = ("G17 G71 G90\nS1000 M3 F100\nG0 X0 Y0 Z1\nMCALL CYCLE81(1,0.1,0,-1.11)\n"
               "CYCLE81(1,0.1,0,-1.11)\nG0 X1.5\nX2.5\nMCALL\nG0 Z5\nM30\n")
    conv = api.transpile(program, read="sinumerik", write="iso-m")
    assert _structural(conv) and conv.text.count("G81") == 2 and "G67" not in conv.text
    assert api.equiv(program, conv.text, read_a="sinumerik", read_b="iso-m")
