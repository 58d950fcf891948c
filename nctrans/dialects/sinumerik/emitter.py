"""IR -> idiomatic Sinumerik 840D text, on the emitter base (nctrans.dialects.emit): statements
dispatched to `w_<NodeType>` methods, G/M codes from rules/sinumerik.toml (code_for), expressions
printed from its [expressions] table (nctrans.dialects.sinumerik.spelling); what cannot be written
raises NotExpressible and is refused (NC402) at its statement's line, never written as a placeholder.

What the output looks like (spec section 11.5): `DEF` blocks at the top of the program / PROC,
`;` comments, `CR=` where the IR has a radius, structured control flow kept (IF/ELSE/ENDIF,
WHILE, FOR, LOOP, REPEAT/UNTIL, CASE), frames as TRANS/ATRANS/ROT/AROT/SCALE/MIRROR instructions,
comparisons always parenthesised inside other operators (they bind weakest, spec 4.1).

Lowerings for IR from other dialects (each reported as NC401 info, or NC402 when impossible):
- ISO macro variables Var("num", n) -> R parameters Rn (#1 -> R1 ... #999 -> R999; more than
  R99 needs machine data 28050 MM_NUM_R_PARAM > n). #0 (vacant) and n > 999 are refused (NC402).
  ISO G65/G66 arguments land in R parameters too: their `bindings` (A -> #1 ...) become
  `R1=... R2=...` assignments in the calling block, then the call (global R parameters, so a
  nested call can overwrite the caller's arguments: that is the NC401 note).
- ISO numbered subprograms ("1000", "O1000") are called and defined as L1000.
- ISO canned cycles (ModeChange("cycle") + CycleParams + positioning motions) become
  `MCALL CYCLE8x(RTP, RFP, SDIS, DP)` before the first positioning block and `MCALL` at G80,
  with RTP = R level under G99 and the ISO initial level under G98; incremental R/Z are added
  to the initial level. The initial level is the last constant programmed position of the drill
  axis when the program text fixes it (plain numbers), else `$P_EP[<drill axis>]` (the
  programmed position when the MCALL block is read). Which cycle, and its further parameters, come
  from rules/cycle-mapping.toml (nctrans.cyclemap): G81, G82, G83 (CYCLE83 VARI=1 with the ISO
  re-approach distance as _DIS1), G85 and G89 make the same strokes as their Siemens cycles; the
  others (G73 and G84/G74 whose strokes differ in detail, G76/G86/G87/G88) are refused with NC402
  naming why, so they are expanded into motion instead.
- ISO G92 -> ATRANS by ($P_EP - target); G92.1 -> TRANS; G68/G51/G51.1 pivots -> ATRANS/AROT
  (ASCALE, AMIRROR)/ATRANS sequences; G28/G30 -> G0 via point + G74/G75.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Optional

from nctrans import spilled
from nctrans import alarm_numbers
from nctrans.diagnostics import Diagnostic, at_span
from nctrans.calls import call_arguments
from nctrans.dialects.base import EmitResult
from nctrans.dialects.emit import Emitter, NotExpressible, rewrites
from nctrans.dialects.tool_timing import ToolTiming
from nctrans.dialects.sinumerik.spelling import SinumerikSpelling
from nctrans.dialects.sinumerik.spelling import format_number as _fmt
from nctrans.ir import nodes as ir
from nctrans.ir import walk
from nctrans.cyclemap import mapping_table, peck_clearance
from nctrans.lower import computed_g, macro_procs, modal_numbers, restart_loop
from nctrans.lower import frame_locals
from nctrans.lower.macro_procs import ends_with_restart as _ends_with_restart
from nctrans.lower.macro_procs import reads_arguments as _reads_arguments
from nctrans.plainrun import PlainRun, run_blocks
from nctrans.dialects.sinumerik.edge_selection import EdgeSelection, NoEdge, jump_regions, writes_radius_data
from nctrans.rules import option as rules_option, system_meaning, system_spelling
from nctrans.plainrun import RUNS
from nctrans.dialects.iso_m.profiles import is_common
from nctrans.interp import corner_elements
from nctrans.interp.settable_frames import external_frame_variable
from nctrans.interp.unmodelled import FRAME_NOT_MODELLED, REPORTED_AS_ERROR
from nctrans.ir.vocabulary import NO_EFFECT_PREFIX

DIALECT = "sinumerik"
EXTERNAL_FRAME = external_frame_variable(DIALECT)
_DRILL_AXIS = {"XY": "Z", "ZX": "Y", "YZ": "X"}
# the cycle alarm a computed ISO jump raises when its value names no block of the unit
COMPUTED_GOTO_ALARM = 65000
# a converted ISO macro file called without an argument it uses as a whole value (ISO: the word
# is dropped when vacant; a PROC parameter not programmed would read 0)
ARGUMENT_MISSING_ALARM = 65001
# a construct refused at its place (NC412: no Sinumerik counterpart, and it cannot be lowered to
# plain motion on its own): the control stops there until it is ported by hand
NOT_CONVERTED_ALARM = 65002
_GOTO = {"forward": "GOTOF", "backward": "GOTOB", "any": "GOTO"}
_SUB_NUM = re.compile(r"^O?(\d+)$", re.IGNORECASE)
_NUMBERED_M = re.compile(r"M\d+=\d+", re.IGNORECASE)     # a spindle function with its spindle (M1=3)
# address letters whose value may be an expression written `M=R501` (seed "Indirect programming":
# every address takes a variable except N, G and L)
_COMPUTED_WORDS = frozenset("MH")
# statements after which the programmed position is no longer a known constant
_FORGETS = (ir.SubCall, ir.HomeReturn, ir.SetPosition, ir.ResetSetPosition, ir.FrameOp, ir.CycleCall,
            ir.ModeSelect)


def _named(kind: str) -> bool:
    """Whether an ISO cycle kind has a Sinumerik standard cycle making the same moves
    (rules/cycle-mapping.toml)."""
    mapping = mapping_table().for_modal(kind)
    return mapping is not None and bool(mapping.named) and mapping.exact


@dataclass
class _State:
    """Modal facts the emitter needs while walking blocks in source order (the programmed
    position is the base's `pos`)."""
    motion: str = "linear"
    plane: str = "XY"
    distance: str = "absolute"
    arc_abs: bool = False
    cycle: str = "off"
    cycle_retract: str = "initial"
    cycle_params: dict = field(default_factory=dict)
    cycle_pending: bool = False
    cycle_active: bool = False
    cycle_call: str = ""                    # the active cycle call text, for holes at the current position
    cycle_init: Optional[float] = None      # ISO initial level when known statically
    feed: Optional[ir.Expr] = None          # modal F, S and feed mode (a tapping cycle's pitch)
    speed: Optional[ir.Expr] = None
    feed_mode: str = "per_min"
    units: str = "mm"
    diameter: bool = False                  # X words are diameters (ISO-T, DIAMON): frames are radii
    # frame components of another dialect's source in force, in text order (local, g92, rot,
    # scale, mirror): Sinumerik writes them into one programmable frame, which TRANS clears whole
    frame_parts: set = field(default_factory=set)


class SinumerikEmitter(SinumerikSpelling, Emitter):
    """IR -> Sinumerik text on the emitter base: statements in `w_<NodeType>` methods, codes from
    rules/sinumerik.toml (code_for), expressions from its [expressions] table; a statement that
    cannot be written raises NotExpressible and is refused (NC402) at its line."""
    dialect = DIALECT
    table_name = DIALECT
    target_text = "Sinumerik"
    lowered_for = ""

    def __init__(self, program: ir.Program):
        super().__init__(program)
        self.p = program
        self.t = self.table
        self.lines = spilled.output_lines()    # to a temporary file once many (spilled.OutputLines)
        self.st = _State()
        self.pending = None
        self.targets = walk.program_jump_targets(program)
        self.unit_nodes: list = []
        # the tool words moved to where this control's words change the tool as the source's do
        self.tool_timing = ToolTiming(program.dialect, DIALECT)
        # G65 macros written as PROCs with named parameters (nctrans.lower.macro_procs), and while
        # one is written, its locals #n by name
        self.procs = macro_procs.plan(program) if program.dialect != DIALECT else {}
        self.indirect_g = computed_g.plan(program, self.t) if program.dialect != DIALECT else {}
        self.unit_is_main = True
        self.call_variables = (computed_g.call_variables(program)
                               if program.dialect != DIALECT else ())
        self.local_names: dict[int, str] = {}
        # ISO tool length (G43/G44/G49 H) and radius register D as the cutting edge D
        # (nctrans.dialects.sinumerik.edge_selection); a Sinumerik source writes its own D words
        self.edges = EdgeSelection(writes_radius_data(program)) if program.dialect == "iso-m" else None
        # an ISO turning T word's offset register (T0401: tool 4, register 1) as the D of the tool:
        # D1 is the tool's own edge, so register 1 under another tool has no D (edge_selection's
        # rule for ISO milling); the turret tool is followed through T and its change
        from nctrans.rules import option
        self.t_registers = (self.edges is None and program.dialect != "sinumerik"
                            and not option(program.dialect, "offsets_of_active_tool", False))
        self.t_selected = self.t_active = None
        self.call_comp: dict[str, set] = {}     # callee -> compensation states at its calls
        self.jump_regions: dict[int, dict] = {}  # per unit: label -> what jumps to it may change
        self.vacancy: dict[int, int] = {}      # local -> PROC parameter position ($P_SUBPAR)
        self.vacancy_flags: dict[int, str] = {}  # local the PROC sets -> flag carrying its vacancy
        self.frame_locals: dict[str, str] = {}     # the unit's call-frame local -> its DEF name
        self.frame_plan: dict = {}                 # unit -> its frame_locals (lower.frame_locals)
        self.macro_file = None                 # an ISO macro file written as a PROC (run())
        # (file, line) -> why: constructs convert() asks to refuse at their place (NC412)
        self.in_place: dict = dict((program.meta or {}).get("refuse_in_place") or {})
        self.alarmed: set = set()              # the (file, line)s whose alarm is written

    # ---------------------------------------------------------------- diagnostics
    def info(self, key: str, msg: str) -> None:
        """NC401, once per kind of lowering."""
        self.lowered(msg, once=key)

    def lowered(self, what: str, once: Any = None) -> None:
        Emitter.lowered(self, what, once)

    def refuse_because(self, msg: str) -> None:
        """NC402 with a message of its own (why, and what to do instead) at the current line."""
        self.diags.append(at_span("NC402", "error", msg, self._where()))

    # ---------------------------------------------------------------- expressions
    def term(self, e: Any) -> tuple[str, int]:
        if e is None:                  # an argument left out
            return "", self.syntax.atom
        return super().term(e)

    @rewrites(ir.Binary, "==", "!=")
    def _vacancy_or_compare(self, e: ir.Binary) -> tuple[str, int]:
        test = self.vacancy_test(e) if self.vacancy else None
        return (test, 0) if test is not None else self.binary(e)

    def vacancy_test(self, e: ir.Binary) -> Optional[str]:
        """An ISO comparison that can see a vacant argument, inside a PROC: `#k EQ #0` asks whether
        the call left the parameter out (NOT $P_SUBPAR[i]); `#k EQ 5` is false for a vacant #k
        where the parameter reads 0 (so: $P_SUBPAR[i] AND (ARG==5)). None for other comparisons."""
        def param(x):
            if type(x) is ir.Var and x.space == "num" and x.key in self.vacancy and not x.indices:
                return x
            return None

        def vacant(x):
            return type(x) is ir.Var and x.space == "num" and x.key == 0

        left, right = e.left, e.right
        if param(left) is None:
            left, right = right, left
        if param(left) is None:
            return None
        spelling = next((sp for sp, m in self.t.system_variables.items()
                         if m == "argument_programmed"), None)
        if spelling is None:
            return None
        given = self.vacancy_flags.get(left.key) or f"{spelling}[{self.vacancy[left.key]}]"
        self.info("vacancy", "ISO vacancy tests of a macro argument written with "
                             f"{spelling}[i] (whether the call programmed the parameter)")
        if vacant(right):
            return f"NOT {given}" if e.op == "==" else given
        if type(right) is ir.Var:
            return None                  # both sides may be vacant: macro_procs kept such calls whole
        atom = self.syntax.atom
        cmp = self.expr(left, atom) + self.syntax.binary[e.op].text + self.expr(right, atom)
        return f"{given} AND ({cmp})" if e.op == "==" else f"NOT {given} OR ({cmp})"

    def var(self, v: ir.Var, target: bool = False) -> str:
        """A variable; another control's system variable (space "system" of a non-Sinumerik
        source) by its neutral meaning, else refused: it was written verbatim (Fagor
        V.E.LAYERS=3 in Sinumerik output, a name the control does not know)."""
        if v.space == "system" and self.p.dialect != DIALECT:
            return self.foreign_system_var(v, target)
        return super().var(v, target)

    def foreign_system_var(self, v: ir.Var, target: bool) -> str:
        """Another control's named system variable (Fagor V.A.POS.X) as the Sinumerik variable of
        the same neutral meaning (rules/<dialect>.toml [system_variables]); one no table gives a
        meaning (a Fagor V.E interface variable: machine-wide, set by the HMI or the OEM) or that
        is written is refused at its line (NC402: lowered where the run knows its value)."""
        found = system_spelling(DIALECT, str(v.key)) if not v.indices else None
        if found is None:
            raise NotExpressible(f"the {self.p.dialect} system variable {v.key} (no Sinumerik variable "
                                 "of the same meaning)")
        if target:
            raise NotExpressible(f"writing the {self.p.dialect} system variable {v.key}")
        name, axis = found
        self.info("foreign-sysvar", f"{self.p.dialect} system variables written as the Sinumerik "
                                    "variables of the same meaning")
        return f"{name}[{axis}]" if axis else name

    def foreign_var(self, v: ir.Var, target: bool, idx: str) -> str:
        """ISO macro variables: a G65 macro's locals by name, system variables (#1000 and up) by
        meaning, the rest as R parameters."""
        if v.space == "local" and not v.indices and str(v.key).upper() in self.frame_locals:
            return self.frame_locals[str(v.key).upper()]
        if v.space != "num":
            raise NotExpressible(f"the variable {v.space}:{v.key}")
        if v.key in self.local_names and not v.indices:
            return self.local_names[v.key]
        if v.space == "num" and is_common(v.key, self.p.meta) and not v.indices:
            self.info("profile-common", f"common variables of the {self.p.meta.get('profile')} profile "
                      f"#{v.key}.. written as R parameters of the same numbers (MD 28050 "
                      "MM_NUM_R_PARAM must cover them)")
            return f"R{v.key}"
        if (v.space == "num" and target and isinstance(v.key, int) and 5201 <= v.key <= 5206
                and not v.indices and self.st.distance != "incremental"):
            self.info("extframe", "ISO external work offset (G10 L2 P0, #5201..) written as the "
                                  "external zero offset frame $P_EXTFRAME")
            return f"{EXTERNAL_FRAME}[{'XYZABC'[v.key - 5201]},TR]"
        if isinstance(v.key, int) and v.key >= 1000 and not v.indices:
            edge = self.edge_register(v.key)
            if edge is not None:
                return edge
            return self.system_var(v, target)
        self.info("num", "ISO macro variables #n written as R parameters Rn")
        if v.key is None:
            return f"R{idx}"
        if not isinstance(v.key, int) or v.key < 1 or v.key > 999:
            raise NotExpressible(f"the macro variable #{v.key} (no R parameter is its equivalent)")
        return f"R{v.key}"

    def system_var(self, v: ir.Var, target: bool) -> str:
        """An ISO system variable (#1000 and up) as the Sinumerik variable of the same neutral
        meaning (rules/<dialect>.toml [system_variables]: #5021 -> $AA_IM[X])."""
        found = system_spelling(DIALECT, v.key)
        if found is None and not target:
            modal = self.modal_number(v.key)
            if modal is not None:
                return modal
        if found is None:
            meaning = system_meaning(v.key)
            what = meaning.replace('_', ' ') if meaning else self.numbered_meaning(v.key)
            raise NotExpressible(f"the system variable #{v.key}" + (f" ({what})" if what else ""))
        if target:
            raise NotExpressible(f"writing the system variable #{v.key}")
        name, axis = found
        self.info("sysvar", "ISO system variables written as the Sinumerik variables of the same meaning")
        return f"{name}[{axis}]" if axis else name

    def edge_register(self, number: int) -> Optional[str]:
        """An ISO tool offset register (#2001 length 1, #2401 radius 1: the source table's
        "tool_length" / "tool_radius" ranges) as the cutting-edge datum of the same flat D number
        (`$TC_DP3[1]`, `$TC_DP6[1]`; rules/sinumerik.toml [options.flat_edge_data]), read or written;
        None for any other number. The output's D words are the ISO numbers already, so both name
        the same register (MD 18102 flat D number structure)."""
        spell = {k: sp for sp, k in (self.t.options.get("flat_edge_data") or {}).items()}
        for e in ((self.p.meta or {}).get("options") or {}).get("numbered_variables") or ():
            first = int(e.get("first", -1)) if isinstance(e, dict) else -1
            kind = {"tool_length": "length", "tool_radius": "radius"}.get(e.get("source"))
            if kind in spell and first <= number <= int(e.get("last", first)):
                self.info("edge-data", "ISO tool offset registers (#2001.., #2401..) written as the "
                                       "edge data of the same flat D number ($TC_DP3[d] length, "
                                       "$TC_DP6[d] radius; MD 18102 flat D numbers)")
                return f"{spell[kind]}[{number - first + 1}]"
        return None

    def numbered_meaning(self, number: int) -> str:
        """What the source's numbered-variable table says a number is (ISO #2001: tool length
        offset 1), for a refusal that names it; "" when the table does not list it."""
        for e in ((self.p.meta or {}).get("options") or {}).get("numbered_variables") or ():
            first = int(e.get("first", -1)) if isinstance(e, dict) else -1
            if not first <= number <= int(e.get("last", first)):
                continue
            src = e.get("source")
            if src in ("tool_length", "tool_radius"):
                return (f"tool {src[5:]} offset {number - first + 1}: Sinumerik keeps offsets per tool "
                        "and cutting edge ($TC_DP..[t,d]), and an ISO offset number names neither")
            if src == "work_offset":
                return "work offset data: Sinumerik settable frames ($P_UIFR) are not analysed here"
            return str(e.get("meaning") or e.get("group") or src)
        return ""

    def modal_number(self, number: int) -> Optional[str]:
        """A source modal-state number (ISO #4007) as the G-group index expression reading the
        same number here (`($P_GG[7]+39)`, nctrans.lower.modal_numbers), or None."""
        entries = ((self.p.meta or {}).get("options") or {}).get("numbered_variables") or ()
        entry = next((e for e in entries if isinstance(e, dict) and e.get("source") == "modal"
                      and int(e.get("first", -1)) == number), None)
        if entry is None:
            return None
        if not hasattr(self, "_selected"):
            self._selected = modal_numbers.selected_values(self.p)
        values = (self._selected or {}).get(entry["group"])
        found = modal_numbers.as_group_index(entry, values or set(), self.t) if values else None
        if found is None:
            return None
        variable, group, constant = found
        self.info("sysvar-modal", "ISO modal-state numbers (#4001..) written as the G-group index "
                                  f"{variable}[n] plus the constant that gives the same number")
        return f"({variable}[{group}]{constant:+d})" if constant else f"{variable}[{group}]"

    # ---------------------------------------------------------------- words
    def word(self, addr: str, e: ir.Expr) -> str:
        if len(addr) == 1 and isinstance(e, ir.Num):
            text = self.number(e)
            if text[:1].isdigit() or text[:1] in "-+.":
                return addr + text
        return f"{addr}={self.expr(e)}"

    def axis(self, name: str, av: ir.AxisValue, arc: bool = False) -> str:
        mode = av.mode
        if arc and mode is None and self.st.arc_abs:
            mode = "abs"
        if mode == "abs":
            return f"{name}=AC({self.expr(av.value)})"
        if mode == "inc":
            return f"{name}=IC({self.expr(av.value)})"
        return self.word(name, av.value)

    def code_of(self, m: ir.ModeChange) -> Optional[str]:
        r = self.t.lookup(m.code) if m.code else None
        if r is not None and (r.group, r.value) == (m.group, m.value):
            return r.code
        r = self.t.code_for(m.group, m.value)
        return r.code if r else None


    # ---------------------------------------------------------------- statements
    def statement(self, s, out: "_Line") -> None:
        """Write one statement into `out`; what cannot be written raises NotExpressible (the block
        refuses it, NC402) and leaves `out` as it was."""
        if isinstance(s, _FORGETS) or (isinstance(s, ir.ModeChange) and s.group in ("units", "work_offset")):
            self.pos = {}
        words, done, extra = len(out.words), len(out.done), len(out.comment_extra)
        try:
            self.dispatch("w_", s, out)
        except NotExpressible:
            del out.words[words:], out.done[done:], out.comment_extra[extra:]
            raise

    def describe(self, node: Any) -> str:
        return f"{type(node).__name__} statements"

    def w_ModeChange(self, s: ir.ModeChange, out: "_Line") -> None:
        st = self.st
        g = s.group
        if g == "motion":
            st.motion = s.value
        elif g == "plane":
            st.plane = s.value
        elif g == "distance":
            st.distance = self.distance = s.value
        elif g == "feed_mode":
            st.feed_mode = s.value
        elif g == "diameter":
            st.diameter = s.value == "diameter"
        elif g == "units":
            st.units = s.value
            if not out.join and any(w.startswith("F") for w in out.words):
                # an F the source reads before its units switch (ISO order): Sinumerik reads
                # the whole block in the new units, so the F goes in a block of its own first
                out.done.append(" ".join(out.words))
                out.words = []
        if g == "cycle":
            self.cycle_mode(s, out)
            return
        if g == "cycle_retract":
            st.cycle_retract, st.cycle_pending = s.value, True
            return
        if g == "arc_distance":
            st.arc_abs = s.value == "absolute"
            self.info("arc_distance", "absolute arc centres written as I=AC(...)")
            return
        if g == "tool_length":
            if self.edges is None:
                self.info("tool_length", "tool length compensation is part of the D cutting edge "
                                         "in Sinumerik: G43/G44/G49 dropped")
            else:
                self.info("tool_length", "tool length compensation written as the cutting edge D "
                                         "(G49 -> D0, G43 H<k> -> D<k>, or D1 where k is the tool "
                                         "in the spindle)")
            return
        code = self.code_of(s)
        if code is None:
            raise NotExpressible(s.code or f"{s.group}={s.value}")
        if g == "spindle" and self.p.dialect == DIALECT and _NUMBERED_M.fullmatch(s.code or ""):
            code = s.code.upper()       # M1=3 stays spindle 1's after a SETMS(n), not the master's
        out.words.append(code)

    def cycle_mode(self, s: ir.ModeChange, out: "_Line") -> None:
        """An ISO canned-cycle mode: G80 ends the MCALL, a drilling code starts one (written at the
        first positioning block), refused where no standard cycle drills the same."""
        st = self.st
        if s.value == "off":
            if st.cycle_active:
                out.alone("MCALL")
                if st.motion != "rapid":
                    out.alone(self.code_for("motion", st.motion))   # positioning blocks were G0
            st.cycle, st.cycle_active, st.cycle_params = "off", False, {}
            st.cycle_init = None
            return
        st.cycle, st.cycle_pending = s.value, True
        mapping = mapping_table().for_modal(s.value)
        if mapping is None or not mapping.named:
            why = f" ({mapping.none})" if mapping is not None and mapping.none else ""
            self.refuse_because(f"canned cycle {s.code or s.value} has no Sinumerik standard cycle"
                                f"{why}: convert with --flatten to expand it into motion")
        elif not mapping.exact:
            self.refuse_because(f"canned cycle {s.code or s.value} has no exact Sinumerik standard "
                                f"cycle ({mapping.differs}): convert with --flatten to expand it "
                                "into motion")

    def w_Motion(self, s: ir.Motion, out: "_Line") -> None:
        self.motion(s, out)

    def w_Feed(self, s: ir.Feed, out: "_Line") -> None:
        st = self.st
        out.words.append(self.word("F", s.value))
        if st.cycle_active and st.feed != s.value and self.cycle_takes("feed", "pitch"):
            st.cycle_pending = True         # the cycle call carries the feed: call it anew
        st.feed = s.value

    def w_SpindleSpeed(self, s: ir.SpindleSpeed, out: "_Line") -> None:
        st = self.st
        if s.spindle == 1:
            if st.cycle_active and st.speed != s.value and self.cycle_takes("pitch"):
                st.cycle_pending = True
            st.speed = s.value
        plain = s.spindle == 1 and not getattr(s, "addressed", False)   # S1= stays S1= (SETMS)
        out.words.append(self.word("S", s.value) if plain else f"S{s.spindle}={self.expr(s.value)}")

    def w_SpindleLimit(self, s: ir.SpindleLimit, out: "_Line") -> None:
        out.words.append(f"LIMS={self.expr(s.value)}")

    def w_ToolSelect(self, s: ir.ToolSelect, out: "_Line") -> None:
        self.t_selected = s.tool.value if type(s.tool) is ir.Num else None
        out.words.append(self.word("T", s.tool))

    def w_ToolChange(self, s: ir.ToolChange, out: "_Line") -> None:
        self.t_active = self.t_selected
        out.words.append(self.code_for("tool_change"))

    def w_OffsetSelect(self, s: ir.OffsetSelect, out: "_Line") -> None:
        if self.edges is not None:
            return          # the block's D word comes from edge_selection (block_edge)
        if (self.t_registers and s.kind == "radius" and type(s.index) is ir.Num and s.index.value == 1
                and self.t_active not in (None, 1)):
            raise NotExpressible(f"offset register 1 while T{self.t_active:g} is active: a Sinumerik D1 is "
                                 f"the own edge of T{self.t_active:g}, not register 1")
        if s.kind == "radius":
            out.words.append(self.word("D", s.index))
        else:
            self.info("H", "length offset H dropped: Sinumerik takes the length from the D edge")

    def w_Dwell(self, s: ir.Dwell, out: "_Line") -> None:
        dwell = self.code_for("dwell")
        if s.revolutions is None and s.seconds is None:
            out.alone(dwell)
        elif s.revolutions is not None:
            out.alone(f"{dwell} " + self.word("S", s.revolutions))
        else:
            out.alone(f"{dwell} " + self.word("F", s.seconds if s.seconds is not None else ir.Num(0.0)))

    def w_FrameOp(self, s: ir.FrameOp, out: "_Line") -> None:
        self.frame(s, out)

    def w_SetPosition(self, s: ir.SetPosition, out: "_Line") -> None:
        """ISO G92 / ISO-T G50: ATRANS by the position minus the new value. A frame offset is a
        radius; an X set under diameter programming (ISO-T, DIAMON) is a diameter, halved. Whether
        the control reads $P_EP[X] as a diameter under DIAMON is not documented (NC138), so there
        the ATRANS stands between DIAMOF and DIAMON, where $P_EP[X] is the radius either way."""
        self.info("G92", "G92 written as ATRANS by the programmed position minus the new value")
        self.st.frame_parts.add("g92")
        halve = self.st.diameter and "X" in s.target
        ws = [f"{a}=$P_EP[{a}]-({self.expr(v.value)})" + ("/2" if a == "X" and self.st.diameter else "")
              for a, v in s.target.items()]
        if halve:
            out.alone(self.code_for("diameter", "radius"))
        out.alone(f"{self.code_for('frame', 'trans_add')} " + " ".join(ws))
        if halve:
            out.alone(self.code_for("diameter", "diameter"))

    def w_ResetSetPosition(self, s: ir.ResetSetPosition, out: "_Line") -> None:
        others = sorted(self.st.frame_parts - {"g92"})
        self.st.frame_parts.discard("g92")
        if others and self.p.dialect != DIALECT:
            raise NotExpressible(f"cancelling G92 while {', '.join(others)} stays in force: the "
                                 "Sinumerik TRANS it needs clears the whole programmable frame")
        self.info("G92.1", "G92.1 written as TRANS (clears the whole programmable frame)")
        out.alone(self.code_for("frame", "trans"))

    def w_HomeReturn(self, s: ir.HomeReturn, out: "_Line") -> None:
        self.home(s, out)

    def w_CycleParams(self, s: ir.CycleParams, out: "_Line") -> None:
        self.st.cycle_params.update(s.values)
        self.st.cycle_pending = True

    def w_CycleCall(self, s: ir.CycleCall, out: "_Line") -> None:
        self.cycle_call(s, out)

    def w_SubCall(self, s: ir.SubCall, out: "_Line") -> None:
        self.subcall(s, out)

    def w_ModalCallOff(self, s: ir.ModalCallOff, out: "_Line") -> None:
        out.words.append("MCALL")

    def w_Return(self, s: ir.Return, out: "_Line") -> None:
        if s.to_label:
            self.info("M99P", "M99 P written as RET(\"N..\") (SW 6.4 parameterised return)")
            out.alone(f'RET("N{s.to_label}")')
        else:
            out.words.append("RET" if out.only else self.code_for("return"))

    def w_ProgramEnd(self, s: ir.ProgramEnd, out: "_Line") -> None:
        if s.kind == "restart":
            if self.macro_file is not None:
                # every M99 of a macro file returns to its G65 caller, not only its last one
                self.w_Return(ir.Return(), out)
                return
            raise NotExpressible("a program restart (M99) in the middle of a main program")
        out.words.append(self.code_for("end", "end_rewind" if s.kind == "end_rewind" else "end"))

    def w_Stop(self, s: ir.Stop, out: "_Line") -> None:
        out.words.append(self.code_for("stop", "optional" if s.optional else "program"))

    def w_Assign(self, s: ir.Assign, out: "_Line") -> None:
        flag = self.vacancy_flags.get(s.target.key) if s.target.space == "num" and not s.target.indices else None
        vacant = type(s.value) is ir.Var and s.value.space == "num" and s.value.key == 0
        # #k=#0 of a flagged argument: vacant again, which reads 0 in arithmetic as the parameter does
        value = "0" if flag is not None and vacant else self.expr(s.value)
        out.words.append(f"{self.var(s.target, target=True)}={value}")
        if flag is not None:
            out.words.append(f"{flag}={self.vacancy_after(s.value)}")

    def vacancy_after(self, value) -> str:
        """Whether an ISO local holds a value after `#k=value` (macro B: #0 is vacant, a bare copy
        copies the vacancy, any arithmetic or constant is a value: vacant reads 0 there)."""
        if type(value) is ir.Var and value.space == "num" and not value.indices:
            if value.key == 0:
                return "FALSE"
            if value.key in self.vacancy_flags:
                return self.vacancy_flags[value.key]
            if value.key in self.vacancy:
                return f"$P_SUBPAR[{self.vacancy[value.key]}]"
        return "TRUE"

    def w_VarDecl(self, s: ir.VarDecl, out: "_Line") -> None:
        out.alone(self.vardecl([s]))

    def w_Goto(self, s: ir.Goto, out: "_Line") -> None:
        if s.computed is not None:
            self.computed_goto(s, out)
            return
        tgt = "N" + s.target if s.target.isascii() and s.target.isdigit() else s.target
        kw = _GOTO.get(s.direction, "GOTO")
        if s.cond is not None:
            out.alone(f"IF {self.expr(s.cond)} {kw} {tgt}")
        else:
            out.words.append(f"{kw} {tgt}")

    def computed_goto(self, s: ir.Goto, out: "_Line") -> None:
        """ISO `GOTO #2`: Sinumerik jumps to labels and block numbers written out only, so the
        jump becomes a CASE over the block numbers of its program unit (the value rounded, as ISO
        reads a block number); a value that names none of them raises an alarm, as the ISO
        control stops with "sequence number not found"."""
        numbers: list[int] = []
        for b in walk.blocks(self.unit_nodes):
            if b.number is not None and b.number.isdigit() and int(b.number) not in numbers:
                numbers.append(int(b.number))
        self.info("computed_goto", f"computed jump GOTO {s.target} written as a CASE over the "
                                   "block numbers of its program unit, with an alarm (SETAL) when "
                                   "none matches")
        cond = None if s.cond is None else self.expr(s.cond)
        if cond is not None:
            out.alone(f"IF {cond}")
        if numbers:
            branches = " ".join(f"{k} GOTO N{k}" for k in numbers)
            out.alone(f"CASE ROUND({self.expr(s.computed)}) OF {branches}")
        out.alone(f'SETAL({COMPUTED_GOTO_ALARM}, "COMPUTED JUMP: NO SUCH BLOCK NUMBER")')
        if cond is not None:
            out.alone("ENDIF")

    def w_SectionRepeat(self, s: ir.SectionRepeat, out: "_Line") -> None:
        words = ["REPEATB" if s.line_only else "REPEAT", s.start] + ([s.end] if s.end else [])
        if s.count is not None:
            words.append(f"P={self.expr(s.count)}")
        out.alone(" ".join(words))

    def w_Message(self, s: ir.Message, out: "_Line") -> None:
        out.words.append(f"MSG({self.expr(s.text)})")

    def w_Alarm(self, s: ir.Alarm, out: "_Line") -> None:
        """SETAL with the number moved into this control's bands (nctrans.alarm_numbers; NC408)."""
        w = alarm_numbers.written(s, DIALECT, self.program.dialect)
        if w.note:
            self.diags.append(at_span("NC408", "info", w.note, self.span))
        extra = f", {self.expr(w.text)}" if w.text is not None else ""
        out.words.append(f"SETAL({self.expr(w.number)}{extra})")

    def w_PolarPole(self, s: ir.PolarPole, out: "_Line") -> None:
        ws = [self.axis(a, v) for a, v in s.target.items()]
        if s.polar:
            ws += [f"{k}={self.expr(s.polar[key])}" for k, key in (("AP", "angle"), ("RP", "radius"))
                   if key in s.polar]
        out.alone(" ".join([self.code_for("pole", s.relative_to), *ws]))

    def w_ModeSelect(self, s: ir.ModeSelect, out: "_Line") -> None:
        out.words.append(f"G[{s.family}]={self.expr(s.index)}")    # the mode is chosen as it runs

    def w_TravelLimit(self, s: ir.TravelLimit, out: "_Line") -> None:
        if s.dialect == DIALECT:
            out.alone(s.text)
            return
        self.refuse_because(f"travel limits {s.text!r} from {s.dialect or 'the source'} "
                            f"({s.scope.replace('_', ' ')} limits differ between controls)")
        out.comment_extra.append(f"NC402 {s.dialect}: {s.text}")

    def w_Passthrough(self, s: ir.Passthrough, out: "_Line") -> None:
        if s.dialect in (DIALECT, "") or s.reason == "ISO dialect section":
            out.words.append(s.text)        # (an unparsed G291 section is ISO text in place)
        elif corner_elements.kind_of(s):
            # another dialect's rounding or chamfer (ISO ,R / ,C): the Sinumerik word of that element
            own = {v: k for k, v in corner_elements.settings(DIALECT).get("words", {}).items()}
            word = own.get(corner_elements.kind_of(s))
            if word is None:
                raise NotExpressible(f"{s.dialect} {s.reason} {s.text.strip()!r}")
            out.words.append(f"{word}={self.expr(s.value)}")
        elif computed_g.is_computed_g(s):
            self.computed_g(s, out)
        elif s.address and s.value is not None and s.address in _COMPUTED_WORDS:
            # a code word with a computed value (ISO M#501): the same word, Sinumerik syntax
            text = f"{s.address}={self.expr(s.value)}"
            self.diags.append(at_span("NC403", "warning", f"kept from {s.dialect}: {s.text} "
                                      f"({s.reason}) as {s.address}=<value>", self.span))
            out.words.append(text)
        elif s.reason.startswith(FRAME_NOT_MODELLED):
            # a coordinate-system change the analysis leaves out: the target would run its own
            # meaning of the text, unproven
            self.refuse_because(f"{s.dialect} construct has no Sinumerik equivalent: {s.text} ({s.reason})")
            out.comment_extra.append(f"NC402 {s.dialect}: {s.text}")
        elif s.reason.startswith(NO_EFFECT_PREFIX):
            # the source control's own function with no effect on the path (ISO POPEN/DPRNT,
            # Haas G103, M29): never written as a Sinumerik word it does not mean
            out.comment_extra.append(self.foreign_function_comment(s))
        elif _reads_as_sinumerik(s.text, moves_allowed=s.reason != "directive"):
            self.diags.append(at_span("NC403", "warning", f"kept verbatim from {s.dialect}: "
                                      f"{s.text} ({s.reason})", self.span))
            out.words.append(s.text)
        else:
            self.refuse_because(f"{s.dialect} construct has no Sinumerik equivalent: {s.text} ({s.reason})")
            out.comment_extra.append(f"NC402 {s.dialect}: {s.text}")

    def computed_g(self, s: ir.Passthrough, out: "_Line") -> None:
        """ISO `G#143` as indirect G code: the group's index computed into the declared INT
        variable in a line of its own, then `G[7]=<variable>` in the block (nctrans.lower.computed_g)."""
        key = s.value.key if type(s.value) is ir.Var else None
        found = self.indirect_g.get(key) if self.unit_is_main else None
        if found is None:
            raise NotExpressible(f"{s.text} (a computed G code: Sinumerik indirect G code needs the "
                                 "G group, and this program does not set the variable to constants "
                                 "of one group only)")
        self.info("computed-g", f"computed G code {s.text} written as indirect G code "
                  f"G[{found.family}]= (the program sets it to {', '.join(found.codes)} only)")
        index = ir.Binary("-", s.value, ir.Num(found.offset)) if found.offset else s.value
        out.alone(f"{found.variable}={self.expr(index)}")
        out.words.append(f"G[{found.family}]={found.variable}")

    def external_offset(self, s: ir.DataSetting, out: "_Line") -> bool:
        """ISO G10 L2 P0 (absolute) as the external zero offset frame it writes, one axis
        translation each (`$P_EXTFRAME[X,TR]=7`, seed sinumerik-iso-milling L1330-1332); False
        for every other data setting (refused by the caller)."""
        if (s.kind != "work_offset" or s.extended or not isinstance(s.index, ir.Num)
                or s.index.value != 0 or self.st.distance == "incremental"
                or not s.values or any(a.upper() not in "XYZABC" for a in s.values)):
            return False
        self.info("extframe", "ISO external work offset (G10 L2 P0, #5201..) written as the "
                              "external zero offset frame $P_EXTFRAME")
        for a, e in s.values.items():
            out.alone(f"{EXTERNAL_FRAME}[{a.upper()},TR]={self.expr(e)}")
        self.pos = {}
        return True

    def w_DataSetting(self, s: ir.DataSetting, out: "_Line") -> None:
        if not self.external_offset(s, out):
            raise NotExpressible(self.describe(s))

    def motion(self, m: ir.Motion, out: "_Line") -> None:
        st = self.st
        if st.cycle != "off" and m.target and _named(st.cycle):
            self.iso_cycle_position(m, out)
            return
        self.track(m)
        ws = []
        if m.machine_coords:
            ws.append(self.code_for("machine_coords", "SUPA"))
        for a, v in m.target.items():
            ws.append(self.axis(a, v))
        for a, v in (m.center or {}).items():
            ws.append(self.axis(a, v, arc=True))
        via_names = {v: k for k, v in self.t.options.get("via_words", {}).items()}
        for a, v in (m.via or {}).items():
            ws.append(self.axis(via_names.get(a, a + "1"), v))
        if m.radius is not None:
            ws.append(f"CR={self.expr(m.radius)}")
        if m.aperture is not None:
            ws.append(f"AR={self.expr(m.aperture)}")
        if m.polar:
            self.polar_words_check(m)
            if "angle" in m.polar:
                ws.append(f"AP={self.expr(m.polar['angle'])}")
            if "radius" in m.polar:
                ws.append(f"RP={self.expr(m.polar['radius'])}")
        if m.turns is not None:
            ws.append(f"TURN={self.expr(m.turns)}")
        for axis, v in m.indirect or ():
            ws.append(f"AX[{self.expr(axis)}]={self.expr(v.value)}")
        if m.thread_start is not None:          # SD 42000 THREAD_START_ANGLE, as ISO's Q
            ws.append(f"SF={self.expr(m.thread_start)}")
        if st.motion == "thread" and not m.center and self._lead_is_feed():
            ws.append(self._lead_from_feed(m, out))
        out.words.extend(ws)

    def _lead_is_feed(self) -> bool:
        """The source reads a thread's lead from F (its table's `thread_lead = "feed"`: ISO G33
        Z.. F<lead>); Sinumerik reads it from I/J/K only."""
        return rules_option(self.p.dialect, "thread_lead") == "feed"

    def _lead_from_feed(self, m: ir.Motion, out: "_Line") -> str:
        """The lead word (I/J/K of the one axis that moves) holding the F of the block, or the F
        in force ($P_F) when the block has none."""
        axes = [a for a in m.target if a in ("X", "Y", "Z")]
        if len(axes) != 1:
            raise NotExpressible("a thread (G33) whose lead is its F along more than one axis "
                                 "(Sinumerik needs the lead on one axis: I/J/K)")
        feed = next((w for w in out.words if w.startswith("F")), None)
        value = feed[1:].lstrip("=") if feed else "$P_F"
        return f"{'IJK'['XYZ'.index(axes[0])]}={value}"

    def _frame_parts(self, f: ir.FrameOp) -> None:
        """Another dialect's frame components are independent (ISO G52, G92, G68, G51, G51.1:
        each cancelled on its own); in Sinumerik they are one programmable frame, and the TRANS
        written for a cancel or a G52 clears (replaces) all of it. Where another component is in
        force there (in text order), that TRANS would drop it: refused, so the stretch is lowered
        or refused at its line instead of moving silently elsewhere (ISO `G52 X50 / G68 R30 /
        G69 / X10` went to X10, not X60)."""
        if self.p.dialect == DIALECT:
            return
        parts = self.st.frame_parts
        part = "local" if f.local else f.op
        zero = all(isinstance(v, ir.Num) and v.value == 0 for v in f.values.values())
        if f.op == "all" and f.clear:
            parts.clear()
            return
        replaces = (f.clear and not f.values) or f.local or (not f.additive and f.center is None)
        others = sorted(parts - {part}) if replaces else []
        # the source's own meaning first (a refused op still runs on the source's control)
        if f.clear or (f.local and zero):
            parts.discard(part)
        elif f.local or f.additive or f.center is not None:
            parts.add(part)
        else:
            parts.clear()
            parts.add(part)
        if others:
            raise NotExpressible(
                f"{'a G52 local offset' if f.local else 'cancelling one frame component'} while "
                f"{', '.join(others)} stays in force: the Sinumerik TRANS it needs replaces the "
                "whole programmable frame")

    def frame(self, f: ir.FrameOp, out: "_Line") -> None:
        self._frame_parts(f)
        trans, trans_add = self.code_for("frame", "trans"), self.code_for("frame", "trans_add")
        add = "_add" if f.additive else ""
        if f.op in ("mirror", "scale") and f.additive and not f.clear:
            from nctrans.interp.offsets import additive_frames_compose
            if not additive_frames_compose(self.program.dialect):
                # the source's mirror set or factor replaces its component (Fagor G11-G14, G72);
                # AMIRROR/ASCALE would compose with the one in force
                raise NotExpressible(f"a {f.op} that replaces the one in force (AMIRROR/ASCALE add to it)")
        if f.op == "all" or (f.clear and not f.values):
            if f.op not in ("all",):
                self.info("frame_clear", "cancelling one frame component clears the whole "
                                         "programmable frame in Sinumerik (TRANS)")
            out.alone(trans)
            return
        if f.local:
            self.info("G52", "G52 local offset written as TRANS (replaces the programmable frame)")
        if f.op == "mirror" and f.clear and f.values:
            # ISO G50.1 X..: the mirror off on the axes named, the rest of the frame kept; MIRROR X0
            # would switch it on (and replace the frame), MIRROR alone clears the whole frame
            raise NotExpressible("a mirror cancelled on some axes (G50.1 X..) while the other frame "
                                 "components stay")
        if f.center is not None and not f.center and f.op == "rot":
            raise NotExpressible("a rotation about the current position (ISO G68 without a centre)")
        pre, post = [], []
        if f.center is not None and not f.center:
            add = "_add"                # ISO G51 about the work zero: the other components stay
        elif f.center:
            self.info("pivot", "frame pivot written as ATRANS to the pivot, the frame, ATRANS back")
            c = {k: self.expr(v.value) for k, v in f.center.items()}
            pre.append(f"{trans_add} " + " ".join(f"{k}={v}" for k, v in c.items()))
            post.append(f"{trans_add} " + " ".join(f"{k}=-({v})" for k, v in c.items()))
            add = "_add"
        if f.op not in ("trans", "rot", "scale", "mirror"):
            raise NotExpressible(f"the frame operation {f.op!r}")
        op = self.code_for("frame", f.op + add)
        if f.op == "rot" and f.angle is not None:
            words = " ".join(self.word(k, v) for k, v in f.values.items())
            body = f"{op} {words} RPL={self.expr(f.angle)}".replace("  ", " ")
        elif f.op == "mirror":
            body = f"{op} " + " ".join(f"{k}0" for k in f.values)
        else:
            body = f"{op} " + " ".join(self.word(k, v) for k, v in f.values.items())
        if f.indirect:
            if f.op == "mirror":
                body = body.rstrip() + " " + " ".join(f"AX[{self.expr(a)}]=0" for a, _ in f.indirect)
            else:
                body = body.rstrip() + " " + " ".join(f"AX[{self.expr(a)}]={self.expr(v)}"
                                                      for a, v in f.indirect)
        for line in pre + [body.strip()] + post:
            out.alone(line)

    def home(self, h: ir.HomeReturn, out: "_Line") -> None:
        """G74 (ref 1) / G75 FP=ref-1 on the machine axes X1.. ; an ISO intermediate point that
        moves (not incremental zero) is a G0 block before it."""
        inc = lambda v: v.mode == "inc" or (v.mode is None and self.st.distance == "incremental")
        direct = all(inc(v) and isinstance(v.value, ir.Num) and v.value.value == 0
                     for v in h.via.values())
        if h.via and not direct:
            self.info("G28", "reference point return written as G0 to the intermediate point, then G74/G75")
            out.alone(f"{self.code_for('motion', 'rapid')} " + " ".join(self.axis(a, v) for a, v in h.via.items()))
        axes = " ".join(f"{a}1=0" for a in (h.via or {"X": 0, "Y": 0, "Z": 0}))
        out.alone(f"{self.code_for('home', 'ref')} {axes}" if h.ref == 1 else
                  f"{self.code_for('home', 'fixed')} FP={h.ref - 1} {axes}")
        if h.via and not direct and self.st.motion != "rapid":
            out.alone(self.code_for("motion", self.st.motion))

    def cycle_call(self, c: ir.CycleCall, out: "_Line") -> None:
        from nctrans.interp.cycles import cycle_table
        t = cycle_table()
        entries = {x.name: x.params for x in t.cycle}
        entries.update({x.name: x.params for x in t.pattern})
        entries.update({x.name: x.params for x in t.swivel})
        entries.update({x.name: x.params for x in t.milling})
        name = c.name if c.name in entries else next(
            (x.name for x in t.cycle if x.kind == c.kind), None)
        if name is None:
            name = {"holes_line": "HOLES1", "holes_circle": "HOLES2", "holes_grid": "CYCLE801",
                    "swivel_plane": "CYCLE800"}.get(c.kind)
        if name is None:
            raise NotExpressible(f"the cycle kind {c.kind!r} (no Sinumerik standard cycle)")
        keys = [t.neutral(p) for p in entries[name]]
        vals = [c.params.get(k) for k in keys]
        while vals and vals[-1] is None:
            vals.pop()
        text = f"{name}({','.join(self.expr(v) for v in vals)})"
        out.words.append(("MCALL " if c.modal else "") + text)

    def iso_cycle_position(self, m: ir.Motion, out: "_Line") -> None:
        st = self.st
        ax = _DRILL_AXIS.get(st.plane, "Z")
        pos = {a: v for a, v in m.target.items() if a != ax}
        if ax in m.target:
            st.cycle_params["bottom"] = m.target[ax].value
            st.cycle_pending = True
        if st.cycle_pending:
            p = st.cycle_params
            r = p.get("r_plane")
            z = p.get("bottom")
            if r is None or z is None:
                raise NotExpressible("a canned cycle without R level or depth")
            if not st.cycle_active:
                st.cycle_init = self.pos.get(ax)
            absolute = st.distance == "absolute"
            if "absolute" in p and isinstance(p["absolute"], ir.Num):
                absolute = bool(p["absolute"].value)
            zi = st.cycle_init
            if zi is not None and isinstance(r, ir.Num) and isinstance(z, ir.Num):
                # the initial level is known from the program text: plain numbers
                rv = r.value if absolute else zi + r.value
                dv = z.value if absolute else rv + z.value
                rtv = rv if st.cycle_retract == "r_plane" else zi
                rfp, dp, rtp = _fmt(rv), _fmt(dv), _fmt(rtv)
                self.pos[ax] = rtv
            else:
                # otherwise the programmed position when the MCALL block is read
                init = _fmt(zi) if zi is not None else f"$P_EP[{ax}]"
                if absolute:
                    rfp, dp = self.expr(r), self.expr(z)
                else:
                    rfp = f"{init}+{self.expr(r, 9)}"
                    dp = f"{init}+{self.expr(r, 9)}+{self.expr(z, 9)}"
                rtp = rfp if st.cycle_retract == "r_plane" else init
                self.pos.pop(ax, None)
            mapping = mapping_table().for_modal(st.cycle)
            given = {"RTP": rtp, "RFP": rfp, "SDIS": "0", "DP": dp}
            for param, source in mapping.args.items():
                text = self.cycle_arg(source, p)
                if text is None:
                    return
                given[param] = text
            from nctrans.interp.cycles import named_cycles
            args = [given.get(param, "") for param in named_cycles()[mapping.named].params]
            while args and args[-1] == "":
                args.pop()
            self.info("cycle", "ISO canned cycle written as MCALL of the Siemens standard cycle")
            text = "".join((("," if a == "" else ", ") if i else "") + a for i, a in enumerate(args))
            st.cycle_call = f"{mapping.named}({text})"
            out.alone("MCALL " + st.cycle_call)
            st.cycle_pending, st.cycle_active = False, True
        words = [self.code_for("motion", "rapid")] + [self.axis(a, v) for a, v in pos.items()]
        if not pos:
            # ISO drills at the current position when the block moves nothing in the plane; an
            # MCALL only fires on a block that moves, so call the cycle once, here
            words = [st.cycle_call]
        n = 1
        rep = st.cycle_params.pop("repeat", None)      # ISO K: this block only
        if isinstance(rep, ir.Num):
            n = int(rep.value)
        for _ in range(n):
            out.alone(" ".join(words))

    def cycle_takes(self, *sources: str) -> bool:
        """Whether the active ISO cycle's named call carries one of these derived values."""
        mapping = mapping_table().for_modal(self.st.cycle)
        return mapping is not None and any(v in sources for v in mapping.args.values())

    def cycle_arg(self, source, params: dict) -> Optional[str]:
        """The text of one further named-cycle argument (rules/cycle-mapping.toml `args`): a
        number, an ISO cycle parameter, or a derived value; None after refusing."""
        st = self.st
        if isinstance(source, (int, float)):
            return _fmt(float(source))
        if source == "peck_clearance":
            return _fmt(peck_clearance(st.units == "mm"))
        if source == "feed":
            if st.feed is None:
                raise NotExpressible("a canned cycle without a feed rate")
            return self.expr(st.feed)
        if source == "pitch":
            sign = "-" if st.cycle == "tap_left" else ""
            if st.feed is None or (st.feed_mode != "per_rev" and st.speed is None):
                raise NotExpressible("a tapping cycle without a feed rate and spindle speed (its pitch "
                                     "is unknown)")
            if st.feed_mode == "per_rev":
                lead = st.feed
            elif isinstance(st.feed, ir.Num) and isinstance(st.speed, ir.Num) and st.speed.value:
                lead = ir.Num(st.feed.value / st.speed.value)
            else:
                lead = ir.Binary("/", st.feed, st.speed)
            text = self.expr(lead, 10)
            return f"-{text}" if sign else text
        value = params.get(source)
        return "" if value is None else self.expr(value)

    def subname(self, name: str) -> str:
        """Sinumerik spelling of a program name: ISO O1000 -> L1000; invalid names are refused."""
        m = _SUB_NUM.match(name)
        if m and self.p.dialect != DIALECT:
            return "L" + m.group(1)
        m = _LETTER_NUMBER.match(name)
        if m and self.p.dialect != DIALECT:
            # a letter and digits (a Haas M97 local subprogram "N100") breaks the two-letter
            # rule of names (seed L839) and reads back as an address word: N_100
            return f"{m.group(1)}_{m.group(2)}"
        if self.p.dialect != DIALECT and not _NAME_OK.match(name):
            self.refuse_because(f"program name {name!r} is not a Sinumerik name")
            fixed = re.sub(r"\W", "_", name)[:31]
            return fixed if re.match(r"[A-Za-z_]", fixed) else "_" + fixed[:30]
        return name

    def _defined(self, name: str) -> bool:
        """Whether this program defines the subprogram `name` (ISO O1000 and 1000 are one)."""
        def key(x: str) -> str:
            m = _SUB_NUM.match(x)
            return str(int(m.group(1))) if m else x.upper()
        return any(key(k) == key(name) for k in self.p.subprograms)

    def subcall(self, c: ir.SubCall, out: "_Line") -> None:
        if c.target is not None:            # CALL PROGNAME, read from Sinumerik
            out.words.append(f"CALL {self.expr(c.target)}")
            return
        if not c.name and "P" in c.named_args and self.p.dialect != DIALECT:
            self.indirect_call(c, out)
            return
        name = self.subname(c.name)
        if self.p.dialect != DIALECT and c.name and not self._defined(c.name):
            self.diags.append(at_span(
                "NC404", "warning", f"the call of {c.name} is kept as a call of {name}: it is not in "
                f"this program (a file beside the source is not converted with it), so the target control "
                f"must provide {name} "
                f"(convert {c.name}'s own file to get it)", self.span))
        pre = []
        proc = self.procs.get(macro_procs.key(c.name)) if c.kind == "g65" else None
        if proc is not None:
            out.words.append(f"{name}({self.proc_args(proc, c)})")
            return
        if c.kind in ("g65", "g66") and self.p.dialect != DIALECT and c.name and not self._defined(c.name) \
                and not c.args:
            # a macro file converted on its own is the PROC with every letter a parameter, in
            # this order (standalone_macro): the same call, however each side was converted
            self.info("g65-external", "G65/G66 call of a macro not in this program passed as PROC "
                                      "parameters by letter order (A B C D E F H M Q R S T U V W X Y Z I J K)")
            args = call_arguments(c)
            text = f"{name}({', '.join('' if a is None else self.expr(a) for a in args)})"
            if c.repeat is not None:
                text += " " + self.word("P", c.repeat)
            out.words.append(("MCALL " if c.modal != "none" else "") + text)
            return
        passed = self.frame_plan.get(c.name, {}).get(frame_locals.PARAMETERS)
        if passed is not None:
            # a new frame with its arguments: the PROC's parameters in number order (A = P0 ...)
            by_key = {str(v.key).upper(): c.named_args[letter] for letter, v in c.bindings.items()
                      if letter in c.named_args}
            text = f"{name}(" + ", ".join(self.expr(by_key[k]) if k in by_key else ""
                                          for k in passed) + ")"
            out.words.append(("MCALL " if c.modal != "none" else "") + text)
            return
        if c.bindings or (c.kind == "g65" and self._defined(c.name)):
            self.info("g65", "macro call arguments passed in R parameters (global: a nested call can "
                             "overwrite them)")
            for letter, var in c.bindings.items():
                if letter in c.named_args:
                    pre.append(f"{self.var(var)}={self.expr(c.named_args[letter])}")
            pre.extend(self.fresh_locals(c))
        elif c.named_args:
            self.refuse_because(f"named call arguments of {c.name} have no binding to write")
        if c.kind == "call" and not c.args:
            text = f'CALL "{name}"'
        elif c.kind in ("isocall", "extcall") and not c.args:
            text = f'{c.kind.upper()} "{name}"'
        elif c.kind == "pcall":
            text = f"PCALL {name}" + (f"({self.args(c.args)})" if c.args else "")
        elif re.fullmatch(r"[A-Za-z]\d+", name) and not name.upper().startswith("L"):
            text = f"{name}({self.args(c.args)})"      # B200() would read back as an axis word
        else:
            text = name + (f"({self.args(c.args)})" if c.args else "")
        if c.modal != "none":
            text = "MCALL " + text
        if c.repeat is not None:
            text += " " + self.word("P", c.repeat)
        out.words.extend(pre)
        out.words.append(text)

    def indirect_call(self, c: ir.SubCall, out: "_Line") -> None:
        """ISO `M98 P#144` as the Sinumerik indirect call of the program named L<number>: the
        number into an INT variable, the name built from it in a STRING variable, `CALL <variable>`
        (seed sinumerik-840d-advanced-programming L5110-5130: indirect calls pass no parameters).
        The variables are declared at the top of the main program (computed_g.call_variables)."""
        number = c.named_args["P"]
        if (not self.unit_is_main or not self.call_variables or c.repeat is not None
                or len(c.named_args) != 1 or c.args or c.modal != "none"):
            self.refuse_because(f"the called program's number is computed (P={self.expr(number)}) "
                                "in a call Sinumerik cannot make indirectly (repeated, with arguments, "
                                "modal, or in a subprogram)")
            return
        count, name = self.call_variables
        self.diags.append(at_span(
            "NC404", "warning", f"the call of the program numbered P={self.expr(number)} is kept as an "
            "indirect CALL of L<number>: the target control must provide the programs this file "
            "does not define", self.span))
        self.info("indirect-call", "ISO M98 P<expression> written as the indirect CALL of a STRING "
                                   f'variable ("L"<<number)')
        out.alone(f"{count}={self.expr(number)}")
        out.alone(f'{name}="L"<<{count}')
        out.alone(f"CALL {name}")

    def fresh_locals(self, c: ir.SubCall) -> list[str]:
        """A G65 call of a macro in this program written with R parameters: the macro's locals
        start vacant in ISO, but R parameters keep the value of before. A local it reads only as
        0 would be is cleared in the call (`R2=0`); one whose vacancy shows (a word dropped, an EQ
        test) cannot be written so: refused (NC402), the call is lowered instead."""
        k = macro_procs.key(c.name)
        sub = next((s for n, s in self.p.subprograms.items() if macro_procs.key(n) == k), None)
        if sub is None or type(sub.body) is not list:
            return []
        if not hasattr(self, "_uses"):
            self._uses: dict = {}
        if k not in self._uses:
            self._uses[k] = macro_procs.local_use(sub.body)
        use = self._uses[k]
        if use is None:
            return []
        passed = {v.key for v in c.bindings.values() if isinstance(v.key, int)}
        clear, shows = use.left_out(passed)
        if shows:
            self.refuse_because(f"the call of {c.name} leaves out #{', #'.join(map(str, shows))}, which the "
                        "macro reads while vacant (a word dropped or an EQ/NE test): a Sinumerik "
                        "R parameter would hold the value of before")
        return [f"R{k}=0" for k in clear]

    def proc_args(self, proc: "macro_procs.MacroProc", c: ir.SubCall) -> str:
        """A G65 call's arguments by the position of the PROC parameter each letter binds; a
        parameter no letter passes stays empty (the PROC sees it unprogrammed)."""
        at: dict[int, str] = {}
        for letter, var in c.bindings.items():
            pos = proc.position(var.key) if letter in c.named_args else None
            if pos is None:
                self.refuse_because(f"argument {letter} of {c.name} has no parameter of its PROC")
                continue
            at[pos] = self.expr(c.named_args[letter])
        return ", ".join(at.get(i, "") for i in range(1, max(at, default=0) + 1))

    def vardecl(self, ds: list) -> str:
        d0 = ds[0]
        scope = "" if d0.scope in ("local", "", None) else d0.scope.upper() + " "
        typ = d0.type + (f"[{d0.length}]" if d0.length is not None else "")
        for word, v in zip(("LLI", "ULI"), d0.limits or ()):
            if v is not None:
                typ += f" {word} {v:g}"
        parts = []
        for d in ds:
            s = d.name
            sym = (self.p.meta or {}).get("symbolic_dims", {}).get(d.name)
            if sym and len(sym) == len(d.dims):
                s += "[" + ",".join(t if t else str(x) for t, x in zip(sym, d.dims)) + "]"
            elif d.dims:
                s += "[" + ",".join(str(x) if x else "" for x in d.dims) + "]"
            if d.init:
                if d.type == "AXIS" and len(d.init) == 1:
                    s += "=(" + self.arg(d.init[0]) + ")"
                elif len(d.init) == 1 and not (d.dims and not isinstance(d.init[0], ir.Func)):
                    s += "=" + self.expr(d.init[0])
                else:
                    s += "=SET(" + ",".join(self.expr(x) for x in d.init) + ")"
            parts.append(s)
        return f"DEF {scope}{typ} " + ", ".join(parts)

    # ---------------------------------------------------------------- structure
    def refused_in_place(self, node) -> Optional[str]:
        """The alarm line that stands for `node` when convert() asked to refuse it at its place
        (NC412), else None. A block holding a syntax error is never refused in place: the source
        is not a program there (it stays NC402)."""
        span = getattr(node, "span", None)
        key = (span.file, span.line) if span is not None else None
        why = self.in_place.get(key)
        if why is None or (isinstance(node, ir.Block) and any(
                isinstance(s, ir.Passthrough) and s.reason in REPORTED_AS_ERROR for s in node.body)):
            return None
        if key in self.alarmed:
            return ""           # more blocks of that line (a lowered construct's): after its alarm
        self.alarmed.add(key)
        self.diags.append(at_span(
            "NC412", "warning", f"{why}; refused in place: written as alarm SETAL({NOT_CONVERTED_ALARM}) "
            "at its place, so the control stops there until it is ported by hand; the rest keeps "
            "its structure", span))
        return f'SETAL({NOT_CONVERTED_ALARM}, "NOT CONVERTED: SOURCE LINE {span.line}")'

    def block(self, b: ir.Block, ind: str) -> None:
        self.span = b.span
        alarm = self.refused_in_place(b) if self.in_place else None
        if alarm == "":
            return
        if alarm is not None:
            # the block alone is the alarm; nothing falls through it, so what it would have
            # changed (modes, edge state) is left as before it, as for a block never run
            head = []
            if b.skip is not None:      # skipped with its block, as the source block is
                head.append("/" if b.skip == 0 else f"/{b.skip}")
            if b.number is not None:
                head.append(f"N{b.number}")
            if b.label:
                head.append(f"{b.label}:")
            # the source's comment stays with it (not a lowering's own "nctrans: ..." note)
            comment = [";" + b.comment] if b.comment is not None and not b.comment.startswith("nctrans:") else []
            self.lines.append(ind + " ".join(head + [alarm] + comment))
            return
        if (b.label and b.label in self.targets) or (b.number and b.number in self.targets):
            self.pos = {}            # a jump target: the position depends on the path taken
            self.tool_timing.forget()
            if self.edges is not None:
                self.edge_step(ind)     # the path falling through arrives in step, as every
                # jump does (a Goto is written in step); what the unit changes depends on the path
                regions = self.jump_regions.get(id(self.unit_nodes))
                if regions is None:
                    regions = self.jump_regions[id(self.unit_nodes)] = jump_regions(
                        self.unit_nodes, self.callee_body)
                self.edges.forget_fields(set().union(
                    *(regions.get(_jump_key(x), set()) for x in (b.label, b.number) if x)))
        body = self.tool_timing.apply(self, b.body)
        decls = [s for s in body if isinstance(s, ir.VarDecl)]
        rest = [s for s in body if not isinstance(s, ir.VarDecl)]
        line = _Line(only=len(rest) == 1, join=self.p.dialect == DIALECT)
        groups: list[list] = []
        for d in decls:
            if groups and (groups[-1][0].type, groups[-1][0].length, groups[-1][0].scope,
                           groups[-1][0].limits) == (d.type, d.length, d.scope, d.limits):
                groups[-1].append(d)
            else:
                groups.append([d])
        for g in groups:
            try:
                line.alone(self.vardecl(g))
            except NotExpressible as e:
                self.refuse(str(e))
        for s in rest:
            try:
                self.statement(s, line)
            except NotExpressible as e:
                self.refuse(str(e))
            if self.edges is not None and isinstance(s, ir.Passthrough) and computed_g.is_computed_g(s):
                key = s.value.key if type(s.value) is ir.Var else None
                found = self.indirect_g.get(key) if self.unit_is_main else None
                self.edges.computed_g(found.codes if found is not None else None)
            elif self.edges is not None:
                self.edges.statement(s, self.st.cycle != "off")
        texts = line.finish()
        if self.edges is not None:
            texts = self.block_edge(rest, texts)
        head = []
        if b.skip is not None:
            head.append("/" if b.skip == 0 else f"/{b.skip}")
        if b.number is not None:
            head.append(f"N{b.number}")
        if b.label:
            head.append(f"{b.label}:")
        comment = b.comment
        if line.comment_extra:
            comment = (comment + " " if comment else "") + "; ".join(line.comment_extra)
        if not texts:
            texts = [""]
        for i, t in enumerate(texts):
            parts = (head if i == 0 else []) + ([t] if t else [])
            if i == len(texts) - 1 and comment is not None:
                parts.append(";" + comment)
            text = " ".join(parts)
            if text:
                self.lines.append(ind + text)

    def block_edge(self, rest: list, texts: list[str]) -> list[str]:
        """The block's texts with the D word the ISO length / radius state needs (edge_selection):
        in the block itself where it holds a tool change (a D there overrides the change's D1) or
        only modes and moves (D acts before the move), else on a line of its own before it (a call,
        jump or return runs with it). No edge gives the state: NC402 at the block."""
        try:
            d = self.edges.block_end()
        except NoEdge as e:
            self.refuse(f"the ISO tool length state here: {e}")
            self.edges.forget()             # said once; what follows is judged afresh
            return texts
        self.edge_assumed()
        for s in rest:
            if isinstance(s, ir.SubCall):   # the subprogram may change it (in step at its return)
                self.call_comp.setdefault(macro_procs.key(s.name), set()).add(self.edges.iso.comp)
                self.edges.forget_changed_by([ir.Block(s.span if hasattr(s, "span") else None, [s])],
                                             self.callee_body)
        if d is None:
            return texts
        word = f"D{d}"
        if any(isinstance(s, ir.ToolChange) for s in rest) or all(
                isinstance(s, (ir.ModeChange, ir.Motion, ir.OffsetSelect, ir.Feed, ir.SpindleSpeed,
                               ir.ToolSelect)) for s in rest):
            if texts and texts[-1]:
                return texts[:-1] + [f"{texts[-1]} {word}"]
            return texts + [word] if texts else [word]
        return [word] + texts

    def callee_body(self, name: str) -> Optional[list]:
        """The body of the program's own subprogram `name` (None: not in this file)."""
        want = macro_procs.key(name)
        for sub_name, sub in self.p.subprograms.items():
            if macro_procs.key(sub_name) == want:
                return sub.body
        return None

    def edge_step(self, ind: str) -> None:
        """Bring the edge in step with the ISO state on a line of its own (before a structure, a
        jump target, at the end of a structure body); NC402 where no edge gives it."""
        if self.edges is None:
            return
        try:
            d = self.edges.block_end(sees=True)
        except NoEdge as e:
            self.refuse(f"the ISO tool length state here: {e}")
            self.edges.forget()
            return
        self.edge_assumed()
        if d is not None:
            self.lines.append(f"{ind}D{d}")

    def edge_assumed(self) -> None:
        """NC405 where the edge was chosen by the machine's offset values, not by its number."""
        why, self.edges.assumed = self.edges.assumed, None
        if why is None:
            return
        name = getattr(self.edges._machine, "name", "?")
        self.diags.append(at_span(
            "NC405", "warning", f"{why}; the edge written gives the same length and radius on "
            f"machine {name!r} only (its offset data), so the Sinumerik program is the same where "
            "the control holds that data: convert with the real machine (--machine) to check",
            self._where()))

    def iso_section(self, ns: list) -> Optional[str]:
        """A G291 ISO-mode section is written by the iso-m emitter (the front end parsed it so)."""
        try:
            from nctrans.dialects import base
            iso = base.get("iso-m")
        except Exception:       # iso-m not installed: fall back to Sinumerik words
            return None
        if iso is None:
            return None
        res = iso.emit(ir.Program(self.p.file, "iso-m", ns, {}, {}))
        self.diags.extend(res.diagnostics)
        lines = [l for l in spilled.as_str(res.text).splitlines() if l.strip() and not l.strip().startswith("%")]
        return "\n".join(lines)

    def nodes(self, ns: list, ind: str = "") -> None:
        i = 0
        while i < len(ns):
            n = ns[i]
            i += 1
            if type(n) in RUNS:                 # a compact body's run (base.CompactBody)
                self.plain_run(n, ind, i < len(ns) and isinstance(ns[i], _STRUCT))
                continue
            self.span = getattr(n, "span", None)
            if isinstance(n, ir.Block) and _mode_switch(n, "ISO dialect mode"):
                j = i
                while j < len(ns) and not (isinstance(ns[j], ir.Block) and _mode_switch(ns[j], "native dialect mode")):
                    j += 1
                text = self.iso_section(ns[i:j]) if j > i and not all(
                    isinstance(x, ir.Block) and all(isinstance(s, ir.Passthrough) and s.dialect == "iso-m"
                                                    for s in x.body) for x in ns[i:j]) else None
                self.block(n, ind)
                if text is not None:
                    self.lines.extend(ind + l for l in text.split("\n"))
                    i = j
                continue
            if isinstance(n, ir.Block) and _deco(n) and i < len(ns) and isinstance(ns[i], _STRUCT):
                self.pending = _deco(n)          # "N30 FOR ..." / "IF ... ; comment" on one line
                continue
            if isinstance(n, ir.Block):
                self.block(n, ind)
                continue
            deco, self.pending = self.pending, None
            alarm = self.refused_in_place(n) if self.in_place else None
            if alarm is not None:           # the structure whole, at its line (its first test)
                if alarm:
                    self.ctl(ind, alarm, deco)
                continue
            self.pos = {}            # loops and branches: positions depend on the path taken
            self.tool_timing.forget()
            self.edge_step(ind)      # every path through the structure starts in step
            if self.edges is not None and not isinstance(n, ir.If):
                self.edges.forget_changed_by([n])    # a loop's body follows its own last pass
            start, span = len(self.lines), self.span
            try:
                if isinstance(n, ir.If):
                    self.ctl(ind, f"IF {self.expr(n.cond)}", deco)
                    before = self.edges.snapshot() if self.edges is not None else None
                    close = self.body(n.then, ind)
                    if n.orelse:
                        self.ctl(ind, "ELSE", close)
                        self.edges = before
                        close = self.body(n.orelse, ind)
                    self.ctl(ind, "ENDIF", close)
                elif isinstance(n, ir.While):
                    self.ctl(ind, f"WHILE {self.expr(n.cond)}", deco)
                    self.ctl(ind, "ENDWHILE", self.body(n.body, ind))
                elif isinstance(n, ir.ForLoop):
                    self.for_loop(n, ind, deco)
                elif isinstance(n, ir.Loop):
                    self.ctl(ind, "LOOP", deco)
                    self.ctl(ind, "ENDLOOP", self.body(n.body, ind))
                elif isinstance(n, ir.RepeatUntil):
                    self.ctl(ind, "REPEAT", deco)
                    self.ctl(ind, f"UNTIL {self.expr(n.cond)}", self.body(n.body, ind))
                elif isinstance(n, ir.Case):
                    parts = [f"{self.expr(v)} GOTOF {t}" for v, t in n.branches]
                    if n.default:
                        parts.append(f"DEFAULT GOTOF {n.default}")
                    self.ctl(ind, f"CASE {self.expr(n.subject)} OF " + " ".join(parts), deco)
                else:
                    self.refuse(self.describe(n))
            except NotExpressible as e:     # the structure is refused whole, at its line
                del self.lines[start:]
                self.span = span
                self.refuse(str(e))
            self.pos = {}
            self.tool_timing.forget()
            if self.edges is not None:       # every path leaves in step; what it changed is not known
                self.edges.forget_changed_by([n])

    def plain_run(self, run: PlainRun, ind: str, structure_follows: bool) -> None:
        """The blocks of a run as nodes() writes them, built a few at a time: its last block,
        when it holds only a number or comment before a structure, goes on the structure's line."""
        last = None
        for b in run_blocks(run):
            if last is not None:
                self.block(last, ind)
            last = b
        if last is None:
            return
        if structure_follows and _deco(last):
            self.span = last.span
            self.pending = _deco(last)
        else:
            self.block(last, ind)

    def ctl(self, ind: str, text: str, deco) -> None:
        """A control-structure line, with the block number / comment of its source line."""
        pre, post = deco or ("", "")
        self.lines.append(f"{ind}{pre}{text}{post}")

    def body(self, ns: list, ind: str):
        """Emit a structure body; a trailing number/comment-only block goes on the closing line."""
        if ns and isinstance(ns[-1], ir.Block) and _deco(ns[-1]):
            self.nodes(ns[:-1], ind + "  ")
            self.edge_step(ind + "  ")
            return _deco(ns[-1])
        self.nodes(ns, ind + "  ")
        self.edge_step(ind + "  ")
        return None

    def for_loop(self, n: ir.ForLoop, ind: str, deco=None) -> None:
        var = self.var(n.var, target=True)
        step_one = n.step is None or (isinstance(n.step, ir.Num) and n.step.value == 1)
        if step_one and n.var.space == "name":
            self.ctl(ind, f"FOR {var}={self.expr(n.start)} TO {self.expr(n.end)}", deco)
            self.ctl(ind, "ENDFOR", self.body(n.body, ind))
            return
        if deco:
            self.ctl(ind, "", deco)
        self.info("for", "counting loop with a step or a non-INT variable written as WHILE")
        step = n.step if n.step is not None else ir.Num(1.0)
        down = isinstance(step, ir.Num) and step.value < 0
        self.lines.append(f"{ind}{var}={self.expr(n.start)}")
        self.lines.append(f"{ind}WHILE {var}{'>=' if down else '<='}{self.expr(n.end, 2)}")
        self.nodes(n.body, ind + "  ")
        self.edge_step(ind + "  ")
        self.lines.append(f"{ind}  {var}={var}+{self.expr(step, 9)}")
        self.lines.append(f"{ind}ENDWHILE")

    def unit(self, nodes: list) -> None:
        """Emit a unit's nodes with DEF blocks that follow code hoisted to the end of the preamble."""
        self.unit_nodes = nodes          # the blocks a computed jump can land on
        self.jump_regions = {}
        pre = 0
        for n in nodes:
            if isinstance(n, ir.Block) and all(isinstance(s, ir.VarDecl) for s in n.body):
                pre += 1
            else:
                break
        late: list = []
        body = nodes[pre:]
        for n in body:
            if isinstance(n, ir.Block) and any(isinstance(s, ir.VarDecl) for s in n.body):
                late.extend(s for s in n.body if isinstance(s, ir.VarDecl))
        if late and self.p.dialect != DIALECT:
            self.info("def", "DEF statements moved to the top of the program")
            body = [ir.Block(n.span, [s for s in n.body if not isinstance(s, ir.VarDecl)], n.number,
                             n.label, n.skip, n.comment) if isinstance(n, ir.Block) else n for n in body]
            hoisted = [ir.Block(ir.Span("", 0), [d]) for d in late]
            nodes = nodes[:pre] + hoisted + body
        self.nodes(nodes)

    def prologue(self, source_defaults: dict) -> None:
        """A program from another dialect relies on that controller's power-on modes (ISO: G0,
        G80...): where they differ from Sinumerik's (G1, G500...) the first block selects them."""
        self.st.diameter = source_defaults.get("diameter") == "diameter"
        if self.p.dialect == DIALECT:
            return
        mine = self.t.defaults()
        codes = []
        for group, value in source_defaults.items():
            if group in ("cycle", "cycle_retract", "tool_length") or mine.get(group) == value:
                continue
            rule = self.t.code_for(group, value)
            if rule is not None:
                codes.append(rule.code)
                if group == "motion":
                    self.st.motion = value
        if codes:
            self.span = ir.Span(self.p.file, 1)      # the note belongs to the program's file
            self.info("defaults", f"power-on modes of {self.p.dialect} written out: {' '.join(codes)}")
            self.lines.append(" ".join(codes))

    def run(self) -> str:
        self.macro_file = self.standalone_macro()
        # a main program's call-frame locals (Fagor P0..P99, V.P.): DEF'd variables of its own
        self.frame_plan = (frame_locals.plan(self.p)
                           if self.p.dialect != DIALECT and self.macro_file is None else {})
        self.frame_locals = self.frame_plan.get(None, {})
        self.head()
        body = self.p.body
        # a compact body (base.CompactBody) is written item by item, its runs a few blocks at a time
        self.unit(self.restart_as_loop(body if type(body) is list else list(body)))
        self.subprograms()
        return spilled.joined(self.lines)

    def restart_as_loop(self, body: list) -> list:
        """ISO M99 at the end of a main program from another dialect. In a program that reads G65
        arguments (#1-#33 it never sets) it is the macro's return: M17. Otherwise the control starts
        the program again for ever: the body runs inside LOOP ... ENDLOOP (never one pass)."""
        if self.p.dialect == DIALECT:
            return body
        last = restart_loop.restart_block(body)
        if last is None:
            return body
        b = body[last]
        self.span = b.span
        if _reads_arguments(body):
            self.info("m99-return", "M99 at the end of a program that reads G65 arguments is its "
                                    "return: written M17")
            new = [ir.Return() if isinstance(s, ir.ProgramEnd) else s for s in b.body]
            return body[:last] + [ir.Block(b.span, new, b.number, b.label, b.skip, b.comment)] + body[last + 1:]
        self.info("m99-loop", "M99 in a main program (it starts again for ever) written as "
                              "LOOP ... ENDLOOP")
        return restart_loop.as_loop(body, last)

    def head(self) -> None:
        """What comes before the main body: archive header, path, power-on modes (a macro file:
        its PROC line instead of the power-on modes, which are its caller's)."""
        meta = self.p.meta or {}
        if meta.get("header"):
            self.lines.append(f"%{meta['header']}")
        if meta.get("path"):
            self.lines.append(f";$PATH={meta['path']}")
        if self.macro_file is not None:
            self.macro_proc_head(self.macro_file)
        for found in self.indirect_g.values():        # DEF before the first executable block
            self.lines.append(f"DEF INT {found.variable}")
        if self.call_variables:
            self.lines.append(f"DEF INT {self.call_variables[0]}")
            self.lines.append(f"DEF STRING[32] {self.call_variables[1]}")
        if self.frame_locals:
            self.span = ir.Span(self.p.file, 1)
            self.declare_frame_locals("the main program")
        if self.macro_file is not None:
            self.vacancy_flags_on_entry(self.macro_file.proc)
            self.argument_checks(self.macro_file)
            return
        self.prologue(meta.get("defaults") or {})

    def standalone_macro(self) -> "Optional[macro_procs.Standalone]":
        """An ISO macro file (it reads G65 arguments it never sets and returns with M99) as the
        PROC its converted callers call: every argument letter a parameter, in the order a caller
        converted on its own passes them (nctrans.calls.LETTER_LOCALS); None for any other
        program. A macro file that cannot be such a PROC is written as before, reading its
        arguments from R parameters, with NC414: its converted callers pass PROC parameters, which
        the control refuses for a program without them (a refusal, not a lowering: a macro file has
        no toolpath of its own to lower to)."""
        body = self.p.body
        if self.p.dialect == DIALECT or type(body) is not list or not _ends_with_restart(body) \
                or not _reads_arguments(body):
            return None
        found, why = macro_procs.standalone(self.p)
        if found is None or not self.p.name:
            self.diags.append(at_span(
                "NC414", "warning", f"the macro file {self.p.name or self.p.file} is written reading its "
                f"arguments from R parameters, not as a PROC with its argument letters as parameters: "
                f"{why or 'it has no program number to name the PROC'}; G65 calls converted by nctrans "
                "pass PROC parameters, so they do not call it until it is ported by hand",
                ir.Span(self.p.file, 1)))
            return None
        return found

    def macro_proc_head(self, macro: "macro_procs.Standalone") -> None:
        proc = macro.proc
        name = self.subname(self.p.name)
        self.info("macro-file", f"macro file {self.p.name} written as PROC {name} with its argument "
                                "letters as parameters in the order a converted G65 call passes them "
                                "(A B C D E F H M Q R S T U V W X Y Z I J K; #n -> ARG_<letter>, locals "
                                "without a letter -> LOC<n>)")
        self.local_names = {k: f"ARG_{letter}" for k, letter in proc.params}
        self.local_names.update({k: f"LOC{k}" for k in proc.plain_locals})
        self.vacancy = {k: proc.position(k) for k in proc.vacancy_tested | proc.vacancy_flags}
        self.lines.append(f"PROC {name}(" + ", ".join(f"REAL ARG_{letter}" for _, letter in proc.params) + ")")
        if proc.plain_locals:
            self.lines.append("DEF REAL " + ", ".join(f"LOC{k}" for k in proc.plain_locals))
        self.declare_vacancy_flags(proc)

    def declare_frame_locals(self, unit: str) -> None:
        """DEF REAL of the call-frame parameters and local user variables of a unit (Fagor P0..P99,
        V.P.: nctrans.lower.frame_locals), which end with it as the frame's locals do."""
        self.info("frame-locals", f"call-frame parameters and local user variables of {unit} written "
                                  "as its own variables (DEF REAL): " + ", ".join(
                                      f"{k} -> {v}" for k, v in list(self.frame_locals.items())[:4])
                  + (" ..." if len(self.frame_locals) > 4 else ""))
        self.lines.append("DEF REAL " + ", ".join(self.frame_locals.values()))

    def declare_vacancy_flags(self, proc: "macro_procs.MacroProc") -> None:
        """An argument the macro tests for vacancy after setting it (Renishaw O9810: IF[#26EQ#0]
        after #26=#26+..): $P_SUBPAR only says whether the call passed it, so a BOOL flag carries
        its vacancy, $P_SUBPAR[i] on entry (written by vacancy_flags_on_entry), updated at each
        assignment."""
        letters = dict(proc.params)
        self.vacancy_flags = {k: f"GIVEN_{letters[k]}" for k in sorted(proc.vacancy_flags)}
        if self.vacancy_flags:
            self.info("vacancy-flag", "an argument the macro tests for vacancy after setting it "
                                      "carries its vacancy in a flag GIVEN_<letter> ($P_SUBPAR[i] on "
                                      "entry, set at each assignment)")
            self.lines.append("DEF BOOL " + ", ".join(self.vacancy_flags.values()))

    def vacancy_flags_on_entry(self, proc: "macro_procs.MacroProc") -> None:
        for k, flag in self.vacancy_flags.items():
            self.lines.append(f"{flag}=$P_SUBPAR[{proc.position(k)}]")

    def argument_checks(self, macro: "macro_procs.Standalone") -> None:
        """An argument the macro uses as a whole value (X#24: ISO drops the word when the call
        leaves it out) must be passed: an alarm on entry where it is not, never a move to 0."""
        for k in sorted(macro.bare, key=macro.proc.position):
            letter = dict(macro.proc.params)[k]
            self.info("macro-bare", "an argument the macro uses as a whole value must be passed: "
                                    f"checked on entry ($P_SUBPAR, alarm {ARGUMENT_MISSING_ALARM})")
            self.lines.append(f"IF NOT $P_SUBPAR[{macro.proc.position(k)}]")
            self.lines.append(f'  SETAL({ARGUMENT_MISSING_ALARM}, "ARGUMENT {letter} NOT PASSED")')
            self.lines.append("ENDIF")

    def flush(self, write) -> None:
        """Hand the lines written so far to `write` (a streamed conversion) and forget them."""
        if self.lines:
            write("\n".join(self.lines) + "\n")
            self.lines.clear()

    def subprograms(self) -> None:
        self.unit_is_main = False       # what the main body declared is not seen here
        p = self.p
        meta = p.meta or {}
        entry = meta.get("entry")
        headers = meta.get("unit_headers", {})
        for name, sub in p.subprograms.items():
            self.span = sub.span
            self.t_selected = self.t_active = None      # the caller's tool
            sname = self.subname(name)
            if name in headers and not re.match(r"_N_\w+_(?:MPF|SPF)$", headers[name], re.I):
                self.lines.append(f"%{headers[name]}")          # a member header kept as written
            elif name != entry:
                self.lines.append(f"%_N_{sname}_SPF")
            params = []
            proc = self.procs.get(macro_procs.key(name))
            if proc is not None:
                self.info("proc", f"G65 macro {name} written as PROC {sname} with named parameters "
                          f"(#n -> ARG_<letter>, locals without a letter -> LOC<n>)")
                self.local_names = {k: f"ARG_{letter}" for k, letter in proc.params}
                self.local_names.update({k: f"LOC{k}" for k in proc.plain_locals})
                self.vacancy = {k: proc.position(k) for k in proc.vacancy_tested | proc.vacancy_flags}
                params = [f"REAL ARG_{letter}" for _, letter in proc.params]
            for prm in sub.params:
                dims = "[" + ",".join(str(x) if x else "" for x in prm.dims) + "]" if prm.dims else ""
                params.append(("VAR " if prm.by_ref else "") + prm.type + " " + prm.name + dims)
            frame = dict(self.frame_plan.get(name, {}))
            passed = frame.pop(frame_locals.PARAMETERS, [])
            params += [f"REAL {frame[k]}" for k in passed]
            head = f"PROC {sname}" + (f"({', '.join(params)})" if params else "")
            if getattr(sub, "attrs", None):
                head += " " + " ".join(sub.attrs)
            if name not in meta.get("members_without_proc", []):
                self.lines.append(head)
            if proc is not None and proc.plain_locals:
                self.lines.append("DEF REAL " + ", ".join(f"LOC{k}" for k in proc.plain_locals))
            self.frame_locals = {k: v for k, v in frame.items() if k not in passed}
            if passed:
                self.info("frame-params", "a subprogram every call of which opens a new frame with its "
                                          "arguments (#PCALL A..Z = P0..P25) written as a PROC with "
                                          "those parameters: P0 -> REAL P_0 ...")
            if self.frame_locals:
                self.declare_frame_locals(f"subprogram {name}")
            self.frame_locals = frame
            if proc is not None:
                self.declare_vacancy_flags(proc)
                self.vacancy_flags_on_entry(proc)
            self.st = _State()
            # a subprogram of a diameter-programming source (ISO-T) is read in diameter too
            self.st.diameter = ((meta.get("defaults") or {}).get("diameter") == "diameter")
            self.pos, self.distance = {}, "absolute"
            if self.edges is not None:
                self.edges.forget()     # the caller's state, written in step before the call
                comp = self.call_comp.get(macro_procs.key(name), set())
                if len(comp) == 1:      # every call is made with compensation on / off
                    self.edges.iso.comp = next(iter(comp))
            self.unit(sub.body)
            self.local_names, self.vacancy, self.vacancy_flags, self.frame_locals = {}, {}, {}, {}


def _reads_as_sinumerik(text: str, moves_allowed: bool = True) -> bool:
    """Foreign text is kept verbatim (NC403) only when it is also a valid Sinumerik block; a
    directive (no effect on the path where it comes from, such as Fagor's "G198 X-100" limits)
    that would move the axes here is not."""
    from nctrans.dialects.sinumerik.frontend import parse
    if not text.strip() or "\n" in text or ";" in text:
        return False
    res = parse(text, "<passthrough>")
    # a foreign word Sinumerik reads only as a word it does not know (G123), or as a call of a
    # subprogram nobody wrote (ISO POPEN), would not mean on the target what it meant at the source
    return not res.diagnostics and all(
        (not isinstance(s, ir.Passthrough) or s.reason not in _NOT_SINUMERIK)
        and not isinstance(s, (ir.SubCall, ir.CycleCall))
        and (moves_allowed or not isinstance(s, ir.Motion))
        for b in res.program.body if isinstance(b, ir.Block) for s in b.body)


# what the Sinumerik front end makes of text that is no Sinumerik vocabulary
_NOT_SINUMERIK = frozenset(("syntax error", "unknown function", "invalid number", "address without value"))

_LETTER_NUMBER = re.compile(r"^([A-KM-Za-km-z])(\d+)$")     # not L<n>: a Sinumerik name itself
_NAME_OK = re.compile(r"^[A-Za-z_][A-Za-z_0-9]{0,30}$")


_STRUCT = (ir.If, ir.While, ir.ForLoop, ir.Loop, ir.RepeatUntil, ir.Case)


def _jump_key(x) -> str:
    t = str(x).upper()
    return str(int(t)) if t.isdigit() else t


def _deco(b: ir.Block):
    """(prefix, suffix) when a block holds only a block number and/or a comment."""
    if b.body or b.label or b.skip is not None or (b.number is None and b.comment is None):
        return None
    return (f"N{b.number} " if b.number is not None else "",
            f" ;{b.comment}" if b.comment is not None else "")


def _mode_switch(b: ir.Block, reason: str) -> bool:
    return any(isinstance(s, ir.Passthrough) and s.reason == reason for s in b.body)


class _Line:
    """Words of one output block; statements that must stand alone start their own lines."""

    def __init__(self, only: bool = False, join: bool = False):
        self.join = join               # Sinumerik-origin blocks stay one block (round trip)
        self.words: list[str] = []
        self.done: list[str] = []
        self.only = only
        self.comment_extra: list[str] = []

    def alone(self, text: str) -> None:
        if not text:
            return
        if self.join and not text.startswith(("IF ", "DEF ")):
            self.words.append(text)
            return
        if self.words:
            self.done.append(" ".join(self.words))
            self.words = []
        self.done.append(text)

    def finish(self) -> list[str]:
        if self.words:
            self.done.append(" ".join(self.words))
        return self.done


def emit_stream(program: ir.Program, chunks, write) -> list[Diagnostic]:
    """emit() for a program that runs straight through and arrives as lists of blocks (a streamed
    parse; program.body is not read): the same text, handed to `write` chunk by chunk, so a
    conversion's memory does not grow with the program."""
    import copy
    shell = copy.copy(program)
    shell.body = []              # the emitter's look-ahead (jump targets) must not drain the stream
    e = SinumerikEmitter(shell)
    chunks = iter(chunks)
    first = next(chunks, None)  # a streamed parse fills program.meta (defaults) as it starts
    e.head()
    # each chunk is let go before the next is parsed: one chunk of IR is held at a time
    if first is not None:
        e.unit(first)
        e.flush(write)
    first = None
    for chunk in chunks:
        e.unit(chunk)
        e.flush(write)
        del chunk
    e.subprograms()
    e.flush(write)
    return e.diags


def emit(program: ir.Program) -> EmitResult:
    e = SinumerikEmitter(program)
    text = e.run()
    return EmitResult(text, e.diags)
