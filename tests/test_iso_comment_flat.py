"""ISO output never nests parentheses in a comment: Fanuc ends a comment at its first ")" and LinuxCNC
stops with "Nested comment found" at a "(" inside one, so text carried over from a Sinumerik comment
or function call (`; CHECK (A)`, `SETPIECE(1)`) must still read back as one comment on those controls."""
from __future__ import annotations

import pytest
from hypothesis import given, settings, strategies as st

import rs274 as harness
from nctrans import api

# Sinumerik comment text: anything printable on one line (a ";" comment runs to the end of the line).
comment_text = st.text(st.characters(min_codepoint=0x20, max_codepoint=0x7E), min_size=1, max_size=30) \
    .filter(lambda t: t.strip())


def flat_reading(line: str) -> tuple[str, str]:
    """(code, comment) of an ISO line the Fanuc way: a comment starts at "(" and ends at the first ")"."""
    start = line.index("(")
    end = line.index(")", start)
    return line[:start] + line[end + 1:], line[start + 1:end]


@settings(max_examples=60, deadline=None)
@given(text=comment_text)
def test_a_carried_comment_is_one_flat_comment(text):
    src = f"G0 X1 Y2 ; {text}\nM30\n"
    conv = api.transpile(src, read="sinumerik", write="iso-m")
    assert conv.ok
    line = next(l for l in conv.text.splitlines() if l.startswith("G0"))
    code, comment = flat_reading(line)
    assert code.strip() == "G0 X1. Y2."                 # nothing of the comment is left as code
    assert "(" not in comment
    back = api.lint(conv.text, dialect="iso-m")
    assert not [d for d in back if d.rule.startswith("NC0")]


def test_rs274_reads_a_commented_function_call(tmp_path, rs274):
    src = "G0 X0 Y0\nSETPIECE(1)\nG1 X10 F100 ; CHECK (A) AND (B)\nM30\n"
    conv = api.transpile(src, read="sinumerik", write="iso-m")
    assert conv.ok
    program = tmp_path / "flat.ngc"
    program.write_text(conv.text, encoding="ascii")
    tools = harness.write_tool_table(tmp_path / "tools.tbl", [(1, 0.0, 0.0)])
    run = harness.run_rs274(program, tools, tmp_path / "flat.out")
    assert "comment" not in run.message.lower()
    assert "STRAIGHT_FEED" in (tmp_path / "flat.out").read_text()
