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
