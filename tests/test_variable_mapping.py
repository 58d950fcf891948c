"""Variables between Sinumerik (DEF names, arrays, R parameters) and ISO (# numbers): the ISO output
names where each variable went in comments, keeps the toolpath, and what ISO cannot hold (strings,
frames) is refused at that construct's line only."""
from __future__ import annotations

from nctrans import api
from nctrans.dialects.base import get

SOURCE = ("DEF REAL LEN=4, ARR[3]\nDEF INT II\nR7=2\nARR[1]=LEN*R7\nFOR II=0 TO 2\n"
          "G1 X=ARR[II]+II Y=R7 F100\nENDFOR\nM30\n")


def test_the_name_table_is_written_as_comments_and_the_toolpath_kept():
    conv = api.transpile(SOURCE, read="sinumerik", write="iso-m")
    lines = conv.text.splitlines()
    table = [x for x in lines if x.startswith("(VAR ")]
    # hand-checked against the assignments the output makes
    assert table == ["(VAR LEN = #100)", "(VAR II = #101)", "(VAR R7 = #507)", "(VAR ARR[3] = #508..#510)"]
    assert "#100=4" in lines and "#509=#100*#507" in lines
    assert lines.index(table[0]) < lines.index("#100=4")        # the table precedes the program
    assert api.equiv(SOURCE, conv.text, read_a="sinumerik", read_b="iso-m")


def test_strings_and_frames_are_refused_at_their_own_lines_only():
    src = ('DEF STRING[10] SA="AB"\nDEF FRAME FR1\nDEF REAL LEN=4\nG1 X=LEN F100\n'
           "FR1=CTRANS(X,10)\nG1 X0\nM30\n")
    out = get("iso-m").emit(get("sinumerik").parse(src, "a.mpf").program)
    refused = sorted(d.line for d in out.diagnostics if d.rule == "NC402")
    assert refused == [1, 2, 5]
    assert "G1 F100. X#100" in out.text            # the rest is written
