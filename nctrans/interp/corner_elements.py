"""Contour corner elements as motion: Sinumerik RND/RNDM/CHF/CHR with FRC/FRCM, ISO `,R`/`,C`.

The word sits in the block that leads to the corner; the control inserts the rounding arc or the
chamfer between that block and the next contour block. The interpreter therefore holds back the
one move that carries a corner element (the *pending* move, in program coordinates, before cutter
compensation: the control rounds the programmed contour) until the next move is known; records
of blocks between them (M functions) wait with it. Memory stays flat: at most one move and a few
records are held.

Which words exist, what they mean and what the control does when no contour element follows are
data: `[options.corner_elements]` of the dialect's rules table (words -> round, round_modal,
chamfer_length, chamfer_leg, feed, feed_modal; `missing_next` "alarm" (ISO seed L4000-4004) or
"none" (Sinumerik [GK]: no element is inserted); `dummy_blocks`, the blocks without motion that
may stand between, and `zero_length = "dummy"` where a G1 that moves nothing counts as one of
them (Sinumerik: the element goes to the next block that moves); `feed_from`). The geometry is
corners.py. A writer whose word cannot say how the source control inserts an element asks
nctrans.lower.corner_fit, fed by `_mark`.

Not inserted, said at the line of the word (NC217 warning, NC218 error where the control alarms):
the next move is not G1/G2/G3 in the same plane, or moves outside the plane, the plane, the frame
or the cutter compensation changes between the two blocks, an element is a full circle or helix,
or the element does not fit where the control alarms (ISO). A Sinumerik element too large for its
blocks is shrunk to fit, as the control does [GK] (`_shrunk`, NC229 at the word's line).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Optional

from nctrans.interp import corners
from nctrans.interp.frames import PLANE_AXES
from nctrans.ir import nodes as n

CONTOUR_KINDS = ("linear", "arc")
_NOUN = {"round": "rounding", "round_modal": "modal rounding", "chamfer_length": "chamfer",
         "chamfer_leg": "chamfer"}


@lru_cache(maxsize=None)
def settings(dialect: str) -> dict:
    """The dialect's `[options.corner_elements]` table ({} when it has none)."""
    from nctrans.rules import option
    return dict(option(dialect, "corner_elements") or {})


def kind_of(s: n.Passthrough) -> Optional[str]:
    """The corner-element meaning of a Passthrough (round, chamfer_leg, feed ...), or None."""
    if not s.address or s.value is None:
        return None
    return settings(s.dialect).get("words", {}).get(s.address.upper())


@dataclass
class Move:
    """A move as records.py's _move had it, in program coordinates."""
    kind: str
    start: dict
    end: dict
    center: Optional[tuple]
    cw: Optional[bool]
    turns: Optional[int]
    payload: tuple
    span: Optional[n.Span] = None
    probe: tuple = ()
    corner: tuple = ()              # (kind, value, feed or None, dialect) it carries


@dataclass
class StillMove:
    """A G1 that moves nothing, held with the records behind a corner element (its block counts as
    one without motion): replayed as a move of no length where the tool then stands, so the
    toolpath keeps its block (line, feed, modes) as it does without a corner."""
    file: str
    line: int
    payload: tuple


@dataclass
class CornerStage:
    """The interpreter's corner state; exists only while something is programmed or held."""
    block: Optional[tuple] = None           # (kind, value, span, dialect) of this block's word
    block_feed: Optional[tuple] = None      # (FRC value, span)
    modal_round: Optional[tuple] = None     # (RNDM radius, dialect)
    modal_feed: Optional[float] = None      # FRCM
    pending: Optional[Move] = None
    queued: list = field(default_factory=list)
    still: set = field(default_factory=set)   # (file, line) of G1 blocks held back that move nothing


def compile_word(it, s: n.Passthrough):
    """(handler, data) of a corner word: evaluated where the block runs, before its motion."""
    return (_h_word, (it, kind_of(s), it.ev.compile(s.value), s))


def _h_word(d) -> None:
    it, kind, f, s = d
    if it.capture is not None and it.contour_table is None:     # a turning cycle's contour (lathe.py)
        it.diag("NC220", "warning", f"{s.text.strip()!r} ({s.reason}) in a turning cycle's contour "
                "is not modelled: the cycle's toolpath leaves it out")
        return
    v = it._value(f, s.text.strip())
    if v is None:
        return
    v = float(v)
    if kind in ("round", "round_modal", "chamfer_length", "chamfer_leg"):
        v *= it.st.scale
    if v < 0 or (v == 0 and kind == "feed"):
        it.diag("NC120", "error", f"{s.text.strip()} must be {'greater than 0' if kind == 'feed' else 'a length without sign'}: "
                "the control refuses it; nothing is inserted")
        return
    if it.contour_table is not None:    # filed with the element in a contour table (contour_tables)
        from nctrans.interp import contour_tables
        contour_tables.note_corner(it, kind, v, s.dialect)
        return
    cs = it.corner or CornerStage()
    it.corner = cs
    if kind == "round_modal":
        cs.modal_round = (v, s.dialect) if v > 0 else None
    elif kind == "feed_modal":
        cs.modal_feed = v if v > 0 else None
    elif kind == "feed":
        cs.block_feed = (v, it.span)
    else:
        _stale(it, cs)
        cs.block = (kind, v, it.span, s.dialect) if v > 0 else None
    _idle(it)


def _stale(it, cs: CornerStage) -> None:
    """A block word left from a block that had no move: the corner has nothing to follow."""
    b = cs.block
    if b is not None and b[2] is not it.span:
        cs.block = None
        it.diag("NC217", "warning", f"the {_NOUN[b[0]]} is not inserted: its block moves nothing "
                "to a corner", b[2])


def _idle(it) -> None:
    cs = it.corner
    if (cs is not None and cs.block is None and cs.block_feed is None and cs.modal_round is None
            and cs.modal_feed is None and cs.pending is None and not cs.queued):
        it.corner = None


def _carried(it, cs: CornerStage, kind: str) -> tuple:
    """The corner element this move leads to: (kind, value, feed, dialect), or ()."""
    feed = None
    bf = cs.block_feed
    if bf is not None:
        cs.block_feed = None
        if bf[1] is it.span:
            feed = bf[0]
    if feed is None:                    # FRCM in force where the element is programmed
        feed = cs.modal_feed
    b = cs.block
    if b is not None and b[2] is it.span:
        cs.block = None
        return (b[0], b[1], feed, b[3])
    _stale(it, cs)
    if cs.modal_round is not None and kind in CONTOUR_KINDS:
        return ("round", cs.modal_round[0], feed, cs.modal_round[1])
    return ()


def _probe(it, m: Move) -> tuple:
    """The machine points of three program points at the corner: equal at both blocks when the
    frame, offsets and tool length have not changed between them."""
    a1, _, _ = PLANE_AXES[m.payload[6]]
    shifted = dict(m.end)
    shifted[a1] = shifted.get(a1, 0.0) + 1.0
    return (it._to_machine(m.start), it._to_machine(m.end), it._to_machine(shifted),
            it.st.comp_side, it.comp_radius, it.comp is None, it.comp_exit)


def move(it, kind, start, end, center, cw, turns, payload) -> None:
    """records._move with a corner stage: hold, join or pass on the move."""
    cs = it.corner
    if cs.pending is not None and kind == "linear" and start == end and _stands_still_as_dummy(it, cs):
        # a G1 that moves nothing counts as a block without motion in the plane: the element
        # goes to the next block that moves, as long as few enough stand between
        cs.still.add((payload[0], payload[1]))
        if not _too_many_between(it, cs):
            cs.queued.append(StillMove(payload[0], payload[1], payload))
            return
        it.corner = cs                  # the flush may have let the stage go; this move uses it
    new = Move(kind, start, end, center, cw, turns, payload, it.span)
    new.corner = _carried(it, cs, kind)
    p = cs.pending
    if p is not None and cs.queued and _too_many_between(it, cs, it.span):
        p = None                        # gone uninserted: blocks without motion stood between
        it.corner = cs                  # (the flush may have let the stage go; this move uses it)
    if p is not None:
        cs.pending = None
        new = _join(it, p, new)
    if new.corner:
        if kind in CONTOUR_KINDS:
            new.probe = _probe(it, new)
            cs.pending = new
            _idle(it)
            return
        _not_inserted(it, new, "its block is not a contour move (G1, G2, G3)")
    _emit(it, new)
    _idle(it)


def record(it, rec) -> bool:
    """A non-motion record while a move is held: it waits (True), unless too many blocks without
    motion in the plane stand between (the corner then goes, uninserted)."""
    cs = it.corner
    if cs is None or cs.pending is None:
        return False
    cs.queued.append(rec)
    _too_many_between(it, cs, it.span)
    return True


def _too_many_between(it, cs: CornerStage, own: Optional[n.Span] = None) -> bool:
    """Whether more blocks without motion in the plane stand between the held move and the next
    one than the control allows (the held move then goes, uninserted). The records of `own`, the
    block running (a spindle speed that constant surface speed sets before its move), are not
    counted yet: whether that block moves is known at its move."""
    allowed = int(settings(cs.pending.corner[3]).get("dummy_blocks", 0))
    lines = {(r.file, r.line) for r in cs.queued} | cs.still
    if own is not None:
        lines.discard((own.file, own.line))
    if len(lines) > allowed:
        flush(it, f"{'a block' if not allowed else f'more than {allowed} blocks'} without motion "
              "in the plane stands between it and the next contour move")
        return True
    return False


def _stands_still_as_dummy(it, cs: CornerStage) -> bool:
    """A move of no length that the held element's control counts as a block without motion
    (rules corner_elements.zero_length = "dummy"), unless it programs an element of its own."""
    if settings(cs.pending.corner[3]).get("zero_length") != "dummy":
        return False
    b = cs.block
    return not (b is not None and b[2] is it.span)


def flush(it, why: str = "no contour move follows it") -> None:
    """Let the held move go as programmed (no corner element), then what waited behind it."""
    cs = it.corner
    if cs is None:
        return
    _stale(it, cs)
    p = cs.pending
    if p is not None:
        cs.pending = None
        _not_inserted(it, p, why)
        _emit(it, p)
    _replay(it, cs, p.end if p is not None else None)
    _idle(it)


def finish(it) -> None:
    """The program ended: what is held goes, and a word whose block never moved is said."""
    cs = it.corner
    if cs is not None and cs.block is not None:
        b, cs.block = cs.block, None
        it.diag("NC217", "warning", f"the {_NOUN[b[0]]} is not inserted: its block moves nothing "
                "to a corner", b[2])
    flush(it)


def _replay(it, cs: CornerStage, at: Optional[dict] = None) -> None:
    """The records that waited behind the held move, in order; a StillMove as a move of no length
    at `at` (program coordinates: where the held move, or the element after it, left the tool)."""
    cs.still = set()
    queued, cs.queued = cs.queued, []
    for rec in queued:
        if type(rec) is StillMove:
            if at is not None:
                it._emit_move("linear", at, at, None, None, None, rec.payload)
        else:
            it._push_record(rec)


def _emit(it, m: Move) -> None:
    it._emit_move(m.kind, m.start, m.end, m.center, m.cw, m.turns, m.payload)


def _not_inserted(it, m: Move, why: str, control_does: str = "") -> None:
    """Said at the corner word's line: NC218 where the control alarms, NC217 where it inserts no
    element either, NC219 where it does something nctrans does not model (`control_does`)."""
    kind, value, _, dialect = m.corner
    alarm = settings(dialect).get("missing_next") == "alarm"
    if alarm:
        rule, severity, control = "NC218", "error", "the control stops with an alarm"
    elif control_does:
        rule, severity, control = "NC219", "warning", f"{control_does}; nctrans does not model how"
    else:
        rule, severity, control = "NC217", "warning", "the control inserts none"
    it.diag(rule, severity, f"the {_NOUN[kind]} ({value:g}) is not in the analysed toolpath: {why} "
            f"({control}; the analysed toolpath runs the corner sharp)", m.span)


def _mark(it, m: Move) -> None:
    """Note the element's block for a writer that asks which elements it cannot write as the
    same word (nctrans.lower.corner_fit sets `corner_unfit` on the interpreter it runs)."""
    sink = it.__dict__.get("corner_unfit")
    if sink is not None and m.span is not None:
        sink.add((m.span.file, m.span.line))


# The control computes positions at 0.001 mm (MD 10200 INT_INCR_PER_MM = 1000 by default [GK]); a
# shrunk element is taken at that resolution, in program units, so a writer can state it exactly.
_RESOLUTION = {True: 0.001, False: 0.0001}      # mm program / inch program


def _shrunk(it, m: Move, first: corners.Element, second: corners.Element) -> Optional[corners.Corner]:
    """The element a Sinumerik control puts where the programmed one is too large for its blocks
    (rules `too_large = "reduced"`): [GK, Siemens Fundamentals "Chamfer, rounding": a chamfer or
    rounding too large for the contour elements is reduced automatically to a value that fits]. The
    manual does not say to which value: nctrans takes the largest that fits on both blocks as they
    stand (the element then takes the whole of the shorter one) [NC], at the control's resolution.
    Said at the word's line (NC229), since the program asks for another size; None where not even
    the smallest element fits."""
    kind, value, _, dialect = m.corner
    scale = it.st.scale or 1.0
    step = _RESOLUTION[scale == 1.0]
    lo, hi = 0.0, value
    for _ in range(60):                     # the largest that fits: it fits below, not above
        mid = (lo + hi) / 2
        if _shape(kind, first, second, mid)[0] is not None:
            lo = mid
        else:
            hi = mid
    size = math.floor(lo / scale / step + 1e-9) * step      # program units, at the resolution
    corner = _shape(kind, first, second, size * scale)[0] if size > 0 else None
    if corner is None:
        return None
    word = {v: k for k, v in settings(dialect).get("words", {}).items()}.get(kind, kind)
    it.diag("NC229", "warning", f"the {_NOUN[kind]} ({word}={value / scale:g}) is too large for its "
            f"blocks: the control reduces it to fit; the analysed toolpath inserts it at {size:g} (the "
            "largest that fits, nctrans' reading of 'reduced to a suitable value')", m.span)
    sink = it.__dict__.get("corner_shrunk")
    if sink is not None and m.span is not None:
        sink[(m.span.file, m.span.line)] = size
    return corner


def _in_plane(m: Move, a1: str, a2: str) -> bool:
    keys = set(m.start) | set(m.end)
    return all(abs(m.end.get(a, 0.0) - m.start.get(a, 0.0)) < 1e-9 for a in keys if a not in (a1, a2))


def _shape(kind: str, first, second, value: float):
    """(the rounding arc or chamfer line between two elements, or None, why not) for a corner word's kind."""
    if kind in ("round", "round_modal"):
        return corners.rounding(first, second, value)
    if kind == "chamfer_leg":
        return corners.chamfer_legs(first, second, value)
    return corners.chamfer_length(first, second, value)


def _element(m: Move, a1: str, a2: str) -> corners.Element:
    return corners.Element(m.kind, (m.start[a1], m.start[a2]), (m.end[a1], m.end[a2]),
                           m.center, m.cw)


def _join(it, p: Move, new: Move) -> Move:
    """Emit the held move `p` and the corner element between it and `new`; return `new`, its
    start moved to the element's end (unchanged when nothing is inserted)."""
    plane = p.payload[6]
    a1, a2, _ = PLANE_AXES[plane]
    why = ""
    control_does = ""
    if new.kind == "rapid" and new.payload[6] == plane and _in_plane(p, a1, a2) and _in_plane(new, a1, a2):
        # Siemens inserts the element before an in-plane G0 and traverses it at rapid (F and FRC
        # have no effect then) [GK: Siemens Fundamentals, "Chamfer, rounding"]
        why = "the next move is a rapid (G0) in the plane"
        control_does = "the control inserts it and traverses it at rapid"
    elif new.kind not in CONTOUR_KINDS:
        why = "the next move is not a contour move (G1, G2, G3)"
    elif new.payload[6] != plane:
        why = "the plane changes before the next move"
    elif not (_in_plane(p, a1, a2) and _in_plane(new, a1, a2)):
        why = "a move leaves the plane"
    elif any(m.kind == "arc" and (m.turns or (m.start.get(a1), m.start.get(a2)) ==
                                  (m.end.get(a1), m.end.get(a2))) for m in (p, new)):
        why = "an element is a full circle"
    elif _probe(it, p) != p.probe:
        why = "the frame, an offset or cutter compensation changes before the next move"
    elif any(corners.degenerate(_element(m, a1, a2)) for m in (p, new)):
        why = "an element has no length in the plane"
    if why:
        _not_inserted(it, p, why, control_does)
        _emit(it, p)
        _replay(it, it.corner, p.end)
        return new
    first, second = _element(p, a1, a2), _element(new, a1, a2)
    kind, value, feed, dialect = p.corner
    corner = None
    if not corners.is_tangent(first, second):
        corner, why = _shape(kind, first, second, value)
        if corner is None and settings(dialect).get("too_large") == "reduced":
            corner = _shrunk(it, p, first, second)
            if corner is None:
                _not_inserted(it, p, why, "the control shrinks it to fit")
                _mark(it, p)
        elif corner is None:
            _not_inserted(it, p, why)
    if corner is None:
        _emit(it, p)
        _replay(it, it.corner, p.end)
        return new

    def at(point, like):
        out = dict(like)
        out[a1], out[a2] = point
        return out
    if it.corner.still:
        _mark(it, p)                    # inserted across blocks that move nothing
    t1 = at(corner.first_end, p.end)
    t2 = at(corner.second_start, p.end)
    _emit(it, replace(p, end=t1))
    cs = it.corner
    pay = new.payload
    file, line = p.payload[0], p.payload[1]
    element_payload = (file, line, feed if feed is not None else pay[2], pay[3], pay[4], pay[5], plane, pay[7])
    it._emit_move(corner.kind, t1, t2, corner.center, corner.cw, None, element_payload)
    _replay(it, cs, t2)
    return replace(new, start=t2)


def apply_to_contour(it, blocks, moves: list) -> list:
    """A turning cycle's contour read without moving (lathe.py `_capture_contour`: tuples (kind,
    start, end, centre, cw, span, block)) with the roundings and chamfers its blocks program
    inserted, as the control machines the contour (RND/CHR in CYCLE95 contours, `,R`/`,C` in G71
    contours). Evaluated as the blocks are read; what cannot be inserted is said at its line."""
    words = {}                                  # id(block) -> (kind, value, dialect)
    modal = None
    for blk in blocks:
        for s in blk.body:
            if type(s) is not n.Passthrough or not (kind := kind_of(s)):
                continue
            try:
                v = it._value(it.ev.compile(s.value), s.text.strip())
            except Exception:                   # an evaluation error: said by the run itself
                v = None
            if v is None or kind in ("feed", "feed_modal"):
                continue
            v = float(v) * it.st.scale
            if v < 0:
                it.diag("NC120", "error", f"{s.text.strip()} must be a length without sign: the control "
                        "refuses it; nothing is inserted", blk.span)
                continue
            if kind == "round_modal":
                modal = (v, s.dialect) if v > 0 else None
            elif v > 0:
                words[id(blk)] = (kind, v, s.dialect)
        if id(blk) not in words and modal is not None:
            words[id(blk)] = ("round", modal[0], modal[1])
    if not words:
        return moves
    return insert_corners(it, moves, words)


def insert_corners(it, moves: list, words: dict) -> list:
    """The contour `moves` ((kind, start, end, centre, cw, span, key) in program coordinates) with
    the corner elements `words` ({id(key): (kind, value, dialect)}) inserted after the last move
    of each key: shared by turning-cycle contours and contour tables (contour_tables)."""
    a1, a2, _ = PLANE_AXES[it.st.plane]
    out: list = []
    for i, mv in enumerate(moves):
        out.append(mv)
        blk = mv[6]
        here = words.get(id(blk))
        last_of_block = i + 1 >= len(moves) or moves[i + 1][6] is not blk
        if here is None or not last_of_block:
            continue
        nxt = moves[i + 1] if i + 1 < len(moves) else None
        kind, value, dialect = here
        m = Move(mv[0], mv[1], mv[2], mv[3], mv[4], None, (), blk.span, corner=(kind, value, None, dialect))
        if nxt is None or nxt[0] not in CONTOUR_KINDS or mv[0] not in CONTOUR_KINDS:
            _not_inserted(it, m, "the contour has no contour move after it")
            continue
        n2 = Move(nxt[0], nxt[1], nxt[2], nxt[3], nxt[4], None, ())
        if not (_in_plane(m, a1, a2) and _in_plane(n2, a1, a2)):
            _not_inserted(it, m, "a move leaves the plane")
            continue
        first, second = _element(m, a1, a2), _element(n2, a1, a2)
        if corners.degenerate(first) or corners.degenerate(second):
            _not_inserted(it, m, "an element has no length in the plane")
            continue
        if corners.is_tangent(first, second):
            continue
        corner, why = _shape(kind, first, second, value)
        if corner is None:
            _not_inserted(it, m, why)
            continue
        t1, t2 = dict(mv[2]), dict(mv[2])
        t1[a1], t1[a2] = corner.first_end
        t2[a1], t2[a2] = corner.second_start
        out[-1] = (mv[0], mv[1], t1) + tuple(mv[3:])
        out.append((corner.kind, t1, t2, corner.center, corner.cw, mv[5], blk))
        moves[i + 1] = (nxt[0], t2) + tuple(nxt[2:])
    return out
