"""A computed G word of another dialect (ISO `G#143`) as Sinumerik indirect G code.

Sinumerik selects a G code by its number inside one modal group: `G[<group>]=<variable>`, the
number being the code's place in the group as `$P_GG[n]` reads it (seed
sinumerik-840d-advanced-programming L1467-1552; rules/sinumerik.toml [options.g_group_index]).
"Arithmetic functions are not legal in indirect G code programming": the number is computed in
a line of its own, into an INT variable the program declares at its top.

An ISO G number names a code in any group, so the mapping is written only where the program says
which codes it can be: the G word's value is one variable (`G#143`) and every assignment to that
variable in the program is a constant, all of whose codes are plain modal codes of one Sinumerik
group at the same distance from their number (G41 -> 2, G42 -> 3: index = #143 - 39). Any other
computed G word stays a refusal at its line (nctrans.interp.computed_g models the ISO side).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from nctrans.interp.computed_g import code_of, is_computed_g
from nctrans.ir import nodes as ir
from nctrans.ir import walk


@dataclass(frozen=True)
class IndirectG:
    family: int          # the Sinumerik G group written G[family]=
    offset: float        # index = the variable's value - offset
    variable: str        # the INT variable declared for the index
    codes: tuple         # the source codes the variable's constants name, for the note


def _variable(e) -> Optional[int]:
    if type(e) is ir.Var and e.space == "num" and isinstance(e.key, int) and not e.indices:
        return e.key
    return None


def plan(program: ir.Program, target_table) -> dict[int, IndirectG]:
    """Source variable number -> how its computed G words of the main body are written."""
    used = {_variable(s.value) for b in walk.blocks(program.body) for s in b.body
            if type(s) is ir.Passthrough and is_computed_g(s)} - {None}
    if not used:
        return {}
    values: dict[int, set] = {k: set() for k in used}
    bodies = [program.body] + [sub.body for sub in (program.subprograms or {}).values()]
    for body in bodies:
        for b in walk.blocks(body):
            for s in b.body:
                if type(s) is ir.Assign and (k := _variable(s.target)) in values:
                    values[k].add(s.value.value if type(s.value) is ir.Num else None)
    groups = {str(k): list(v) for k, v in (target_table.options.get("g_group_index") or {}).items()}
    out = {}
    for k, vs in values.items():
        found = _family(program.dialect, vs, groups, target_table)
        if found is not None:
            family, offset, codes = found
            out[k] = IndirectG(family, offset, f"INDEX_G{family}_{k}", codes)
    return out


def _family(dialect: str, values: set, groups: dict, target_table):
    if not values or None in values:
        return None
    places = set()
    codes = []
    for v in sorted(values):
        rule = code_of(dialect, v)
        mine = target_table.code_for(rule.group, rule.value) if rule is not None else None
        where = next(((int(f), codes_.index(mine.code) + 1) for f, codes_ in groups.items()
                      if mine is not None and mine.code in codes_), None)
        if where is None:
            return None
        places.add((where[0], v - where[1]))
        codes.append(rule.code)
    if len(places) != 1:
        return None
    family, offset = places.pop()
    return family, offset, tuple(codes)


def call_variables(program: ir.Program) -> tuple[str, str]:
    """The INT and STRING variables the main body's computed calls (ISO `M98 P#144`) use for an
    indirect Sinumerik CALL, or () when it has none."""
    for b in walk.blocks(program.body):
        for s in b.body:
            if type(s) is ir.SubCall and not s.name and s.target is None and "P" in s.named_args:
                return ("CALL_NUMBER", "CALL_NAME")
    return ()
