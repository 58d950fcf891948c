"""The dialect-neutral IR.

Every dialect's front end lowers to these nodes; the interpreter, the lowering passes and every
emitter read them. The IR knows no dialect: modal functions are named by neutral (group, value)
pairs taken from `rules/<dialect>.toml`, cycles by neutral kinds, variables by neutral spaces.

Two levels of node:
- *structure* (`Block`, `If`, `While`, `ForLoop`, `Loop`, `RepeatUntil`, `Case`): what a program is
  made of, in source order. Structured control flow keeps its bodies so emitters can keep it.
- *statements* inside a `Block`, in execution order (the front end orders them, so the interpreter
  runs them as listed and needs no dialect knowledge of in-block ordering).

The internal form is plain slotted dataclasses (cheap to build per block); `nctrans.ir.schema`
gives the JSON form and its pydantic schema.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Union


def _repr(self) -> str:
    """Name(field=value, ...) as dataclass writes it. One shared function: dataclass compiles a
    __repr__ per class, which was half of this module's import time (~12 ms of every run)."""
    return f"{type(self).__qualname__}({', '.join(f'{k}={getattr(self, k)!r}' for k in self.__slots__)})"


def _eq(self, other) -> bool:
    """Field-by-field equality of two nodes of the same class, as dataclass compares them."""
    if other.__class__ is not self.__class__:
        return NotImplemented
    names = self.__slots__
    return tuple(getattr(self, k) for k in names) == tuple(getattr(other, k) for k in names)


def node(cls=None, /, *, frozen: bool = False):
    """@dataclass(slots=True) with shared __repr__ and __eq__ (unhashable, as dataclass makes
    them); every IR node class is declared with it. A frozen node keeps dataclass's own eq and
    hash (Span is used as a key)."""
    def wrap(c):
        c = dataclass(slots=True, frozen=frozen, repr=False, eq=frozen)(c)
        c.__repr__ = _repr
        if not frozen:
            c.__eq__ = _eq
            c.__hash__ = None
        return c
    return wrap if cls is None else wrap(cls)


@node(frozen=True)
class Span:
    """Where a node came from: 1-based line and column, end exclusive."""
    file: str
    line: int
    col: int = 1
    end_line: int = 0
    end_col: int = 0


# --------------------------------------------------------------------------- expressions

@node
class Num:
    """A numeric literal. `text` keeps the source spelling (for round trips and decimal-point rules)."""
    value: float
    text: Optional[str] = None


@node
class Str:
    value: str


@node
class Var:
    """A variable reference.

    space: "num" (ISO macro #n, key int or `index` expr), "R" (R parameters), "name" (declared
    user/GUD/LUD names), "system" ($-variables, key is the name), "arg" (call argument by letter),
    "local" (a local parameter of the call frame: bound by a call, shared with calls that open no level
    of their own, read before it is assigned is NC101).
    indices: array subscripts (Sinumerik A[1,2]) or the computed number of an ISO #[expr].
    """
    space: str
    key: Union[int, str, None]
    indices: Optional[list["Expr"]] = None
    span: Optional[Span] = None


@node
class Unary:
    op: str          # "-", "+", "not", "bnot"
    operand: "Expr"


@node
class Binary:
    """op: + - * / pow mod div and or xor band bor bxor == != < <= > >= concat"""
    op: str
    left: "Expr"
    right: "Expr"


@node
class Func:
    """A builtin function by neutral name (sin cos tan asin acos atan atan2 sqrt abs round fix fup
    trunc ln exp pow minval maxval ...). Angles are in degrees, as on every supported controller."""
    name: str
    args: list["Expr"]


Expr = Union[Num, Str, Var, Unary, Binary, Func]


# --------------------------------------------------------------------------- statement pieces

@node
class AxisValue:
    """A programmed coordinate. mode None follows the modal distance mode; "abs"/"inc" override it
    for this one word (Sinumerik AC()/IC(), ISO U/V/W on lathes)."""
    value: Expr
    mode: Optional[str] = None


# --------------------------------------------------------------------------- statements

@node
class ModeChange:
    """Select a modal (or one-shot) function: neutral (group, value) from the rules table.

    Examples: ("motion", "linear"), ("plane", "XY"), ("distance", "incremental"),
    ("units", "inch"), ("feed_mode", "per_rev"), ("cutter_comp", "left"), ("tool_length", "plus"),
    ("work_offset", "G54"), ("path_mode", "exact_stop"), ("cycle_retract", "r_plane"),
    ("spindle", "cw"), ("coolant", "flood"), ("cycle", "drill").
    `code` is the source spelling, for messages only.
    """
    group: str
    value: str
    code: str = ""


@node
class ModeSelect:
    """Select the function numbered `index` (evaluated as the program runs) in one modal group of
    the dialect (Sinumerik indirect G code `G[8]=INT_VAR`). `choices[i - 1]` is the neutral
    [group, value, code] that number i selects, or None where that number means nothing the IR
    models; `family` is the dialect's name of the group (its G group number), for writing back."""
    family: int
    index: Expr
    choices: list


@node
class Motion:
    """Move to `target` with the modal motion mode in force.

    center: arc centre words (I/J/K), incremental from the start unless AxisValue.mode == "abs".
    radius: arc radius (ISO R, Sinumerik CR=); negative selects the long arc.
    turns: extra full turns of an arc or helix (ISO L / Sinumerik TURN=).
    via: intermediate point of a 3-point arc (Sinumerik CIP).
    machine_coords: one-shot machine coordinates (ISO G53, Sinumerik SUPA/G53).
    polar: polar words (angle, radius) when the dialect programs them.
    indirect: axis words whose axis is computed when the block runs (Sinumerik AX[expr]=value):
    [(axis expression, AxisValue)].
    aperture: opening angle of an arc in degrees (Sinumerik AR=), with centre or end point.
    thread_start: start angle of a thread in degrees (Sinumerik SF=, ISO G33 Q in 0.001 deg): it
    sets the control's setting (SD 42000 THREAD_START_ANGLE), in force for later threads too.
    """
    target: dict[str, AxisValue] = field(default_factory=dict)
    center: Optional[dict[str, AxisValue]] = None
    radius: Optional[Expr] = None
    turns: Optional[Expr] = None
    via: Optional[dict[str, AxisValue]] = None
    machine_coords: bool = False
    polar: Optional[dict[str, Expr]] = None
    aperture: Optional[Expr] = None
    indirect: Optional[list] = None
    thread_start: Optional[Expr] = None


@node
class Feed:
    value: Expr


@node
class SpindleSpeed:
    value: Expr
    spindle: int = 1
    addressed: bool = False      # written with its spindle number (Sinumerik S2=): not "the master"


@node
class SpindleLimit:
    """Maximum spindle speed in rpm, the clamp of constant surface speed (ISO-T G50 S, Sinumerik LIMS=)."""
    value: Expr
    spindle: int = 1


@node
class ToolSelect:
    tool: Expr


@node
class ToolChange:
    """M6 (or a T that changes the tool at once on dialects without M6). `turret`: a lathe's T
    word, which indexes the turret; naming the tool already at the cutting position changes only
    its offset register (ISO T0101 then T0102), no tool."""
    turret: bool = False


@node
class OffsetSelect:
    """kind "length" (ISO H) or "radius" (ISO D / Sinumerik D cutting edge)."""
    kind: str
    index: Expr


@node
class Dwell:
    seconds: Optional[Expr] = None
    revolutions: Optional[Expr] = None


@node
class SetPosition:
    """ISO G92: the current position becomes `target` in program coordinates (shifts the frame)."""
    target: dict[str, AxisValue]


@node
class ResetSetPosition:
    """ISO G92.1/G92.2: drop the G92 shift."""


@node
class FrameOp:
    """A programmable frame: op in {"trans", "rot", "scale", "mirror"}.

    additive: add to the current programmable frame (Sinumerik ATRANS/AROT...) instead of replacing it.
    clear: cancel this component (ISO G69/G50/G50.1) or, with op "all", the whole programmable frame.
    values: per-axis values (translation, scale factor, mirror flag, or rotation angle per axis).
    center: pivot for ISO G68/G51/G51.1 (program coordinates); angle: rotation in the active plane.
    local: ISO G52 local coordinate system (a translation that stacks under G68/G51).
    indirect: values whose axis is computed when the block runs (Sinumerik `TRANS AX[AXVAR]=10`,
    seed L1422): [(axis expression, value)]; the axis is known only to the run.
    """
    op: str
    values: dict[str, Expr] = field(default_factory=dict)
    center: Optional[dict[str, AxisValue]] = None
    angle: Optional[Expr] = None
    additive: bool = False
    clear: bool = False
    local: bool = False
    indirect: Optional[list[tuple[Expr, Expr]]] = None


@node
class HomeReturn:
    """ISO G28/G30 (Sinumerik G74/G75): move via `via` to reference point `ref` (1 = home)."""
    ref: int
    via: dict[str, AxisValue] = field(default_factory=dict)
    ref_index: Optional[Expr] = None


@node
class CycleParams:
    """Parameters of a canned cycle, neutral keys:
    bottom (hole bottom), r_plane, retract_plane, safety, peck, dwell (s), shift, repeat, feed_out,
    plus dialect-neutral extras a cycle needs. For ISO the values are raw programmed values whose
    meaning (absolute or from R) follows the distance mode; `absolute` records what they are.
    """
    values: dict[str, Expr]


@node
class CycleCall:
    """A one-shot or modal call of a standard cycle by neutral kind with named parameters
    (Sinumerik CYCLE81 ...). ISO canned cycles use ModeChange("cycle", kind) + CycleParams instead,
    and the interpreter runs the cycle at each positioning block while the mode is active."""
    kind: str
    params: dict[str, Expr]
    modal: bool = False
    name: str = ""


@node
class SubCall:
    """Call a subprogram or macro.

    name: program name as the dialect resolves it (ISO "O1000"/"1000", Sinumerik "L10", "WARMUP").
    args: positional arguments; named_args: by letter/name (ISO G65 Type I/II letter keys like "A",
    "I1", "J2"). repeat: repetition count. modal: "none", "after_move" (ISO G66, Sinumerik MCALL).
    kind: how the source spelled it ("m98", "g65", "g66", "call", "proc", "l") for emitters.
    bindings: where each named argument lands in the callee (ISO G65 "A" -> Var("num", 1)), so the
    interpreter binds arguments without dialect knowledge. Positional args bind to the callee's
    Subprogram.params in order. target: the program's name computed as the call runs (Sinumerik
    indirect `CALL <string variable>`; name is then ""); an ISO `M98 P#144` keeps its number in
    named_args["P"] with name "".
    """
    name: str
    args: list[Expr] = field(default_factory=list)
    named_args: dict[str, Expr] = field(default_factory=dict)
    repeat: Optional[Expr] = None
    modal: str = "none"
    kind: str = ""
    bindings: dict[str, "Var"] = field(default_factory=dict)
    target: Optional[Expr] = None


@node
class ModalCallOff:
    """ISO G67 / Sinumerik MCALL without a name."""


@node
class Return:
    """Return from a subprogram (ISO M99, Sinumerik RET/M17); to_label: ISO M99 P<n>."""
    to_label: Optional[str] = None


@node
class ProgramEnd:
    """kind: "end" (M2), "end_rewind" (M30), "restart" (ISO M99 in a main program)."""
    kind: str = "end"


@node
class Stop:
    optional: bool = False


@node
class Assign:
    target: Var
    value: Expr


@node
class VarDecl:
    """Sinumerik DEF: type in {INT, REAL, BOOL, CHAR, STRING, AXIS, FRAME}; dims for arrays.
    limits: the declared lower and upper limit (Sinumerik LLI / ULI; None where not given)."""
    name: str
    type: str
    dims: list[int] = field(default_factory=list)
    init: Optional[list[Expr]] = None
    length: Optional[int] = None
    scope: str = "local"
    limits: Optional[list[Optional[float]]] = None


@node
class Goto:
    """Jump to a label or block number. direction: "forward", "backward", "any".
    cond: jump only when true (ISO IF [..] GOTO n, Sinumerik IF .. GOTOF L).
    computed: the block number as an expression evaluated when the jump runs (ISO `GOTO #2`);
    `target` is then only its text."""
    target: str
    direction: str = "any"
    cond: Optional[Expr] = None
    computed: Optional[Expr] = None


@node
class SectionRepeat:
    """Sinumerik program section repetition: run the blocks from label `start` again `count` times
    (P=n; None = once), then go on after this statement. `line_only` (REPEATB): the labelled block
    alone. `end` (REPEAT start end): up to and including the block labelled `end`. Neither: up to
    the first ENDLABEL block after `start`, else up to the block before the REPEAT."""
    start: str
    end: Optional[str] = None
    count: Optional[Expr] = None
    line_only: bool = False


@node
class Message:
    text: Expr


@node
class Alarm:
    """The control stops with an alarm. `own_base` set: `number` is one of the program's own
    (user) alarms, the author's alarm n = number - own_base (ISO #3000=n: base 0; Sinumerik
    SETAL(66000+n): base 66000; rules `[options] alarms`), which a writer moves into its own user
    band. None: a number of the source control's own alarm list (a Sinumerik cycle alarm 61000, a
    Fagor error-list number), or no number at all (`number` None: a Fagor #ERROR ["text"])."""
    number: Optional[Expr]
    text: Optional[Expr] = None
    own_base: Optional[int] = None


@node
class DataSetting:
    """Programmable data input (ISO G10): write a work offset or a tool-offset table entry.

    kind "work_offset": values per axis letter; index 0 = external offset, 1..6 = G54..G59, or with
    extended=True the G54.1 P number (G10 L20). kind "tool_length" / "tool_length_wear" /
    "tool_radius" / "tool_radius_wear": values {"value": R}, index = offset number (G10 L10-L13).
    Under incremental distance mode the values are added to the stored ones (seed L1197-1204).
    """
    kind: str
    index: "Expr"
    values: dict[str, "Expr"] = field(default_factory=dict)
    extended: bool = False


@node
class PolarPole:
    """Sets the pole of polar motion words (Motion.polar) in the active plane (Sinumerik
    G110/G111/G112). relative_to: "last_point" (the last programmed point, G110), "zero" (the
    workpiece zero, G111) or "pole" (the last pole, G112); target: the pole's plane coordinates
    relative to that point (an axis left out counts 0); polar: the pole given itself in polar
    words (angle, radius) about that point. code: how the source spelled it, for emitters."""
    relative_to: str
    target: dict[str, AxisValue] = field(default_factory=dict)
    polar: Optional[dict[str, Expr]] = None
    code: str = ""


@node
class TravelLimit:
    """Programmable travel limits: they move nothing; the interpreter hands them to the machine
    check as `limits` toolpath records, in machine coordinates.

    scope (where the values are and which point they bound):
    - "machine": machine axis positions (Fagor G198/G199 software limits);
    - "work_area": the tool tip with tool-length compensation, without work offsets or frames
      (the basic coordinate system: Sinumerik G25/G26 working area, switched by WALIMON/WALIMOF);
    - "zone": a box the tool tip must not enter, in the same coordinates (ISO G22 stored stroke
      check / protection zone 3; G23 switches it off).
    kind: "lower" / "upper" (per-axis limits in `values`), "box" (`values` one corner, `corner`
    the other), "on" / "off" (switch the scope's limits). incremental: the values are added to
    the limits in force (Fagor G91 G198). text/dialect: the source spelling, which only that
    dialect's emitter writes back (the scopes differ between controls)."""
    kind: str
    scope: str
    values: dict[str, "Expr"] = field(default_factory=dict)
    corner: dict[str, "Expr"] = field(default_factory=dict)
    incremental: bool = False
    text: str = ""
    dialect: str = ""


@node
class Passthrough:
    """A valid construct the IR has no concept for: kept verbatim (never dropped) with why.
    `address`/`value`: when the construct is one code word with a computed value (ISO `M#501`,
    Sinumerik `M=R501`), its address letter and value expression, so another dialect can write the
    same word in its own expression syntax."""
    text: str
    reason: str = ""
    dialect: str = ""
    address: str = ""
    value: Optional[Expr] = None


Statement = Union[
    ModeChange, Motion, Feed, SpindleSpeed, SpindleLimit, ToolSelect, ToolChange, OffsetSelect, Dwell,
    SetPosition, ResetSetPosition, FrameOp, HomeReturn, CycleParams, CycleCall, SubCall,
    ModalCallOff, Return, ProgramEnd, Stop, Assign, VarDecl, Goto, Message, Alarm, Passthrough,
    DataSetting, PolarPole, SectionRepeat, TravelLimit, ModeSelect,
]


# --------------------------------------------------------------------------- structure

@node
class Block:
    """One NC block (normally one source line).

    number: the N number as written (without N), label: a name label (Sinumerik `LBL:`),
    skip: block-skip level (0 for plain `/`) or None; body: statements in execution order;
    comment: the block's comment text (without delimiters).
    """
    span: Span
    body: list[Statement] = field(default_factory=list)
    number: Optional[str] = None
    label: Optional[str] = None
    skip: Optional[int] = None
    comment: Optional[str] = None


@node
class If:
    span: Span
    cond: Expr
    then: list["Node"]
    orelse: list["Node"] = field(default_factory=list)


@node
class While:
    span: Span
    cond: Expr
    body: list["Node"]
    label: Optional[str] = None     # ISO DO m / END m identifier


@node
class ForLoop:
    span: Span
    var: Var
    start: Expr
    end: Expr
    body: list["Node"]
    step: Optional[Expr] = None


@node
class Loop:
    """Endless loop (Sinumerik LOOP/ENDLOOP); left only by GOTO."""
    span: Span
    body: list["Node"]


@node
class RepeatUntil:
    span: Span
    body: list["Node"]
    cond: Expr


@node
class Case:
    span: Span
    subject: Expr
    branches: list[tuple[Expr, str]]     # value -> label to jump to (Sinumerik CASE ... GOTOF)
    default: Optional[str] = None


Node = Union[Block, If, While, ForLoop, Loop, RepeatUntil, Case]


@node
class Param:
    name: str
    type: str = "REAL"
    by_ref: bool = False
    dims: list[int] = field(default_factory=list)


@node
class Subprogram:
    name: str
    span: Span
    body: list[Node]
    params: list[Param] = field(default_factory=list)
    attrs: list[str] = field(default_factory=list)   # Sinumerik PROC SAVE / DISPLOF / SBLOF


@node
class Program:
    """A parsed source file: its main body and the subprograms it defines (ISO O-blocks after the
    main program, Sinumerik PROC). meta holds header facts: program number/name, `%` marks, the
    archive header, the dialect profile in force."""
    file: str
    dialect: str
    body: list[Node]
    subprograms: dict[str, Subprogram] = field(default_factory=dict)
    meta: dict[str, object] = field(default_factory=dict)
    name: Optional[str] = None


def _program_repr(self: Program) -> str:
    """A program prints as a one-line summary (a whole IR repr runs to megabytes on CAM files)."""
    body = self.body
    size = f"{len(body)} top-level nodes" if type(body) is list else "streamed body"
    subs = list(self.subprograms)
    named = f" ({', '.join(subs[:5])}{', ...' if len(subs) > 5 else ''})" if subs else ""
    return f"<Program {self.file} [{self.dialect}]: {size}, {len(subs)} subprograms{named}>"


Program.__repr__ = _program_repr    # type: ignore[method-assign]
