"""Blocks written to a temporary file as they are made and read back a chunk at a time: the plain
motion of a construct lowered on its own in a compact program (nctrans.lower.constructs), which
may be as long as the CAM stretch it covers (Sinumerik G70 over millions of blocks), so it is
never held whole.

A `Spill` is filled once (`add`, then `close`); a `SpilledRun` is a cursor over it with the
`take(count)` of plainrun.PlainRun, so the emitters write it as they write a run of plain blocks
(plainrun.run_blocks), as often as they like. Blocks are pickled: they come back equal, field by
field, to the ones the flattener made (the whole-parse conversion writes those same Blocks)."""
from __future__ import annotations

import pickle
import tempfile
from typing import Optional

# Blocks per pickled chunk: a chunk is what a reader holds (~1 KiB of IR per block).
CHUNK = 1024


class Spill:
    """Blocks in a temporary file (removed when the Spill is collected or the process ends),
    `count` of them in chunks of at most CHUNK."""

    def __init__(self):
        self.file = tempfile.TemporaryFile(prefix="nctrans-spill-")
        self.chunks: list[tuple[int, int, int]] = []      # (offset, length, blocks)
        self.count = 0
        self._pending: list = []

    def add(self, blocks: list) -> None:
        """Append blocks (the caller may clear its list afterwards)."""
        self._pending.extend(blocks)
        while len(self._pending) >= CHUNK:
            self._write(self._pending[:CHUNK])
            del self._pending[:CHUNK]

    def close(self) -> "SpilledRun":
        """Write what is pending; the run of all the blocks added."""
        if self._pending:
            self._write(self._pending)
            self._pending = []
        return SpilledRun(self, 0)

    def _write(self, blocks: list) -> None:
        data = pickle.dumps(blocks, protocol=pickle.HIGHEST_PROTOCOL)
        self.file.seek(0, 2)
        self.chunks.append((self.file.tell(), len(data), len(blocks)))
        self.file.write(data)
        self.count += len(blocks)

    def read(self, k: int) -> list:
        offset, length, _ = self.chunks[k]
        self.file.seek(offset)
        return pickle.loads(self.file.read(length))


class SpilledRun:
    """The blocks of a Spill from chunk `k` on; `take` as plainrun.PlainRun.take (a chunk at a
    time whatever `count` asks, at least one block while any is left)."""
    __slots__ = ("spill", "k")

    def __init__(self, spill: Spill, k: int):
        self.spill = spill
        self.k = k

    @property
    def blocks(self) -> int:
        return sum(c[2] for c in self.spill.chunks[self.k:])

    def take(self, count: int) -> tuple[list, Optional["SpilledRun"]]:
        if self.k >= len(self.spill.chunks):
            return [], None
        out = self.spill.read(self.k)
        rest = SpilledRun(self.spill, self.k + 1) if self.k + 1 < len(self.spill.chunks) else None
        return out, rest
