"""Sinumerik CYCLE95, stock removal along a contour (issue 8, nctrans/interp/stock_removal.py):
a hand-computed case, the refusals, properties over random contours, conversion to ISO turning.

Expected values are worked out by hand from the model in the module docstring (facts [GK] of the
Siemens turning cycles manual, choices [NC]): equal infeeds of at most MID from the contour's
outermost point (plus allowance) to its deepest; each cut runs to the contour plus allowance and
follows it back to the previous level; lift-off _VRT in both axes; start point beyond the contour
by allowance + _VRT in both axes."""
from __future__ import annotations

import math

import pytest
from hypothesis import given, settings, strategies as st

from nctrans import api, pipeline
from nctrans.interp import turning
from nctrans.interp.milling_cycles import MillingError
from nctrans.interp.stock_removal import plan
from nctrans.source import from_text

CONTOUR = "ANF: G1 X20 Z0\nZ-10\nX30 Z-15\nENDE: X40\n"


def _run(call: str, contour: str = CONTOUR, start: str = "X60 Z10"):
    text = f"G18 G90 DIAMON T1 D1\nS1000 M3 G95 F0.3\nG0 {start}\n{call}\nG0 X100\nM30\n{contour}"
    ld = pipeline.load_source(from_text(text, "t.mpf"), "t.mpf", "sinumerik")
    recs = [r for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear", "arc") and r.line == 4]
    got = [(r.kind, round(r.end["X"], 6), round(r.end["Z"], 6), r.feed if r.kind != "rapid" else None)
           for r in recs]
    return got, ld.diagnostics, text


def test_complete_longitudinal_outside_by_hand():
    # contour (radius) (10,0) -> (10,-10) -> (15,-15) -> (20,-15); FALX 0.5 (radius), FALZ 0.25,
    # _VRT 1, MID 2: shifted (10.5,0.25) (10.5,-9.75) (15.5,-14.75) (20.5,-14.75); start point
    # A = (20.5+1, 0.25+1); depth 20.5-10.5 = 10 in 5 cuts at 18.5 16.5 14.5 12.5 10.5
    got, diags, _ = _run('CYCLE95("ANF:ENDE", 2, 0.25, 0.5, 0, 0.3, 0.1, 0.1, 9, , , 1)')
    assert not [d for d in diags if d.severity != "info"]
    r, f1, f3 = "rapid", 0.3, 0.1
    want = [(r, 21.5, 1.25, None),
            (r, 18.5, 1.25, None), ("linear", 18.5, -14.75, f1), ("linear", 20.5, -14.75, f1),
            (r, 21.5, -13.75, None), (r, 21.5, 1.25, None),
            (r, 16.5, 1.25, None), ("linear", 16.5, -14.75, f1), ("linear", 18.5, -14.75, f1),
            (r, 19.5, -13.75, None), (r, 19.5, 1.25, None),
            # the taper: d 14.5 at p -9.75 - 4; follow it to its end, then the shoulder to 16.5
            (r, 14.5, 1.25, None), ("linear", 14.5, -13.75, f1), ("linear", 15.5, -14.75, f1),
            ("linear", 16.5, -14.75, f1), (r, 17.5, -13.75, None), (r, 17.5, 1.25, None),
            (r, 12.5, 1.25, None), ("linear", 12.5, -11.75, f1), ("linear", 14.5, -13.75, f1),
            (r, 15.5, -12.75, None), (r, 15.5, 1.25, None),
            (r, 10.5, 1.25, None), ("linear", 10.5, -9.75, f1), ("linear", 12.5, -11.75, f1),
            (r, 13.5, -10.75, None), (r, 13.5, 1.25, None),
            (r, 21.5, 1.25, None),
            # finishing: in at the start's level along Z, the contour at FF3, lift-off, back to A
            (r, 10, 1.25, None), ("linear", 10, 0, f3), ("linear", 10, -10, f3), ("linear", 15, -15, f3),
            ("linear", 20, -15, f3), (r, 21, -15, None), (r, 21.5, -15, None), (r, 21.5, 1.25, None)]
    assert got == [(k, pytest.approx(x), pytest.approx(z), f) for k, x, z, f in want]


def test_roughing_only_and_finishing_only_are_the_two_halves():
    full, _, _ = _run('CYCLE95("ANF:ENDE", 2, 0.25, 0.5, 0, 0.3, 0.1, 0.1, 9, , , 1)')
    rough, _, _ = _run('CYCLE95("ANF:ENDE", 2, 0.25, 0.5, 0, 0.3, 0.1, 0.1, 1, , , 1)')
    finish, _, _ = _run('CYCLE95("ANF:ENDE", 2, 0.25, 0.5, 0, 0.3, 0.1, 0.1, 5, , , 1)')
    assert rough == full[:len(rough)] and rough[-1][1:3] == (21.5, 1.25)
    assert [("rapid", 21.5, 1.25, None)] + full[len(rough):] == finish


def test_contour_subprogram_beside_the_program_and_face_machining(tmp_path):
    # face outside (VARI 2): d = Z steps towards -Z, passes along X from the deep end (Z-4 at X40)
    # towards X0. Contour (radius): (20,-4) -> (10,-4) -> (10,0) -> (0,0); FALZ 0.5, FALX 0, MID 2,
    # _VRT 0 (1 mm): shifted in Z by +0.5; A = (X 21, Z 1.5); levels Z-1.5, Z-3.5
    (tmp_path / "KONT.SPF").write_text("G1 X40 Z-4\nX20\nZ0\nX0\nRET\n")
    (tmp_path / "MAIN.MPF").write_text("G18 G90 DIAMON T1 D1\nS800 M3 G95\nG0 X60 Z10\n"
                                       "CYCLE95(\"KONT\", 2, 0.5, 0, 0, 0.2, 0.1, 0.1, 2)\nM30\n")
    ld = pipeline.load(str(tmp_path / "MAIN.MPF"), "sinumerik")
    got = [(r.kind, round(r.end["X"], 6), round(r.end["Z"], 6)) for r in pipeline.toolpath_of(ld)
           if r.kind in ("rapid", "linear") and r.line == 4]
    assert not [d for d in ld.diagnostics if d.severity != "info"]
    assert got == [("rapid", 21, 1.5),
                   ("rapid", 21, -1.5), ("linear", 10, -1.5), ("linear", 10, 0.5),
                   ("rapid", 11, 1.5), ("rapid", 21, 1.5),         # lift-off: +Z and back along +X
                   ("rapid", 21, -3.5), ("linear", 10, -3.5), ("linear", 10, -1.5),
                   ("rapid", 11, -0.5), ("rapid", 21, -0.5), ("rapid", 21, 1.5)]


def test_fal_is_an_allowance_along_the_normal_by_hand():
    # FAL 0.5 only, roughing, MID 2, _VRT 1. The offset contour: the floor at d 10.5; the 45-degree
    # taper d = -p moved 0.5 along its normal: d + p = 0.5 sqrt 2 (w); the shoulder at p -14.5.
    # Concave corners at the intersections: (10.5, w - 10.5) and (w + 14.5, -14.5); top 20;
    # A = (21, 1); depth 20 - 10.5 = 9.5 in 5 cuts of 1.9.
    got, diags, _ = _run('CYCLE95("ANF:ENDE", 2, 0, 0, 0.5, 0.3, 0.1, 0.1, 1, , , 1)')
    assert not [d for d in diags if d.severity != "info"]
    w = 0.5 * math.sqrt(2)
    r, f1 = "rapid", 0.3
    want = [(r, 21, 1, None),
            (r, 18.1, 1, None), ("linear", 18.1, -14.5, f1), ("linear", 20, -14.5, f1),
            (r, 21, -13.5, None), (r, 21, 1, None),
            (r, 16.2, 1, None), ("linear", 16.2, -14.5, f1), ("linear", 18.1, -14.5, f1),
            (r, 19.1, -13.5, None), (r, 19.1, 1, None),
            (r, 14.3, 1, None), ("linear", 14.3, w - 14.3, f1), ("linear", w + 14.5, -14.5, f1),
            ("linear", 16.2, -14.5, f1), (r, 17.2, -13.5, None), (r, 17.2, 1, None),
            (r, 12.4, 1, None), ("linear", 12.4, w - 12.4, f1), ("linear", 14.3, w - 14.3, f1),
            (r, 15.3, w - 13.3, None), (r, 15.3, 1, None),
            (r, 10.5, 1, None), ("linear", 10.5, w - 10.5, f1), ("linear", 12.4, w - 12.4, f1),
            (r, 13.4, w - 11.4, None), (r, 13.4, 1, None), (r, 21, 1, None)]
    assert got == [(k, pytest.approx(x, abs=1e-6), pytest.approx(z, abs=1e-6), f) for k, x, z, f in want]


@pytest.mark.parametrize("call, contour, rule", [
    ('CYCLE95("ANF:ENDE", 2, 0, 0, 0, 0.3, 0.1, 0.1, 9)', "ANF: G1 X20 Z0\nX30 Z-10\nX26 Z-15\nENDE: X40\n", "NC113"),
    ('CYCLE95("ANF:ENDE", 2, 0, 0, 0, 0.3, 0.1, 0.1, 9, 1, 5)', CONTOUR, "NC113"),
    ('CYCLE95("ANF:ENDE", 2, 0, 0, 0, 0.3, 0.1, 0.1, 13)', CONTOUR, "NC114"),
    ('CYCLE95("ANF:ENDE", 0, 0, 0, 0, 0.3, 0.1, 0.1, 1)', CONTOUR, "NC114"),
    ('CYCLE95("NONE", 2, 0, 0, 0, 0.3, 0.1, 0.1, 9)', CONTOUR, "NC114"),
    ('CYCLE95("ANF:NOEND", 2, 0, 0, 0, 0.3, 0.1, 0.1, 9)', CONTOUR, "NC114"),
])
def test_what_is_not_modelled_or_alarms_moves_nothing_and_says_so(call, contour, rule):
    got, diags, _ = _run(call, contour)
    assert got == []
    assert [d.rule for d in diags if d.line == 4 and d.severity != "info"] == [rule]


def test_converted_to_iso_turning_is_equivalent():
    _, _, text = _run('CYCLE95("ANF:ENDE", 2, 0.25, 0.5, 0, 0.3, 0.1, 0.1, 9, , , 1)')
    conv = api.transpile(text, "sinumerik", "iso-t")
    assert conv.text is not None and "CYCLE95" not in conv.text
    assert api.equiv(text, conv.text, read_a="sinumerik", read_b="iso-t")


# Random monotonic contours (outside longitudinal): radius non-decreasing, Z non-increasing.
steps_ = st.lists(st.tuples(st.sampled_from(["z", "x", "taper"]), st.floats(0.5, 15)), min_size=1, max_size=6)


def _contour(steps):
    pts = [(5.0, 0.0)]
    for kind, v in steps:
        d, p = pts[-1]
        pts.append((d, p - v) if kind == "z" else (d + v, p) if kind == "x" else (d + v / 2, p - v))
    return pts


def _distance_to(pts, q) -> float:
    best = math.inf
    for a, b in zip(pts, pts[1:]):
        ax, ay, bx, by = *a, *b
        L = (bx - ax) ** 2 + (by - ay) ** 2
        t = 0.0 if L == 0 else max(0.0, min(1.0, ((q[0] - ax) * (bx - ax) + (q[1] - ay) * (by - ay)) / L))
        best = min(best, math.hypot(q[0] - ax - t * (bx - ax), q[1] - ay - t * (by - ay)))
    return best


def _inside_part(pts, q) -> bool:
    """Strictly inside the part bounded by the contour (outside turning: below it in d)."""
    if not pts[-1][1] < q[1] < pts[0][1]:
        return False
    ds = turning.hits((pts[0][1], pts[0][0]), [("linear", (b[1], b[0]), None, None) for b in pts[1:]], q[1])
    return bool(ds) and q[0] < max(ds) - 1e-7


@settings(max_examples=60, deadline=None)
@given(steps_, st.floats(0.3, 6), st.floats(0, 1), st.floats(0, 1), st.one_of(st.just(0.0), st.floats(0.05, 1)),
       st.one_of(st.just(0.0), st.floats(0.1, 2)), st.sampled_from([1, 5, 9]))
def test_never_below_the_allowance_finishes_on_the_contour_ends_safe(steps, mid, falz, falx, fal, vrt, vari):
    pts = _contour(steps)
    moves = [("linear", q, None, None) for q in pts[1:]]
    p = dict(MID=mid, FALZ=falz, FALX=falx, FAL=fal, VRT=vrt, FF1=0.3, FF3=0.1, VARI=vari)
    try:
        a, out = plan(pts[0], moves, p, face=False, inside=False, what={1: "rough", 5: "finish", 9: "complete"}[vari])
    except MillingError as err:     # a step smaller than FAL: the offset is not modelled (located, NC113)
        assert fal > 0 and err.rule == "NC113" and "FAL" in err.message
        return
    v = vrt or 1.0
    assert a[0] >= max(d for d, _ in pts) + falx + v - 1e-9 and a[1] >= pts[0][1] + falz + v - 1e-9
    assert _distance_to(pts, (a[0] - falx, a[1] - falz)) >= fal + v - 1e-6    # clear of the allowance
    assert out[-1][0] == "rapid" and out[-1][1] == pytest.approx(a)     # ends at the start point
    feed, here, finishing = None, None, []
    for s in out:
        if s[0] == "feed":
            feed = s[1]
            continue
        if here is not None and feed == 0.3 and s[0] == "linear":
            for t in (0.0, 0.25, 0.5, 0.75, 1.0):               # roughing: never into contour + allowance
                q = (here[0] + t * (s[1][0] - here[0]) - falx, here[1] + t * (s[1][1] - here[1]) - falz)
                # the part grown by FAL, shifted by FALX/FALZ: the tool stays out of it
                dist = _distance_to(pts, q)
                assert (dist < 1e-6 or not _inside_part(pts, q)) and dist > fal - 1e-6, (q, s)
        if feed == 0.1 and s[0] == "linear":
            finishing.append(s[1])
        here = s[1]
    if vari in (5, 9):                                          # finishing runs the whole contour
        assert [c for q in finishing for c in q] == pytest.approx([c for q in pts for c in q])
    else:
        assert not finishing
    if vari in (1, 9) and max(d for d, _ in pts) > pts[0][0] + 1e-6:
        rough = out[:next((i for i, s in enumerate(out) if s[:2] == ("feed", 0.1)), len(out))]
        cuts = [s[1] for s in rough if s[0] == "linear"]        # the deepest cut reaches the allowance
        if not cuts:                                            # the whole step lies in the allowance
            assert max(d for d, _ in pts) - pts[0][0] <= fal + 1e-6
            return
        deepest = min(cuts, key=lambda q: q[0])                 # on the allowance's boundary
        assert _distance_to(pts, (deepest[0] - falx, deepest[1] - falz)) == pytest.approx(fal, abs=1e-6)


def test_any_values_plan_or_refuse():
    pts = _contour([("z", 10), ("taper", 4), ("x", 5)])
    moves = [("linear", q, None, None) for q in pts[1:]]
    for bad in (dict(MID=float("nan")), dict(MID=1e-9), dict(MID=-1.0), dict(VRT=float("inf"))):
        with pytest.raises(MillingError):
            plan(pts[0], moves, dict(dict(MID=1.0, VARI=1), **bad), False, False, "rough")


def test_a_contour_section_after_m30_is_not_unreachable(tmp_path, capsys):
    from nctrans import cli
    _, _, text = _run('CYCLE95("ANF:ENDE", 2, 0.25, 0.5, 0, 0.3, 0.1, 0.1, 9, , , 1)')
    src = tmp_path / "p.mpf"
    src.write_text(text)
    assert cli.main(["lint", str(src), "--from", "sinumerik", "--fail-on", "warning"]) == 0
    assert "NC112" not in capsys.readouterr().out
    src.write_text(text.replace('"ANF:ENDE"', '"ANX:ENDE"'))          # nothing reaches it now
    cli.main(["lint", str(src), "--from", "sinumerik"])
    assert "NC112" in capsys.readouterr().out
