"""The main unit's instructions for a compact body that may be jumped into (base.CompactBody.jumps):
the whole parse's code, instruction for instruction, with each run of plain blocks taking one
BLOCK instruction per block at the same positions, but its Blocks built only as they run, a chunk
at a time (the window), and never kept compiled: the code of a program of millions of plain lines
stays the size of its structure. A jump lands on a block outside every run (the front end split
the runs there, dialects/compact_jumps.py), so labels are indexed as usual; a jump back to the
start of a run starts its window again."""
from __future__ import annotations

import bisect
from typing import Optional

from nctrans.interp.compiled import BLOCK
from nctrans.plainrun import PlainRun, cut

WINDOW = 1024           # blocks of a run built at a time


class CompactCode:
    """A list of instructions as flow.py uses it (len, [pc], [pc] = ins, append, slices)."""

    def __init__(self):
        self.entries: dict[int, Optional[tuple]] = {}   # pc -> instruction outside the runs
        self.run_pcs: list[int] = []                    # first pc of each run
        self.runs: list[PlainRun] = []
        self.size = 0
        # the window: (run index, pc of its first block, its blocks, the run's rest after them)
        self.window: Optional[tuple[int, int, list, Optional[PlainRun]]] = None

    def __len__(self) -> int:
        return self.size

    def append(self, ins: Optional[tuple]) -> None:
        self.entries[self.size] = ins
        self.size += 1

    def add_run(self, run: PlainRun) -> None:
        self.run_pcs.append(self.size)
        self.runs.append(run)
        self.size += run.blocks

    def __setitem__(self, pc: int, ins: tuple) -> None:
        if pc in self.entries:          # a run's block is compiled again each time it runs
            self.entries[pc] = ins

    def __getitem__(self, pc):
        if type(pc) is slice:
            return [self[i] for i in range(*pc.indices(self.size))]
        if pc in self.entries:
            return self.entries[pc]
        if not 0 <= pc < self.size:
            raise IndexError(pc)
        b = self._block(pc)
        return (BLOCK, None, b, b.span)

    def _block(self, pc: int):
        w = self.window
        if w is not None:
            k, first, blocks, rest = w
            if first <= pc < first + len(blocks):
                return blocks[pc - first]
            if pc == first + len(blocks) and rest is not None:
                blocks, rest = rest.take(WINDOW)
                self.window = (k, pc, blocks, rest)
                return blocks[0]
        k = bisect.bisect_right(self.run_pcs, pc) - 1
        run, offset = self.runs[k], pc - self.run_pcs[k]
        if offset:
            run = cut(run, offset)[1]
        blocks, rest = run.take(WINDOW)
        self.window = (k, pc, blocks, rest)
        return blocks[0]
