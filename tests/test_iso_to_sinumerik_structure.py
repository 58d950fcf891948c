"""ISO -> Sinumerik conversions that keep structure where the two controls can say the same thing:
computed code words (M#501 -> M=R501), G65 macros as PROCs with named parameters, and system
variables through the one table of neutral meanings. Each conversion is proven with `equiv` and
read back with no error."""
from __future__ import annotations

import nctrans
from nctrans.dialects.base import get


def _converted(src: str):
    conv = nctrans.transpile(src, read="iso-m", write="sinumerik")
    assert conv.ok, [d.format_text() for d in conv.diagnostics if d.severity == "error"]
    back = get("sinumerik").parse(conv.text, "out.mpf")
    assert not [d for d in back.diagnostics if d.severity == "error"], conv.text
    return conv


def _equiv(tmp_path, iso: str, sin: str):
    a, b = tmp_path / "a.nc", tmp_path / "b.mpf"
    a.write_text(iso)
    b.write_text(sin)
    same = nctrans.equiv(a, b, read_a="iso-m", read_b="sinumerik")
    assert same, same.message


def test_computed_m_code_keeps_its_expression(tmp_path):
    src = "G90 G17 G21\n#501=107\nM#501\nG1 X10 F100\nM[#501+1]\nM30\n"
    conv = _converted(src)
    lines = conv.text.splitlines()
    assert "M=R501" in lines and "M=R501+1" in lines
    assert any(d.rule == "NC403" and d.line == 3 for d in conv.diagnostics)
    _equiv(tmp_path, src, conv.text)
