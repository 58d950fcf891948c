"""Blocks written to a temporary file as they are made and read back a chunk at a time: the plain
motion of a construct lowered on its own in a compact program (nctrans.lower.constructs), which
may be as long as the CAM stretch it covers (Sinumerik G70 over millions of blocks), so it is
never held whole.

A `Spill` is filled once (`add`, then `close`); a `SpilledRun` is a cursor over it with the
`take(count)` of plainrun.PlainRun, so the emitters write it as they write a run of plain blocks
(plainrun.run_blocks), as often as they like. Blocks are pickled: they come back equal, field by
field, to the ones the flattener made (the whole-parse conversion writes those same Blocks)."""
from __future__ import annotations

import codecs
import pickle
import tempfile
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Iterator, Optional, Union

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


# --------------------------------------------------------------------------- output lines

# Whether the emitters' output lines may go to a temporary file (OutputLines): only where the
# caller writes the text out piece by piece (api.transpile with `out`, the CLI); elsewhere an
# emission's text stays a str.
_SPOOLING: ContextVar[bool] = ContextVar("nctrans_spool_output", default=False)

# Lines an OutputLines holds before it writes them to its file (~60 bytes a line held), and the
# first lines it always holds (an emitter inserts its name table or header among them).
SPILL_LINES = 8192
HEAD_LINES = 64


@contextmanager
def spooled_output() -> Iterator[None]:
    """Within: the emitters' output lines go to a temporary file once they are many, and an
    emission's text is a SpilledText (SpilledText.pieces writes it out)."""
    token = _SPOOLING.set(True)
    try:
        yield
    finally:
        _SPOOLING.reset(token)


def output_lines():
    """The list an emitter writes its output lines to: an OutputLines where spooling is on
    (spooled_output), else a plain list."""
    return OutputLines() if _SPOOLING.get() else []


def joined(lines) -> "Union[str, SpilledText]":
    """"\\n".join(lines) + "\\n": a str, or a SpilledText for lines that went to a file."""
    if type(lines) is OutputLines:
        return lines.text()
    return "\n".join(lines) + "\n"


def as_str(text) -> Optional[str]:
    """An emission's text as a str (a SpilledText read back whole; None stays None)."""
    return text if text is None or type(text) is str else str(text)


class OutputLines:
    """An emitter's output lines, the older ones in a temporary file: a program that jumps back
    into its body (an ISO M99 restart written as one Sinumerik LOOP) is written as one structure
    the writer may still take back (`del lines[start:]`) when a construct in it is refused, so its
    lines cannot be handed out as they come, and held they grew with the program. The list
    operations the emitters use: append, extend, len, del lines[k:], slice insertion among the
    first HEAD_LINES lines (or while nothing went to the file); anything else reads the lines back."""

    def __init__(self):
        self.head: list[str] = []        # the first lines, always held
        self.tail: list[str] = []        # the lines after those in the file
        self.file = None
        self.chunks: list[tuple[int, int]] = []     # (offset, lines) in the file
        self.filed = 0                   # lines in the file

    def __len__(self) -> int:
        return len(self.head) + self.filed + len(self.tail)

    def __bool__(self) -> bool:
        return len(self) > 0

    def append(self, line: str) -> None:
        self.tail.append(line)
        if len(self.tail) >= SPILL_LINES:
            self._spill()

    def extend(self, lines) -> None:
        self.tail.extend(lines)
        if len(self.tail) >= SPILL_LINES:
            self._spill()

    def _spill(self) -> None:
        if len(self.head) < HEAD_LINES and not self.filed:
            k = HEAD_LINES - len(self.head)
            self.head.extend(self.tail[:k])
            del self.tail[:k]
        if not self.tail:
            return
        if self.file is None:
            self.file = tempfile.TemporaryFile("w+b", prefix="nctrans-out-")
        data = ("\n".join(self.tail) + "\n").encode("utf-8", "surrogateescape")
        self.file.seek(0, 2)
        self.chunks.append((self.file.tell(), len(self.tail)))
        self.file.write(data)
        self.filed += len(self.tail)
        self.tail = []

    def _chunk_lines(self, k: int) -> list[str]:
        offset, _ = self.chunks[k]
        end = self.chunks[k + 1][0] if k + 1 < len(self.chunks) else None
        self.file.seek(offset)
        data = self.file.read() if end is None else self.file.read(end - offset)
        return data.decode("utf-8", "surrogateescape").split("\n")[:-1]

    def _filed_lines(self) -> Iterator[str]:
        for k in range(len(self.chunks)):
            yield from self._chunk_lines(k)

    def __iter__(self) -> Iterator[str]:
        yield from list(self.head)
        if self.filed:
            yield from self._filed_lines()
        yield from list(self.tail)

    def __delitem__(self, key) -> None:
        if type(key) is not slice or key.stop is not None or key.step is not None:
            raise TypeError("OutputLines deletes only a trailing slice (lines[k:])")
        start = max(0, key.start or 0) if (key.start or 0) >= 0 else max(0, len(self) + key.start)
        held = len(self.head) + self.filed
        if start >= held:
            del self.tail[start - held:]
            return
        self.tail = []
        if start <= len(self.head):
            del self.head[start:]
            self._drop_file(0)
            return
        at = start - len(self.head)     # the first filed line taken back
        seen = 0
        for k, (_, count) in enumerate(self.chunks):
            if seen + count > at:
                kept = self._chunk_lines(k)[:at - seen]
                self._drop_file(k)
                self.tail = kept
                return
            seen += count

    def _drop_file(self, k: int) -> None:
        """Forget the file's chunks from the k-th on."""
        if k < len(self.chunks):
            self.file.truncate(self.chunks[k][0])
            self.filed -= sum(c for _, c in self.chunks[k:])
            del self.chunks[k:]

    def __getitem__(self, key):
        if not self.filed:
            return (self.head + self.tail)[key]
        return list(self)[key]

    def __setitem__(self, key, value) -> None:
        if type(key) is not slice:
            raise TypeError("OutputLines replaces only slices")
        if not self.filed:
            both = self.head + self.tail
            both[key] = value
            self.head, self.tail = both, []
            return
        start = key.start or 0
        stop = start if key.stop is None else key.stop
        if stop > len(self.head):
            raise IndexError("OutputLines changes only its first lines once lines went to its file")
        self.head[key] = value

    def clear(self) -> None:
        self.head, self.tail = [], []
        self._drop_file(0)

    def text(self) -> "Union[str, SpilledText]":
        if not self.filed:
            return "\n".join(self.head + self.tail) + "\n"
        if self.head and self.tail:
            return SpilledText("\n".join(self.head) + "\n", self, "\n".join(self.tail) + "\n")
        return SpilledText("\n".join(self.head) + "\n" if self.head else "", self,
                           "\n".join(self.tail) + "\n" if self.tail else "")


# Characters read from an OutputLines' file at a time when its text is written out.
PIECE = 1 << 20


class SpilledText:
    """The text of an OutputLines whose lines went to a file: its held head, the file, its held
    tail. `pieces()` gives it a piece at a time (what the conversion writes); str() reads it whole
    (a caller that needs a str: a read-back check, a conversion returned as text)."""
    __slots__ = ("head", "lines", "tail")

    def __init__(self, head: str, lines: OutputLines, tail: str):
        self.head = head
        self.lines = lines
        self.tail = tail

    def pieces(self) -> Iterator[str]:
        if self.head:
            yield self.head
        f = self.lines.file
        f.seek(0, 2)
        end = f.tell()
        decoder = codecs.getincrementaldecoder("utf-8")("surrogateescape")
        pos = 0
        while pos < end:        # a piece may end inside a character: the decoder keeps it back
            f.seek(pos)
            data = f.read(min(PIECE, end - pos))
            pos += len(data)
            yield decoder.decode(data, final=pos >= end)
        if self.tail:
            yield self.tail

    def with_head(self, change) -> "SpilledText":
        """The same text with its held head replaced by change(head)."""
        return SpilledText(change(self.head), self.lines, self.tail)

    def __str__(self) -> str:
        return "".join(self.pieces())

    def __len__(self) -> int:
        return sum(len(p) for p in self.pieces())


def pieces(text) -> Iterator[str]:
    """An emission's text a piece at a time (a str is one piece)."""
    if type(text) is str:
        yield text
    else:
        yield from text.pieces()
