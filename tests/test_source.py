"""Reading programs: encodings, newlines, control characters, spans, and what is not text at all."""
from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

from nctrans.source import SourceError, decode, from_text, read_source
from conftest import CORPUS



def rules(src):
    return [d.rule for d in src.diagnostics]


def test_utf8_plain_and_with_bom_give_the_same_text():
    body = "G0 X1 (Maß)\nM30\n".encode("utf-8")
    a, b = decode(body, "a.nc"), decode(b"\xef\xbb\xbf" + body, "a.nc")
    assert a.text == b.text == "G0 X1 (Maß)\nM30\n"
    assert (a.encoding, b.encoding) == ("utf-8", "utf-8-sig")
    assert a.diagnostics == b.diagnostics == []


@pytest.mark.parametrize("enc", ["utf-16", "utf-16-le", "utf-16-be"])
def test_utf16_with_or_without_bom_is_nc001(enc):
    src = decode("%\nO1000\nG0 X10 Y10\nM30\n%\n".encode(enc), "w.nc")
    assert rules(src) == ["NC001"]
    d = src.diagnostics[0]
    assert d.severity == "error" and "UTF-16" in d.message and (d.file, d.line, d.column) == ("w.nc", 1, 1)
    assert src.text == "" and not src.ok


def test_binary_data_is_nc001():
    png = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(range(256)) * 4
    assert rules(decode(png, "x.nc")) == ["NC001"]
    noisy = bytes([1, 2, 3, 4, 5, 6, 14, 15, 16]) * 50 + b"G0 X1\n"
    assert rules(decode(noisy)) == ["NC001"]


def test_nul_padding_after_the_program_is_not_binary():
    src = decode(b"G0 X1\nM30\n" + b"\x00" * 300 + b"\x1a")
    assert src.ok and src.text == "G0 X1\nM30\n"


@pytest.mark.parametrize("data", [b"", b"\n\n", b"   \r\n\t\r\n", b"\xef\xbb\xbf"])
def test_empty_file_is_nc004(data):
    src = decode(data, "e.nc")
    assert rules(src) == ["NC004"] and src.diagnostics[0].file == "e.nc"


def test_cp1252_comment_decodes_to_the_right_letters():
    src = decode("G0 X1 (Würfel – Ø10 °C)\n".encode("cp1252"))
    assert src.encoding == "cp1252" and "Würfel – Ø10 °C" in src.text and src.ok


def test_cp1250_comment_is_recognised():
    src = decode("G1 X5 (Łożysko, śruba ąę)\nM30\n".encode("cp1250"))
    assert src.encoding == "cp1250" and "Łożysko, śruba ąę" in src.text


def test_undecodable_8bit_bytes_never_fail():
    src = decode(b"G0 X1 (\x81\x8d\x8f\x90\x9d)\n")
    assert src.ok and src.text.startswith("G0 X1 (")


@pytest.mark.parametrize("nl", [b"\n", b"\r\n", b"\r"])
def test_newlines_normalised_and_lines_indexed(nl):
    src = decode(nl.join([b"G0 X1", b"G1 Y2 F100", b"M30"]))
    assert src.text == "G0 X1\nG1 Y2 F100\nM30\n"
    assert src.line_count == 3
    assert src.line(2) == "G1 Y2 F100"
    assert src.location(src.text.index("Y2")) == (2, 4)
    assert src.offset(2, 4) == src.text.index("Y2")


def test_missing_final_newline_is_added_and_recorded():
    src = decode(b"G0 X1\nM30")
    assert src.text.endswith("M30\n") and not src.had_final_newline
    assert decode(b"M30\n").had_final_newline


def test_stray_controls_become_spaces_and_columns_stay():
    src = decode(b"G0\x0cX1\x7fY2\tZ3\x1a\n")
    assert src.text == "G0 X1 Y2\tZ3 \n"
    assert src.location(src.text.index("Y2")) == (1, 7)


def test_read_source_errors_are_source_errors(tmp_path):
    with pytest.raises(SourceError, match="no such file"):
        read_source(tmp_path / "missing.nc")
    with pytest.raises(SourceError, match="is a directory"):
        read_source(tmp_path)


def test_reading_never_modifies_the_file(tmp_path):
    p = tmp_path / "a.nc"
    raw = b"G0 X1\r\nG1\x07 Y2"
    p.write_bytes(raw)
    read_source(p)
    assert p.read_bytes() == raw


def test_every_corpus_program_reads_as_text_without_diagnostics():
    files = [p for p in CORPUS.rglob("*") if p.is_file() and p.suffix != ".tsv"]
    assert len(files) > 50
    for p in files:
        src = read_source(p)
        assert src.diagnostics == [], p
        assert "\r" not in src.text and src.text.endswith("\n")


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=600))
def test_decode_never_raises_and_output_is_clean(data):
    src = decode(data, "f.nc")
    assert src.encoding
    assert "\r" not in src.text
    assert all(c in "\t\n" or ord(c) >= 0x20 for c in src.text)
    assert not any(0x7F <= ord(c) <= 0x9F for c in src.text)
    if src.text:
        assert src.text.endswith("\n")
    assert all(d.rule in ("NC001", "NC004") and d.severity == "error" for d in src.diagnostics)


printable_lines = st.lists(st.text(st.characters(min_codepoint=0x20, max_codepoint=0x7E) | st.sampled_from("\t\x0b\x0c\x07"),
                                   max_size=40), min_size=1, max_size=12)


@settings(max_examples=200, deadline=None)
@given(printable_lines, st.sampled_from(["\n", "\r\n", "\r"]))
def test_line_and_column_of_every_character_survive_normalisation(lines, nl):
    text = nl.join(lines)
    src = from_text(text)
    for i, line in enumerate(lines, 1):
        got = src.line(i)
        assert len(got) == len(line)                       # one character for one character
        for col, ch in enumerate(line, 1):
            if ch.isprintable() or ch == "\t":
                assert got[col - 1] == ch
                assert src.location(src.offset(i, col)) == (i, col)


@pytest.mark.parametrize("text", ["a\r\nb", "a\rb", "a\r\r\nb\n\rc\r", "\r\n\r\n", "a\x0cb\x7fc\td", "ä\x85x\ufeffy\x01"])
def test_newlines_and_stray_controls_normalised_as_the_plain_regexes_would(text):
    import re
    want = re.sub("[\x00-\x08\x0b-\x1f\x7f-\x9f\ufeff]", " ", re.sub("\r\n?", "\n", text))
    got = from_text(text, "t.nc").text
    assert got == (want if want.endswith("\n") else want + "\n")


def test_a_stray_control_past_the_first_piece_is_normalised():
    """The ASCII check goes a piece at a time: a control in a later piece, or at a piece's
    edge, is still replaced."""
    size = 1 << 16                  # the piece source._ascii_stray checks at a time
    for at in (size - 1, size, 2 * size + 5):
        text = "G0 X1\n" * (3 * size // 6)
        text = text[:at] + "\x0c" + text[at + 1:]
        got = from_text(text, "big.nc").text
        assert len(got) == len(text) and got[at] == " " and "\x0c" not in got
