"""Bounds that keep hostile or broken input from exhausting memory, stack or time.

One place for every limit nctrans puts on its input, so each is documented once (README "Limits")
and tests/test_hostile.py can hold the program to it. Where a controller manual states a limit the
same limit applies here (the seeds: Fanuc 3 nested DO levels, Sinumerik STRING of at most 200
characters; control structures: the dialect's rules table); the rest are far beyond any real part
program and only stop runaway input.
"""
from __future__ import annotations

import math
import os
import re
from contextvars import ContextVar
from typing import Optional

# Largest input read (bytes): 512 MiB holds ~20 M CAM blocks. The text is held in memory once
# (streamed commands then keep memory flat beyond it), so the limit bounds memory too. Larger
# inputs are refused with exit 2 before they are read; NCTRANS_MAX_INPUT_BYTES raises the limit.
MAX_INPUT_BYTES = 512 * 1024 ** 2

# Characters in one block (line). Controllers read a few hundred (the longest line in the shared
# corpus has 619); a longer one is an NC010 error and is not analysed, so one line of many MB
# cannot turn into millions of words. NCTRANS_MAX_BLOCK_CHARS overrides it.
MAX_BLOCK_CHARS = 64 * 1024

# Bracket / parenthesis nesting inside one block (Fanuc allows 5 levels of [ ]; the limit here
# leaves room for generated Sinumerik expressions and still keeps every recursive walk shallow).
MAX_BRACKET_DEPTH = 32
# Operators in one block: a left-deep chain of N operators is an expression tree N deep.
MAX_OPERATORS = 200

# Nesting of control structures: each dialect's table states its controller's own limit
# (options.max_do_nesting / max_structure_nesting); this bound applies where a table is silent.
MAX_STRUCTURE_NESTING = 16

# Strings (Sinumerik STRING[n]; n at most 200 characters on the 840D): an undeclared string
# (a concatenation result, a CHAR/STRING parameter) is capped at the same length.
MAX_STRING = 200
# Repeated execution (loop iterations, jumps back, calls) of one run before NC205 stops it;
# straight-line blocks run the first time are free. NCTRANS_MAX_STEPS overrides it.
MAX_STEPS = 2_000_000
# Repeated execution `equiv` follows where a side restarts its main program for ever (ISO M99):
# both sides are endless, and comparing thousands of passes says what millions would, in seconds
# (a 39-line Haas program ending in M99 took 4 min 40 s at MAX_STEPS). NCTRANS_MAX_ENDLESS_STEPS
# overrides it; MAX_STEPS stays the cap when it is lower.
MAX_ENDLESS_STEPS = 100_000
# Blocks of plain motion a conversion holds in memory when it is not streamed: one construct the
# target lacks, lowered on its own (an endless loop around it would otherwise grow until the step
# budget: gigabytes), or a whole program lowered as the last resort. Beyond it the construct is
# refused (NC402 at its line) and `convert --flatten` streams the whole program instead (~1 KiB of
# IR per block: 100,000 blocks ~ 100 MiB). NCTRANS_MAX_LOWERED_BLOCKS overrides it.
MAX_LOWERED_BLOCKS = 100_000
# Moves a lowering to plain motion (--flatten, or a conversion's last resort) writes from repeated
# execution: what its loops and calls unroll into. A cycle inside a loop writes tens of moves per
# step, so the step budget alone let an endless loop write for minutes (24 M moves at 2 M steps);
# past this budget the run stops with NC205 at the loop (the lowering is then refused, NC402), in
# ~10 s. Straight-line blocks and a subprogram's first run are free. NCTRANS_MAX_UNROLLED overrides it.
MAX_UNROLLED = 500_000
# Moves one backplot draws: a scene holds each move it draws (~1 KiB with its record), so an endless
# loop (2 M steps of a drilling cycle: 24 M moves) would need gigabytes. Past it the plot shows the
# first moves, says so in the plot, and NC011 names the line of the first move left out; the run
# goes on to its end (its diagnostics). NCTRANS_MAX_PLOTTED_MOVES overrides it.
MAX_PLOTTED_MOVES = 250_000
# The largest coordinate (mm or degrees) a toolpath record holds: no machine travels a million
# kilometres, and past it squares and sums of coordinates (lengths, times, bounds) overflowed.
# Beyond it a move is out of range (NC108), as infinity is. The native kernel holds the same number.
MAX_COORDINATE = 1e12
# Elements of one declared array (DEF REAL A[n,m]): REP() and SET() walk them all.
MAX_ARRAY_ELEMENTS = 1_000_000


def _whole_number(text: str) -> Optional[int]:
    """`text` as a whole number of ASCII digits (blanks around allowed), else None."""
    text = text.strip()
    return int(text) if text.isascii() and text.isdigit() else None


def setting(name: str, default: int) -> int:
    """A limit from the environment (NCTRANS_<NAME>, a whole number), else `default`: for a shop
    whose programs need more, and for the catalogue's examples, which need less. A value that is
    not a whole number is ignored here; the CLI refuses it first (environment_errors)."""
    value = _whole_number(os.environ.get(f"NCTRANS_{name}", ""))
    return default if value is None else value


# The step budget of the runs started in this context (equiv of endless programs); None: MAX_STEPS.
STEP_BUDGET: ContextVar[Optional[int]] = ContextVar("STEP_BUDGET", default=None)


def step_budget() -> int:
    """Repeated steps a run may take: the context's budget, else MAX_STEPS (or its setting)."""
    budget = STEP_BUDGET.get()
    return setting("MAX_STEPS", MAX_STEPS) if budget is None else budget


# The limits the environment may set (NCTRANS_<NAME>).
SETTINGS = ("MAX_INPUT_BYTES", "MAX_BLOCK_CHARS", "MAX_STEPS", "MAX_ENDLESS_STEPS", "MAX_LOWERED_BLOCKS",
            "MAX_UNROLLED", "MAX_PLOTTED_MOVES", "MAX_DIAGNOSTICS")



def environment_errors() -> list[str]:
    """What is wrong with the limits set in the environment: a value that is not a whole number
    (negative, a fraction, text) would otherwise be dropped silently for the default."""
    out = []
    for name in SETTINGS:
        raw = os.environ.get(f"NCTRANS_{name}")
        if raw is not None and raw.strip() and _whole_number(raw) is None:
            out.append(f"NCTRANS_{name}={raw!r} is not a whole number of 0 or more "
                       "(README \"Limits\")")
    return out


_OPERATOR_CHARS = re.compile(r"[-+*/<>=]|\b(?:AND|OR|XOR|MOD|NOT|B_AND|B_OR|B_XOR|B_NOT|DIV)\b",
                             re.IGNORECASE)
_STACKED_SIGNS = re.compile(r"[-+]{2,}")
_HUGE_INTEGER = re.compile(r"(?<![\d.])0*[1-9]\d{308,}")


def bracket_depth(code: str, opening: str = "[(", closing: str = "])") -> tuple[int, int]:
    """(deepest nesting, 0-based index where it is first reached) of brackets in `code`."""
    depth = deepest = 0
    where = 0
    for i, ch in enumerate(code):
        if ch in opening:
            depth += 1
            if depth > deepest:
                deepest, where = depth, i
        elif ch in closing:
            depth -= 1
    return deepest, where


def too_complex(code: str, opening: str = "[(", closing: str = "])") -> Optional[tuple[int, str]]:
    """(0-based index, message) when a block nests brackets or chains operators beyond what any
    walker of its expression tree may recurse into; None for every real block."""
    if len(code) <= MAX_BRACKET_DEPTH * 2 and len(code) <= MAX_OPERATORS:
        return None
    deepest, where = bracket_depth(code, opening, closing)
    if deepest > MAX_BRACKET_DEPTH:
        return where, (f"brackets nested {deepest} deep (at most {MAX_BRACKET_DEPTH}): "
                       "nesting too deep")
    ops = 0
    for m in _OPERATOR_CHARS.finditer(code):
        ops += 1
        if ops > MAX_OPERATORS:
            return m.start(), (f"more than {MAX_OPERATORS} operators in one block: "
                               "expression nesting too deep; split the computation")
    return None


def stacked_signs(code: str) -> Optional[tuple[int, str]]:
    """(0-based index, the signs) of two or more signs in a row (`X1--5`, `#1=1+-+5`)."""
    m = _STACKED_SIGNS.search(code)
    return None if m is None else (m.start(), m.group())


def huge_literal(code: str) -> Optional[tuple[int, str]]:
    """(0-based index, digits) of an integer literal too large for a double (more than 308
    digits): it would read as infinity."""
    if len(code) < 309:
        return None
    m = _HUGE_INTEGER.search(code)
    return None if m is None else (m.start(), m.group())


def finite(value: float) -> bool:
    return not math.isinf(value) and not math.isnan(value)
