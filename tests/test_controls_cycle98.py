"""Sinumerik CYCLE98, chained threads (issue 8, nctrans/interp/milling_cycles.py
`thread_chain_steps`): a hand-computed chain, the refusals, equivalence after conversion.

Expected values by hand from the model in the function's docstring (CYCLE97's passes [GK], each
running through the chain PO1..PO4 with the section's lead PP1..PP3); a property over random
chains."""
from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

from nctrans import api, pipeline
from nctrans.interp.milling_cycles import thread_chain_steps
from nctrans.source import from_text


def _text(call: str) -> str:
    return f"G18 G90 DIAMON T1 D1\nS500 M3\nG0 X30 Z10\n{call}\nG0 X40\nM30\n"


def _run(call: str):
    text = _text(call)
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear") and r.line == 4]
    return [(r.kind, round(r.end["X"], 6), round(r.end["Z"], 6), r.pitch) for r in recs], ld.diagnostics


def test_chain_of_three_sections_by_hand():
    # radius 10 from Z0 to Z-10 (PP1 1.5), the taper to radius 12 at Z-20 (PP2 2), radius 12 to
    # Z-30 (PP3 1.5); run-in 2 (Z2), run-out 2 (Z-32); depth 1 in two cuts (0.5, 1.0); clear
    # 12 + 1 = 13. Each pass: in at Z2, the five thread moves, out to 13, back to Z2.
    moves, diags = _run("CYCLE98(0, 20, -10, 20, -20, 24, -30, 24, 2, 2, 1, 0, 0, 0, 2, 0, 1.5, 2, 1.5, 1, 1, 0)")
    assert not [d for d in diags if d.severity != "info"]
    want = [("rapid", 13, 2, None)]
    for d in (0.5, 1.0):
        want += [("rapid", 10 - d, 2, None), ("linear", 10 - d, 0, 1.5), ("linear", 10 - d, -10, 1.5),
                 ("linear", 12 - d, -20, 2.0), ("linear", 12 - d, -30, 1.5), ("linear", 12 - d, -32, 1.5),
                 ("rapid", 13, -32, None), ("rapid", 13, 2, None)]
    assert moves == [(k, pytest.approx(x), pytest.approx(z), p) for k, x, z, p in want]


@pytest.mark.parametrize("call, rule", [
    ("CYCLE98(0, 20, -10, 20, -20, 24, -30, 24, 2, 2, 1, 0, 0, 0, 2, 0, 1.5, 2, 1.5, 1, -2, 0)", "NC225"),  # NUMTH
    ("CYCLE98(0, 20, -10, 20, 5, 24, -30, 24, 2, 2, 1, 0, 0, 0, 2, 0, 1.5, 2, 1.5, 1, 1, 0)", "NC224"),   # turns back
    ("CYCLE98(0, 20, -1, 40, -20, 40, -30, 40, 2, 2, 1, 0, 0, 0, 2, 0, 1.5, 2, 1.5, 1, 1, 0)", "NC224"),  # a face
    ("CYCLE98(0, 20, -10, 20, -20, 24, -30, 24, 2, 2, 1, 0, 0, 0, 2, 0, 1.5, 0, 1.5, 1, 1, 0)", "NC225"),  # no PP2
    ("CYCLE98(0, 20, -10, 20, -20, 24, -30, 24, 2, 2, 0, 0, 0, 0, 2, 0, 1.5, 2, 1.5, 1, 1, 0)", "NC225"),  # no TDEP
    ("CYCLE98(0, 20, -10, 20, -20, 24, -30, 24, 2, 2, 1, 0, 0, 0, 2, 0, 1.5, 2, 1.5, 7, 1, 0)", "NC225"),  # VARI
])
def test_what_is_not_modelled_or_alarms_moves_nothing_and_says_so(call, rule):
    moves, diags = _run(call)
    assert moves == []
    said = [d for d in diags if d.line == 4 and d.severity != "info"]
    assert [d.rule for d in said] == [rule] and "CYCLE98" in said[0].message


def test_internal_chain_cuts_outwards_from_the_crest():
    # VARI 2 (internal): crest = nominal radius - TDEP, cuts outwards; one cut at full depth
    moves, _ = _run("CYCLE98(0, 20, -10, 20, -20, 20, -30, 20, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 1, 2, 1, 0)")
    threads = [m for m in moves if m[0] == "linear"]
    assert [(x, z) for _, x, z, _ in threads] == [(10, -10), (10, -20), (10, -30)]
    assert moves[0] == ("rapid", 8, 10) + (None,) and moves[-1] == ("rapid", 8, 0, None)


def test_converted_to_iso_turning_is_equivalent():
    text = _text("CYCLE98(0, 20, -10, 20, -20, 24, -30, 24, 2, 2, 1, 0.1, 30, 0, 3, 1, 1.5, 2, 1.5, 3, 1, 0)")
    conv = api.transpile(text, "sinumerik", "iso-t")
    assert conv.text is not None and "CYCLE98" not in conv.text
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-t")


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(2, 20), min_size=3, max_size=3), st.lists(st.floats(-0.3, 0.3), min_size=3, max_size=3),
       st.floats(40, 80), st.floats(0.2, 3), st.integers(1, 6), st.sampled_from([1, 2, 3, 4]),
       st.floats(-40, 40), st.lists(st.floats(0.5, 4), min_size=3, max_size=3))
def test_every_pass_runs_the_chain_and_the_last_reaches_the_root(lengths, tapers, dm, tdep, nrc, vari, iang, pp):
    zs, ds = [0.0], [dm]
    for length, taper in zip(lengths, tapers):
        zs.append(zs[-1] - length)
        ds.append(ds[-1] + 2 * taper * length)             # tapers under 45 degrees
    p = dict(PO1=zs[0], DM1=ds[0], PO2=zs[1], DM2=ds[1], PO3=zs[2], DM3=ds[2], PO4=zs[3], DM4=ds[3],
             APP=1, ROP=1, TDEP=tdep, FAL=0, IANG=iang, NRC=nrc, VARI=vari, PP1=pp[0], PP2=pp[1], PP3=pp[2])
    steps = thread_chain_steps(p, (max(ds) / 2 + 10, 5.0))
    external = vari in (1, 3)
    sd = -1.0 if external else 1.0
    threads = [s for s in steps if s[0] == "thread"]
    passes = [threads[i:i + 5] for i in range(0, len(threads), 5)]
    assert len(threads) == 5 * nrc and len(passes) == nrc
    for k, cut in enumerate(passes):
        assert [s[2] for s in cut] == [pp[0], pp[0], pp[1], pp[2], pp[2]]
        for s, z, d in zip(cut[:4], zs, ds):            # on each chain point, never below the root
            crest = d / 2 if external else d / 2 - tdep
            depth = (s[1][0] - crest) * sd
            assert -1e-9 <= depth <= tdep + 1e-9
            if k == nrc - 1:
                assert depth == pytest.approx(tdep) and s[1][1] == pytest.approx(z)
    assert steps[-1][0] == "rapid" and steps[-1][1][1] == pytest.approx(zs[0] + 1)
