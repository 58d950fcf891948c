"""`backplot A --compare B`: two scenes on one plot, and marks where their toolpaths differ.

The differences are equiv's (nctrans.equivalence.differences), not a second comparison: each one names a
record of A and a record of B, and the mark goes where the tool is at that record in each plot.
"""
from __future__ import annotations

import bisect
from dataclasses import dataclass, field
from typing import Optional

from nctrans.backplot.scene import XYZ, Scene
from nctrans.toolpath import ToolpathRecord

MAX_MARKS = 50      # past the first few, marks usually echo one difference that put A and B out of step


@dataclass(slots=True)
class Side:
    """Where a difference is on one side: its source line and the tool position there."""
    file: str
    line: int
    position: XYZ
    move_index: int          # the move drawn at (or right after) the record


@dataclass(slots=True)
class DiffMark:
    message: str
    a: Optional[Side]
    b: Optional[Side]


@dataclass
class Comparison:
    a: Scene
    b: Scene
    marks: list[DiffMark] = field(default_factory=list)
    truncated: bool = False

    @property
    def equivalent(self) -> bool:
        return not self.marks


def _side(scene: Scene, seqs: list[int], rec: Optional[ToolpathRecord]) -> Optional[Side]:
    """The record's place in the plot: a move's end, or for an event the start of the next move."""
    if rec is None or scene.empty:
        return None
    i = bisect.bisect_left(seqs, rec.seq)
    if i < len(seqs) and seqs[i] == rec.seq:
        m = scene.moves[i]
        return Side(rec.file, rec.line, m.end, i)
    if i < len(seqs):
        m = scene.moves[i]
        return Side(rec.file, rec.line, m.start, i)
    m = scene.moves[-1]
    return Side(rec.file, rec.line, m.end, len(seqs) - 1)


def compare_scenes(a: Scene, b: Scene, records_a: list[ToolpathRecord], records_b: list[ToolpathRecord],
                   tol: float) -> Comparison:
    from nctrans.equivalence import differences
    seqs_a = [m.record.seq for m in a.moves]
    seqs_b = [m.record.seq for m in b.moves]
    cmp = Comparison(a, b)
    for d in differences(records_a, records_b, tol):
        if len(cmp.marks) >= MAX_MARKS:
            cmp.truncated = True
            break
        cmp.marks.append(DiffMark(d.format(), _side(a, seqs_a, d.a), _side(b, seqs_b, d.b)))
    return cmp
