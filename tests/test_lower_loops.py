"""IR -> IR loop lowering (nctrans.lower.loops): same toolpath, no FOR left, one NC401, input kept."""
from __future__ import annotations

import copy

import pytest

from nctrans import convert
from nctrans.dialects import base
from nctrans.interp import interpret
from nctrans.ir import nodes as n
from nctrans.ir import walk
from nctrans.lower.loops import for_to_while

NESTED = """DEF INT I, J
G0 X0 Y0 Z5
FOR I=1 TO 3
  G1 X=I*10 F100
  FOR J=2 TO 0
    G1 Y=J
  ENDFOR
  FOR J=1 TO 2
    G1 Y=J*5
  ENDFOR
ENDFOR
M30
"""


def _moves(program):
    diags: list = []
    recs = [(r.kind, r.end) for r in interpret(program, None, diagnostics=diags) if r.kind in ("rapid", "linear")]
    return recs, diags


def test_for_loops_become_while_loops_with_the_same_toolpath():
    program = base.get("sinumerik").parse(NESTED, "t.mpf").program
    before = copy.deepcopy(program)
    lowered, diags = for_to_while(program)
    assert program == before                                  # the input is not touched
    assert not any(type(x) is n.ForLoop for x in walk.walk(lowered.body))
    assert sum(type(x) is n.While for x in walk.walk(lowered.body)) == 3
    assert [(d.rule, d.line) for d in diags] == [("NC401", 3)]  # once, at the first FOR
    moves, run_diags = _moves(lowered)
    assert (moves, run_diags) == _moves(program)
    # hand-counted: rapid, then per I: X move, (J=2 TO 0 runs no time), Y at 5 and 10
    assert [m[1]["X"] for m in moves if m[0] == "linear"] == [10, 10, 10, 20, 20, 20, 30, 30, 30]


def test_a_program_without_for_is_returned_as_it_is():
    program = base.get("sinumerik").parse("G0 X1\nWHILE R1<2\nR1=R1+1\nENDWHILE\nM30\n", "t.mpf").program
    assert for_to_while(program) == (program, [])


def test_iso_targets_list_the_pass_and_conversion_runs_it():
    assert for_to_while in base.get("iso-m").lowering_passes
    assert for_to_while not in base.get("sinumerik").lowering_passes
    program = base.get("sinumerik").parse(NESTED, "t.mpf").program
    result = convert.convert(program, base.get("iso-m"), flatten_with=None)
    assert result.text is not None and "WHILE[" in result.text
    assert [d.message for d in result.diagnostics if "FOR" in d.message] == ["FOR loops written as WHILE loops"]
