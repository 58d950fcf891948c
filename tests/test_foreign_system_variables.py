"""Another control's system variable in Sinumerik output: by its neutral meaning, or refused at its
line (then lowered where the run knows its value). Fagor V.E.<name> interface variables (machine-
wide HMI/OEM data) were written verbatim (`V.E.LAYERS=3`), names a Sinumerik control does not know."""
from __future__ import annotations

from nctrans import api, equivalence, pipeline
from nctrans.source import from_text

# three layers, one per pass of the $FOR: Z-1, Z-2, Z-3, each with a cut to X10
LAYERS = ("%O1000\nG17 G71 G90\nT1 D1 M6\nS1000 M3\nG0 X0 Y0 Z5\nV.E.LAYERS=3\n"
          "$FOR V.E.K=1,V.E.LAYERS,1\nG1 Z-V.E.K F100\nG1 X10\nG0 Z5 X0\n$ENDFOR\nM30\n")


def _run(text: str, dialect: str):
    ld = pipeline.load_source(from_text(text, "p"), "p", dialect)
    return list(pipeline.toolpath_of(ld))


def test_a_fagor_interface_variable_is_not_written_into_sinumerik():
    conv = api.transpile(LAYERS, "fagor", "sinumerik", file="p.fgr")
    assert conv.text is not None
    assert "V.E." not in conv.text
    notes = [d for d in conv.diagnostics if d.rule == "NC401" and "V.E.LAYERS" in d.message]
    assert [d.line for d in notes] == [6]
    # the loop ran out as plain motion: the three plunges by hand (Z-1, Z-2, Z-3)
    plunges = [line for line in conv.text.splitlines() if "Z-" in line]
    assert [p.split("Z")[-1] for p in plunges] == ["-1", "-2", "-3"]
    assert equivalence.compare(_run(LAYERS, "fagor"), _run(conv.text, "sinumerik")) is None


def test_strict_refuses_it_at_its_line():
    conv = api.transpile(LAYERS, "fagor", "sinumerik", file="p.fgr", strict=True)
    assert conv.text is None
    assert any(d.severity == "error" and d.line == 6 and "V.E.LAYERS" in d.message
               for d in conv.diagnostics)
