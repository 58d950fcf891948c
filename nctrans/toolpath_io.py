"""Writing toolpath records (jsonl, csv) as they stream out of the interpreter, and the summary.

jsonl keys follow the contract ("Toolpath"); keys that do not apply to a record are absent, floats
are rounded to 6 decimals (1 nm: far below any machine's resolution, and it keeps lines short and
diffs stable). Writers take an iterator and write each record as it comes, so memory does not grow
with program length.
"""
from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass, field
from typing import IO, Iterable, Optional

from nctrans.machine import Machine
from nctrans.plainrun import JsonChunk
from nctrans.toolpath import ToolpathRecord

CSV_AXES = ("X", "Y", "Z", "A", "B", "C")
CSV_COLUMNS = (
    ["seq", "file", "line", "kind"]
    + [f"{p}_{a}" for p in ("start", "end", "center") for a in CSV_AXES]
    + ["direction", "plane", "turns", "feed", "feed_mode", "spindle", "tool", "dwell_s",
       "spindle_dir", "coolant", "stop_kind", "pitch"]
)


def _num(v) -> str:
    """JSON spelling of a number rounded to 6 decimals; -0 prints as 0; NaN/inf as null."""
    if v.__class__ is int:
        return str(v)
    if not math.isfinite(v):
        return "null"
    return repr(round(v, 6) + 0.0)


# Number spellings seen recently: CAM output repeats coordinates (a Z level, an X column) all the
# time, and a dict hit is ~10x cheaper than formatting. Bounded: cleared when it grows past the cap.
_SPELLED: dict = {}
_SPELLED_CAP = 1 << 16


def _spell(v) -> str:
    """repr(round(v, 6) + 0.0), computed as '%.6f' with the trailing zeros cut where the two agree:
    1e-4 <= |v| < 1e9 gives at most 15 significant digits, which a double always round-trips, so
    the shortest repr of the rounded value is exactly those digits (repr switches to an exponent
    below 1e-4, so smaller magnitudes go the slow way). Non-finite values spell 'nan'/'inf', which
    to_json_line routes to the always-valid path."""
    s = _SPELLED.get(v)
    if s is not None:
        return s
    a = abs(v)
    if 1e-4 <= a < 1e9:
        s = ("%.6f" % v).rstrip("0")
        if s[-1] == ".":
            s += "0"
    elif a == a and a != math.inf:
        s = repr(round(v, 6) + 0.0)
    else:
        return repr(v)
    if len(_SPELLED) >= _SPELLED_CAP:
        _SPELLED.clear()
    _SPELLED[v] = s
    return s


# '{"X":%s,"Y":%s,"Z":%s}' per tuple of axis names (a handful per program).
_AXES_FORMAT: dict = {}


def _axes(d: dict) -> str:
    keys = tuple(d)
    f = _AXES_FORMAT.get(keys)
    if f is None:
        f = "{" + ",".join('"%s":%%s' % k.replace("%", "%%") for k in keys) + "}"
        if len(_AXES_FORMAT) < 1024:
            _AXES_FORMAT[keys] = f
    get = _SPELLED.get
    return f % tuple([get(v) or _spell(v) for v in d.values()])


_FILE_JSON: dict[str, str] = {}


def _str(s: str) -> str:
    """JSON string literal of s (file names are few: cached)."""
    out = _FILE_JSON.get(s)
    if out is None:
        out = json.dumps(s)
        if len(_FILE_JSON) < 1024:
            _FILE_JSON[s] = out
    return out


def _safe_json_line(r: ToolpathRecord) -> str:
    """The slow, always-valid path. A non-finite scalar is an unknown value (a spindle angle turned
    by IC from a turning spindle, said by NC220 at its line): its key is left out, never null.
    Coordinates are never non-finite (NC108 stops them before a record is made)."""
    d = {}
    for name in ToolpathRecord.__slots__:
        v = getattr(r, name)
        if v is None:
            continue
        if isinstance(v, float):
            if not math.isfinite(v):
                continue
            v = round(v, 6) + 0.0
        elif isinstance(v, dict):
            v = {k: (round(x, 6) + 0.0 if math.isfinite(x) else None) for k, x in v.items()}
        d[name] = v
    return json.dumps(d, separators=(",", ":"))


# The start of a motion record is the previous record's end dict (shared, never mutated by the
# interpreter): its spelling is kept and reused. Holding the dict keeps its id from being reused.
_LAST_END: list = [None, ""]


def to_json_line(r: ToolpathRecord) -> str:
    """One compact JSON object (no newline), keys in contract order, absent when they do not apply.
    Built from cached number spellings and per-axis-set format strings (see _spell)."""
    s = f'{{"seq":{r.seq},"file":{_str(r.file)},"line":{r.line},"kind":"{r.kind}"'
    start = r.start
    if start is not None:
        last = _LAST_END
        if start is last[0]:
            s += ',"start":' + last[1]
        else:
            s += ',"start":' + _axes(start)
    end = r.end
    if end is not None:
        e = _axes(end)
        _LAST_END[0] = end
        _LAST_END[1] = e
        s += ',"end":' + e
    if r.center is not None:
        s += ',"center":' + _axes(r.center)
    if r.direction is not None:
        s += f',"direction":"{r.direction}"'
    if r.plane is not None:
        s += f',"plane":"{r.plane}"'
    if r.turns is not None:
        s += f',"turns":{int(r.turns)}'
    if r.feed is not None:
        s += ',"feed":' + _spell(r.feed)
    if r.feed_mode is not None:
        s += f',"feed_mode":"{r.feed_mode}"'
    if r.spindle is not None:
        s += ',"spindle":' + _spell(r.spindle)
    if r.tool is not None:
        s += f',"tool":{int(r.tool)}'
    if r.dwell_s is not None:
        s += ',"dwell_s":' + _spell(r.dwell_s)
    if r.spindle_dir is not None:
        s += f',"spindle_dir":"{r.spindle_dir}"'
    if r.coolant is not None:
        s += f',"coolant":"{r.coolant}"'
    if r.stop_kind is not None:
        s += f',"stop_kind":"{r.stop_kind}"'
    if r.pitch is not None:
        s += ',"pitch":' + _spell(r.pitch)
    if r.css is not None:
        s += ',"css":' + _spell(r.css)
    if r.spindle_limit is not None:
        s += ',"spindle_limit":' + _spell(r.spindle_limit)
    if r.css_axis is not None:
        s += ',"css_axis":' + _spell(r.css_axis)
    if r.zone is not None:
        s += f',"zone":"{r.zone}"'
    if r.call is not None:
        s += ',"call":' + _str(r.call)
    if r.args is not None:
        s += ',"args":[' + ",".join("null" if a is None else _spell(a) for a in r.args) + "]"
    if r.spindle_angle is not None:
        s += ',"spindle_angle":' + _spell(r.spindle_angle)
    if r.thread_start is not None:
        s += ',"thread_start":' + _spell(r.thread_start)
    s += "}"
    if "nan" in s or "inf" in s:      # a non-finite number (or a file name containing the letters)
        return _safe_json_line(r)
    return s


def write_jsonl(records: Iterable, out: IO[str], on_record=None) -> int:
    """Write each record as one line as it arrives; returns the count. on_record(rec) sees each one.
    The items may include JsonChunk (records the native kernel already wrote: toolpath_of(...,
    fast_sink="jsonl")); on_record never sees those, so a caller that needs every record object
    does not ask for them."""
    n = 0
    write = out.write
    for r in records:
        if r.__class__ is JsonChunk:
            write(r.text)
            n += r.count
            continue
        write(to_json_line(r) + "\n")
        if on_record is not None:
            on_record(r)
        n += 1
    return n


def _csv_num(v) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return "" if not math.isfinite(v) else repr(round(v, 6) + 0.0)
    return str(v)


def write_csv(records: Iterable[ToolpathRecord], out: IO[str], on_record=None) -> int:
    """CSV with a fixed header (CSV_COLUMNS); axes other than XYZABC are not in the csv form."""
    w = csv.writer(out, lineterminator="\n")
    w.writerow(CSV_COLUMNS)
    n = 0
    for r in records:
        row = [r.seq, r.file, r.line, r.kind]
        for pt in (r.start, r.end, r.center):
            row.extend(_csv_num(pt.get(a)) if pt else "" for a in CSV_AXES)
        row += [r.direction or "", r.plane or "", "" if r.turns is None else r.turns,
                _csv_num(r.feed), r.feed_mode or "", _csv_num(r.spindle),
                "" if r.tool is None else r.tool, _csv_num(r.dwell_s),
                r.spindle_dir or "", r.coolant or "", r.stop_kind or "", _csv_num(r.pitch)]
        w.writerow(row)
        if on_record is not None:
            on_record(r)
        n += 1
    return n


# --------------------------------------------------------------------------- summary

def arc_sweep(r: ToolpathRecord) -> tuple[float, float, float, tuple[str, str]]:
    """(start angle, signed sweep in radians, radius, (first, second) plane axes) of an arc record."""
    a1, a2 = PLANE_AXES.get(r.plane or "XY", ("X", "Y"))
    s, e, c = r.start or {}, r.end or {}, r.center or {}
    sx, sy = s.get(a1, 0.0) - c.get(a1, 0.0), s.get(a2, 0.0) - c.get(a2, 0.0)
    ex, ey = e.get(a1, 0.0) - c.get(a1, 0.0), e.get(a2, 0.0) - c.get(a2, 0.0)
    t0 = math.atan2(sy, sx)
    t1 = math.atan2(ey, ex)
    radius = math.hypot(sx, sy)
    if r.direction == "cw":
        sweep = t1 - t0
        if sweep >= -1e-12:
            sweep -= 2 * math.pi
    else:
        sweep = t1 - t0
        if sweep <= 1e-12:
            sweep += 2 * math.pi
    turns = r.turns or 0
    sweep += math.copysign(2 * math.pi * turns, sweep)
    return t0, sweep, radius, (a1, a2)


PLANE_AXES = {"XY": ("X", "Y"), "ZX": ("Z", "X"), "YZ": ("Y", "Z")}


def motion_length(r: ToolpathRecord) -> float:
    """Path length in mm of a rapid/linear/arc record (linear axes only; helix included)."""
    s, e = r.start or {}, r.end or {}
    if r.kind == "arc":
        _t0, sweep, radius, (a1, a2) = arc_sweep(r)
        planar = abs(sweep) * radius
        others = [a for a in set(s) | set(e) if a not in (a1, a2) and a in "XYZUVW"]
        axial = math.sqrt(sum((e.get(a, 0.0) - s.get(a, 0.0)) ** 2 for a in others))
        return math.hypot(planar, axial)
    axes = [a for a in set(s) | set(e) if a in "XYZUVW"]
    return math.sqrt(sum((e.get(a, 0.0) - s.get(a, 0.0)) ** 2 for a in axes))


@dataclass
class Summary:
    """Accumulates the facts `toolpath --summary` prints while records stream past."""
    machine: Optional[Machine] = None
    counts: dict[str, int] = field(default_factory=dict)
    rapid_mm: float = 0.0
    feed_mm: float = 0.0
    time_s: float = 0.0
    dwell_s: float = 0.0
    lo: dict[str, float] = field(default_factory=dict)
    hi: dict[str, float] = field(default_factory=dict)
    tools: list[int] = field(default_factory=list)
    unknown_time: int = 0   # feed moves whose time cannot be estimated (no feed, per-rev without S)

    def _extend(self, pt: Optional[dict]) -> None:
        if not pt:
            return
        lo, hi = self.lo, self.hi
        for a, v in pt.items():
            if a not in lo or v < lo[a]:
                lo[a] = v
            if a not in hi or v > hi[a]:
                hi[a] = v

    def _rapid_rate(self, r: ToolpathRecord) -> float:
        """mm/min of a rapid: the slowest moving axis's rapid rate limits (default 10 m/min)."""
        rate = 0.0
        if self.machine is not None:
            s, e = r.start or {}, r.end or {}
            rates = [ax.rapid for name, ax in self.machine.axes.items()
                     if ax.rapid and abs(e.get(name, 0.0) - s.get(name, 0.0)) > 1e-9]
            rate = min(rates) if rates else 0.0
        return rate or 10000.0

    def add(self, r: ToolpathRecord) -> None:
        self.counts[r.kind] = self.counts.get(r.kind, 0) + 1
        kind = r.kind
        if kind in ("rapid", "linear", "arc"):
            length = motion_length(r)
            self._extend(r.start)
            self._extend(r.end)
            if kind == "arc":
                self._extend_arc(r)
            if kind == "rapid":
                self.rapid_mm += length
                self.time_s += 60.0 * length / self._rapid_rate(r)
            else:
                self.feed_mm += length
                t = self._feed_time(r, length)
                if t is None:
                    self.unknown_time += 1
                else:
                    self.time_s += t
        elif kind == "dwell" and r.dwell_s:
            self.dwell_s += r.dwell_s
            self.time_s += r.dwell_s
        elif kind == "tool_change" and r.tool is not None and r.tool not in self.tools:
            self.tools.append(r.tool)

    def _feed_time(self, r: ToolpathRecord, length: float) -> Optional[float]:
        f = r.feed
        if not f or f <= 0:
            return None
        if r.feed_mode == "inverse_time":
            return 60.0 / f
        if r.feed_mode == "per_rev":
            if not r.spindle:
                return None
            f = f * r.spindle
        return 60.0 * length / f

    def _extend_arc(self, r: ToolpathRecord) -> None:
        """Add the arc's extreme points (where it crosses a quadrant boundary) to the bounding box."""
        t0, sweep, radius, (a1, a2) = arc_sweep(r)
        c = r.center or {}
        k0 = math.floor(min(t0, t0 + sweep) / (math.pi / 2)) + 1
        k1 = math.floor(max(t0, t0 + sweep) / (math.pi / 2))
        for k in range(k0, min(k1, k0 + 4) + 1):
            ang = k * math.pi / 2
            self._extend({a1: c.get(a1, 0.0) + radius * math.cos(ang),
                          a2: c.get(a2, 0.0) + radius * math.sin(ang)})

    def format(self, diagnostics: int = 0) -> str:
        moves = sum(self.counts.get(k, 0) for k in ("rapid", "linear", "arc"))
        lines = ["records: " + (", ".join(f"{k} {self.counts[k]}" for k in sorted(self.counts)) or "none")]
        lines.append(f"moves: {moves}; rapid {self.rapid_mm:.3f} mm, feed {self.feed_mm:.3f} mm")
        if self.lo:
            axes = [a for a in ("X", "Y", "Z", "A", "B", "C", "U", "V", "W") if a in self.lo] + \
                   sorted(a for a in self.lo if a not in "XYZABCUVW")
            lines.append("bounding box: " + "  ".join(f"{a} {self.lo[a]:.3f} .. {self.hi[a]:.3f}" for a in axes))
        lines.append("tools: " + (" ".join(f"T{t}" for t in self.tools) or "none"))
        m, s = divmod(self.time_s, 60.0)
        h, m = divmod(int(m), 60)
        est = f"{h}:{m:02d}:{s:04.1f}" if h else f"{m}:{s:04.1f}"
        note = f" ({self.unknown_time} feed moves without a usable feed not counted)" if self.unknown_time else ""
        lines.append(f"estimated cycle time: {est} (feeds and rapids at programmed/rapid rates, "
                     f"dwell {self.dwell_s:.1f} s){note}")
        lines.append(f"diagnostics: {diagnostics}")
        return "\n".join(lines) + "\n"
