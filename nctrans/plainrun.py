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
on corpus programs and generated ones).

A run is "open" when the front end makes it (it knows only that the run starts with plain lines):
the kernel finds where it ends as it runs it, holding each line to scan()'s checks, so a plain
line is read once. Whoever needs the end before the kernel has found it (the front end going on
past the run, an expansion in Python, a conversion) finds it with scan() (`resolve`); the pieces a
run is split into share one RunEnd, where the end is written once found. The kernel is optional: without the compiled extension, or
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


class RunEnd:
    """Where a run of plain lines ends, once someone has found it: `pos` (where the next line
    starts; None until found), `line` (its number), and the front end's static motion mode and
    canned cycle after the run's last block."""
    __slots__ = ("pos", "line", "motion", "cycle")

    def __init__(self):
        self.pos: Optional[int] = None
        self.line = 0
        self.motion: Optional[str] = None
        self.cycle: Optional[str] = None

    def found(self, pos: int, line: int, motion: Optional[str], cycle: Optional[str]) -> None:
        self.pos, self.line, self.motion, self.cycle = pos, line, motion, cycle


class PlainRun:
    """Lines text[start:end) of a streamed ISO program: `blocks` plain blocks (blank lines between
    them do not count), the first on line `line`. `lower(code, motion, cycle, arc_abs)` turns a line's
    code (blanks removed) into the Block body the Python fast path would build (Lowering.plain_line), given
    the front end's static motion mode, canned cycle and centre mode (G90.1), which were `motion`,
    `cycle`, `arc_abs` at `start`.

    Open (see the module's docstring): `end` and `known_blocks` are None until found (reading
    `blocks` finds them); `strict` and `max_chars` are the front end's scan() arguments (words
    separated; the longest line it reads), `ends` the RunEnd the run's pieces share."""
    __slots__ = ("file", "text", "start", "end", "line", "sep", "known_blocks", "lower", "motion", "cycle",
                 "arc_abs", "strict", "max_chars", "ends")

    def __init__(self, file: str, text: str, start: int, end: Optional[int], line: int, sep: str,
                 blocks: Optional[int], lower: Callable, motion: Optional[str], cycle: Optional[str],
                 arc_abs: bool, strict: bool = False, max_chars: int = 0, ends: Optional[RunEnd] = None):
        self.file = file
        self.text = text
        self.start = start
        self.end = end
        self.line = line
        self.sep = sep
        self.known_blocks = blocks
        self.lower = lower
        self.motion = motion
        self.cycle = cycle
        self.arc_abs = arc_abs
        self.strict = strict
        self.max_chars = max_chars
        self.ends = ends

    @property
    def is_open(self) -> bool:
        """The run's end is not found yet."""
        return self.known_blocks is None

    @property
    def blocks(self) -> int:
        """The blocks in the run (found now with scan() when it is open)."""
        self.resolve()
        return self.known_blocks

    @classmethod
    def open(cls, file: str, text: str, start: int, line: int, sep: str, lower: Callable,
             motion: Optional[str], cycle: Optional[str], arc_abs: bool, strict: bool,
             max_chars: int) -> "PlainRun":
        """A run that starts with plain lines at `start` and whose end is not known yet."""
        return cls(file, text, start, None, line, sep, None, lower, motion, cycle, arc_abs, strict,
                   max_chars, RunEnd())

    def piece(self, start: int, line: int, motion: Optional[str], cycle: Optional[str],
              blocks_run: int) -> "PlainRun":
        """The rest of this run from `start` (line `line`) after `blocks_run` of its blocks ran,
        the front end's static state there being `motion`, `cycle`."""
        left = None if self.known_blocks is None else self.known_blocks - blocks_run
        return PlainRun(self.file, self.text, start, self.end, line, self.sep, left, self.lower,
                        motion, cycle, self.arc_abs, self.strict, self.max_chars, self.ends)

    def resolve(self) -> None:
        """Find this run's end with scan() when nobody has yet (the run is then closed: `end` and
        `blocks` known). The piece may start on blank lines inside the run (the kernel stopped
        before them), which scan() never starts on: they are stepped over here first."""
        if self.known_blocks is not None:
            return
        text, sep, pos, line = self.text, self.sep, self.start, self.line
        while pos <= len(text):
            nl = text.find(sep, pos)
            if nl < 0:
                nl = len(text)
            if nl - pos > self.max_chars or text[pos:nl].strip(" \r"):
                break
            pos, line = nl + 1, line + 1
        end, lines, blocks, last = (native.scan(text, pos, sep, motion_code(self.motion), self.cycle is None,
                                                self.arc_abs, self.strict, self.max_chars)
                                    if pos <= len(text) else (pos, 0, 0, -1))
        if blocks == 0:         # only blank lines were left: the run ended before them
            end, line = self.start, self.line
        else:
            line += lines
        self.end, self.known_blocks = end, blocks
        motion, cycle = (MOTIONS[last], None) if last >= 0 else (self.motion, self.cycle)
        if self.ends.pos is None:
            self.ends.found(end, line, motion, cycle)

    def extent(self) -> RunEnd:
        """Where the whole run ends (found now by scan() if the kernel has not found it running)."""
        if self.ends.pos is None:
            self.resolve()
        return self.ends

    def take(self, count: int) -> tuple[list, Optional["PlainRun"]]:
        """The first `count` blocks as IR Blocks, and the rest of the run (None when none is left)."""
        from nctrans.ir.nodes import Block, Span
        self.resolve()
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
        rest = self.piece(pos, line, motion, cycle, len(out)) if self.blocks > len(out) else None
        return out, rest

    def expand(self) -> list:
        """All the run's Blocks: what the front end builds without the kernel."""
        return self.take(self.blocks)[0]


def cut(run: PlainRun, k: int) -> tuple[PlainRun, PlainRun]:
    """(the first `k` blocks of `run`, the rest), 0 < k < run.blocks, as PlainRuns over its text
    (the first k blocks are built a chunk at a time to find where the rest starts)."""
    rest: Optional[PlainRun] = run
    taken = 0
    while taken < k:
        blocks, rest = rest.take(min(1024, k - taken))
        taken += len(blocks)
    assert rest is not None
    end = RunEnd()
    end.found(rest.start, rest.line, rest.motion, rest.cycle)
    head = PlainRun(run.file, run.text, run.start, rest.start, run.line, run.sep, k, run.lower,
                    run.motion, run.cycle, run.arc_abs, run.strict, run.max_chars, end)
    return head, rest


# Blocks of a run built at a time when a consumer takes a run block by block (the emitters of a
# compact body): enough that per-take costs vanish, few enough that memory stays flat.
RUN_CHUNK = 1024


def run_blocks(run: "PlainRun", size: int = RUN_CHUNK):
    """The Blocks of a run one by one, built `size` at a time (never the whole run at once): how
    the whole-program emitters write a compact body's runs (base.CompactBody) with flat memory."""
    while run is not None:
        blocks, run = run.take(size)
        yield from blocks
        del blocks


# The node types of a compact body that stand for blocks read back a few at a time (`take`): a
# PlainRun, and the spilled plain motion of a construct lowered in a compact program
# (nctrans.spilled). The emitters write both with run_blocks.
from nctrans.spilled import SpilledRun  # noqa: E402 (no import of this module there)
RUNS = (PlainRun, SpilledRun)
