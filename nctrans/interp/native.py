"""The native lane: runs of plain blocks (PlainRun, from a streamed main body) go through the C
kernel (nctrans.plainrun.native) while the interpreter's state is one the kernel models exactly;
what it hands back runs through the Python handlers, block by block.

A mixin of Interpreter: it reads and updates the state the motion handlers keep (st, pos, mpos,
off, frame, last_from/last_arc, feed flags) and appends JsonChunk items to `out` when the consumer
takes records already written as JSON lines (fast_sink "jsonl").
"""
from __future__ import annotations

from typing import Optional

from nctrans import plainrun
from nctrans.interp import arcs
from nctrans.interp.compiled import BLOCK, _plain_entry
from nctrans.plainrun import JsonChunk, PlainRun
from nctrans.toolpath_io import _spell
from nctrans.toolpath_io import _str as _json_str

PLAIN_EXPAND = 64           # blocks of a PlainRun expanded at a time when the kernel cannot run it
KERNEL_BLOCKS = 4096        # blocks per kernel call: its JSON text (~1 MB) is all it holds
_KERNEL_AXES = frozenset("XYZABCUVW")


class NativeLaneMixin:
    """Plain runs through the native kernel, and the state in which it may take them."""

    def _plain(self, run: PlainRun, budget: int) -> tuple[int, list]:
        """Run a PlainRun: through the native kernel as far as it goes identically, then the
        blocks it hands back through the Python path. Returns (blocks run here, code entries
        still to run: the next Blocks and the rest of the run)."""
        done = 0
        tried = self._kernel_ready()
        if tried:
            limit = min(budget, KERNEL_BLOCKS)
            done, run = self._plain_kernel(run, limit)
            if run is None:
                return done, []
            if done == limit < budget:          # only the call's size stopped it: go on
                return done, [_plain_entry(run)]
        blocks, rest = run.take(1 if tried else PLAIN_EXPAND)
        entries = [(BLOCK, None, b, b.span) for b in blocks]
        if rest is not None:
            entries.append(_plain_entry(rest))
        return done, entries

    def _kernel_ready(self) -> bool:
        """The state the kernel handles: _h_fast's (no cycle, comp, frame), no modal call or
        flatten hook, feed per minute or per revolution, one axis order for both positions."""
        st = self.st
        if (self.fast_sink is None or st.cycle != "off" or self.modal_cycle is not None
                or self.comp is not None or self.comp_exit or st.comp_side != "off"
                or not self.frame.identity or self.modal_call is not None or self.hook is not None
                or st.feed_mode not in ("per_min", "per_rev") or self.out
                or self.unmodelled_motion is not None or self.spindle_stopped or self.watch
                or self.corner is not None or st.polar or self.capture is not None):
            return False
        axes = "".join(self.pos)
        return len(axes) == len(self.pos) and axes == "".join(self.mpos) and _KERNEL_AXES.issuperset(axes)

    def _plain_kernel(self, run: PlainRun, budget: int) -> tuple[int, Optional[PlainRun]]:
        st = self.st
        pos, mpos = self.pos, self.mpos
        axes = "".join(pos)
        tot = self.off.total
        motion = plainrun.motion_code(st.motion)
        tail = ""
        if st.spindle_speed is not None:
            tail += ',"spindle":' + _spell(st.spindle_speed)
        if st.tool is not None:
            tail += f',"tool":{int(st.tool)}'
        write = self.fast_sink == "jsonl"
        # an open run (its end not found yet): the kernel finds it, holding each line to scan()'s
        # checks in the front end's static state where the run starts
        is_open = run.is_open
        scan_state = ((plainrun.motion_code(run.motion), run.cycle is None, run.arc_abs, run.strict,
                       run.max_chars) if is_open else None)
        (stop, line, blocks, chunk, records, prog, mach, new_motion, feed, feed_seen,
         last_from, last_arc, last_g, ended) = self.native.run(
            run.text, run.start, len(run.text) if is_open else run.end, run.sep, run.line, axes,
            list(pos.values()),
            [tot.get(a, 0.0) for a in axes] if tot else None, list(mpos.values()), st.scale,
            st.incremental, motion, st.feed, f',"feed_mode":"{st.feed_mode}"', tail, self._seq,
            _json_str(run.file), budget, write, st.plane, st.arc_absolute,
            arcs.CENTER_TOL_INCH if st.scale != 1.0 else arcs.CENTER_TOL_MM,
            st.feed_scale,                          # Sinumerik G70: inch lengths, feeds in mm
            scan_state)
        if blocks:
            self.pos = dict(zip(axes, prog))
            self.mpos = dict(zip(axes, mach))
            if last_from is not None:
                self.last_from = dict(zip(axes, last_from))
                self.last_arc = None if last_arc is None else ((last_arc[0], last_arc[1]), last_arc[2])
                self.moved = True
            if new_motion != motion:
                st.set("motion", plainrun.MOTIONS[new_motion])
            if feed_seen:
                st.feed = feed
                self.feed_reported = False
                self._rc_feed_scale = st.feed_scale
            if records:
                if write:
                    self.out.append(JsonChunk(chunk, records))
                else:
                    self._seq += records
        # the front end's static mode where the rest starts: the last G word the kernel ran
        motion_at, cycle_at = ((plainrun.MOTIONS[last_g], None) if last_g >= 0
                               else (run.motion, run.cycle))
        if is_open and ended:
            if run.ends.pos is None:
                run.ends.found(stop, line, motion_at, cycle_at)
            return blocks, None
        if is_open or blocks < run.blocks:
            return blocks, run.piece(stop, line, motion_at, cycle_at, blocks)
        return blocks, None
