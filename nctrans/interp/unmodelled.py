"""What the interpreter does with a construct it does not model (an IR Passthrough).

The rule (issue 8): a word, G/M code or function the interpreter does not model never moves the
tool, and toolpath, lint and check always say so: NC220 (warning) naming the construct at its line.
Two kinds of Passthrough are exempt, both decided by data, not code:
- constructs known to have no effect on the programmed path (set-up, HMI, machine-data and
  preprocessing words): their front end gives them a reason in NO_MOTION_EFFECT, or a reason that
  starts with "no motion effect" (words listed in `[options.no_motion_effect]` of a rules table);
  reasons starting with MILL_ONLY have no effect on a mill only (Sinumerik DIAM90 on a mill);
- nothing else: an unknown M function is reported like any other word.
An unmodelled code that takes over the block's motion (a thread, a tapping or a soft-approach G
code: `[options.unmodelled_motion] codes` of the rules table, plus every code of motion group 1 the table
marks "passthrough"; and any G code the table does not know, UNKNOWN_G_REASONS) makes the
block's axis words and the following blocks' until the next modelled motion code move nothing,
with NC220 naming the code.
"""
from __future__ import annotations

import re
from functools import lru_cache
from typing import Optional

from nctrans.ir import nodes as n
from nctrans.ir.vocabulary import MILL_ONLY, NO_EFFECT_ELSEWHERE, NO_EFFECT_PREFIX, NO_MOTION_EFFECT
_CODE = re.compile(r"\s*([A-Za-z_$][A-Za-z_0-9.]*)")


# Rules that say part of the program was not analysed (not modelled, unknown, not found, cut
# short), by their catalogue name: a name ending in one of these suffixes, or one of these names.
# `check` reports them beside its own findings: a check that passed over an unmodelled construct
# must not look clean (issue 8: toolpath, lint and check all say it at its line). By name, so a
# rule added later for another unmodelled construct (NC113 turning-cycle-not-modelled) is one too.
NOT_ANALYSED_SUFFIXES = ("not-modelled", "not-run", "not-in-model")
# NC217/NC218: a programmed rounding or chamfer the analysed corner runs without (where the
# control shrinks it, the machine's corner is not the analysed one); NC123: a compensation radius
# of a tool the program never chose, analysed as 0
NOT_ANALYSED_NAMES = frozenset(("unresolved-call", "unknown-at-analysis-time", "analysis-truncated",
                                "corner-element-not-inserted", "corner-element-alarm",
                                "compensation-radius-of-unknown-tool"))


@lru_cache(maxsize=None)
def not_analysed_rules() -> frozenset[str]:
    """Codes of the catalogue's rules that say part of the program was not analysed (NC220,
    NC103, NC107, NC205, NC224, NC113, NC415, NC416 ...); NC3xx check findings excluded."""
    from nctrans import catalogue
    return frozenset(r.code for r in catalogue.load().rule if not r.code.startswith("NC3")
                     and (r.name.endswith(NOT_ANALYSED_SUFFIXES) or r.name in NOT_ANALYSED_NAMES))


# reasons of coordinate-system changes the interpreter leaves out (ISO G68 with an I/J/K vector):
# the moves after them are analysed in the old system, so no conversion keeps their text
FRAME_NOT_MODELLED = "coordinate system change not modelled"

# reasons whose construct the front end has already reported as an error (NC002/NC007)
REPORTED_AS_ERROR = frozenset(("syntax error", "invalid number"))


def modelled(s: n.Passthrough) -> bool:
    """A Passthrough the interpreter models all the same (a corner element RND/CHF/,R/,C, the
    contour offset OFFN): kept verbatim for conversions, acted on by the run."""
    from nctrans.interp import contour_offset, corner_elements
    return bool(corner_elements.kind_of(s)) or contour_offset.is_offset_word(s)


def no_motion_effect(reason: str, machine_kind: str = "mill") -> bool:
    """True when a Passthrough with this reason changes nothing on the toolpath of this machine."""
    if reason in NO_MOTION_EFFECT:
        return True
    if reason.startswith(MILL_ONLY):
        return machine_kind == "mill"
    return reason.startswith(NO_EFFECT_PREFIX)


def harmless_elsewhere(s: n.Passthrough, machine_kind: str = "mill") -> bool:
    """True when a construct with no motion effect, written on another control as a comment, leaves
    nothing undone that its own control does (NO_EFFECT_ELSEWHERE reasons, the source table's
    `[options.no_motion_effect] harmless_elsewhere` words, a mill-only word on a mill)."""
    if s.reason in NO_EFFECT_ELSEWHERE:
        return True
    if s.reason.startswith(MILL_ONLY):
        return machine_kind == "mill"
    return leading_word(s.text) in _harmless_words(s.dialect)


@lru_cache(maxsize=None)
def _harmless_words(dialect: str) -> frozenset[str]:
    return _table_words(dialect, "no_motion_effect", "harmless_elsewhere")


def _table_words(dialect: str, section: str, key: str) -> frozenset[str]:
    """The upper-cased words of `[options.<section>] <key>` in the dialect's rules table (none when
    the dialect has no table of its own)."""
    try:
        from nctrans.rules import load_table
        t = load_table(dialect) if dialect else None
    except Exception:           # a dialect without a table of its own
        return frozenset()
    if t is None:
        return frozenset()
    return frozenset(str(w).upper() for w in t.options.get(section, {}).get(key, ()))


def leading_word(text: str) -> str:
    """The construct's name as written first in its text (G34, TRAORI, CHF), upper case."""
    m = _CODE.match(text)
    if not m:
        return text.strip()[:16]
    w = m.group(1).upper()
    g = re.match(r"^([GM])0*(\d+(?:\.\d+)?)$", w)
    return f"{g.group(1)}{g.group(2)}" if g else w


@lru_cache(maxsize=None)
def one_block_codes(dialect: str) -> frozenset[str]:
    """Non-modal codes of `dialect` that take over their own block's motion only
    (`[options.unmodelled_motion] one_block`: ISO G31)."""
    return _table_words(dialect, "unmodelled_motion", "one_block")


@lru_cache(maxsize=None)
def motion_codes(dialect: str) -> frozenset[str]:
    """Codes of `dialect` that take over the block's motion when the interpreter does not model
    them: the table's `unmodelled_motion` list plus its motion-group codes kept as passthrough."""
    if not dialect:
        return frozenset()
    try:
        from nctrans.rules import load_table
        t = load_table(dialect)
    except Exception:           # a dialect without a table of its own
        return frozenset()
    out = {str(c).upper() for c in t.options.get("unmodelled_motion", {}).get("codes", ())}
    out |= one_block_codes(dialect)
    for c in t.codes:
        if c.group == "passthrough" and str(c.dialect_group) == "1":
            out.add(c.code.upper())
    return frozenset(out)


_G_CODE = re.compile(r"^G\d")
# reasons of a G code no table knows (or one given by an expression): it may be a motion code
# (LinuxCNC G5.2 NURBS, Haas G12/G47), so it is taken as one: its axis words, and those of the
# blocks after it, move nothing until the next modelled motion code. (Before, the control points
# after a G5.2 ran as G1 moves, warned only for their P word.) The control itself stops at a G
# code it does not know.
UNKNOWN_G_REASONS = ("unknown code", "unknown function", "unknown G code", "computed G code")


def takes_motion(s: n.Passthrough) -> Optional[str]:
    """The code when this unmodelled construct is a motion code (see motion_codes), or a G code
    the dialect's table does not know; else None."""
    word = leading_word(s.text)
    if word in motion_codes(s.dialect):
        return word
    if s.reason.startswith(UNKNOWN_G_REASONS) and _G_CODE.match(word):
        return word
    return None
