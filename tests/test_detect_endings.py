"""A Sinumerik file ending (.mpf/.spf) with only plain word blocks is Sinumerik (issue #8).

Plain blocks (G0 X10, M30) are valid in every dialect, so they must not outvote an ending that only
one dialect uses; content that only another dialect has (#1=, an ISO comment) still counts.
"""
from __future__ import annotations

import subprocess
import sys

from hypothesis import given, strategies as st

from nctrans.detection import detect

SHORT = {
    "a.mpf": "G0 X10 Y10\nG1 X20 F100\nG0 Z50\nM30\n",
    "b.mpf": "N10 G0 X10 Y10\nN20 G1 X20 F100\nN30 G0 Z50\nN40 M30\n",
    "c.mpf": "T1 D1\nG0 X10 Y10 Z5\nG1 Z-2 F100\nM30\n",
    "sub.spf": "G0 X10\nM17\n",
}


def test_short_plain_sinumerik_files_are_told_by_their_ending(tmp_path):
    for name, text in SHORT.items():
        (tmp_path / name).write_text(text)
        g = detect(text, name)
        assert g.dialect == "sinumerik" and not g.ambiguous, (name, g.describe())
    # the same text under a shared ending stays ISO, and without a name it has no ending to decide
    assert detect(SHORT["a.mpf"], "a.nc").dialect == "iso-m"
    out = subprocess.run([sys.executable, "-m", "nctrans", "detect", *sorted(SHORT)], cwd=tmp_path,
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
    assert out.stdout.count("sinumerik (confidence 1.00)") == 4, out.stdout


def test_content_only_another_dialect_has_still_counts_against_the_ending():
    g = detect("#1=5\nG0 X#1\nM98 P100\nM30\n", "a.mpf")
    assert g.dialect == "iso-m", g.describe()
    g = detect("G0 X1 (HOLE)\nM30\n", "a.mpf")          # an ISO comment in a .mpf: really ambiguous
    assert g.ambiguous and g.dialect is None, g.describe()


_WORD = st.sampled_from(["G0", "G1", "G90", "G17", "M3", "M5", "S1000", "F200", "X1.5", "Y-2", "Z10", "T1", "D1"])


@given(st.lists(st.lists(_WORD, min_size=1, max_size=5), min_size=1, max_size=6),
       st.sampled_from([".mpf", ".spf", ".MPF", ".SPF"]))
def test_any_plain_word_program_with_a_sinumerik_ending_is_sinumerik(blocks, ending):
    text = "".join(" ".join(b) + "\n" for b in blocks)
    assert detect(text, "part" + ending).dialect == "sinumerik"
