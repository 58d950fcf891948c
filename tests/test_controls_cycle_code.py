"""Real cycle code runs instead of the built-in model (issue 8): a CYCLE81.SPF beside the program is
executed as the control executes it, with indirect axes (AX[..]=) and $P_AXN3. The file below is
written here in the Sinumerik language to do what the built-in model does (G0 to RFP+SDIS, G1 to
the depth, G0 to RTP); the two must agree move for move over a range of parameter sets."""
from __future__ import annotations

from pathlib import Path

import pytest

from nctrans import pipeline

CYCLE81 = """PROC CYCLE81(REAL RTP, REAL RFP, REAL SDIS, REAL DP, REAL DPR) SAVE SBLOF DISPLOF
; drilling cycle written for this test: approach, drill, retract along the plane's applicate
DEF REAL _ZSD
DEF AXIS _AX
_AX=$P_AXN3
IF DPR<>0 GOTOF _REL
_ZSD=DP
GOTOF _GO
_REL:
_ZSD=RFP-DPR
_GO:
G0 AX[_AX]=RFP+SDIS
G1 AX[_AX]=_ZSD
G0 AX[_AX]=RTP
RET
"""

PROGRAMS = {
    "plain": "G17 G90 G0 X0 Y0 Z50 F100 S1000 M3\nCYCLE81(10, 0, 2, -5)\nG0 X5\nM30\n",
    "dpr": "G17 G90 G0 X3 Y4 Z20 F80 S900 M3\nCYCLE81(10, 1, 2, , 7)\nM30\n",
    "mcall": "G17 G90 G0 X0 Y0 Z50 F100 S1000 M3\nMCALL CYCLE81(10, 0, 2, -5)\nX10\nY10\nX20 Y5\n"
             "MCALL\nX0\nM30\n",
    "zx-plane": "G18 G90 G0 X0 Y40 Z0 F100 S1000 M3\nCYCLE81(30, 5, 1, -10)\nM30\n",
    "mcall-dpr": "G17 G90 G0 X0 Y0 Z50 F120 S1000 M3\nMCALL CYCLE81(5, -2, 1, , 3)\nG1 X10\nG0 Y7\n"
                 "MCALL\nM30\n",
}


def moves(where: Path, text: str):
    path = where / "MAIN.MPF"
    path.write_text(text)
    ld = pipeline.load(str(path), "sinumerik")
    recs = list(pipeline.toolpath_of(ld))
    # NC211 is lint advice on the zx-plane program (drilling outside XY), not a model problem
    bad = [d.format_text() for d in ld.diagnostics if d.severity in ("error", "warning") and d.rule != "NC211"]
    return [(r.kind, {a: round(v, 6) for a, v in r.end.items()}, r.feed)
            for r in recs if r.kind in ("rapid", "linear", "arc")], bad


@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_cycle_file_beside_the_program_runs_and_agrees_with_the_model(tmp_path, name):
    builtin_dir, file_dir = tmp_path / "builtin", tmp_path / "file"
    builtin_dir.mkdir()
    file_dir.mkdir()
    (file_dir / "CYCLE81.SPF").write_text(CYCLE81)
    want, bad_builtin = moves(builtin_dir, PROGRAMS[name])
    got, bad_file = moves(file_dir, PROGRAMS[name])
    assert bad_builtin == [] and bad_file == []
    assert got == want


def test_the_file_is_what_runs(tmp_path):
    # a CYCLE81.SPF that does something else shows that the file, not the model, ran
    (tmp_path / "CYCLE81.SPF").write_text(
        "PROC CYCLE81(REAL RTP, REAL RFP, REAL SDIS, REAL DP, REAL DPR)\nG0 AX[$P_AXN1]=RTP\nRET\n")
    got, _ = moves(tmp_path, "G17 G90 G0 X0 Y0 Z50\nCYCLE81(10, 0, 2, -5)\nM30\n")
    assert [m[1] for m in got] == [{"X": 0, "Y": 0, "Z": 50}, {"X": 10, "Y": 0, "Z": 50}]
