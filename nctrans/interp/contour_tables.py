"""Contour tables (seed 14, L23169-23960): CONTPRON / CONTDCON .. EXECUTE fill a REAL array with the
contour the blocks between them describe, without moving the tool; EXECTAB traverses one row.

Why: user stock-removal programs and cycle code (CYCLE95) read their contour through these
tables; left unmodelled, such code moved nothing (NC220).

- `CONTPRON(TAB, MACH, NN, MODE)` (L23230-23262, 11 columns, L23370-23400, L23470-23530): row per
  element, col 0 previous row, col 1 next row (the printed tables, L23355-23365, L23440-23460,
  and the footnotes L23505-23530, put "previous" in col 0; the column list's words are swapped),
  col 2 code abc (a G90 0 / G91 1, b G70 0 / G71 1, c G0..G3), cols 3-4 start, 5-6 end
  (abscissa, ordinate of the plane), col 7 relief marker, col 8 angle, cols 9-10 arc centre.
  Row 0 is the first block's element (from the point where CONTPRON was called); row 0's cols
  0/1 hold the row of the contour end and the last row used; the row after that holds the
  number of relief cuts forwards (col 0) and backwards (col 1). MODE 1 (SW 4.4, L23262,
  L23318-23320) adds the contour backwards from the table's last row down (L23516-23530).
- `CONTDCON(TAB, MODE)` (L23540-23700, 6 columns): row 0 the start point (col 0 = 10 x unit code,
  col 5 the last row), rows 1..n the elements: col 0 the code (L23680-23700), 1-2 end point,
  3-4 arc centre, 5 the feed. MODE 0 only (L23655 "Value 1 is not permitted").
- `EXECUTE(ERR)` ends the table (L23300-23312): ERR 0, or 1 when the contour was refused.
- `EXECTAB(TAB[n])` (L23960-23985) runs row n of a CONTPRON table as one block.
- `INTERSEC(TAB1[n1], TAB2[n2], CUT)` (L23870-23915): where two rows' elements meet.

Derived from the seed's two CONTPRON tables (L23355-23365, L23440-23460), all [NC] where the
text is silent: col 8 is the element's angle to the abscissa in [0, 180) (a line: its direction
modulo 180; an arc: the largest value its tangent takes inside it, 180 when it reaches the
horizontal from above); col 7 marks relief cuts: walking the contour, a relief starts at an
element that descends (away from the material side: X falling for "L", rising for "G"; Z for the
face modes "P"/"N" [NC]) and ends at the next element that rises; the start element holds the row
of the end element, the end element minus the row of the next relief start, -1111 for none. An
end element that rises above the relief's start level is split there; the rest is appended after
the table's rows. A relief that starts at row 0 is not split at its end (row 0 is the way from
the call point, not the contour; its level is where the tool happened to stand). The contour is extended along the ordinate to its extreme level when it does not
end there (backwards in the seed's example 2). A relief starting at row 0 (the approach from the
call point) is not counted. NN gets the forward count.
Not derived, said at the line (NC242): an arc whose level turns inside it (col 7 and the count
are then not reliable), transverse machining angles (col 8 measured from the ordinate [NC]).
The table holds lengths as the blocks program them: program units, X a diameter under DIAMON;
the geometry (angles, levels, splits, INTERSEC) is worked out true to size, X a radius.
The blocks' modal changes and the position are undone at EXECUTE: the blocks were only read.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Optional

from nctrans.interp.evaluate import Array, EvalError, Ref
from nctrans.interp.frames import PLANE_AXES
from nctrans.ir import nodes as n

EPS = 1e-9
RELIEF_NONE = -1111                      # seed L23358: the last relief's end marker
PREPARE_COLS, DECODE_COLS = 11, 6
_UNIT_CODE = {"G70": 0, "G71": 1, "G700": 2, "G710": 3}      # L23684 (CONTDCON tens)
_PATH_CODE = {"G60": 0, "G64": 1, "G641": 2, "G642": 3}      # L23690 ("G44" read as G64 [NC])
_FEED_CODE = {"inverse_time": 0, "per_min": 1, "per_rev": 2}  # L23688 (G96: 3)


def kinds(program) -> dict:
    """{procedure name: what it does} of the program's dialect (rules options.contour_tables)."""
    meta = program.meta if isinstance(program.meta, dict) else {}
    return meta.get("contour_tables") or {}


@dataclass
class Snapshot:
    """The modal codes in force when a contour block moved (CONTDCON's code and feed)."""
    incremental: bool
    unit: int
    feed_code: int
    path_code: Optional[int]
    exact_once: bool
    feed: float
    corner: Optional[tuple] = None       # (kind, value, dialect) of the block's RND/CHF
    span: Any = None
    scale: float = 1.0


class _Capture(list):
    """The interpreter's capture list (records._move appends (kind, start, end, centre, cw,
    span)): each move gets the modal snapshot of its block."""

    def __init__(self, it, session):
        super().__init__()
        self.it, self.session = it, session

    def append(self, item):
        super().append(tuple(item) + (self.session.snapshot(self.it),))


@dataclass
class Session:
    kind: str                            # "prepare" (CONTPRON) or "decode" (CONTDCON)
    table: Array
    name: str
    mach: str = "L"
    nn: Any = None
    mode: int = 0
    span: Any = None
    saved: tuple = ()
    problems: list = field(default_factory=list)     # (span, message): the contour is refused
    pending: Optional[tuple] = None      # (span, kind, value, dialect) of a corner word
    modal_round: Optional[tuple] = None

    exact_span: Any = None               # the block that programs G9 (non-modal)
    depth: int = 0                       # call depth of the CONTPRON/CONTDCON (len(it.stack))

    def note_mode(self, it, group: str) -> None:
        if group == "exact_stop_once":
            self.exact_span = it.span

    def snapshot(self, it) -> Snapshot:
        st = it.st
        spelt = it.spelt_codes
        unit = spelt.get("units")
        unit_code = _UNIT_CODE.get(str(unit).upper()) if unit else None
        if unit_code is None:
            unit_code = {"inch_geometry": 0, "inch": 2}.get(st.groups.get("units", "mm"), 1)
        path = spelt.get("path_mode")
        path_code = _PATH_CODE.get(str(path).upper(), None) if path else 0
        feed_code = 3 if st.groups.get("spindle_mode") == "css" else _FEED_CODE.get(st.feed_mode, 1)
        corner = None
        if self.pending is not None and self.pending[0] is it.span:
            corner = self.pending[1:]
        elif self.modal_round is not None:
            corner = ("round",) + self.modal_round
        feed = (st.feed or 0.0) / (st.feed_scale or 1.0)
        return Snapshot(st.incremental, unit_code, feed_code, path_code,
                        self.exact_span is not None and self.exact_span is it.span, feed, corner,
                        it.span, st.scale)


CONTOUR_MOTIONS = frozenset(("rapid", "linear", "arc_cw", "arc_ccw", "arc_3point", "arc_tangent"))


def refuse_motion(it, motion: str) -> None:
    """A motion mode other than G0-G3/CIP/CT in a contour table's block (seed L23281-23285)."""
    it.contour_table.problems.append((it.span, f"a {motion} move: only G0-G3 (with RND/CHF, CIP, CT) "
                                      "may describe the contour (seed L23281-23285)"))


def _problem(it, message: str, span=None) -> None:
    it.diag("NC242", "error", message, span)


# ---------------------------------------------------------------------------------------------
# CONTPRON / CONTDCON / EXECUTE in the interpreter

def run_call(it, s: n.SubCall, what: str) -> None:
    """A contour-table procedure call (what: prepare, decode, execute, traverse)."""
    if what == "traverse":
        return traverse(it, s)
    if what == "execute":
        return execute(it, s)
    name = s.name.upper()
    if it.contour_table is not None:
        _problem(it, f"{name} while the table of {it.contour_table.name} is still being filled "
                 "(no EXECUTE since): the control alarms (seed L23640); the call is ignored")
        return
    args = list(s.args)
    need = 3 if what == "prepare" else 1
    if len(args) < need or type(args[0]) is not n.Var:
        _problem(it, f"{name} needs {'TABNAME, MACH, NN' if need == 3 else 'TABNAME'} (seed "
                 f"{'L23233' if need == 3 else 'L23578'}); the blocks up to EXECUTE still move nothing")
        args = []
    ev = it.ev
    table = None
    try:
        table = ev.make_ref(args[0]) if args else None
        mach, nn, mode = "L", None, 0
        if what == "prepare" and args:
            mach = str(ev.compile(args[1])()).strip().upper()
            nn = ev.make_ref(args[2]) if len(args) > 2 and not _omitted(args[2]) else None
            if len(args) > 3 and not _omitted(args[3]):
                mode = int(round(float(ev.compile(args[3])())))
        elif what == "decode" and len(args) > 1 and not _omitted(args[1]):
            mode = int(round(float(ev.compile(args[1])())))
    except (EvalError, TypeError, ValueError) as ex:
        _problem(it, f"{name}: {ex}")
        table = None
    cols = PREPARE_COLS if what == "prepare" else DECODE_COLS
    session = Session(what, table if isinstance(table, Array) else None,
                      str(args[0].key).upper() if args else "?", mach, nn, mode, it.span)
    session.depth = len(it.stack)
    if args and session.table is None:
        session.problems.append((it.span, f"{name}: {args[0].key} is not an array"))
    elif session.table is not None and (len(session.table.dims) != 2 or session.table.dims[1] != cols):
        session.problems.append((it.span, f"{name}: the table {session.name} must be declared "
                                 f"[rows, {cols}] (seed {'L23336' if cols == 11 else 'L23640'})"))
    if what == "prepare" and len(args) > 2 and not _omitted(args[2]) and type(args[2]) is not n.Var:
        # NN is written by the call ("result variable", seed L23242): a value there cannot
        # take the count
        session.problems.append((it.span, "CONTPRON: NN must be a variable, which receives the "
                                 "number of relief cuts (seed L23242)"))
    if what == "prepare" and mach not in ("G", "L", "N", "P"):
        session.problems.append((it.span, f"CONTPRON machining type {mach!r}: the seed knows G, L, N, "
                                 "P (L23236-23240)"))
    if what == "prepare" and mode not in (0, 1):
        session.problems.append((it.span, f"CONTPRON MODE {mode}: 0 forwards or 1 both directions "
                                 "(seed L23262)"))
    if what == "decode" and mode != 0:
        session.problems.append((it.span, f"CONTDCON MODE {mode}: only 0 is permitted (seed L23655)"))
    if it.st.comp_side != "off":
        session.problems.append((it.span, f"{name} with tool radius compensation on: G40 must be "
                                 "active before the call (seed L23275, L23610)"))
    import copy
    st = copy.copy(it.st)
    st.groups = dict(it.st.groups)
    from nctrans.interp.offsets import copy_frame
    # the frame is edited in place (offsets._h_frame): keep a copy to compare and restore
    session.saved = (it.pos, it.mpos, it.st, it.last_from, it.last_arc, it.css_surface,
                     dict(it.spelt_codes), it.off.total, copy_frame(it.frame))
    it.st = st
    it.css_surface = None
    it.contour_table = session
    it.capture = _Capture(it, session)


def _close(it, session) -> bool:
    """End the table session: position, modal state and frame as they were at the call (the
    blocks between only described the contour). True where the blocks changed a frame or offset."""
    from nctrans.interp.offsets import copy_frame
    (it.pos, it.mpos, it.st, it.last_from, it.last_arc, it.css_surface, spelt, total,
     frame) = session.saved
    it.spelt_codes.clear()
    it.spelt_codes.update(spelt)
    it.capture = None
    it.contour_table = None
    changed = it.off.total != total or any(
        getattr(it.frame, slot) != getattr(frame, slot) for slot in type(frame).__slots__)
    if changed:
        copy_frame(frame, it.frame)
    return changed


def _omitted(e) -> bool:
    return type(e) is n.Num and e.text == ""


def unclosed(it) -> None:
    """The program ended between CONTPRON/CONTDCON and EXECUTE: its blocks were only read."""
    session = it.contour_table
    if session is None:
        return
    it.capture = None
    it.contour_table = None
    _problem(it, f"the table of {session.name} is never ended: no EXECUTE after this call before the "
             "program ends (seed L23300); the blocks after it were only read and moved nothing",
             session.span)


def left_by_return(it) -> None:
    """A subprogram returned between its CONTPRON/CONTDCON and EXECUTE: the table is refused at
    the call and the session ends there, so the caller's blocks move again (they are no contour)."""
    session = it.contour_table
    if session is None or session.depth <= len(it.stack):
        return
    _close(it, session)
    _problem(it, f"the table of {session.name} is never ended: its subprogram returned with no "
             "EXECUTE (seed L23300); the blocks after the call were only read and moved nothing",
             session.span)


def refuse_cycle(it, name: str) -> None:
    """A cycle called in a contour table's blocks (only G0-G3 may describe it, seed L23281)."""
    it.contour_table.problems.append((it.span, f"{name} called while a contour table is read: only "
                                      "G0-G3 (with RND/CHF, CIP, CT) may describe the contour (seed "
                                      "L23281-23285); the cycle is skipped"))


def note_corner(it, kind: str, value: float, dialect: str) -> None:
    """RND/CHF/RNDM inside the table's blocks: kept for the element they end (EXECUTE)."""
    session = it.contour_table
    if kind == "round_modal":
        session.modal_round = (value, dialect) if value > 0 else None
    elif kind in ("feed", "feed_modal"):
        return
    else:
        session.pending = (it.span, kind, value, dialect) if value > 0 else None


def execute(it, s: n.SubCall) -> None:
    """EXECUTE(ERR): the table from the moves read since CONTPRON/CONTDCON; ERR 0 or 1."""
    session = it.contour_table
    if session is None:
        _problem(it, "EXECUTE without CONTPRON or CONTDCON before it: nothing to end")
        return
    moves = list(it.capture)
    frame_changed = _close(it, session)
    problems = list(session.problems)
    if frame_changed:
        problems.append((it.span, "a frame or offset changed between the call and EXECUTE (seed "
                         "L23290); the frame of the call is in force again"))
    rows = None
    if not problems:
        try:
            rows = _rows(it, session, moves, problems)
        except _Refused as ex:
            problems.append((ex.span or it.span, str(ex)))
    warnings = [p for p in problems if len(p) == 3]      # ("warn", span, message): NC243
    problems = [p for p in problems if len(p) == 2]
    for _, span, message in warnings:
        it.diag("NC243", "warning", f"contour table {session.name}: {message}", span)
    for span, message in problems:
        _problem(it, f"contour table {session.name}: {message}; EXECUTE returns 1", span)
    if rows is not None and not problems:
        table = session.table
        table.data.clear()
        count = rows.pop("_count", 0)
        for r, row in rows.items():
            for c, v in enumerate(row):
                if v:
                    table.set((r, c), float(v))
        if session.kind == "prepare" and isinstance(session.nn, Ref):
            session.nn.set(int(count))
    # ERR is resolved last, after the session is closed and its findings said: a bad ERR (an
    # undefined name, an index error) is said at this line and leaves the run as at the call
    err_ref = it.ev.make_ref(s.args[0]) if s.args and type(s.args[0]) is n.Var else None
    if s.args and not _omitted(s.args[0]) and type(s.args[0]) is not n.Var:
        _problem(it, "EXECUTE: ERR must be a variable, which receives 0 or 1 (seed L23247); "
                 "the status is not kept")
    if isinstance(err_ref, Ref):
        err_ref.set(1 if problems else 0)


class _Refused(Exception):
    def __init__(self, message: str, span=None):
        super().__init__(message)
        self.span = span


# ---------------------------------------------------------------------------------------------
# Elements in table measure

@dataclass
class Element:
    code: int                      # G0..G3 (c digit)
    start: tuple
    end: tuple
    centre: Optional[tuple]
    snap: Optional[Snapshot]
    span: Any = None


def _elements(it, session, moves) -> tuple[tuple, list]:
    """(start point, elements) in table measure: plane (abscissa, ordinate), program units, X a
    diameter under DIAMON; RND/CHF inserted."""
    st = it.st
    a1, a2, normal = PLANE_AXES[st.plane]
    from nctrans.interp import corner_elements
    keyed = [(k, s, e, c, cw, sp, snap) for k, s, e, c, cw, sp, snap in moves]
    words = {id(m[6]): m[6].corner for m in keyed if m[6].corner is not None}
    if words:
        keyed = corner_elements.insert_corners(it, keyed, words)
    if not keyed:
        raise _Refused("no contour block between the call and EXECUTE (seed L23640: too few "
                       "contour blocks)")

    def f(axis: str, v: float) -> float:
        return v / (st.scale or 1.0)

    def pt(p) -> tuple:
        return (f(a1, p.get(a1, 0.0)), f(a2, p.get(a2, 0.0)))
    out = []
    for kind, s, e, c, cw, sp, snap in keyed:
        if isinstance(snap, Snapshot) and abs(snap.scale - st.scale) > EPS:
            raise _Refused("G70/G71/G700/G710 changed between the call and EXECUTE (seed L23290)", sp)
        if kind not in ("rapid", "linear", "arc"):
            raise _Refused(f"a {kind} move: only G0-G3 (with RND/CHF, CIP, CT) may describe the "
                           "contour (seed L23281-23285)", sp)
        if abs(s.get(normal, 0.0) - e.get(normal, 0.0)) > 1e-6:
            raise _Refused(f"a move along {normal}, out of the plane: the table holds plane "
                           "elements only [NC]", sp)
        code = {"rapid": 0, "linear": 1}.get(kind, 2 if cw else 3)
        centre = None
        if kind == "arc":
            centre = (f(a1, c[0]), f(a2, c[1]))
        out.append(Element(code, pt(s), pt(e), centre, snap if isinstance(snap, Snapshot) else None, sp))
    return out[0].start, out


def _rows(it, session, moves, problems) -> dict:
    """The table's rows. The geometry is worked out true to size (program units, X a radius);
    the rows hold X as programmed, a diameter under DIAMON [NC]."""
    start, elements = _elements(it, session, moves)
    if session.kind == "decode":
        rows = _decode_rows(session, start, elements)
        cols = ((1, 2), (3, 4))
    else:
        rows = _prepare_rows(it, session, elements, problems)
        cols = ((3, 4), (5, 6), (9, 10))
    k = diameter_index(it)
    if k is not None:
        for r, row in rows.items():
            if r == "_count" or (session.kind == "prepare" and r == _counts_row(rows)):
                continue
            for pair in cols:
                if session.kind == "decode" and r == 0 and pair == (3, 4):
                    continue
                row[pair[k]] *= 2
    return rows


def diameter_index(it) -> Optional[int]:
    """The table coordinate (0 abscissa, 1 ordinate) that holds X as a diameter, or None."""
    a1, a2, _ = PLANE_AXES[it.st.plane]
    if not it.st.diameter or "X" not in (a1, a2):
        return None
    return 0 if a1 == "X" else 1


def _counts_row(rows: dict) -> int:
    """The CONTPRON row after the forward table: the relief counts (no coordinates)."""
    return int(rows[0][1]) + 1


def _decode_rows(session, start, elements) -> dict:
    """CONTDCON rows (L23660-23700)."""
    need = len(elements) + 1
    if need > session.table.dims[0]:
        raise _Refused(f"{len(elements)} elements need {need} rows; the table has "
                       f"{session.table.dims[0]} (seed L23640)")
    first = elements[0].snap
    rows = {0: [10 * (first.unit if first else 1), start[0], start[1], 0, 0, len(elements)]}
    for i, el in enumerate(elements, 1):
        sn = el.snap
        if sn.path_code is None:
            raise _Refused("a continuous-path mode CONTDCON cannot code (G60, G64, G641, G642 only, "
                           "seed L23690)", el.span)
        code = (el.code + 10 * sn.unit + 100 * int(sn.incremental) + 1000 * sn.feed_code
                + 10000 * sn.path_code + 100000 * int(sn.exact_once))
        c = el.centre or (0.0, 0.0)
        rows[i] = [code, el.end[0], el.end[1], c[0], c[1], sn.feed]
    return rows


# ---------------------------------------------------------------------------------------------
# CONTPRON

def _norm180(a: float) -> float:
    a = math.fmod(a, 180.0)
    if a < 0:
        a += 180.0
    return 0.0 if abs(a - 180.0) < 1e-9 or abs(a) < 1e-9 else a


def sweep(start, end, centre, cw: bool) -> float:
    """Signed sweep (degrees, ccw positive) of an arc; a full circle when start == end."""
    a0 = math.atan2(start[1] - centre[1], start[0] - centre[0])
    a1 = math.atan2(end[1] - centre[1], end[0] - centre[0])
    d = math.degrees(a1 - a0)
    if cw:
        d = d % 360.0
        d = -(360.0 - d) if d > 1e-9 else -360.0
    else:
        d = d % 360.0
        d = d if d > 1e-9 else 360.0
    return d


def angle(el: Element, transverse: bool) -> float:
    """Column 8: the element's angle to the abscissa (to the ordinate when transverse [NC])."""
    def direction(dx, dy):
        return math.degrees(math.atan2(dx, dy)) if transverse else math.degrees(math.atan2(dy, dx))
    if el.centre is None:
        return _norm180(direction(el.end[0] - el.start[0], el.end[1] - el.start[1]))
    cw = el.code == 2
    r0 = (el.start[0] - el.centre[0], el.start[1] - el.centre[1])
    t0 = (r0[1], -r0[0]) if cw else (-r0[1], r0[0])
    sw = sweep(el.start, el.end, el.centre, cw)
    phi0 = direction(*t0)
    phi1 = phi0 + (-sw if transverse else sw)
    lo, hi = min(phi0, phi1), max(phi0, phi1)
    k = math.floor(hi / 180.0 + 1e-12)
    if 180.0 * k > lo + 1e-9:          # a multiple of 180 in (lo, hi]: approached from below
        return 180.0
    return _norm180(hi) if _norm180(hi) > 0 else 180.0


def _level(mach: str):
    """The level a relief is judged on and its sign: (coordinate index, sign)."""
    return {"L": (1, 1.0), "G": (1, -1.0), "P": (0, 1.0), "N": (0, -1.0)}[mach]


def _arc_turns(el: Element, axis: int) -> bool:
    """True when the arc's coordinate `axis` has an extremum strictly inside it."""
    sw = sweep(el.start, el.end, el.centre, el.code == 2)
    a0 = math.degrees(math.atan2(el.start[1] - el.centre[1], el.start[0] - el.centre[0]))
    targets = (90.0, 270.0) if axis == 1 else (0.0, 180.0)
    for t in targets:
        d = (t - a0) % 360.0 if sw > 0 else (a0 - t) % 360.0
        if 1e-9 < d < abs(sw) - 1e-9:
            return True
    return False


def _split(el: Element, axis: int, value: float) -> tuple[Element, Element]:
    """A line split where its coordinate `axis` reaches `value`."""
    t = (value - el.start[axis]) / (el.end[axis] - el.start[axis])
    p = tuple(el.start[i] + t * (el.end[i] - el.start[i]) for i in range(2))
    p = tuple(value if i == axis else p[i] for i in range(2))
    return (Element(el.code, el.start, p, None, el.snap, el.span),
            Element(el.code, p, el.end, None, el.snap, el.span))


def _split_arc(el: Element, axis: int, value: float) -> Optional[tuple]:
    r = math.hypot(el.start[0] - el.centre[0], el.start[1] - el.centre[1])
    other = 1 - axis
    d = value - el.centre[axis]
    if abs(d) > r:
        return None
    h = math.sqrt(max(r * r - d * d, 0.0))
    sw = sweep(el.start, el.end, el.centre, el.code == 2)
    a0 = math.atan2(el.start[1] - el.centre[1], el.start[0] - el.centre[0])
    best = None
    for sgn in (1.0, -1.0):
        q = [0.0, 0.0]
        q[axis] = value
        q[other] = el.centre[other] + sgn * h
        a = math.atan2(q[1] - el.centre[1], q[0] - el.centre[0])
        dd = math.degrees(a - a0) % 360.0 if sw > 0 else math.degrees(a0 - a) % 360.0
        if 1e-9 < dd < abs(sw) - 1e-9 and (best is None or dd < best[0]):
            best = (dd, tuple(q))
    if best is None:
        return None
    p = best[1]
    return (Element(el.code, el.start, p, el.centre, el.snap, el.span),
            Element(el.code, p, el.end, el.centre, el.snap, el.span))


def _arc_extremes(el: Element, axis: int) -> list:
    """The values of coordinate `axis` at the arc's inner turning points."""
    sw = sweep(el.start, el.end, el.centre, el.code == 2)
    r = math.hypot(el.start[0] - el.centre[0], el.start[1] - el.centre[1])
    a0 = math.degrees(math.atan2(el.start[1] - el.centre[1], el.start[0] - el.centre[0]))
    out = []
    for t, v in (((90.0, el.centre[1] + r), (270.0, el.centre[1] - r)) if axis == 1 else
                 ((0.0, el.centre[0] + r), (180.0, el.centre[0] - r))):
        d = (t - a0) % 360.0 if sw > 0 else (a0 - t) % 360.0
        if 1e-9 < d < abs(sw) - 1e-9:
            out.append(v)
    return out


def _extreme(elements: list, axis: int, sign: float) -> float:
    """The contour's extreme level (largest sign*coordinate), arcs' inner extremes included; the
    first element's start (where the tool stood at the call) is not the contour's."""
    best = None
    for el in elements:
        vals = [el.end[axis]] + ([el.start[axis]] if best is not None else [])
        if el.centre is not None:
            vals += _arc_extremes(el, axis)
        for v in vals:
            if best is None or sign * v > sign * best:
                best = v
    return best


def _chain(it, session, elements: list, first_is_approach: bool, extend_to: Optional[float],
           alloc, problems) -> tuple[list, list, int]:
    """Relief analysis of one direction. elements in contour order; alloc() gives the next free
    row. Returns (rows in chain order as (row, Element, marker)), count of reliefs, rows used."""
    axis, sign = _level(session.mach)
    chain = [[alloc(), el, 0] for el in elements]
    last = chain[-1][1]
    if extend_to is not None and abs(last.end[axis] - extend_to) > 1e-9:
        p = list(last.end)
        p[axis] = extend_to
        chain.append([alloc(), Element(1, last.end, tuple(p), None, last.snap, last.span), 0])
    reported = False
    inside = None                       # (index in chain, level) of the open relief's start
    starts: list[int] = []               # chain indices of relief starts
    ends: list[int] = []
    i = 0
    while i < len(chain):
        el = chain[i][1]
        if el.centre is not None and _arc_turns(el, axis) and not reported:
            reported = True
            problems.append(("warn", el.span, "an arc whose level turns inside it: col 7 (relief "
                             "markers) and the relief count are not derived for it [NC]"))
        h0, h1 = sign * el.start[axis], sign * el.end[axis]
        if inside is None and h1 < h0 - 1e-9:
            inside = (i, h0)
            starts.append(i)
        elif inside is not None and h1 > h0 + 1e-9:
            top = inside[1]
            approach = first_is_approach and inside[0] == 0
            if h1 > top + 1e-9 and not approach:    # above the relief's start level: split there
                pieces = (_split(el, axis, sign * top) if el.centre is None
                          else _split_arc(el, axis, sign * top))
                if pieces is not None:
                    chain[i][1] = pieces[0]
                    chain.insert(i + 1, [alloc(), pieces[1], 0])
            ends.append(i)
            inside = None
        i += 1
    for k, si in enumerate(starts):
        if k < len(ends):
            chain[si][2] = chain[ends[k]][0]
    for k, ei in enumerate(ends):
        nxt = starts[k + 1] if k + 1 < len(starts) else None
        chain[ei][2] = -chain[nxt][0] if nxt is not None else RELIEF_NONE
    count = sum(1 for si in starts if not (first_is_approach and si == 0))
    return chain, count


def _prepare_rows(it, session, elements: list, problems) -> dict:
    """CONTPRON rows (L23336-23530)."""
    size = session.table.dims[0]
    transverse = session.mach in ("N", "P")
    axis, sign = _level(session.mach)
    extreme = _extreme(elements, axis, sign)
    rows: dict = {}
    free = {"next": 0}

    def alloc_fwd():
        r = free["next"]
        free["next"] += 1
        return r
    fwd, count_f = _chain(it, session, elements, True, extreme, alloc_fwd, problems)
    fwd_end = free["next"] - 1
    count_b = 0
    bwd = []
    if session.mode == 1 and len(elements) < 2:
        raise _Refused("one contour block only: both directions need two or more (seed L23640: "
                       "too few contour blocks)")
    if session.mode == 1:
        down = {"next": size - 2}

        def alloc_bwd():
            r = down["next"]
            down["next"] -= 1
            return r
        rev = [Element({2: 3, 3: 2}.get(el.code, el.code), el.end, el.start, el.centre, el.snap, el.span)
               for el in reversed(elements[1:])]
        # the reversed elements take rows from the table's end in forward order (L23440-23460)
        rows_for = {id(el): alloc_bwd() for el in reversed(rev)}
        bwd, count_b = _chain_bwd(it, session, rev, rows_for, extreme, alloc_bwd, problems)
        lowest = down["next"] + 1
        if lowest <= fwd_end + 1:
            raise _Refused(f"the table of {size} rows is too small for both directions (seed L23640)")
    if fwd_end + 1 >= size:
        raise _Refused(f"the contour needs {fwd_end + 2} rows; the table has {size} (seed L23640)")

    def code(el):
        sn = el.snap
        a = int(sn.incremental) if sn else 0
        b = 1 if (sn is None or sn.unit in (1, 3)) else 0
        return 100 * a + 10 * b + el.code

    def fill(chain, first_prev, last_next):
        for k, (r, el, marker) in enumerate(chain):
            prev = chain[k - 1][0] if k else first_prev
            nxt = chain[k + 1][0] if k + 1 < len(chain) else last_next
            c = el.centre or (0.0, 0.0)
            rows[r] = [prev, nxt, code(el), el.start[0], el.start[1], el.end[0], el.end[1],
                       marker, angle(el, transverse), c[0], c[1]]
    fill(fwd, 0, 0)
    rows[0][0] = fwd[-1][0]             # contour end forwards (L23505)
    rows[0][1] = fwd_end                # contour table end forwards (L23507)
    rows[0][7] = 0
    rows[fwd_end + 1] = [count_f, count_b] + [0] * 9
    if session.mode == 1:
        fill(bwd, 0, 0)
        e0 = elements[0]
        back0 = Element({2: 3, 3: 2}.get(e0.code, e0.code), e0.end, e0.start, e0.centre, e0.snap, e0.span)
        c = back0.centre or (0.0, 0.0)
        rows[size - 1] = [min(r for r, _, _ in bwd), bwd[0][0], code(back0), back0.start[0],
                          back0.start[1], back0.end[0], back0.end[1], 0, angle(back0, transverse),
                          c[0], c[1]]
    rows["_count"] = count_f
    return rows


def _chain_bwd(it, session, rev, rows_for, extreme, alloc, problems):
    """The backward chain: the reversed elements keep the rows allocated from the table's end in
    forward order (rows_for); extensions and splits take the next rows down."""
    pending = [rows_for[id(el)] for el in rev]
    state = {"i": 0}

    def alloc_b():
        if state["i"] < len(pending):
            r = pending[state["i"]]
            state["i"] += 1
            return r
        return alloc()
    return _chain(it, session, rev, False, extreme, alloc_b, problems)


# ---------------------------------------------------------------------------------------------
# EXECTAB

def traverse(it, s: n.SubCall) -> None:
    """EXECTAB(TAB[n]): row n of a CONTPRON table as one block: its G code (G0-G3) to its end
    point, an arc about its centre (L23960-23985). The end point is absolute [NC]; the modal
    motion code is not changed (the seed: "non-modally", L23978)."""
    arg = s.args[0] if s.args else None
    if type(arg) is not n.Var or len(arg.indices or ()) != 1:
        _problem(it, "EXECTAB needs one table row, EXECTAB(TAB[n]) (seed L23965); nothing moves")
        return
    try:
        store = it.ev._lookup_name(str(arg.key).upper())
        table = store[str(arg.key).upper()] if store is not None else None
        if type(table) is Ref:
            table = table.get()
        row = int(round(float(it.ev.compile(arg.indices[0])())))
    except (EvalError, TypeError, ValueError) as ex:
        _problem(it, f"EXECTAB: {ex}; nothing moves")
        return
    if not isinstance(table, Array) or len(table.dims) != 2 or table.dims[1] != PREPARE_COLS:
        _problem(it, f"EXECTAB: {arg.key} is not a CONTPRON table (11 columns, seed L23950); nothing moves")
        return
    if not 0 <= row < table.dims[0]:
        _problem(it, f"EXECTAB: row {row} outside the table; nothing moves")
        return
    vals = [float(table.get((row, c)) or 0.0) for c in range(PREPARE_COLS)]
    g = int(round(vals[2])) % 10
    st = it.st
    a1, a2, _ = PLANE_AXES[st.plane]

    def f(axis, v):
        v = v * st.scale
        return v / 2 if axis == "X" and st.diameter else v
    end = it._target([(a1, f(a1, vals[5]), "abs"), (a2, f(a2, vals[6]), "abs")])
    it.moved = True
    if g == 0:
        it._move("rapid", end)
    elif g == 1:
        it._need_feed()
        it._move("linear", end)
    else:
        from nctrans.interp import arcs
        centre = (f(a1, vals[9]), f(a2, vals[10]))
        err = arcs.check_center(it.pos.get(a1, 0.0), it.pos.get(a2, 0.0), end[a1], end[a2], centre[0],
                                centre[1], st.scale != 1.0)
        if err:                 # the row's arc does not start where the tool stands: the control alarms
            it.diag("NC203", "error", f"EXECTAB({arg.key}[{row}]): {err}")
            return
        it._need_feed()
        it._move("arc", end, centre, g == 2)


# ---------------------------------------------------------------------------------------------
# INTERSEC

def _row_element(ev, var: n.Var) -> tuple:
    """(kind, start, end, centre, cw) of CONTPRON table row TAB[n] (kind "line" or "arc")."""
    name = str(var.key).upper()
    store = ev._lookup_name(name)
    table = store[name] if store is not None else None
    if type(table) is Ref:
        table = table.get()
    if not isinstance(table, Array) or len(table.dims) != 2 or table.dims[1] != PREPARE_COLS:
        raise EvalError("NC242", f"INTERSEC: {var.key} is not a CONTPRON table (11 columns, seed L23910)")
    if len(var.indices or ()) != 1:
        raise EvalError("NC242", f"INTERSEC: {var.key} needs one row index, {var.key}[n] (seed L23885)")
    row = int(round(float(ev.compile(var.indices[0])())))
    v = [float(table.get((row, c)) or 0.0) for c in range(PREPARE_COLS)]
    g = int(round(v[2])) % 10
    if g >= 2:
        return ("arc", (v[3], v[4]), (v[5], v[6]), (v[9], v[10]), g == 2)
    return ("line", (v[3], v[4]), (v[5], v[6]), None, None)


def _scaled(el, k: int, f: float) -> tuple:
    def s(p):
        return None if p is None else tuple(v * f if i == k else v for i, v in enumerate(p))
    return (el[0], s(el[1]), s(el[2]), s(el[3]), el[4])


def _along(el, q) -> Optional[float]:
    """Where q lies on the element, 0..1 from its start (None: not on it)."""
    kind, s, e, c, cw = el
    if kind == "line":
        dx, dy = e[0] - s[0], e[1] - s[1]
        L = dx * dx + dy * dy
        if L <= EPS:
            return None
        t = ((q[0] - s[0]) * dx + (q[1] - s[1]) * dy) / L
        off = abs((q[0] - s[0]) * dy - (q[1] - s[1]) * dx) / math.sqrt(L)
        return t if -1e-9 <= t <= 1 + 1e-9 and off <= 1e-6 else None
    sw = sweep(s, e, c, cw)
    a0 = math.degrees(math.atan2(s[1] - c[1], s[0] - c[0]))
    a = math.degrees(math.atan2(q[1] - c[1], q[0] - c[0]))
    d = (a - a0) % 360.0 if sw > 0 else (a0 - a) % 360.0
    if d > abs(sw) + 1e-7 and d < 360.0 - 1e-7:
        return None
    return 0.0 if d >= 360.0 - 1e-7 else d / abs(sw)


def _circle(el):
    kind, s, e, c, cw = el
    return c, math.hypot(s[0] - c[0], s[1] - c[1])


def _line_circle(s, e, c, r) -> list:
    dx, dy = e[0] - s[0], e[1] - s[1]
    a = dx * dx + dy * dy
    b = 2 * (dx * (s[0] - c[0]) + dy * (s[1] - c[1]))
    cc = (s[0] - c[0]) ** 2 + (s[1] - c[1]) ** 2 - r * r
    disc = b * b - 4 * a * cc
    if a <= EPS or disc < -1e-9:
        return []
    h = math.sqrt(max(disc, 0.0))
    return [(s[0] + t * dx, s[1] + t * dy) for t in {(-b + h) / (2 * a), (-b - h) / (2 * a)}]


def intersections(el1, el2) -> list:
    """Points where two table elements meet, ordered along the first [NC]: both bounded (a line
    between its points, an arc over its sweep); parallel lines meet nowhere."""
    k1, k2 = el1[0], el2[0]
    if k1 == "line" and k2 == "line":
        (s1, e1), (s2, e2) = el1[1:3], el2[1:3]
        d1 = (e1[0] - s1[0], e1[1] - s1[1])
        d2 = (e2[0] - s2[0], e2[1] - s2[1])
        cross = d1[0] * d2[1] - d1[1] * d2[0]
        if abs(cross) <= EPS:
            return []
        t = ((s2[0] - s1[0]) * d2[1] - (s2[1] - s1[1]) * d2[0]) / cross
        cands = [(s1[0] + t * d1[0], s1[1] + t * d1[1])]
    elif k1 == "line" or k2 == "line":
        line, arc = (el1, el2) if k1 == "line" else (el2, el1)
        cands = _line_circle(line[1], line[2], *_circle(arc))
    else:
        (c1, r1), (c2, r2) = _circle(el1), _circle(el2)
        dx, dy = c2[0] - c1[0], c2[1] - c1[1]
        d = math.hypot(dx, dy)
        if d <= EPS or d > r1 + r2 + 1e-9 or d < abs(r1 - r2) - 1e-9:
            return []
        a = (r1 * r1 - r2 * r2 + d * d) / (2 * d)
        h = math.sqrt(max(r1 * r1 - a * a, 0.0))
        m = (c1[0] + a * dx / d, c1[1] + a * dy / d)
        cands = [(m[0] - h * dy / d, m[1] + h * dx / d), (m[0] + h * dy / d, m[1] - h * dx / d)]
    hits = []
    for q in cands:
        t1, t2 = _along(el1, q), _along(el2, q)
        if t1 is not None and t2 is not None:
            hits.append((t1, q))
    return [q for _, q in sorted(hits)]


def compile_intersec(ev, e: n.Func):
    """VARIB=INTERSEC(TAB1[n1], TAB2[n2], CUT) (seed 14.4, L23870-23915): TRUE and the first
    intersection along TAB1[n1] in CUT[0] (abscissa), CUT[1] (ordinate); FALSE when they do not
    meet (CUT unchanged)."""
    args = list(e.args)

    def call():
        if len(args) != 3 or any(type(a) is not n.Var for a in args):
            raise EvalError("NC242", "INTERSEC needs TAB1[n1], TAB2[n2] and a result array (seed L23880)")
        el1, el2 = _row_element(ev, args[0]), _row_element(ev, args[1])
        cut = ev.make_ref(args[2])
        if not isinstance(cut, Array) or len(cut.dims) != 1 or cut.dims[0] < 2:
            raise EvalError("NC242", f"INTERSEC: {args[2].key} must be a REAL array of 2 (seed L23900)")
        reader = getattr(ev, "table_diameter_index", None)
        k = reader() if reader is not None else None
        if k is not None:               # X held as a diameter: the circles are true to size in radius
            el1, el2 = _scaled(el1, k, 0.5), _scaled(el2, k, 0.5)
        hits = intersections(el1, el2)
        if not hits:
            return False
        q = list(hits[0])
        if k is not None:
            q[k] *= 2
        cut.set((0,), float(q[0]))
        cut.set((1,), float(q[1]))
        return True
    return call
