"""A compact main body (base.CompactBody) seen as the whole parse's top-level nodes, without
building them: each PlainRun counts as the blocks it holds, so per-construct lowering
(nctrans.lower.constructs) finds, checks and replaces the same segments by the same indices as on
the whole parse, and a segment may start, end or lie inside a run of millions of plain lines.

Runs are read back a chunk at a time when a scan needs their blocks (plainrun.run_blocks) and cut
into pieces where a segment begins or ends (`slice`): a piece is a PlainRun over part of the
same text, so nothing the size of the program is ever built.

What a plain block may hold is small and fixed ([N] [G0-G3] axis words, centre words, F: the
native kernel's scan()), so the scans that look for other statements (assignments, jumps,
G10, homing, passthroughs) skip runs; the ones a plain block can end (a canned cycle, a tapping
stretch, a corner chain) read them (constructs._Scans)."""
from __future__ import annotations

from typing import Iterator, Optional

from nctrans.ir import nodes as n
from nctrans.ir.walk import walk
from nctrans.plainrun import PlainRun, cut, run_blocks


class CompactView:
    """`items` (a compact body's, runs as PlainRuns) indexed as the whole parse's nodes."""

    def __init__(self, items: list):
        self.items = items
        self.starts: list[int] = []         # index of each item's first node
        total = 0
        for x in items:
            self.starts.append(total)
            total += x.blocks if type(x) is PlainRun else 1
        self.total = total

    def __len__(self) -> int:
        return self.total

    def pairs(self) -> Iterator[tuple[int, object]]:
        """(index, item) of every item: a PlainRun stands at the index of its first block."""
        return zip(self.starts, self.items)

    def run_nodes(self, k: int, skip: int = 0) -> Iterator[tuple[int, n.Block]]:
        """(index, Block) of the blocks of item k (a PlainRun) from its `skip`-th block on."""
        run = self.items[k]
        i = self.starts[k]
        if skip:
            if skip >= run.blocks:
                return
            run = cut(run, skip)[1]
            i += skip
        for b in run_blocks(run):
            yield i, b
            i += 1

    def nodes(self) -> Iterator[tuple[int, object]]:
        """(index, node) of every node, runs taken apart a chunk at a time."""
        for k, (i, x) in enumerate(self.pairs()):
            if type(x) is PlainRun:
                yield from self.run_nodes(k)
            else:
                yield i, x

    def item_at(self, i: int) -> int:
        """The item holding node index i."""
        import bisect
        return bisect.bisect_right(self.starts, i) - 1

    def node(self, i: int):
        """The node at index i (a run's block built alone)."""
        k = self.item_at(i)
        x = self.items[k]
        if type(x) is not PlainRun:
            return x
        return next(self.run_nodes(k, i - self.starts[k]))[1]

    def slice(self, lo: int, hi: int) -> list:
        """The nodes lo..hi (inclusive) as items: runs cut into pieces at lo and hi."""
        out: list = []
        if lo > hi:
            return out
        for k in range(self.item_at(lo), self.item_at(hi) + 1):
            x, start = self.items[k], self.starts[k]
            if type(x) is not PlainRun:
                out.append(x)
                continue
            a, b = max(lo, start) - start, min(hi, start + x.blocks - 1) - start
            if a > 0:
                x = cut(x, a)[1]
            if b - a + 1 < x.blocks:
                x = cut(x, b - a + 1)[0]
            out.append(x)
        return out

    def line_index(self, file: str, lines: set[int]) -> dict[int, int]:
        """Source line -> index of the top-level node that holds it, for `lines` only."""
        index: dict[int, int] = {}
        if not lines:
            return index
        for k, (i, x) in enumerate(self.pairs()):
            if type(x) is PlainRun:
                if x.file == file and any(x.line <= ln < x.extent().line for ln in lines):
                    for j, b in self.run_nodes(k):
                        if b.span.line in lines:
                            index.setdefault(b.span.line, j)
                continue
            for inner in walk([x]):
                sp = getattr(inner, "span", None)
                if sp is not None and sp.file == file and sp.line in lines:
                    index.setdefault(sp.line, i)
        return index


def structural(nodes: list) -> list:
    """The nodes that are not runs of plain blocks (what scans for statements a plain block never
    holds need to look at)."""
    return [x for x in nodes if type(x) is not PlainRun]


def labelled_blocks(nodes: list, wanted: set[str], key) -> Iterator[n.Block]:
    """The blocks of runs among `nodes` whose number `key` maps into `wanted` (read back only when
    something is wanted)."""
    if not wanted:
        return
    for x in nodes:
        if type(x) is PlainRun:
            for b in run_blocks(x):
                if b.number is not None and key(b.number) in wanted:
                    yield b
