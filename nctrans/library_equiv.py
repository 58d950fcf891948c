"""`equiv` of a subprogram library and a program that holds the same subprogram, as callers see them.

A subprogram library (a file whose main body does nothing and which exists to define one entry
subprogram, convert._library_entry) runs nothing on its own, while its conversion to a dialect
that numbers its programs is a program whose own body is the subprogram: run alone, one is empty
and the other moves. A control never runs either alone; a caller calls it. So such a pair is
compared as two callers compare: a one-line caller in the library's dialect calls the entry with
no arguments (its parameters vacant), the same caller converted to the other dialect calls what
the conversion calls it (a program number), and each finds its subprogram beside it (both files
written, under the names their dialects look for, in a temporary directory searched first). The
comparison, its diagnostics and its difference name the two files as given, not their copies.
"""
from __future__ import annotations

import dataclasses
import os
import tempfile
from typing import Any, Callable, Optional

from nctrans.diagnostics import Diagnostic
from nctrans.ir import nodes as n

CALLER = "<caller>"


def _program(opened: tuple[Any, Optional[str]]) -> Optional[n.Program]:
    what = opened[0]
    return what if isinstance(what, n.Program) else getattr(what, "program", None)


def _library(opened: tuple[Any, Optional[str]]) -> Optional[str]:
    """The entry of a library side, None for any other (a streamed body is a plain program's)."""
    from nctrans.convert import _library_entry
    program = _program(opened)
    if program is None or not isinstance(program.body, list):
        return None
    return _library_entry(program)


def _text(opened: tuple[Any, Optional[str]]) -> Optional[str]:
    source = getattr(opened[0], "source", None)
    return getattr(source, "text", None)


def _caller(entry: str, dialect: str) -> Optional[str]:
    """`entry` called with no arguments, then the program end, written in `dialect`."""
    from nctrans.dialects.base import get
    span = lambda line: n.Span(CALLER, line, 1)          # noqa: E731
    body = [n.Block(span(1), [n.SubCall(entry, [], {}, None, "none", "proc", {}, None)]),
            n.Block(span(2), [n.ProgramEnd("end_rewind")])]
    d = get(dialect)
    return None if d is None else d.emit(n.Program(CALLER, dialect, body, {}, {}, None)).text


def _called_name(text: str, dialect: str) -> Optional[str]:
    from nctrans import api
    for node in api.parse(text, dialect).body:
        for st in getattr(node, "body", ()) or ():
            if isinstance(st, n.SubCall):
                return str(st.name)
    return None


def as_called(oa: tuple[Any, Optional[str]], ob: tuple[Any, Optional[str]],
              compare: Callable[..., Any], dirs: list) -> Optional[Any]:
    """The Equivalence of the pair as called (see the module), or None where neither side is a
    library, both are, or a caller cannot be written or converted: then the files are compared
    as they are."""
    from nctrans import api
    from nctrans.dialects.base import get
    libs = [_library(oa), _library(ob)]
    if (libs[0] is None) == (libs[1] is None):
        return None
    lib, other = (oa, ob) if libs[0] is not None else (ob, oa)
    entry = libs[0] if libs[0] is not None else libs[1]
    lib_d, other_d = lib[1], other[1]
    lib_text, other_text = _text(lib), _text(other)
    if not (lib_d and other_d and lib_text is not None and other_text is not None):
        return None
    lib_caller = _caller(entry, lib_d)
    if not lib_caller:
        return None
    other_caller = api.transpile(lib_caller, read=lib_d, write=other_d).text
    called = _called_name(other_caller, other_d) if other_caller else None
    lib_files, other_files = get(lib_d).subprogram_files(entry), get(other_d).subprogram_files(called or "")
    if not (lib_files and other_files) or set(lib_files) & set(other_files):
        # one directory holds both: a name either caller may find must be its own file's alone
        # (a Fagor conversion keeps the PROC's name, which the Sinumerik caller looks for too)
        return None
    with tempfile.TemporaryDirectory(prefix="nctrans-callers-") as where:
        paths = {os.path.join(where, lib_files[0]): lib[0].label,
                 os.path.join(where, other_files[0]): other[0].label}
        for path, text in zip(paths, (lib_text, other_text)):
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
        a_text, b_text = (lib_caller, other_caller) if lib is oa else (other_caller, lib_caller)
        # then the given files' own directories: a subprogram the library calls sits beside it
        # (and its conversion beside the other file), as when either file runs where it is
        beside = [os.path.dirname(os.path.abspath(side[0].label)) for side in (lib, other)
                  if os.path.isfile(side[0].label)]
        result = compare(a_text, b_text, read_a=oa[1], read_b=ob[1],
                         search_path=[where, *dict.fromkeys(beside), *dirs])
    return _relabelled(result, paths)


def _relabelled(result: Any, paths: dict[str, str]) -> Any:
    """The result with the temporary copies named as the files given."""
    def name(file: str) -> str:
        return paths.get(file, paths.get(os.path.realpath(file), file)) if file else file

    paths = {**paths, **{os.path.realpath(p): label for p, label in paths.items()}}
    result.diagnostics = [dataclasses.replace(d, file=name(d.file)) if isinstance(d, Diagnostic) else d
                          for d in result.diagnostics]
    diff = result.difference
    if diff is not None:
        for side in ("a", "b"):
            rec = getattr(diff, side)
            if rec is not None and getattr(rec, "file", None):
                try:
                    setattr(diff, side, dataclasses.replace(rec, file=name(rec.file)))
                except TypeError:
                    pass
    return result
