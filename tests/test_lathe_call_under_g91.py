"""A subprogram called under G91, converted to ISO turning (system A: no G91, incremental words are
U/W where they are written). The G91 went (nothing to write) and the subprogram, written once from its
own text, kept its X0 Y0 absolute: the helix ran to the origin instead of round the bore, exit 0."""
from __future__ import annotations

from nctrans import api, equivalence, pipeline
from nctrans.source import from_text

# four helical turns of r=5 about (25,20), 1.5 mm down each: Z0 -> Z-6
HELIX = ("%\nO2006\nG21 G17 G90 G40 G80\nT7 M6\nS6000 M3\nG54 G0 X30. Y20.\nG1 Z0 F200.\nG91\n"
         "M98 P2020 L4\nG90\nG1 X30. Y20.\nG0 Z50.\nM30\nO2020\nG3 X0 Y0 Z-1.5 I-5. J0 F300.\nM99\n%\n")


def _records(text: str, dialect: str):
    return list(pipeline.toolpath_of(pipeline.load_source(from_text(text, "p"), "p", dialect)))


def test_a_call_under_g91_is_lowered_for_a_lathe():
    conv = api.transpile(HELIX, "iso-m", "iso-t", file="p.nc")
    assert conv.text is not None
    assert any(d.line == 9 and "under G91" in d.message for d in conv.diagnostics)
    source = _records(HELIX, "iso-m")
    arcs = [r for r in source if r.kind == "arc"]
    assert [round(r.end["Z"], 6) for r in arcs] == [-1.5, -3.0, -4.5, -6.0]
    assert all((round(r.end["X"], 6), round(r.end["Y"], 6)) == (30, 20) for r in arcs)
    assert equivalence.compare(source, _records(conv.text, "iso-t")) is None


def test_a_subprogram_that_sets_g91_itself_is_kept():
    # the G91 is in the subprogram's own text: its X/Z words are written U/W there
    text = ("%\nO2007\nG21 G18 G90 G40\nT1 M6\nG0 X10. Z5.\nM98 P2030 L2\nG0 X50. Z50.\nM30\n"
            "O2030\nG91 G1 X1. Z-1. F100.\nG90\nM99\n%\n")
    conv = api.transpile(text, "iso-m", "iso-t", file="p.nc")
    assert conv.text is not None and "M98 P2030 L2" in conv.text and "U2. W-1." in conv.text
    assert equivalence.compare(_records(text, "iso-m"), _records(conv.text, "iso-t")) is None
