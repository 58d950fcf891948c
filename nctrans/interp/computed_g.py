"""A G code word with a computed number (ISO macro B `G#143`, spec iso.md 6.2: "a variable can be
used in an address: G#130"): the number is evaluated as the block runs and the code it names in the
dialect's own table is selected as if it had been written, where it is a plain modal code (motion,
plane, distance, units, cutter compensation, feed mode, work offset, path mode). Any other code it
names (a cycle, a non-modal code, one the table does not know) is not modelled: NC220 at its line,
as the written code would be. A number the analysis cannot know is NC107 and leaves the modes as
they were; a vacant one leaves the word out, as the control does. Sinumerik writes the same selection as indirect G code (`G[7]=...`, indirect_g.py).
"""
from __future__ import annotations

from nctrans.ir import nodes as n

# neutral modal groups whose codes one ModeChange selects completely (no words of their own)
SELECTABLE_GROUPS = frozenset({"motion", "plane", "distance", "units", "cutter_comp", "feed_mode",
                               "work_offset", "path_mode", "arc_distance"})


def is_computed_g(s: n.Passthrough) -> bool:
    return s.address == "G" and s.value is not None


def code_of(dialect: str, number: float):
    """The rule of code G<number> in `dialect`'s table when it is a plain modal code, else None."""
    from nctrans.rules import load_table, normalise_code
    try:
        rule = load_table(dialect).lookup(normalise_code("G", f"{number:.4f}"))
    except Exception:            # a dialect without a table, or a number no code can spell
        return None
    return rule if rule is not None and rule.group in SELECTABLE_GROUPS else None


def select(d) -> None:
    """Interpreter handler; `d` is (interpreter, statement, compiled value)."""
    from nctrans.interp.evaluate import UNKNOWN
    it, s, value = d
    raw = value()
    if raw is None:
        return                   # a vacant variable in an address: the word is ignored (spec 6.2)
    if raw is UNKNOWN or not isinstance(raw, (int, float)):
        it.diag("NC107", "warning", f"{s.text}: the G code number is unknown to the analysis; the "
                "modes are left as they were")
        return
    v = float(raw)
    rule = code_of(s.dialect or it.program.dialect, v)
    if rule is None:
        it.diag("NC220", "warning", f"{s.text} selects G{v:g}, which is not modelled here: the "
                "analysed toolpath leaves it out")
        return
    it._h_mode(n.ModeChange(rule.group, rule.value, rule.code))
