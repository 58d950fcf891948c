"""Constructs that real Sinumerik and ISO programs from outside the corpus showed wrong or silent
(issue 8, wave 13), each reproduced by a hand-written minimal program with hand-computed values:

- `TRANS AX[AXVAR]=10` (a grinding machine's dresser programs name their axes through DEF AXIS
  variables): AX[..] is the axis address written indirectly (seed L1422), so in a frame
  instruction it is the frame's value for that axis. It was read as a motion to 10 and the
  translation dropped, with no word.
"""
from __future__ import annotations

import nctrans


def _ends(text: str, dialect: str) -> list[tuple]:
    """(X, Z) of each motion record's end point."""
    return [(round(r.end["X"], 6), round(r.end["Z"], 6)) for r in nctrans.toolpath(text, dialect)
            if r.kind in ("linear", "rapid", "arc")]


# ------------------------------------------------------------- frames with an indirect axis

AXFRAME = """DEF AXIS AXH
AXH=AXNAME("X")
G18 G90 G1 X0 Z0 F100
TRANS AX[AXH]=10 Z=5
G1 X3 Z1
ATRANS AX[AXH]=1
G1 X3
TRANS
G1 X4
M30
"""


def test_trans_with_an_axis_variable_shifts_that_axis():
    # TRANS X10 Z5 moves nothing; X3 Z1 -> X 10+3 = 13, Z 5+1 = 6; ATRANS adds 1 to X:
    # X3 -> 10+1+3 = 14 (Z stays 6); TRANS alone clears the frame: X4 -> 4
    assert _ends(AXFRAME, "sinumerik") == [(0.0, 0.0), (13.0, 6.0), (14.0, 6.0), (4.0, 6.0)]


def test_a_literal_axis_in_ax_brackets_is_the_same_frame():
    src = "G18 G90 G1 X0 Z0 F100\nTRANS AX[X]=10\nG1 X3\nM30\n"
    assert _ends(src, "sinumerik") == [(0.0, 0.0), (13.0, 0.0)]            # was X10, then X3


def test_the_frame_is_written_back_with_its_indirect_axis():
    conv = nctrans.transpile(AXFRAME, read="sinumerik", write="sinumerik")
    assert "TRANS Z5 AX[AXH]=10" in conv.text.splitlines()
    assert "ATRANS AX[AXH]=1" in conv.text.splitlines()
    assert nctrans.equiv(AXFRAME, conv.text, read_a="sinumerik", read_b="sinumerik")


def test_iso_cannot_name_the_axis_so_the_motion_is_flattened_and_equivalent():
    conv = nctrans.transpile(AXFRAME, read="sinumerik", write="iso-m")
    assert conv.text is not None
    assert nctrans.equiv(AXFRAME, conv.text, read_a="sinumerik", read_b="iso-m")


# ------------------------------------------------------------- a PROC library against its ISO file

LIBRARY = "PROC SQUARE\nG91 G1 X10 F200\nY10\nG90\nRET\n"


def test_a_proc_library_and_its_iso_conversion_compare_as_called(tmp_path):
    # run alone the library runs nothing and its O-number conversion runs its body (X+10, Y+10):
    # they differed at the first move. A one-line caller runs each: from X0 Y0, X10 then X10 Y10
    conv = nctrans.transpile(LIBRARY, read="sinumerik", write="iso-m")
    lib, iso = tmp_path / "SQUARE.SPF", tmp_path / "square.nc"
    lib.write_text(LIBRARY)
    iso.write_text(conv.text)
    result = nctrans.equiv(lib, iso, read_a="sinumerik", read_b="iso-m")
    assert result, result.message
    assert result.records == (3, 3)                  # two feed moves and the caller's end, each side


def test_a_different_subprogram_is_a_difference_named_in_the_files_given(tmp_path):
    conv = nctrans.transpile(LIBRARY, read="sinumerik", write="iso-m")
    lib, iso = tmp_path / "SQUARE.SPF", tmp_path / "square.nc"
    lib.write_text(LIBRARY)
    iso.write_text(conv.text.replace("X10.", "X5."))      # the converted file edited: X+5
    result = nctrans.equiv(lib, iso, read_a="sinumerik", read_b="iso-m")
    assert not result
    # A's first move ends at X10 (SQUARE.SPF line 2), B's at X5: each named by the file given
    assert result.difference.a.file == str(lib) and result.difference.a.line == 2
    assert result.difference.b.file == str(iso)


# ------------------------------------------------------------- equiv: an M5 before any M3

def test_a_spindle_stop_before_any_start_is_no_difference():
    # a student program stops a spindle it never started (M5 with the G28 home), its Fagor
    # conversion lowered that stretch to plain motion, which writes state changes only: no M5.
    # Both spindles are off from power-on to the end: the same machine behaviour
    with_stop = "G21 G90 G54\nG0 X10 Y10 Z50\nG28 G91 Z0 M05\nG90 G0 X0\nM30\n"
    without = "G21 G90 G54\nG0 X10 Y10 Z50\nG28 G91 Z0\nG90 G0 X0\nM30\n"
    assert nctrans.equiv(with_stop, without, read_a="iso-m", read_b="iso-m")
    # a stop after a start still counts: M3 ... M5 against M3 with no stop differs
    started = "S1000 M3\n" + with_stop
    assert not nctrans.equiv(started, "S1000 M3\n" + without, read_a="iso-m", read_b="iso-m")


def test_the_real_conversion_that_lost_the_idle_m5_is_equivalent():
    # excerpt of the shape of O00021 (NIMS level 2): T20 M06 and S1254 but no M03, the face pass,
    # then G28 G91 Y0 M05; Fagor cannot say G28 and lowers those blocks to plain motion
    src = ("G90 G80 G40 G21\nT20 M06\nS1254\nG00 G90 G54 X-141. Y-25.\nG43 Z50. H20\nG01 Z0 F564.\n"
           "G01 X50. F1128.\nG00 Z50.\nG28 G91 Z0 M09\nG28 G91 Y0 M05\nM30\n")
    conv = nctrans.transpile(src, read="iso-m", write="fagor")
    assert conv.text is not None
    assert nctrans.equiv(src, conv.text, read_a="iso-m", read_b="fagor")


# ------------------------------------------------------------- an unknown M code, said once

def test_an_unknown_m_code_is_said_once_by_lint_and_once_by_convert():
    # Shelton's lathe programs start the spindle with M93; lint said NC220 (not modelled) and
    # NC403 (kept verbatim, the conversion's word) at the same line for the one code
    src = "G21 G90 G54\nG0 X10 M93\nM30\n"
    assert [d.rule for d in nctrans.lint(src, "iso-m") if d.line == 2] == ["NC220"]
    conv = nctrans.transpile(src, read="iso-m", write="sinumerik")
    assert [d.rule for d in conv.diagnostics if d.line == 2] == ["NC403"]


def test_a_kept_word_of_another_construct_on_the_line_stays():
    # G31 P2 (a skip with a signal number): NC220 names G31, NC403 names P2: two things
    src = "G21 G90 G54\nG91 G31 P2 Z-10. F100\nM30\n"
    rules = sorted(d.rule for d in nctrans.lint(src, "iso-m") if d.line == 2)
    assert "NC220" in rules and "NC403" in rules


def test_a_conversion_that_keeps_the_library_name_is_compared_as_before(tmp_path):
    # the Fagor conversion of a PROC file is called by the same name: one directory cannot hold
    # both files under names only their own caller finds, so the pair is compared as given (both
    # run nothing: equivalent), not with one caller reading the other's file (it read the
    # Sinumerik text as Fagor: NC129 syntax errors, then a difference)
    src = "PROC PROBEOFF\nM96\nG4 F0.1\nRET\n"
    conv = nctrans.transpile(src, read="sinumerik", write="fagor")
    assert conv.text is not None
    lib = tmp_path / "PROBEOFF.SPF"
    lib.write_text(src)
    result = nctrans.equiv(lib, conv.text, read_a="sinumerik", read_b="fagor")
    assert result, result.message
    assert not [d for d in result.diagnostics if d.rule == "NC129"]


def test_a_library_that_calls_a_sibling_is_compared_with_it_wherever_it_is_run(tmp_path, monkeypatch):
    """Review of wave 13: the callers searched only the temporary directory and --search-path, so
    the subprogram the library calls (beside it) was found from one working directory and not from
    another: "equivalent" from the first, the called part never compared. The given files' own
    directories are searched now: the sibling's move (X30 Y5, edited to X31 on one side) counts."""
    lib_dir, iso_dir = tmp_path / "lib", tmp_path / "conv"
    lib_dir.mkdir()
    iso_dir.mkdir()
    (lib_dir / "LIBH.SPF").write_text("PROC LIBH\nG1 X10 Y10 F200\nHELPR\nM17\n")
    (lib_dir / "HELPR.SPF").write_text("PROC HELPR\nG1 X30 Y5\nM17\n")
    for name in ("LIBH", "HELPR"):
        conv = nctrans.transpile((lib_dir / f"{name}.SPF").read_text(), read="sinumerik",
                                 write="iso-m")
        number = conv.text.split("\n")[1].split()[0]            # the O-number line: O9115
        (iso_dir / f"{number}.nc").write_text(conv.text)
        (iso_dir / f"{name}.nc").write_text(conv.text)
    for cwd in (tmp_path, iso_dir):
        monkeypatch.chdir(cwd)
        same = nctrans.equiv(lib_dir / "LIBH.SPF", iso_dir / "LIBH.nc", read_a="sinumerik",
                             read_b="iso-m")
        assert same, same.message
        assert same.records == (3, 3)          # X10 Y10, the sibling's X30 Y5, the caller's end
    (lib_dir / "HELPR.SPF").write_text("PROC HELPR\nG1 X31 Y5\nM17\n")
    monkeypatch.chdir(tmp_path)
    differs = nctrans.equiv(lib_dir / "LIBH.SPF", iso_dir / "LIBH.nc", read_a="sinumerik",
                            read_b="iso-m")
    assert not differs
    assert differs.difference.a.file.endswith("HELPR.SPF") and differs.difference.a.line == 2
