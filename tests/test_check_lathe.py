"""`nctrans check` on a lathe: the tool tip against the chuck and the tailstock, given in the
machine model as cylinders about the spindle axis (they turn with the part, so each sweeps the
ring |X| <= radius between its Z ends).

The machine below: chuck radius 80 from Z-100 to Z-50, tailstock quill radius 15 from Z150 to
Z300, T1 with a 0.8 mm nose radius; G54 is zero. X is programmed as a diameter (ISO turning), so
X100 is radius 50. Depths are worked out by hand: the nearest face of the rectangle grown by 0.8.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from nctrans import pipeline
from nctrans.check import check_loaded

LATHE = """
name = "test-lathe"
kind = "lathe"
[axes.X]
min = -10.0
max = 300.0
[axes.Z]
min = -200.0
max = 400.0
[spindle]
max_rpm = 4000
[[tools]]
number = 1
radius = 0.8
tip = 3
[[fixtures]]
name = "chuck"
cylinder = { radius = 80.0, z_min = -100.0, z_max = -50.0 }
[[fixtures]]
name = "tailstock"
cylinder = { radius = 15.0, z_min = 150.0, z_max = 300.0 }
"""

HEAD = "G21 G18 G40\nT0101\nG97 S1000 M3\nG0 X100 Z5\n"     # lines 1-4: tip at radius 50, Z5


def collisions(tmp_path: Path, body: str, machine: str = LATHE, dialect: str = "iso-t", name: str = "p.nc",
               head: str = HEAD):
    (tmp_path / name).write_text(head + body + "M30\n")
    (tmp_path / "m.toml").write_text(machine)
    m = pipeline.load_machine(str(tmp_path / "m.toml"))
    diags, result = check_loaded(pipeline.load(str(tmp_path / name), dialect, stream=True), m)
    assert not [d for d in diags if d.severity == "error" and not d.rule.startswith("NC3")], diags
    assert not [f for f in result.findings if f.rule == "NC306"]
    return [f for f in result.findings if f.rule == "NC310"]


def test_turning_into_the_chuck_is_found_and_stopping_short_is_not(tmp_path):
    [f] = collisions(tmp_path, "G1 Z-60 F0.2\n")
    assert (f.line, f.subject) == (5, "chuck")
    assert f.amount == pytest.approx(10.8)                  # Z-60 is 10 past the face, + 0.8 nose
    assert f.position == {"X": pytest.approx(50.0), "Z": pytest.approx(-60.0)}
    assert not collisions(tmp_path, "G1 Z-49 F0.2\n")       # 1 mm short of the face, 0.2 clear


def test_rapid_into_the_tailstock_and_passing_beside_it(tmp_path):
    # X20 is radius 10: inside the quill (15) by 5 + 0.8; X40 (radius 20) passes 4.2 clear
    [f] = collisions(tmp_path, "G0 X200\nZ160\nX20\n")
    assert (f.line, f.subject) == (7, "tailstock") and f.amount == pytest.approx(5.8)
    assert not collisions(tmp_path, "G0 X200\nZ160\nX40\n")


def test_a_move_that_crosses_the_chuck_between_legal_end_points(tmp_path):
    # from (radius 100, Z-40) to (radius 60, Z-110): both ends are outside the ring, the line
    # passes through it. Along it x = 100 - 40t, z = -40 - 70t; inside the grown ring (|X| <= 80.8,
    # -100.8 <= Z <= -49.2) the depth is min(40t - 19.2, 60.8 - 70t, 70t - 9.2), largest where the
    # first two meet: t = 80/110, depth 40 * 80/110 - 19.2 = 9.8909, at radius 70.909, Z-90.909
    [f] = collisions(tmp_path, "G0 X200 Z-40\nG1 X120 Z-110 F0.2\n")
    assert (f.line, f.subject) == (6, "chuck")
    assert f.amount == pytest.approx(40 * 80 / 110 - 19.2)
    assert f.position == {"X": pytest.approx(100 - 40 * 80 / 110), "Z": pytest.approx(-40 - 70 * 80 / 110)}


def test_an_arc_into_the_chuck(tmp_path):
    # a quarter circle of radius 20 from (radius 90, Z-30) to (radius 70, Z-50): its end touches
    # the chuck face at radius 70, and the 0.8 nose reaches 0.8 into it; nowhere on the arc is Z
    # lower than at its end. The same arc 1.5 mm further out ends 0.7 short of the grown face.
    [f] = collisions(tmp_path, "G0 X180 Z-30\nG2 X140 Z-50 R20 F0.2\n")
    assert (f.line, f.subject) == (6, "chuck") and f.amount == pytest.approx(0.8)
    assert not collisions(tmp_path, "G0 X180 Z-28.5\nG2 X140 Z-48.5 R20 F0.2\n")


def test_the_same_in_sinumerik_and_mesh_fixtures_are_said_to_be_unchecked(tmp_path):
    head = "G18 G90 G54 DIAMON\nT1 D1\nS1000 M3\nG0 X100 Z5\n"
    [f] = collisions(tmp_path, "G1 Z-60 F0.2\n", dialect="sinumerik", name="p.mpf", head=head)
    assert (f.line, f.subject) == (5, "chuck")
    boxy = LATHE + '[[fixtures]]\nname = "steady"\nbox = { min = [100, -10, 0], max = [120, 10, 20] }\n'
    (tmp_path / "b.nc").write_text(HEAD + "M30\n")
    (tmp_path / "b.toml").write_text(boxy)
    m = pipeline.load_machine(str(tmp_path / "b.toml"))
    _, result = check_loaded(pipeline.load(str(tmp_path / "b.nc"), "iso-t", stream=True), m)
    [note] = [f for f in result.findings if f.rule == "NC306"]
    assert "cylinders" in note.message and note.line == 4


def test_a_bad_cylinder_is_refused_with_its_key(tmp_path):
    (tmp_path / "m.toml").write_text(LATHE.replace("z_min = -100.0, z_max = -50.0", "z_min = -50.0, z_max = -100.0"))
    with pytest.raises(pipeline.PipelineError, match="z_min"):
        pipeline.load_machine(str(tmp_path / "m.toml"))


def test_a_real_lathe_program_with_the_chuck_just_clear_and_just_too_close(tmp_path, corpus_dir):
    """A Haas valve (22 mm stock, parted off near Z-54.8, the deepest any tool goes): a chuck face
    at Z-56 leaves T1's grown nose 0.4 mm clear; at Z-54, T1 finishing down to Z-54.534 on line 24
    is the first move into it."""
    src = corpus_dir / "iso-turn" / "enier-haas-valve.nc"
    text = src.read_text(encoding="utf-8", errors="replace")

    def found(face: float):
        machine = LATHE.replace("z_min = -100.0, z_max = -50.0", f"z_min = -150.0, z_max = {face}")
        return collisions(tmp_path, "", machine=machine, head=text.replace("M30", "M05"))
    assert not found(-56.0)
    hits = found(-54.0)
    assert hits and min(f.line for f in hits) == 24 and {f.subject for f in hits} == {"chuck"}
