"""Hostile input for the newer control features (issue 15), family by family through the CLI:
contour corner elements on degenerate geometry, SPOS/M19 with extreme angles, the CYCLE93/94/96
grooves and undercuts and the thread cycles with extreme parameters. Each family runs in one
child process held to 700 MiB and 60 s of CPU per command (test_hostile_families.run_all); every
run must end cleanly or with a located diagnostic (assert_sound), its toolpath never carries a
non-finite number or null, and a conversion writes none. tests/fuzz/test_fuzz_controls.py
generates more of the same families."""
from __future__ import annotations

import re

import pytest

from test_hostile_families import assert_sound, run_all

SIN = "G17 G90 G71 T1 D1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z0 F500\n{}\nM30\n"
ISO = "G17 G90 G21 T1 M6\nS1000 M3\nG0 X0 Y0 Z5.\nG1 Z0 F500.\n{}\nM30\n"
LATHE = "G18 G90 DIAMON T1 D1\nS800 M3 G95 F0.1\nG0 X40 Z5\n{}\nG0 X60\nM30\n"
INF = "R9=1EX300*1EX300\n"          # R parameters driven out of range (if the control allows it)

CORNERS = {
    # the corner's line (5) first: a zero-length move before or after it
    "zero-next.mpf": SIN.format("G1 X10 RND=2\nX10\nY10"),
    "zero-this.mpf": SIN.format("G1 X0 CHF=2\nY10"),
    "zero-arc.mpf": SIN.format("G1 X10 CHR=2\nG3 X10 Y0 CR=0"),
    "reversal.mpf": SIN.format("G1 X10 RND=2\nX0"),
    "reversal-arc.mpf": SIN.format("G1 X10 CHR=2\nG3 X0 Y0 CR=5"),
    "huge.mpf": SIN.format("G1 X10 RND=1E6\nY10"),
    "1ex300.mpf": SIN.format("G1 X10 CHF=1EX300\nY10"),
    "inf-var.mpf": SIN.format(INF + "G1 X10 RND=R9\nY10"),
    "nan-var.mpf": SIN.format("G1 X10 RND=SQRT(-1)\nY10"),
    "tiny.mpf": SIN.format("G1 X10 RND=1EX-300\nY10"),
    "full-circle.mpf": SIN.format("G2 X0 Y0 I5 J0 RND=2\nG1 X10"),
    "helix.mpf": SIN.format("G1 X10 RND=2\nG3 X20 Y0 Z-3 CR=5"),
    "rndm.mpf": SIN.format("RNDM=1EX12\nG1 X10\nY10\nX10\nX0\nY0\nRNDM=0"),
    "frc.mpf": SIN.format("G1 X10 RND=2 FRC=1EX300\nY10"),
    "comp.mpf": SIN.format("G41 G1 X10 Y0 RND=50\nY10\nX0\nG40 G1 X-5"),
    "iso-zero.nc": ISO.format("G1 X10. ,R2.\nX10.\nY10."),
    "iso-reversal.nc": ISO.format("G1 X10. ,C2.\nX0"),
    "iso-inf.nc": ISO.format("#9=1" + "0" * 200 + "\n#9=#9*#9\nG1 X10. ,R#9\nY10."),
    "iso-div0.nc": ISO.format("#1=0\nG1 X10. ,C[1/#1]\nY10."),
    "iso-vacant.nc": ISO.format("G1 X10. ,R#100\nY10."),
    # in a turning cycle's contour (a zero-length element was the same ZeroDivisionError)
    "c95.mpf": "G18 G90 DIAMON T1 D1\nS1000 M3 G95 F0.3\nG0 X60 Z10\n"
               'CYCLE95("ANF:ENDE", 2, 0.25, 0.5, 0, 0.3, 0.1, 0.1, 1, , , 1)\nG0 X100\nM30\n'
               "ANF: G1 X20 Z0 RND=1\nX20 Z0\nZ-10 CHR=1\nZ-10\nX30 Z-15\nENDE: X40\n",
    "g71.t.nc": "G18 G90 G21 T0101\nS800 M3 G99 F0.2\nG0 X40. Z5.\nG71 U1. R0.5\nG71 P10 Q20 U0.2 W0.1\n"
                "N10 G0 X20.\nG1 Z0 ,R1.\nZ0\nZ-10. ,C1.\nX30.\nN20 X40.\nG0 X60.\nM30\n",
}
SPOS = {f"spos{i}.mpf": SIN.format(f"{INF}SPOS={v}\nG1 X10\nM3\nG1 Y10") for i, v in enumerate(
    ["1EX300", "-1", "720", "SQRT(-1)", "R9", "IC(1EX300)", "DC(-1EX20)", "ACP(-5)", "IC(SQRT(-1))"])}
SPOS.update({"sposa.mpf": SIN.format("SPOSA=1EX30\nG1 X10"), "spos-index.mpf": SIN.format(f"{INF}SPOS[R9]=45\nG1 X10"),
             "m19.nc": ISO.format("M19 S1.E10\nG1 X10.")})
LATHE_CYCLES = {f"c{i}.mpf": LATHE.format(call) for i, call in enumerate([
    'CYCLE94(0, 0, "E", 3)', 'CYCLE94(1EX300, -20, "E", 3)', 'CYCLE94(30, -20, "E", 1EX20)',
    'CYCLE94(SQRT(-1), -20, "F", 3)', 'CYCLE94("E", 30, -20, 3)', 'CYCLE96(1EX12, -20, "A", 3)',
    'CYCLE96(0.1, -20, "B", 3)', 'CYCLE96(30, SQRT(-1), "B", 3)', 'CYCLE96(30, -20, 5, 3)',
    "CYCLE93(40, -10, 0, 4, 0, 0, 0, 0, 0, 0, 0, 0.2, 0.3, 2, 0.5, 5, 1)",
    "CYCLE93(40, -10, 1EX300, 4, 0, 0, 0, 0, 0, 0, 0, 0.2, 0.3, 2, 0.5, 5, 1)",
    "CYCLE93(40, -10, 8, 4, 0, 0, 0, 0, 0, 0, 0, 0.2, 0.3, 1EX-9, 0.5, 5, 1)",
    "CYCLE93(40, -10, 8, 4, 0, 0, 0, -1EX300, 0, 0, 1, 0.2, 0.3, 2, 0.5, 5, 1)",
    "CYCLE97(1EX300, , 0, -20, 20, 20, 4, 2, 1.2, 0.2, 0, 0, 5, 1, 1, 1)",
    "CYCLE97(2, , 0, -20, 20, 20, 4, 2, 1.2, 0.2, 89.99999, 0, 5, 1, 1, 1)",
    "CYCLE98(0, 20, -10, 25, -20, 30, -30, 30, 2, 2, 1, 1, 1EX300, 1.5, 2, 0.2, 0, 0, 4, 1, 1, 1)",
    "G33 Z-20 K1EX300", "G33 Z-20 K0", "G33 Z-20 K2 SF=1EX300", "G331 Z-20 K0",
])}
MACHINE = 'name = "lathe"\nkind = "lathe"\n[[tools]]\nnumber = 1\ntip = 3\nwidth = 3.0\n'


def _family(tmp_path, programs: dict, target: str, machine: bool = False) -> dict:
    """Every program through lint, toolpath, convert (structural and --flatten) and equiv with
    itself, in one limited child; assert_sound on each, no non-finite number in any output."""
    extra = ["--machine", "m.toml"] if machine else []
    if machine:
        (tmp_path / "m.toml").write_text(MACHINE)
    runs = []
    for name, text in programs.items():
        (tmp_path / name).write_text(text)
        dialect = "iso-t" if name.endswith(".t.nc") else "iso-m" if name.endswith(".nc") else "sinumerik"
        to = target if dialect == "sinumerik" else "sinumerik"
        runs += [["lint", name, "--from", dialect, *extra], ["toolpath", name, "--from", dialect, *extra],
                 ["convert", name, "--from", dialect, "--to", to, *extra, "-o", f"{name}.out"],
                 ["convert", name, "--from", dialect, "--to", to, "--flatten", *extra, "-o", f"{name}.flat"],
                 ["equiv", name, name, "--from-a", dialect, "--from-b", dialect, *extra]]
    results = run_all(runs, tmp_path)
    by = {}
    for argv, rc, out, err in results:
        name = argv[1]
        assert_sound([[argv, rc, out, err]], tmp_path, name)
        if argv[0] == "toolpath":
            assert not re.search(r"null|NaN|Infinity", out), (argv, out[-500:])
        if argv[0] == "convert" and rc == 0:
            written = (tmp_path / argv[argv.index("-o") + 1]).read_text()
            moves = "\n".join(l for l in written.splitlines() if not l.lstrip().startswith((";", "(")))
            assert not re.search(r"\b(nan|inf)\b|\d[eE][+-]?\d", moves, re.IGNORECASE), (argv, moves[-500:])
        by[(argv[0], name, "--flatten" in argv)] = (rc, out + err)
    return by


def located(text: str, rule: str, file: str, line: int) -> bool:
    return re.search(rf"^{re.escape(file)}:{line}:\d+: \w+\[{rule}\]", text, re.M) is not None


def test_corner_elements_on_degenerate_geometry(tmp_path):
    by = _family(tmp_path, CORNERS, "iso-m")
    # a zero-length move beside the corner was a ZeroDivisionError (internal error) in every
    # command; the element is not inserted and that is said at its line
    rc, text = by[("lint", "zero-this.mpf", False)]
    assert located(text, "NC217", "zero-this.mpf", 5) and "no length in the plane" in text, text
    # a move of no length after the corner's block counts as a block without motion (issue #8):
    # the rounding goes to the next block that moves, (8, 0) to (10, 2)
    rc, text = by[("lint", "zero-next.mpf", False)]
    assert rc == 0 and "NC217" not in text, text
    rc, text = by[("toolpath", "zero-next.mpf", False)]
    assert '"kind":"arc"' in text and '"end":{"X":10.0,"Y":2.0' in text, text
    rc, text = by[("lint", "zero-arc.mpf", False)]
    assert rc == 1 and located(text, "NC203", "zero-arc.mpf", 6), text       # an arc of radius 0
    rc, text = by[("lint", "iso-zero.nc", False)]
    assert rc == 1 and located(text, "NC218", "iso-zero.nc", 5), text
    rc, text = by[("lint", "c95.mpf", False)]
    assert located(text, "NC217", "c95.mpf", 7) and located(text, "NC217", "c95.mpf", 9), text
    rc, text = by[("lint", "g71.t.nc", False)]
    assert rc == 1 and located(text, "NC218", "g71.t.nc", 7), text
    rc, text = by[("lint", "inf-var.mpf", False)]
    assert rc == 1, text


def test_spindle_positions_with_extreme_angles(tmp_path):
    _family(tmp_path, SPOS, "iso-m")


def test_grooves_undercuts_and_threads_with_extreme_parameters(tmp_path):
    _family(tmp_path, LATHE_CYCLES, "iso-t", machine=True)
