"""A Sinumerik file whose program header `%_N_NAME_MPF` follows a comment line: the comment belongs
to that program. The header used to open a second, uncalled unit after an empty main program, so
the file ran nothing (no record, no diagnostic, exit 0) and converted to an empty program."""
from __future__ import annotations

from nctrans import api, pipeline
from nctrans.source import from_text

TEXT = ("; pocket, roughing\n%_N_POCKET_MPF\nG17 G90 G71 G54\nT3 D1 M6\nS4500 M3 F600\nG0 X0 Y0 Z5\n"
        "G1 Z-2 F150\nG1 X30 F600\nM30\n")


def test_a_comment_before_the_header_belongs_to_the_program():
    ld = pipeline.load_source(from_text(TEXT, "p.mpf"), "p.mpf", "sinumerik")
    assert not ld.program.subprograms and ld.program.name == "POCKET"
    ends = [(r.end["X"], r.end["Z"]) for r in pipeline.toolpath_of(ld) if r.kind in ("rapid", "linear")]
    assert ends == [(0, 5), (0, -2), (30, -2)]


def test_it_converts_with_its_motion():
    conv = api.transpile(TEXT, "sinumerik", "iso-m", file="p.mpf")
    assert conv.text is not None and "X30." in conv.text and "O9995" not in conv.text


def test_a_second_header_after_code_still_opens_a_subprogram():
    text = TEXT.replace("M30\n", "L10\nM30\n") + "%_N_L10_SPF\nG0 Z20\nM17\n"
    ld = pipeline.load_source(from_text(text, "p.mpf"), "p.mpf", "sinumerik")
    assert "L10" in ld.program.subprograms
