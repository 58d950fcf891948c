"""Frames and offsets: the statements that move the coordinate system rather than the tool.
Work offsets (G54.., via ModeChange in statements.py), G92 / G92.1 set positions, tool length and
radius offset selection (H/D), G10 data setting, programmable frames (ISO G52/G68/G51/G51.1,
Sinumerik TRANS/ROT/SCALE/MIRROR and their additive forms, $P_PFRAME).

Coordinates (all mm): program point -> programmable frame (frames.py) -> work point -> + G92 +
work offset + tool length -> machine point. After any change here the program point is re-derived
from the machine point (_resync): nothing moves. A mixin of Interpreter.
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any, Optional

from nctrans.interp import comp_radius, episode_frame, polar_input
from nctrans.interp.evaluate import EvalError, FrameValue, UNKNOWN
from nctrans.interp.frames import IDENT, PLANE_AXES, ProgrammableFrame, rpy_ordered
from nctrans.interp.state import LINEAR_AXES
from nctrans.ir import nodes as n

NORMAL = {"XY": "Z", "ZX": "Y", "YZ": "X"}
ROT_AXIS = NORMAL


def copy_frame(src: ProgrammableFrame, dst: Optional[ProgrammableFrame] = None) -> ProgrammableFrame:
    """A copy of a programmable frame (dicts copied, tuples shared), or `src` copied into `dst`."""
    if dst is None:
        dst = ProgrammableFrame.__new__(ProgrammableFrame)
    for slot in ProgrammableFrame.__slots__:
        v = getattr(src, slot)
        setattr(dst, slot, dict(v) if type(v) is dict else v)
    return dst


def _turns_off_zero(fr: ProgrammableFrame) -> bool:
    """A rotation in force whose centre is not the work zero (its affine part shifts)."""
    return any(part is not None and part[0] != IDENT and any(abs(t) > 1e-12 for t in part[1])
               for part in (fr.rot, fr.extra))


@lru_cache(maxsize=None)
def _frame_option(dialect: str, key: str):
    """options.<key> of rules/<dialect>.toml (None for a test dialect without a table)."""
    from nctrans.rules import option
    return option(dialect, key)


def additive_frames_compose(dialect: str) -> bool:
    """Whether the dialect's additive mirror and scale act in the current (rotated) system
    (options.additive_frames = "current_system": Sinumerik AMIRROR/ASCALE), rather than
    replacing their component of a fixed-order frame (Fagor G11-G14, G72)."""
    return _frame_option(dialect, "additive_frames") == "current_system"


def mirror_before_rotation(dialect: str) -> bool:
    """Whether the dialect's control mirrors a point before it rotates it, the rotation centre
    mirrored too (options.frame_order = "mirror_first": Fagor manual L10157-10160), rather than
    rotating first (ISO, Sinumerik)."""
    return _frame_option(dialect, "frame_order") == "mirror_first"


def mirror_refused_under_scale_or_rotation(dialect: str) -> bool:
    """Whether the dialect's control alarms at a programmable mirror (on or off) while scaling
    or a coordinate rotation is on (options.mirror_under_scale_or_rotation = "alarm": ISO G51.1
    under G51/G68, seed L1715-1718)."""
    return _frame_option(dialect, "mirror_under_scale_or_rotation") == "alarm"


def rotation_cancel_drops_added(dialect: str) -> bool:
    """Whether cancelling the rotation also cancels the rotations added to it
    (options.rotation_cancel = "with_added": Fagor `G73` alone after `G73 Q` increments)."""
    return _frame_option(dialect, "rotation_cancel") == "with_added"


class OffsetsMixin:
    """Coordinate-system statements and the program <-> machine point mapping."""

    def _offsets_table(self) -> dict:
        """Compilers of offset selection, set position, frame and data-setting statements."""
        return {
            n.OffsetSelect: self._c_offset, n.SetPosition: lambda s: (self._h_setpos, s),
            n.ResetSetPosition: lambda s: (self._h_resetpos, s),
            n.FrameOp: lambda s: (self._h_frame, s), n.DataSetting: lambda s: (self._h_data, s),
        }

    def _resync(self) -> None:
        """Program point from the machine point (after an offset or frame change). Under cutter
        radius compensation the move before is still held (its end waits for the next move's
        corner): the machine point is that move's programmed end under the offsets it was
        programmed with (records.py), not the last emitted, compensated one; the held move keeps
        those offsets, and the change applies from the next move."""
        tot = self.off.total
        held = getattr(self, "comp", None) is not None and self.comp_pos_machine is not None
        m = self.comp_pos_machine if held else self.mpos
        work = {a: v - tot.get(a, 0.0) for a, v in m.items()}
        self.pos = self.frame.to_program(work)
        if held:
            self._said_offset_change()

    def _said_offset_change(self) -> None:
        from nctrans.rules import option
        if option(self.program.dialect, "offset_change_under_comp") == "refused_by_oracle":
            self.diag("NC122", "info", "an offset change under cutter radius compensation: modelled as "
                      "the control applies it (the held compensated move keeps the offsets it was "
                      "programmed with, the next move takes the new ones); LinuxCNC refuses tool length, "
                      "coordinate system and axis offset changes there (end the compensation first)")

    def _to_machine(self, p: dict[str, float]) -> dict[str, float]:
        w = p if self.frame.identity else self.frame.to_work(p)
        tot = self.off.total
        if not tot:
            return dict(w)
        return {a: v + tot.get(a, 0.0) for a, v in w.items()}

    def _work_offset(self, name: str) -> dict[str, float]:
        """The shift of work coordinate system `name`: its own offset plus the external work
        offset (ISO EXOFS: G10 L2 P0, #5201..; Sinumerik $P_EXTFRAME), which moves every work
        system alike (seed sinumerik-iso-milling L1177, $P_EXTFRAME below $P_UIFR). "G53" is no
        settable offset (Sinumerik G500): the external one stays, as a system frame does."""
        up = name.upper()
        own = self.machine.work_offset(up) if up != "G53" else {}
        ext = self.machine.work_offset("EXT") if up != "EXT" else {}
        if not ext:
            return own
        return {a: own.get(a, 0.0) + ext.get(a, 0.0) for a in {**own, **ext}}

    def _work_offset_changed(self, name: str) -> None:
        """Re-apply the active work offset after offset `name` was written (the external one
        moves whichever system is active)."""
        active = (self.st.work_offset or "").upper()
        if active and (active == name or name == "EXT"):
            self.off.set_work(self._work_offset(active))
            self._resync()

    def _apply_length(self) -> None:
        st = self.st
        if self.edges is not None:              # the active cutting edge's length (tool_edges)
            z = self.edges.active_length()
        elif st.length_mode == "off":
            z = 0.0
        else:
            idx = st.length_index if st.length_index is not None else st.tool
            z = self.machine.length_offset(int(idx)) if idx else 0.0
            if st.length_mode == "minus":
                z = -z
        if z != self.off.tool_z or self.comp is None:   # (under G41/G42 _resync says NC122)
            self.off.set_tool(z)
            self._resync()
        if self.travel_limits is not None:      # limits on the tool tip follow its length
            self._send_limits()

    def _c_offset(self, s: n.OffsetSelect):
        return (self._h_offset, (s.kind, self.ev.compile(s.index)))

    def _h_offset(self, d):
        kind, f = d
        v = self._value(f, "offset number")
        if v is None:
            return
        i = int(round(v))
        if kind == "length":
            self.st.length_index = i
            if self.st.length_mode != "off":
                self._apply_length()
        elif self.edges is not None:            # an edge of the active tool (tool_edges)
            self.edges.select(i)
        else:
            self.st.radius_index = i
            self.comp_radius = comp_radius.radius_of(self, i)      # D of the active tool or a register

    def _h_data(self, s):
        """G10 data setting: write work offsets or tool-offset registers into the machine copy."""
        vals = {}
        for k, e in s.values.items():
            v = self._value(self.ev.compile(e), f"{k} value")
            if v is not None:
                vals[k.upper()] = v
        idx = self._value(self.ev.compile(s.index), "offset number")
        if idx is None:
            return
        idx = int(round(idx))
        inc = self.st.incremental
        if self.machine is not None and not getattr(self, "_machine_copied", False):
            self.machine = self.machine.copy()
            self._machine_copied = True
        m = self.machine
        if s.kind == "work_offset":
            if s.extended:
                name = f"G54.1P{idx}"
            elif idx == 0:
                name = "EXT"
            elif 1 <= idx <= 6:
                name = f"G{53 + idx}"
            else:
                self.diag("NC105", "error", f"work offset number {idx} out of range")
                return
            cur = dict(m.offsets.get(name, {}))
            for a, v in vals.items():
                v *= self.st.scale if a in LINEAR_AXES else 1.0
                cur[a] = cur.get(a, 0.0) + v if inc else v
            m.offsets[name] = cur
            self._work_offset_changed(name)
        elif s.kind.startswith("tool_"):
            # the register holds geometry + wear (as sysvars' #2001../#2201.. writes): L10/L12 set
            # the geometry and keep the wear, L11/L13 set the wear and keep the geometry (before,
            # a wear write replaced the whole offset: G10 L13 R.02 left a radius of .02)
            v = vals.get("VALUE", 0.0) * self.st.scale
            kind = "length" if "length" in s.kind else "radius"
            store = m.length_offsets if kind == "length" else m.radius_offsets
            read = m.length_offset if kind == "length" else m.radius_offset
            wear = self.__dict__.setdefault("offset_wear", {})
            old_wear = wear.get((kind, idx), 0.0)
            if s.kind.endswith("_wear"):
                new_wear = old_wear + v if inc else v
                store[idx] = read(idx) - old_wear + new_wear
                wear[(kind, idx)] = new_wear
            else:
                geometry = read(idx) - old_wear
                store[idx] = (geometry + v if inc else v) + old_wear

    def _h_setpos(self, s: n.SetPosition):
        vals = self._eval_words(self._words(s.target))
        if not vals or polar_input.guard(self, vals, "setting the position"):
            return
        target = self._target(vals)
        work = self.frame.to_work(target)
        g92 = dict(self.off.g92)
        wo = self.off.work
        held = self.comp is not None and self.comp_pos_machine is not None
        here = self.comp_pos_machine if held else self.mpos     # (a held compensated move: _resync)
        for a, _, _ in vals:
            tl = self.off.tool_z if a == "Z" else 0.0
            g92[a] = here.get(a, 0.0) - wo.get(a, 0.0) - tl - work[a]
        self.off.set_g92(g92)
        self.pos = target
        if held:
            self._said_offset_change()

    def _h_resetpos(self, s):
        self.off.set_g92({})
        self._resync()

    def _frame_axes_resolved(self, s: n.FrameOp) -> n.FrameOp:
        """The frame op with its AX[expr]=value words under the axes their expressions name when
        the block runs (Sinumerik `TRANS AX[AXVAR]=10`): the same op written with that axis."""
        values = dict(s.values)
        for axis, value in s.indirect:
            name = self._indirect_axis(self.ev.compile(axis)())
            values[name] = value
        return n.FrameOp(s.op, values, s.center, s.angle, s.additive, s.clear, s.local)

    def _h_frame(self, s: n.FrameOp):
        if s.indirect:
            s = self._frame_axes_resolved(s)
        st = self.st
        if st.polar and polar_input.guard(self, [(a,) for a in list(s.values) + list(s.center or ())],
                                          "a frame or local offset with plane axis words"):
            return
        scale = st.scale
        fr = self.frame
        op = s.op

        def num(e, what, lin=True):
            v = self._value(self.ev.compile(e), what)
            return None if v is None else v * (scale if lin else 1.0)

        def center():
            out = {}
            for a, av in (s.center or {}).items():
                e = av.value if isinstance(av, n.AxisValue) else av
                v = num(e, f"{a} centre", a.upper() in LINEAR_AXES)
                if v is not None:
                    out[a.upper()] = v
            return out

        # A programmable op that is neither additive, local (ISO G52) nor pivoted (ISO G68/G51/
        # G51.1 give a centre) replaces the whole programmable frame (Sinumerik TRANS/ROT/SCALE/
        # MIRROR); the others replace only their own component.
        replace_all = (not s.additive and not s.local and s.center is None and not s.clear
                       and op in ("trans", "rot", "scale", "mirror"))
        if replace_all:
            fr.clear()
        if op == "all":
            if s.clear:
                fr.clear()
        elif op == "trans":
            if s.clear:
                fr.set_local({})
            else:
                vals = {}
                for a, e in s.values.items():
                    v = num(e, f"{a} shift", a.upper() in LINEAR_AXES)
                    if v is not None:
                        vals[a.upper()] = v
                fr.set_local(vals, additive=s.additive)
        elif op == "rot":
            if s.clear:
                fr.set_rotation(None, 0.0, {},
                                cancel_added=rotation_cancel_drops_added(self.program.dialect))
            else:
                plane = st.plane
                if s.angle is not None:
                    ang = num(s.angle, "rotation angle", False) or 0.0
                    axis = ROT_AXIS[plane]
                    piv = center()
                    a1, a2, _ = PLANE_AXES[plane]
                    if s.center is not None and not s.additive:
                        # ISO G68: a missing centre coordinate is the current point
                        for a in (a1, a2):
                            piv.setdefault(a, self.pos.get(a, 0.0))
                    fr.set_rotation(axis, ang, piv, additive=s.additive)
                else:
                    first = True
                    for a, e in rpy_ordered(s.values.items()):
                        ang = num(e, f"{a} rotation", False)
                        if ang is not None:
                            fr.set_rotation(a.upper(), ang, center(),
                                            additive=s.additive or not first)
                            first = False
        elif op in ("scale", "mirror") and s.additive and not s.clear and additive_frames_compose(self.program.dialect):
            vals = {a.upper(): num(e, f"{a} {op}", False) for a, e in s.values.items()}
            fr.add_in_current_system(op, {a: v for a, v in vals.items() if v is not None})
        elif op == "scale":
            if s.clear:
                fr.set_scale({}, {})
            else:
                f = {a.upper(): num(e, f"{a} scale", False) for a, e in s.values.items()}
                fr.set_scale({a: v for a, v in f.items() if v is not None}, center())
        elif op == "mirror":
            if fr.mirror_first and _turns_off_zero(fr):
                self.diag("NC216", "warning", "a mirror programmed (or cancelled) while a coordinate "
                          "rotation about a centre other than the work zero is in force: the manual "
                          "mirrors the centre by the mirrors active at the rotation (L10157-10160) and "
                          "does not say whether a later mirror moves it; the analysed toolpath keeps the "
                          "centre where the rotation put it (program the mirror before the rotation)")
            if (fr.rot is not None or fr.scale is not None) and mirror_refused_under_scale_or_rotation(
                    self.program.dialect):
                on = "scaling" if fr.rot is None else "coordinate rotation" if fr.scale is None else \
                    "scaling and coordinate rotation"
                self.diag("NC215", "error", f"programmable mirror {'cancel' if s.clear else 'on'} while {on} is "
                          "on: the control refuses it (program the mirror before scaling and rotation and "
                          "cancel it after them, seed L1715-1718); the analysed toolpath goes on with it "
                          "applied as programmed")
            if s.clear:
                keep = {a: v for a, v in fr.mirror_axes.items()
                        if s.values and a not in {k.upper() for k in s.values}}
                fr.set_mirror(keep)
            else:
                piv = center()
                axes = {a.upper(): piv.get(a.upper(), 0.0) for a in s.values}
                for a, v in piv.items():
                    axes.setdefault(a, v)
                fr.set_mirror(axes)
        episode_frame.frame_changed_under_comp(self)
        self._resync()

    def _set_pframe(self, value: Any) -> None:
        """$P_PFRAME = frame: the programmable frame becomes `value`, each step acting as the
        frame instruction it stands for: the first replaces (TRANS/ROT/SCALE/MIRROR), the
        following ones add in the system it produced (ATRANS/AROT/ASCALE/AMIRROR)."""
        if value is UNKNOWN:
            self.diag("NC107", "info", "the programmable frame variable is assigned a value unknown at "
                      "analysis time; the programmable frame is kept")
            return
        if not isinstance(value, FrameValue):
            raise EvalError("NC104", "the programmable frame needs a frame value (a frame expression or "
                            "variable)")
        self.frame.clear()
        first = True
        for step in value.steps:
            op, vals = step
            if op == "state":
                settable = self.frame.settable       # the settable frame is not the programmable one
                copy_frame(vals, self.frame)
                self.frame.set_settable(settable)
            else:
                self._h_frame(n.FrameOp(op, {a: n.Num(v) for a, v in vals}, additive=not first))
            first = False
        self._resync()
