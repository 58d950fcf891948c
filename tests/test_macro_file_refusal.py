"""An ISO macro file (it reads G65 arguments it never sets and ends with M99) has no toolpath of its
own: a construct of it the target cannot express is never lowered to plain motion run with every
argument vacant, alone or with the whole file. Converted to Sinumerik it is refused at its place
(NC412: an alarm where it stood, the PROC around it kept); to other targets at its line (NC402,
saying it is a macro file). --flatten refuses the file. The way out the message names, flattening
the caller with the macro file beside it, converts and is equivalent."""
from __future__ import annotations

import pytest

from nctrans import api

# #500 EQ #0 (a vacancy test of a common variable: an R parameter is never vacant) has no
# Sinumerik equivalent; before, lines 3-5 were "lowered" with #24 vacant: no move, M99 -> M30
MACRO = "O9005\n#100=1\nIF[#500EQ#0]GOTO9\nG1 X#24 F100.\nN9 M99\n"
CALLER = "O1000\nG0 X0 Y0 Z5.\n#500=1\nG65 P9005 X10.\nG65 P9005 X20.\nM30\n"


def _errors(conv):
    return [d for d in conv.diagnostics if d.severity == "error"]


def test_construct_of_a_macro_file_is_refused_at_its_line():
    conv = api.transpile(MACRO, read="iso-m", write="fagor")
    assert conv.text is None
    errors = _errors(conv)
    assert [d.line for d in errors] == [3]
    assert errors[0].rule == "NC402" and "it is a macro file" in errors[0].message
    assert not [d for d in conv.diagnostics if "lowered to plain motion here" in d.message]


def test_construct_of_a_macro_file_is_refused_in_place_to_sinumerik():
    conv = api.transpile(MACRO, read="iso-m", write="sinumerik")
    assert not _errors(conv), [d.message for d in _errors(conv)]
    assert [(d.rule, d.line) for d in conv.diagnostics if d.rule in ("NC402", "NC412")] == [("NC412", 3)]
    assert "in a macro file" in next(d.message for d in conv.diagnostics if d.rule == "NC412")
    assert not [d for d in conv.diagnostics if "lowered to plain motion here" in d.message]
    lines = conv.text.splitlines()
    # the PROC, its line before (#100=1) and after (the move, the return) kept; line 3 the alarm
    at = lines.index('SETAL(65002, "NOT CONVERTED: SOURCE LINE 3")')
    assert lines[0].startswith("PROC L9005(") or lines[1].startswith("PROC L9005(")
    assert lines[at - 1] == "R100=1" and lines[at + 1:] == ["F100. G1 X=ARG_X", "N9 RET"]


def test_flatten_refuses_a_macro_file():
    conv = api.transpile(MACRO, read="iso-m", write="sinumerik", flatten=True)
    assert conv.text is None
    assert [(d.rule, d.line) for d in _errors(conv)] == [("NC402", 4)]     # where it reads #24
    assert "convert the programs that call it with --flatten" in _errors(conv)[0].message


def test_a_macro_file_the_target_expresses_still_converts():
    conv = api.transpile("O9006\nG1 X#24 F100.\nM99\n", read="iso-m", write="sinumerik")
    assert conv.text is not None and "PROC L9006(" in conv.text


def test_the_caller_flattened_with_the_macro_beside_it_is_equivalent(tmp_path):
    (tmp_path / "O9005.nc").write_text(MACRO)
    caller = tmp_path / "O1000.nc"
    caller.write_text(CALLER)
    conv = api.transpile(caller, read="iso-m", write="sinumerik", flatten=True)
    assert conv.text is not None, [d.format_text() for d in _errors(conv)]
    out = tmp_path / "O1000.mpf"
    out.write_text(conv.text)
    # hand-computed: #500 is set, so each call feeds to its X at Y0 Z5
    assert [r.end for r in api.toolpath(out) if r.kind == "linear"] == [
        {"X": 10.0, "Y": 0.0, "Z": 5.0}, {"X": 20.0, "Y": 0.0, "Z": 5.0}]
    assert api.equiv(caller, out).equivalent


@pytest.mark.parametrize("name, first", [("mojimould-O440000-macro.nc", 6), ("mojimould-O5701-MMC-macro.NC", 4)])
def test_corpus_macro_files_keep_their_proc_refused_in_place(name, first):
    # never a lone alarm from a run with every argument vacant (the old whole lowering): the PROC
    # keeps its body, each construct Sinumerik cannot express (a vacancy test of a common variable
    # at `first`, #4012, a computed offset register) is an alarm at its line; --flatten refuses
    from conftest import CORPUS
    src = CORPUS / "iso-mill" / name
    if not src.is_file():
        pytest.skip("shared corpus not found")
    flat = api.transpile(src, read="iso-m", write="sinumerik", flatten=True)
    assert flat.text is None and all("macro file" in d.message for d in _errors(flat))
    conv = api.transpile(src, read="iso-m", write="sinumerik")
    assert not _errors(conv)
    in_place = sorted(d.line for d in conv.diagnostics if d.rule == "NC412")
    assert in_place[0] == first
    assert f'SETAL(65002, "NOT CONVERTED: SOURCE LINE {first}")' in conv.text
    lines = conv.text.splitlines()
    assert "RET" in lines and "M30" not in lines         # its M99 is the macro's return
    assert not [d for d in conv.diagnostics if d.rule == "NC401" and "plain motion" in d.message]
