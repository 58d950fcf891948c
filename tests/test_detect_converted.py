"""A file nctrans wrote is read back in the dialect it was written in, without --from.

Its content alone may not tell: a lathe program converted from a Sinumerik or Fagor lathe program
is G0/G1 on X and Z with a T word, and the header comment's own shape ("(...)" or "; ...") speaks
for a family. `equiv a b` read such a file as another dialect (a converted iso-t file as iso-m,
"cannot tell the dialect" for a flattened Sinumerik one) unless given --from-b. The header names
the target (`converted by nctrans V from A to B: file`) and detection reads it."""
from __future__ import annotations

import pytest

import nctrans
from nctrans import cli
from nctrans.detection import detect, written_by_nctrans

ISO_LATHE = ("O2000\nG21 G18 G99\nT0101\nG97 S800 M3\nG0 X40. Z2.\nG1 Z-10. F0.2\nG0 X60. Z20.\n"
             "T0202\nG0 X30. Z2.\nG1 Z-5. F0.2\nG0 X60. Z20.\nM30\n")
SIN_LATHE = "G18 G90 G95 DIAMON\nT1 D1\nG97 S800 M3\nG0 X40 Z2\nG1 Z-10 F0.2\nG0 X60 Z20\nT2 D1\nG0 X30 Z2\nM30\n"
FAGOR_LATHE = "G18 G90 G95 G151\nT1 D1\nG97 S800 M3\nG00 X40 Z2\nG01 Z-10 F0.2\nG00 X60 Z20\nT2 D1\nG00 X30 Z2\nM30\n"
ISO_MILL = "G21 G90 G17\nT1 M6\nG43 H1 G0 X0 Y0 Z10\nG1 Z-1 F100\nX10 Y5\nG0 Z10\nM30\n"

SOURCES = [(ISO_LATHE, "iso-t", "a.nc"), (SIN_LATHE, "sinumerik", "a.mpf"), (FAGOR_LATHE, "fagor", "a.pim"),
           (ISO_MILL, "iso-m", "a.nc")]


def test_the_header_names_the_target():
    conv = nctrans.transpile(SIN_LATHE, read="sinumerik", write="iso-t")
    assert f"from sinumerik to iso-t: " in conv.text.splitlines()[1]
    assert written_by_nctrans(conv.text) == "iso-t"
    assert written_by_nctrans(SIN_LATHE) is None


@pytest.mark.parametrize("text,source,name", SOURCES, ids=[s[1] for s in SOURCES])
@pytest.mark.parametrize("target", ["iso-t", "iso-m", "sinumerik", "fagor"])
def test_equiv_reads_a_converted_file_without_from_b(text, source, name, target, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    conv = nctrans.transpile(text, read=source, write=target)
    assert conv.text is not None, conv.diagnostics
    (tmp_path / name).write_text(text)
    (tmp_path / "out.nc").write_text(conv.text)          # a shared ending says nothing
    assert detect(conv.text, "out.nc").dialect == target
    rc = cli.main(["equiv", name, "out.nc", "--from-a", source])
    out = capsys.readouterr()
    assert rc == 0 and "equivalent" in out.out, out.out + out.err


def test_a_round_trip_iso_t_file_is_iso_t(tmp_path):
    # iso-t -> iso-t names iso-t; a file nctrans wrote before the target was named is detected
    # from its content as before
    conv = nctrans.transpile(ISO_LATHE, read="iso-t", write="iso-t")
    assert detect(conv.text, "x.nc").dialect == "iso-t"
    old = conv.text.replace(" to iso-t:", ":")
    assert written_by_nctrans(old) is None
