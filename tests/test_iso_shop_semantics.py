"""ISO constructs real Fanuc/Haas shop programs use, as the controls run them (issue 8): #3006
stops with its message, G31's probing move is not run as the modal G0, G10 L11/L13 write wear
(added to the geometry, not replacing it), and the Haas local subprogram call M97 P<n>.
Positions computed by hand in the comments."""
from __future__ import annotations

from nctrans import pipeline
from nctrans.ir import nodes as n
from nctrans.source import from_text


def run(text: str):
    ld = pipeline.load_source(from_text(text, "t.nc"), "t.nc", "iso-m")
    recs = list(pipeline.toolpath_of(ld))
    return recs, ld.diagnostics, ld.program


def ends(recs):
    return [tuple(round(r.end[a], 6) for a in ("X", "Y", "Z"))
            for r in recs if r.kind in ("rapid", "linear", "arc")]


def test_3006_stops_with_its_message():
    recs, diags, prog = run("G0 X1\n#3006=1 (CHECK PART)\nG0 X2\nM30\n")
    assert [(r.line, r.kind, r.stop_kind) for r in recs if r.kind == "stop"] == [
        (2, "stop", "stop"), (4, "stop", "end")]
    body = prog.body[1].body
    assert [type(s).__name__ for s in body] == ["Message", "Stop"]
    assert body[0].text.value == "CHECK PART"
    assert diags == []


def test_3006_after_then_stops_only_when_true():
    recs, _, _ = run("#1=1\nIF[#1EQ1]THEN#3006=1\nIF[#1EQ2]THEN#3006=2\nM30\n")
    assert [r.line for r in recs if r.kind == "stop" and r.stop_kind == "stop"] == [2]


def test_g31_moves_nothing_and_the_next_block_runs_modal():
    # G0 modal: before, G31 Z-10 ran as a rapid to Z-10; now it is left out (NC220) and the
    # next block without a motion code moves with G0 again
    recs, diags, _ = run("G0 X0 Y0 Z10\nG31 Z-10 F100\nZ20\nX5\nM30\n")
    assert ends(recs) == [(0, 0, 10), (0, 0, 20), (5, 0, 20)]
    assert [(d.line, d.rule) for d in diags] == [(2, "NC220")]


def test_g10_wear_adds_to_the_geometry():
    # L10 H1 = 50, L11 wear -0.2 -> 49.8; a second L10 keeps the wear: 60 - 0.2
    recs, diags, _ = run("G10 L10 P1 R50.\nG10 L11 P1 R-0.2\nG43 H1 G0 Z0\n"
                         "G10 L10 P1 R60.\nG43 H1 G0 Z0\n#100=#2001\n#101=#2201\n"
                         "G49 G0 Z[#100+#101/10]\nM30\n")
    # #2001 reads the geometry (60), #2201 the wear (-0.2): Z = 60 - 0.02
    assert ends(recs) == [(0, 0, 49.8), (0, 0, 59.8), (0, 0, 59.98)]
    assert diags == []


def test_haas_m97_calls_the_numbered_blocks_up_to_m99():
    text = ("(HAAS VF2)\nG0 X0 Y0 Z5\nM97 P100\nG0 X10\nM97 P100\nM30\n"
            "N100 G1 Z-1 F100\nG0 Z5\nM99\n")
    recs, diags, prog = run(text)
    # each call plunges at the current XY and comes back up; the blocks after M30 run only there
    assert ends(recs) == [(0, 0, 5), (0, 0, -1), (0, 0, 5), (10, 0, 5), (10, 0, -1), (10, 0, 5)]
    assert "N100" in prog.subprograms
    assert type(prog.subprograms["N100"].body[-1].body[-1]) is n.Return
    assert diags == []


def test_m97_with_an_address_makes_the_program_a_haas_program():
    # a Fanuc M97 (interrupt disarm) stands alone in its block, else the control alarms (seed
    # sinumerik-iso-milling L4113): "M97 P100" is the Haas local call whatever the header says.
    # It was read as the Fanuc M97 with P kept verbatim (NC403), and the local M99 as a restart
    recs, diags, prog = run("G0 X0 Y0 Z5\nM97 P100\nM30\nN100 G1 Z-1 F100\nM99\n")
    assert ends(recs) == [(0, 0, 5), (0, 0, -1)]
    assert [(d.line, d.rule, d.severity) for d in diags] == [(2, "NC407", "info")]
    assert prog.meta["profile"] == "haas" and "N100" in prog.subprograms


def test_a_bare_m97_stays_the_interrupt_disarm():
    recs, diags, prog = run("G0 X0 Y0 Z5\nM97\n(M97 P100 IN A COMMENT)\nM30\n")
    assert ends(recs) == [(0, 0, 5)]
    assert not prog.meta.get("profile") and not [d for d in diags if d.rule == "NC407"]


# M97 P100 L2 (no header naming the control): N100..M99 runs twice from (0,0,5), incremental:
# X+10 -> (10,0), Y+5 -> (10,5), X+10 -> (20,5), Y+5 -> (20,10); then G0 X50 Y0 absolute
M97_REPEATED = ("%\nO1234 (PART 7)\nG21 G90 G17 G40 G80\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5.\nM97 P100 L2\n"
                "G0 X50. Y0\nM30\nN100 G91 G1 X10. F100.\nY5.\nG90\nM99\n%\n")


def test_m97_repeat_count_runs_the_local_blocks_again():
    recs, diags, _ = run(M97_REPEATED)
    assert ends(recs) == [(0, 0, 5), (10, 0, 5), (10, 5, 5), (20, 5, 5), (20, 10, 5), (50, 0, 5)]
    assert [d.rule for d in diags] == ["NC407"]


def test_m97_converts_to_every_target_with_the_same_toolpath():
    from nctrans import api, equivalence
    source = run(M97_REPEATED)[0]
    for target in ("sinumerik", "fagor", "iso-m", "iso-t"):
        conv = api.transpile(M97_REPEATED, "iso-m", target, file="p.nc")
        assert conv.text is not None, (target, conv.diagnostics)
        back = pipeline.load_source(from_text(conv.text, "q"), "q", target)
        assert equivalence.compare(source, list(pipeline.toolpath_of(back))) is None, target
        if target == "sinumerik":
            # the local subprogram N100 as a valid Sinumerik name (two letters first, seed L839:
            # "N100" read back as a block number), called twice with P2; it was "N100() P2"
            assert "N_100 P2" in conv.text.splitlines() and "PROC N_100" in conv.text
            assert "LOOP" not in conv.text
