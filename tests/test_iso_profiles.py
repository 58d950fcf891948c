"""Control profiles of the ISO milling family (rules/iso-m.toml [options.profiles],
nctrans.dialects.iso_m.profiles). A Haas program's #10000-#10999 are plain common variables
(Haas NGC); on a Fanuc 30i the same numbers are tool offsets, so without a profile they stay
refused. The profile is detected from a header comment naming the control."""
from __future__ import annotations

from hypothesis import given, settings, strategies as st

import nctrans
from nctrans import api

HAAS = """%
O2001 (ARCS)
(HAAS MINI MILL)
G20 G90 G17 G54
#10100 = {v}
G0 X0 Y0
G1 X[1. + #10100] Y#10100 F20.
#10101 = #10100 * 2
G1 X#10101
M30
%
"""


def _convert(text: str, tmp_path):
    path = tmp_path / "p.nc"
    path.write_text(text)
    return nctrans.transpile(path, read="iso-m", write="sinumerik")


def test_haas_header_selects_the_haas_profile():
    assert api.parse(HAAS.format(v="0.25"), "iso-m").meta["profile"] == "haas"
    plain = HAAS.format(v="0.25").replace("(HAAS MINI MILL)", "(MINI MILL)")
    assert api.parse(plain, "iso-m").meta["profile"] is None


def test_haas_common_variables_become_r_parameters(tmp_path):
    conv = _convert(HAAS.format(v="0.25"), tmp_path)
    assert conv.text is not None, conv.diagnostics
    assert "R10100=0.25" in conv.text and "R10101=R10100*2" in conv.text


def test_without_the_profile_they_are_not_kept(tmp_path):
    # a 30i reads #10100 as a tool offset: no guess without the Haas header (plain motion only)
    from nctrans.convert import WHOLE_PROGRAM_NOTE
    conv = _convert(HAAS.format(v="0.25").replace("(HAAS MINI MILL)", "(MINI MILL)"), tmp_path)
    assert "R10100" not in (conv.text or "")
    assert any("#10100" in d.message and WHOLE_PROGRAM_NOTE in d.message for d in conv.diagnostics)


@settings(max_examples=20, deadline=None)
@given(v=st.integers(-2000, 2000).map(lambda i: i / 1000))
def test_haas_conversion_is_equiv(v, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("haas")
    src = HAAS.format(v=f"{v:.3f}")
    conv = _convert(src, tmp)
    assert conv.text is not None
    assert api.equiv(src, conv.text, read_a="iso-m", read_b="sinumerik")
    # hand-computed: the last move ends at X = 2v (inch -> mm)
    last = [r for r in nctrans.toolpath(conv.text, dialect="sinumerik") if r.kind == "linear"][-1]
    assert abs(last.end["X"] - 2 * v * 25.4) < 1e-6


PLAIN = "%\nO1\n(MINI MILL)\nG20 G90 G54\n#10100=.5\nG0 X#10100\nM30\n%\n"


def test_the_user_selects_the_profile_on_the_command_line(tmp_path, capsys):
    from nctrans import cli
    src = tmp_path / "p.nc"
    src.write_text(PLAIN)
    assert cli.main(["convert", str(src), "--to", "sinumerik", "-o", str(tmp_path / "p.mpf"),
                     "--profile", "haas"]) == 0
    out = (tmp_path / "p.mpf").read_text()
    assert "R10100=.5" in out and "G0 X=R10100" in out


def test_an_unknown_profile_is_a_usage_error(tmp_path, capsys):
    from nctrans import cli
    src = tmp_path / "p.nc"
    src.write_text(PLAIN)
    assert cli.main(["convert", str(src), "--to", "sinumerik", "-o", str(tmp_path / "p.mpf"),
                     "--profile", "fanuc-30i"]) == 2
    assert "profile 'fanuc-30i' is not one of iso-m's: haas" in capsys.readouterr().err
    assert not (tmp_path / "p.mpf").exists()


def test_api_profile_overrides_detection(tmp_path):
    path = tmp_path / "p.nc"
    path.write_text(PLAIN)
    conv = nctrans.transpile(path, read="iso-m", write="sinumerik", profile="haas")
    assert conv.text is not None and "R10100=.5" in conv.text
