"""The regex fast path and the grammar of record must read every plain block the same way, and the
hot lowering must build exactly what the general lowering builds."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

from nctrans.dialects.iso_m.fastpath import fast_words
from nctrans.dialects.iso_m.frontend import Lowering
from nctrans.dialects.iso_m.prelex import clean, strip_comments
from nctrans.dialects.iso_m.words import lark_words
from conftest import CORPUS


digits = st.text(alphabet="0123456789", min_size=1, max_size=6)
number = st.one_of(
    digits,
    st.builds(lambda a, b: f"{a}.{b}", digits, st.text(alphabet="0123456789", max_size=5)),
    st.builds(lambda b: f".{b}", digits),
).flatmap(lambda t: st.sampled_from(["", "-", "+"]).map(lambda s: s + t))
word = st.tuples(st.sampled_from(list("ABCDEFGHIJKLMNPQRSTUVWXYZ")), number)


@settings(max_examples=400, deadline=None)
@given(st.lists(word, min_size=1, max_size=10))
def test_fast_path_equals_grammar_on_plain_blocks(words):
    code = "".join(letter + text for letter, text in words)
    assert fast_words(code) == lark_words(code) == [tuple(w) for w in words]


@settings(max_examples=200, deadline=None)
@given(st.lists(word, min_size=1, max_size=6), st.sampled_from(["", " ", "  ", "\t"]))
def test_spaces_and_case_do_not_change_the_words(words, gap):
    raw = gap.join(f"{letter.lower()}{gap}{text}" for letter, text in words)
    assert fast_words(clean(raw)) == [tuple(w) for w in words]


def _corpus_lines():
    for path in sorted((CORPUS / "iso-mill").glob("*")):
        text = path.read_bytes().decode("utf-8", errors="replace")
        for line in text.split("\n"):
            yield line


def test_fast_path_equals_grammar_on_every_corpus_line():
    checked = 0
    for raw in _corpus_lines():
        code = clean(strip_comments(raw).code)
        fast = fast_words(code) if code else None
        if fast is None:
            continue
        assert fast == lark_words(code), raw
        if "(" not in raw and ";" not in raw and ")" not in raw:
            hot_code = raw.replace(" ", "").removesuffix("\r")
            if fast_words(hot_code) is not None:     # what the hot loop reads without clean()
                assert hot_code == code, raw
        checked += 1
    assert checked > 50000


hot_word = st.one_of(
    st.tuples(st.sampled_from(list("XYZABCUVW")), number),
    st.tuples(st.just("G"), st.sampled_from(["0", "00", "1", "01", "2", "3", "17", "90", "81"])),
    st.tuples(st.just("F"), number),
    st.tuples(st.just("N"), digits),
    st.tuples(st.sampled_from(list("IJKRMPQ")), number),
)


@settings(max_examples=400, deadline=None)
@given(st.lists(hot_word, min_size=1, max_size=6), st.sampled_from([None, "arc_cw", "drill", "arc_abs"]))
def test_hot_lowering_equals_general_lowering(words, state):
    words = [tuple(w) for w in words]
    a, b = Lowering("t.nc", []), Lowering("t.nc", [])
    for low in (a, b):
        if state == "arc_cw":
            low.motion = "arc_cw"
        elif state == "drill":
            low.cycle = "drill"
        elif state == "arc_abs":
            low.motion, low.arc_abs = "arc_ccw", True
    hot = a.hot(words)
    if hot is None:
        return
    number, body, structure, unknown = b.lower(words, 1)
    assert (number, body) == hot[:2]
    assert structure == [] and unknown is None
    assert (a.motion, a.cycle) == (b.motion, b.cycle)


@pytest.mark.parametrize("code", ["G1X1.Y2.F300.", "N10G0Z5.", "X1.5", "N1"])
def test_hot_path_covers_cam_blocks(code):
    assert Lowering("t.nc", []).hot(fast_words(code)) is not None
