"""An ISO macro file run on its own (lint, toolpath or equiv of the file alone, no G65 caller).

A macro file (lower/macro_procs.macro_file: it reads locals #1-#33 it never sets and ends with
M99) is a G65 target: its M99 is the return to its caller, not the restart of a main program
(NC205 said "the program restarts", which a macro file never does). Run alone, no call passes
its arguments, so every one of them is vacant and the path analysed is not what a call runs:
said once (NC227, info), at the first line that reads an argument, not at every line using one.
"""
from __future__ import annotations

from typing import Optional


def _letters(program) -> dict[int, str]:
    letters = ((program.meta or {}).get("options") or {}).get("macro_arguments") or {}
    return {int(v): k for k, v in letters.items() if isinstance(v, int)}


def note_if_alone(it) -> bool:
    """At the start of a run: True (and the NC227 note) where the main program is a macro file."""
    from nctrans.lower.macro_procs import arguments_read_first, first_argument_read, macro_file
    program = it.program
    try:
        if not macro_file(program):
            return False
    except Exception:           # a body the classification cannot walk: not a macro file here
        return False
    body = program.body if type(program.body) is list else list(getattr(program.body, "items", []))
    first = first_argument_read(body)
    span: Optional[object] = first[0] if first is not None else None
    names = _letters(program)
    args = ", ".join(f"#{k}" + (f" ({names[k]})" if k in names else "")
                     for k in sorted(arguments_read_first(body)))
    it.diag("NC227", "info",
            f"macro file run alone: it reads the G65 arguments {args}, which no call passes here, so "
            "every one is vacant and what depends on them (positions, feeds, branches) is analysed "
            "for that case only, not for a call; its M99 is the return to its caller (analysed as "
            "the end, no restart). Lint or convert the calling program to analyse a call", span)
    return True
