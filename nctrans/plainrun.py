"""Runs of plain blocks: the fast lane for CAM output through the streamed ISO toolpath.

A CAM program is tens of thousands of blocks like `N1234 G1 X1.234 Y-5.6 F800.` and arcs by
centre (`G3 X.. Y.. I.. J..`). In the streamed
parse the ISO front end marks a run of such lines as one `PlainRun` (a lazy form of the Blocks it
would otherwise build) instead of lowering each line. The interpreter then either

- hands the run to the native kernel (`nctrans._plainrun`, C), which executes it straight from the
  text and writes the JSON lines the toolpath writer would write, when its consumer takes JSON
  chunks (`toolpath --format jsonl`, `lint`) and the state is one the kernel handles (no cutter
  compensation, frame, canned cycle, modal call, flatten hook); or
- expands the run into the Blocks the Python fast path builds (`expand`) and runs those, for every
  other consumer and state, and for the one block the kernel hands back when it cannot run it
  identically.

Either way the toolpath and the diagnostics are the same (tests/test_plainrun.py compares the two
on corpus programs and generated ones). The kernel is optional: without the compiled extension, or
with NCTRANS_NATIVE=0 in the environment, the front end builds no runs at all.
"""
from __future__ import annotations

import os
from typing import Callable, Optional

try:
    from nctrans import _plainrun as native
except ImportError:          # built without a C compiler: everything runs in Python
    native = None

if os.environ.get("NCTRANS_NATIVE", "1") == "0":
    native = None


# Motion modes a plain block may select, in the order of the kernel's MOTION_* codes; any other
# mode is MOTION_OTHER (len(MOTIONS)).
MOTIONS = ("rapid", "linear", "arc_cw", "arc_ccw")


def motion_code(mode: Optional[str]) -> int:
    """The kernel's code for a motion mode name (4 for anything that is not a plain motion)."""
    try:
        return MOTIONS.index(mode)
    except ValueError:
        return len(MOTIONS)


class JsonChunk:
    """Toolpath records the kernel already wrote as JSON lines (text) and how many there are.
    Only a consumer that asked for them (interpret(..., fast_sink="jsonl")) ever sees one."""
    __slots__ = ("text", "count")

    def __init__(self, text: str, count: int):
        self.text = text
        self.count = count


class PlainRun:
    """Lines text[start:end) of a streamed ISO program: `blocks` plain blocks (blank lines between
    them do not count), the first on line `line`. `lower(code, motion, cycle, arc_abs)` turns a line's
    code (blanks removed) into the Block body the Python fast path would build (Lowering.plain_line), given
    the front end's static motion mode, canned cycle and centre mode (G90.1), which were `motion`,
    `cycle`, `arc_abs` at `start`."""
    __slots__ = ("file", "text", "start", "end", "line", "sep", "blocks", "lower", "motion", "cycle",
                 "arc_abs")

    def __init__(self, file: str, text: str, start: int, end: int, line: int, sep: str, blocks: int,
                 lower: Callable, motion: Optional[str], cycle: Optional[str], arc_abs: bool):
        self.file = file
        self.text = text
        self.start = start
        self.end = end
        self.line = line
        self.sep = sep
        self.blocks = blocks
        self.lower = lower
        self.motion = motion
        self.cycle = cycle
        self.arc_abs = arc_abs

    def take(self, count: int) -> tuple[list, Optional["PlainRun"]]:
        """The first `count` blocks as IR Blocks, and the rest of the run (None when none is left)."""
        from nctrans.ir.nodes import Block, Span
        text, sep, end, file, lower = self.text, self.sep, self.end, self.file, self.lower
        pos, line = self.start, self.line
        motion, cycle = self.motion, self.cycle
        out: list = []
        while pos < end and len(out) < count:
            nl = text.find(sep, pos)
            if nl < 0:
                nl = len(text)
            raw = text[pos:nl]
            code = raw.replace(" ", "")
            if code[-1:] == "\r":
                code = code[:-1]
            if code:                                  # a blank line inside the run: no block
                number, body, mode = lower(code, motion, cycle, self.arc_abs)
                if mode is not None:
                    motion, cycle = mode, None
                out.append(Block(Span(file, line, 1, line, len(raw) + 1), body, number))
            pos, line = nl + 1, line + 1
        left = self.blocks - len(out)
        rest = (PlainRun(file, text, pos, end, line, sep, left, lower, motion, cycle, self.arc_abs)
                if left > 0 else None)
        return out, rest

    def expand(self) -> list:
        """All the run's Blocks: what the front end builds without the kernel."""
        return self.take(self.blocks)[0]
