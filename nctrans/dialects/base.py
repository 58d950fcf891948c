"""What a dialect is, and the registry of dialects.

A dialect is a subclass of `Dialect`, in the shape of sqlglot's Dialect: the class declares what the
rest of nctrans needs to know (name, file endings, detection markers, whether it streams, its
definition files, how a called subprogram maps to a file name, the passes it needs as a conversion
target) and provides `parse()` (text -> IR) and `emit()` (IR -> text). Nothing outside
`nctrans/dialects/` names a dialect: detection, the pipeline, the resolver and the CLI ask this
registry.

Adding a dialect `xyz` (see also README "Adding a dialect"):
1. `nctrans/dialects/xyz/__init__.py` defines `class Xyz(Dialect)` with `name = "xyz"` and the
   declarations below. Defining the class registers it: every package under `nctrans/dialects/` is
   imported once when the registry is first read, so no list elsewhere needs editing. Keep that
   module light (no lark, no pydantic): heavy modules are imported inside `parse`/`emit`.
2. `nctrans/dialects/xyz/frontend.py` (text -> IR), `emitter.py` (IR -> text), its grammar
   `grammars/xyz.lark` if it has one, and its code table `rules/xyz.toml`.
3. A dialect that extends a sibling subclasses it (as sqlglot's Trino extends Presto) and overrides
   class attributes and methods: `class IsoTurning(IsoFamily): name = "iso-t"; table = "iso-t"`.
   A class that sets no `name` of its own (a family base) is not registered.

Tests that need a throw-away dialect define it with `class Fake(Dialect, register=False)` and install
it with `registered_only(Fake())` so the real registry is left alone.
"""
from __future__ import annotations

import importlib
import pkgutil
import sys
import re
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, ClassVar, Iterator, NamedTuple, Optional

from nctrans.diagnostics import Diagnostic
from nctrans.ir.nodes import Program


@dataclass
class ParseResult:
    program: Program
    diagnostics: list[Diagnostic] = field(default_factory=list)


@dataclass
class EmitResult:
    text: Any       # str, or a spilled.SpilledText where output spools (spilled.spooled_output)
    diagnostics: list[Diagnostic] = field(default_factory=list)


class CompactBody:
    """The main body of a Program parsed compact (Dialect.parse_compact): its items in order,
    each run of plain blocks as a PlainRun read again from the text when it runs. Not a list, so
    the interpreter runs it batch by batch as a streamed body (iterated again, it starts over);
    only the interpreter and the streamed flattening take it (they take PlainRuns apart).
    `jumps`: something may jump into it (parsed with parse_compact(jumps=True), for convert): no
    run then holds a block anything jumps to, and the interpreter runs it as the whole parse's
    code (interp/compact_code.py) instead of batch by batch."""
    __slots__ = ("items", "jumps")

    def __init__(self, items: list, jumps: bool = False):
        self.items = items
        self.jumps = jumps

    def __iter__(self):
        return iter(self.items)

    def drain(self) -> None:
        """Nothing is left to parse."""


class StreamedBody:
    """The main body of a streamed Program (Dialect.parse_stream): iterating it parses the next
    blocks, once. The interpreter runs each block as it comes and drops it; `drain()` parses what
    is left (after a program end) so that the diagnostics match a full parse."""
    __slots__ = ("_blocks",)

    def __init__(self, blocks):
        self._blocks = blocks

    def __iter__(self):
        return self._blocks

    def drain(self) -> None:
        for _ in self._blocks:
            pass


class CannotStream(Exception):
    """Raised by Dialect.emit_stream when the program turns out to need the whole-program
    emitter (nothing written is final: the caller discards it and converts the whole program)."""


class Marker(NamedTuple):
    """A detection marker: a construct in a line of code (comments removed) that points to a dialect.
    weight: evidence per matching line; cap: at most this many lines count."""
    weight: float
    cap: int
    pattern: re.Pattern


# Comment shapes detection counts while it removes comments (see nctrans.detect): a dialect names the
# ones that point to it in `comment_evidence` as {shape: (weight per line, cap on lines)}.
COMMENT_SHAPES = ("paren_comment",      # "(text)" comment with letters in it
                  "semicolon_line",     # a line that is only a ";" comment
                  "semicolon_tail")     # "G1 X1 ; text": a ";" comment after code

# The dialect a conversion writes and a rule example is read in when none is named: ISO milling, the
# one LinuxCNC's rs274 (the reference interpreter of the tests) runs.
DEFAULT_DIALECT = "iso-m"

# Endings that programs of many controllers use: they count as shared between dialects even when only
# one registered dialect claims them, so they weigh less in detection than an ending of one dialect.
COMMON_ENDINGS = frozenset({".nc", ".tap", ".cnc"})


class Dialect:
    """One CNC dialect. Subclasses set the class attributes and implement parse() and emit().

    parse(text, file) never raises on bad input: it returns the best Program it can with NC0xx
    diagnostics. emit(program) returns text and NC4xx diagnostics for anything the dialect cannot
    express (lowered or refused)."""

    name: ClassVar[str] = ""                 # contract name (`iso-m`, `sinumerik`, ...)
    description: ClassVar[str] = ""
    extensions: ClassVar[tuple[str, ...]] = ()   # file endings, the one written by `convert` first
    table: ClassVar[Optional[str]] = None    # rules/<table>.toml; None: the dialect's name
    # Detection: content markers (matched per line, comments removed), the comment shapes that point
    # here (COMMENT_SHAPES), and `sniff` (a coarse 0..1 look at the whole head).
    markers: ClassVar[tuple[Marker, ...]] = ()
    comment_evidence: ClassVar[dict[str, tuple[float, int]]] = {}
    # the dialect whose own constructs this one's markers need beside them to count against an
    # ending another dialect owns: iso-t's markers (G96, G18, T0101) tell a lathe from a mill,
    # and a Sinumerik lathe program in a .mpf has them too (nctrans.detection)
    family_evidence: ClassVar[Optional[str]] = None
    # True when parse_stream can parse lazily (programs that run straight through).
    streams: ClassVar[bool] = False
    # Endings (lower case) of definition files beside a program whose declarations it may read.
    definition_files: ClassVar[tuple[str, ...]] = ()
    # The default machine when none is given: "mill" or "lathe".
    machine_kind: ClassVar[str] = "mill"
    # IR -> IR passes (functions Program -> (Program, diagnostics), nctrans.lower) run on a program
    # before this dialect emits it as a conversion target.
    lowering_passes: ClassVar[tuple] = ()
    # Subprogram files: endings tried, in this order, after the name as written and before the
    # dialect's own `extensions`; see subprogram_files.
    subprogram_endings: ClassVar[tuple[str, ...]] = ()
    # True when emit() honours program.meta["refuse_in_place"] ((file, line) -> why): those
    # constructs are written as an alarm at their place (NC412), see nctrans.convert
    refuses_in_place: ClassVar[bool] = False

    def __init_subclass__(cls, register: bool = True, **kwargs) -> None:
        super().__init_subclass__(**kwargs)
        if register and "name" in cls.__dict__ and cls.name:
            _REGISTRY[cls.name] = cls()

    # ------------------------------------------------------------------ what subclasses provide

    def parse(self, text: str, file: str = "<stdin>") -> ParseResult:
        raise NotImplementedError(f"dialect {self.name} has no front end")

    def emit(self, program: Program) -> EmitResult:
        raise NotImplementedError(f"dialect {self.name} has no emitter")

    # A whole-line comment (the header of a converted program), and the lines that must open a
    # program before anything else (tape marks, program number, archive header).
    line_comment: ClassVar[str] = "; {}"
    opening_lines: ClassVar[str] = r"%"

    def with_header(self, text: str, comment: str) -> str:
        """`text` with the comment line `comment` after its opening lines (only those are looked
        at: the text of a long program is not split into lines again). A text whose lines went to
        a file (spilled.SpilledText) gets it in its held head."""
        if type(text) is not str:
            return text.with_head(lambda head: self.with_header(head, comment))
        opening = re.compile(self.opening_lines)
        line = self.line_comment.format(comment)
        pos = 0
        while True:
            nl = text.find("\n", pos)
            if not opening.match(text[pos:] if nl < 0 else text[pos:nl]):
                return text[:pos] + line + "\n" + text[pos:]
            if nl < 0:
                return text + "\n" + line
            pos = nl + 1

    def emit_stream(self, program: Program, chunks, write) -> Optional[list[Diagnostic]]:
        """Emit a program that runs straight through, its body given as `chunks` (lists of Blocks
        from a streamed parse), handing the text to `write` as it is produced: emit()'s text and
        diagnostics without holding either whole. None when this dialect does not stream its
        output (the caller then emits the whole program)."""
        return None

    def parse_compact(self, text: str, file: str = "<stdin>", jumps: bool = False) -> Optional[ParseResult]:
        """A whole parse whose main body is a CompactBody, or None (parse() then): for the runs
        of a program that holds structure (loops, calls) around long plain stretches. `jumps`:
        a program that jumps into its main body too (CompactBody.jumps)."""
        return None

    def parse_stream(self, text: str, file: str = "<stdin>") -> Optional[ParseResult]:
        """A lazy parse whose Program.body parses as it is iterated, or None when the text needs the
        whole IR (control flow, subprograms). Only called when `streams` is True."""
        return None

    def sniff(self, text: str) -> float:
        """0..1: how much `text` looks like this dialect (0 when the dialect does not sniff)."""
        return 0.0

    def subprogram_file(self, program: Program) -> bool:
        """Whether `program` is a subprogram file by this dialect's file types (it runs from its
        caller's position and modes, never from the power-on state); False when the dialect's
        files do not say."""
        return False

    def subprogram_stems(self, name: str) -> list[str]:
        """File names without ending that may hold the called program `name`, most likely first."""
        return [name, name.upper()]

    # ------------------------------------------------------------------ derived

    @property
    def table_name(self) -> str:
        return self.table or self.name

    def subprogram_files(self, name: str) -> list[str]:
        """File names (no directory) that may hold the called program `name`, most likely first;
        [] for a name that could leave the search directories."""
        from nctrans.interp.resolver import candidate_names
        return candidate_names(name, self.subprogram_stems,
                               dict.fromkeys((*self.subprogram_endings, *self.extensions)))

    def __repr__(self) -> str:
        return f"<dialect {self.name}>"


# --------------------------------------------------------------------------- registry

_REGISTRY: dict[str, Dialect] = {}
_discovered = False


def _discover() -> None:
    """Import every dialect package under nctrans/dialects/ once: defining its class registers it."""
    global _discovered
    if _discovered:
        return
    _discovered = True
    # the package module itself: the attribute `nctrans.dialects` is the public API function
    pkg = sys.modules[__package__]
    for info in sorted(pkgutil.iter_modules(pkg.__path__), key=lambda i: i.name):
        if info.ispkg:
            importlib.import_module(f"{pkg.__name__}.{info.name}")


def names() -> list[str]:
    """Registered dialect names, in a stable order."""
    _discover()
    return sorted(_REGISTRY)


def get(name: str) -> Optional[Dialect]:
    """The dialect called `name`, or None when there is no such dialect."""
    _discover()
    return _REGISTRY.get(name)


def dialects() -> list[Dialect]:
    """Every registered dialect, in name order."""
    return [_REGISTRY[n] for n in names()]


def get_or_raise(name: str) -> Dialect:
    d = get(name)
    if d is None:
        raise KeyError(f"unknown dialect {name!r} (known: {', '.join(names())})")
    return d


@contextmanager
def registered_only(*dialects_: Dialect) -> Iterator[None]:
    """For tests: the registry holds exactly `dialects_` inside the block."""
    global _discovered
    _discover()
    saved = dict(_REGISTRY)
    _REGISTRY.clear()
    _REGISTRY.update({d.name: d for d in dialects_})
    try:
        yield
    finally:
        _REGISTRY.clear()
        _REGISTRY.update(saved)
