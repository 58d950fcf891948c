"""The compiled form of a program body, which the interpreter loop (flow.py) runs.

A body compiles into a flat list of instructions, each a tuple (opcode, a, b, span):
BLOCK (a: the block's statements compiled into (handler, data) pairs, or None until the block
runs a second time; b: the Block), PLAIN (a: a PlainRun of straight blocks for the native lane),
JUMP (a: target pc), JFALSE (a: compiled condition, b: target pc when false), EXEC (a: a side
effect such as a FOR step), CASE (a: subject, branches, default label). Labels and block numbers
map to instruction positions through label_key; subprogram names compare through program_key.
"""
from __future__ import annotations

import re
from typing import Any

from nctrans.ir import nodes as n
from nctrans.plainrun import PlainRun

BLOCK, JUMP, JFALSE, EXEC, CASE, PLAIN = range(6)
MAX_CALL_DEPTH = 16
_LABEL_NUM = re.compile(r"^N?0*(\d+)$")
_PROG_NUM = re.compile(r"^[OoPp]?0*(\d+)$")


def label_key(text: Any) -> Any:
    """Block numbers compare numerically ("0100" == "N100" == 100); labels by upper-case name."""
    s = str(text).strip()
    if s.isdigit():
        return int(s)
    m = _LABEL_NUM.match(s.upper())
    if m:
        return int(m.group(1))
    return s.upper()


def program_key(name: str) -> str:
    """Subprogram names compare without the O and leading zeros when numeric ("O0100" == "100")."""
    s = str(name).strip()
    m = _PROG_NUM.match(s)
    if m:
        return "#" + str(int(m.group(1)))
    return s.upper()


class Unit:
    """A compiled program body: instructions, label positions, parameters.
    save: the subprogram has the SAVE attribute (modal G codes and frames restored on return)."""
    __slots__ = ("name", "code", "labels", "params", "file", "seen", "save")

    def __init__(self, name: str, file: str, params: list):
        self.name = name
        self.file = file
        self.code: list[tuple] = []
        self.labels: dict[Any, list[int]] = {}
        self.params = params
        self.seen = bytearray()
        self.save = False


class Frame:
    """A call-stack entry: where to resume in the caller, and how to repeat the callee.
    saved: the caller's modal state and frames, restored on return from a SAVE subprogram."""
    __slots__ = ("unit", "pc", "sidx", "scope", "callee", "repeats", "args", "make_scope", "modal",
                 "saved", "section")

    def __init__(self, unit, pc, sidx, scope, callee, repeats, make_scope, modal=False, saved=None,
                 section=False):
        self.unit, self.pc, self.sidx, self.scope = unit, pc, sidx, scope
        self.callee, self.repeats, self.make_scope, self.modal = callee, repeats, make_scope, modal
        self.saved = saved
        self.section = section      # a repeated program section (REPEAT), not a call level


class _Stop(Exception):
    """Internal: end the whole run (program end, alarm)."""


def _plain_entry(run: PlainRun) -> tuple:
    """The code entry of a PlainRun; its span (first line) places an NC205 step-budget warning."""
    return (PLAIN, run, None, n.Span(run.file, run.line, 1, run.line, 1))



