"""Streamed Fagor parse: CAM programs (plain ISO-style blocks, Fagor comments) parsed as they run.

A Fagor program that runs straight through, block after block, is parsed lazily like ISO and
Sinumerik ones: Program.body is a StreamedBody whose blocks are lowered as the interpreter (or a
streamed conversion) pulls them, so memory stays flat however long the program. With the native
kernel, runs of plain lines (`N10 G1 X1.5 Y-2 F800`) become PlainRuns, the fast lane every
dialect shares; `plain_line` lowers such a line as the full front end does when Python runs it.

Where the line is (see `streamable`): a program is streamed only when every line is a program
header (`%NAME`), blank or a comment, or letter-number words whose G and M codes are not calls,
returns or software limits. Anything of Fagor's high-level language takes the whole-program parse
(frontend.parse): `$` flow control, `#` instructions (#RPT, #DEF, #CALL, #MSG, #COMMENT ...),
`%L` local subroutines, `LL`/`L` calls, G180-G189 and MG calls, `[LABEL]` and `N<n>:` targets,
`[ ]` expressions, assignments (P parameters, V. variables, `G159=`, `X1=`), strings and blocks the
grammar must read (a bare number after G04). Those need the whole IR (jump targets, #RPT ranges,
subroutines, the lint analyses of variables), or are rare enough in CAM output not to matter.
"""
from __future__ import annotations

import re
from typing import Optional

from nctrans import plainrun
from nctrans.dialects.base import ParseResult, StreamedBody
from nctrans.ir import nodes as ir
from nctrans.rules import normalise_code

from . import blocks
from .frontend import AXES, DIALECT, Parser, table

# Plain lines in a row before the streamed parse hands them over as one PlainRun.
PLAIN_RUN_MIN = 2
# G/M groups a streamed program may not use: a call (the callee may be a local subroutine later
# in the file), a return, software limits (Program.meta["soft_limits"] is filled at the end).
_NOT_STREAMED_GROUPS = frozenset({"call", "return", "soft_limit"})
_NUM = r"(?:\d+\.?\d*|\.\d+)"
# a block of letter-number words only (frontend._PLAIN, and an empty block)
_WORDS = re.compile(rf"(?:\s*[A-Z]\s*[-+]?\s*{_NUM})*\s*")
_WORD = re.compile(rf"([A-Z])\s*([-+]?)\s*({_NUM})")


def streamable(text: str) -> tuple[bool, Optional[str]]:
    """(whether `text` streams, the name of its first program header or None): see the module's
    docstring for the line. Errs towards the whole-program parse, which is always right. With the
    native kernel the plain lines are stepped over in runs (its strict scan), so only the others
    are looked at in Python."""
    scan = plainrun.native.scan if plainrun.native is not None else None
    arc = plainrun.MOTIONS.index("arc_cw")
    header: Optional[str] = None
    pos, n = 0, len(text)
    while pos < n:
        if scan is not None:
            end, _, found, _ = scan(text, pos, "\n", arc, True, False, True)
            if found:
                pos = end
                continue
        nl = text.find("\n", pos)
        if nl < 0:
            nl = n
        verdict = _stream_line(text[pos:nl])
        pos = nl + 1
        if verdict is False:
            return False, None
        if header is None and isinstance(verdict, str) and verdict:
            header = verdict
    return True, header


def _stream_line(raw: str):
    """False when the line needs the whole-program parse; else True, or the name of the program
    header the line is ("" for a bare `%`)."""
    if "#" in raw or "$" in raw:
        # an instruction or flow, or in a comment (`( #1 )`): the second is rare, and erring
        # towards the whole parse is always right
        return False
    line = blocks.split(0, raw.rstrip("\r"))
    if line.kind == "header":
        return line.name or ""
    if line.kind == "local_sub" or line.error is not None or line.target or line.label is not None:
        return False
    code = line.code
    if not code:
        return True
    if _WORDS.fullmatch(code) is None:
        return False
    for letter, _sign, number in _WORD.findall(code):
        if letter == "L":
            return False                    # L: a subroutine call keyword
        if letter in "GM":
            try:
                rule = table().lookup(normalise_code(letter, number))
            except ValueError:
                return False
            if rule is not None and rule.group in _NOT_STREAMED_GROUPS:
                return False
    return True


def parse_stream(text: str, file: str = "<stdin>") -> Optional[ParseResult]:
    """Lazy parse of a program that streams (see streamable): a ParseResult whose Program.body
    is a StreamedBody and whose diagnostics fill as it is iterated (complete once drained). None
    when the text needs the whole IR."""
    from nctrans.source import from_text
    src = from_text(text, file)
    ok, header = streamable(src.text)
    if not ok:
        return None
    p = Parser(src.text, file)
    p.diags[:0] = src.diagnostics
    if header is not None:
        # the program's name (its first header) before the body is iterated: the full parse
        # takes the same one, wherever in the file it is
        p.meta["program_name"] = header
    program = ir.Program(file, DIALECT, [], {}, p.meta, header)
    program.body = StreamedBody(_blocks(p, src.text, file))
    return ParseResult(program, p.diags)


def _blocks(p: Parser, text: str, file: str):
    """The main body's blocks as Parser.run lowers them, yielded as they are made (none kept);
    runs of plain lines become PlainRuns when the native kernel is there."""
    from nctrans import limits
    low = p.low
    main = p.main.body
    scan = plainrun.native.scan if plainrun.native is not None else None
    max_block = limits.setting("MAX_BLOCK_CHARS", limits.MAX_BLOCK_CHARS)
    pos, end, n = 0, len(text), 0
    while pos <= end:
        if main:
            yield from main
            main.clear()
        if scan is not None and not low.cycle and low.motion in plainrun.MOTIONS:
            # a run starts here when its first PLAIN_RUN_MIN lines are plain; where it ends the
            # kernel finds as it runs it (one pass), else extent() with scan()
            if scan(text, pos, "\n", plainrun.motion_code(low.motion), True, False, True, max_block,
                    PLAIN_RUN_MIN)[2] >= PLAIN_RUN_MIN:
                run = plainrun.PlainRun.open(file, text, pos, n + 1, "\n", plain_line, low.motion, None,
                                             False, True, max_block)
                yield run
                ends = run.extent()
                pos, n = ends.pos, ends.line - 1
                low.motion = ends.motion
                continue
        nl = text.find("\n", pos)
        if nl < 0:
            nl = end
        raw = text[pos:nl]
        pos, n = nl + 1, n + 1
        p.take(blocks.split(n, raw.rstrip("\r")))
    p.close_unit(None)
    if main:
        yield from main
        main.clear()


def plain_line(code: str, motion: Optional[str], cycle: Optional[str], arc_abs: bool) -> tuple:
    """(number, body, motion mode written or None) of a line the kernel's strict scan took (code
    with its blanks removed: [N] [G0-G3] axis words, I J K, F), as the full front end lowers it
    (Lowerer.items: feed, then the motion mode, then the motion; tests/test_fagor_streaming.py
    holds the two to each other). The scan takes centre words only in arc mode and no line at all
    while a canned cycle or a G63 is modal, so the words mean the same whatever the state."""
    number = feed = mode = None
    target: dict = {}
    center: dict = {}
    for letter, sign, num in _WORD.findall(code):
        if letter == "N":
            number = num
        elif letter == "G":
            written = normalise_code("G", num)
            mode = ir.ModeChange("motion", table().lookup(written).value, written)
        else:
            value = ir.Num(-float(num) if sign == "-" else float(num), ("-" if sign == "-" else "") + num)
            if letter == "F":
                feed = ir.Feed(value)
            elif letter in AXES:
                target[letter] = ir.AxisValue(value)
            else:
                center[letter] = ir.AxisValue(value)
    body: list = []
    if feed is not None:
        body.append(feed)
    if mode is not None:
        body.append(mode)
    if target or center:
        body.append(ir.Motion(target, {k: center[k] for k in "IJK" if k in center} or None, None, None,
                              via=None, polar=None))
    return number, body, None if mode is None else mode.value
