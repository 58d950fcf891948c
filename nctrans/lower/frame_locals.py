"""Call-frame locals of a main program (IR space "local": Fagor P0..P99 and V.P. user variables)
as variables a target declares in its main program.

A target that has no call-frame parameters (Sinumerik) declares them as local user data of the
main program (`DEF REAL P_1`): they end with it, as the frame's locals do. Only where nothing else
reaches that frame: a subprogram that shares the caller's frame (Fagor LL / L / #CALL, seed: "the
called subroutine shares the local parameters") or reads V.P. variables of its caller (V.P. is
kept in called subroutines, spec fagor8065 22.57) cannot see a main program's DEF, so a program
calling one outside the program keeps those locals unexpressed (refused or lowered as before);
one inside it that names them leaves the whole program so. V.S. globals survive
the program (they are not call-frame locals) and are never declared here.
"""
from __future__ import annotations

import re
from typing import Optional

from nctrans.ir import nodes as n
from nctrans.ir import walk

GLOBAL_PREFIX = "V.S."      # user variables that outlive the program (spec fagor8065 L523)
SHARED_FRAME_CALLS = ("shared",)


def lasting(key) -> bool:
    """A variable of space "local" that survives its frame: a V.S. global."""
    return str(key).upper().startswith(GLOBAL_PREFIX)


def identifier(key: str) -> str:
    """A name a Sinumerik-style control takes: letters, digits, `_`, the first two a letter or
    `_` (seed sinumerik-840d L839): P1 -> P_1, V.P.DEPTH -> V_P_DEPTH."""
    ident = re.sub(r"\W", "_", str(key).upper())
    if not re.match(r"[A-Z_]{2}", ident):
        ident = ident[:1] + "_" + ident[1:]
    return ident[:31]


def _locals_in(obj, out: dict, bad: list) -> None:
    if obj is None or isinstance(obj, (str, int, float, bool, n.Num, n.Str, n.Span)):
        return
    if type(obj) is n.Var:
        if obj.space == "local":
            if obj.indices or obj.key is None:
                bad.append(obj)
            else:
                out.setdefault(str(obj.key).upper(), None)
        for e in obj.indices or ():
            _locals_in(e, out, bad)
        return
    if isinstance(obj, dict):
        for v in obj.values():
            _locals_in(v, out, bad)
        return
    if isinstance(obj, (list, tuple)):
        for v in obj:
            _locals_in(v, out, bad)
        return
    for name in getattr(obj, "__slots__", ()):
        if type(obj) is n.SubCall and name == "bindings":
            continue                    # where the arguments land in the callee's own frame
        _locals_in(getattr(obj, name, None), out, bad)


def _first_reads(body: list) -> set[str]:
    """The locals a body reads (in source order) before it sets them."""
    written: set[str] = set()
    reads: set[str] = set()

    def read(obj) -> None:
        found: dict = {}
        _locals_in(obj, found, [])
        reads.update(k for k in found if k not in written)

    def write(var) -> None:
        if type(var) is n.Var and var.space == "local" and var.key is not None:
            written.add(str(var.key).upper())

    for node in walk.walk(body):
        if type(node) is n.Block:
            for st in node.body:
                if type(st) is n.Assign:
                    read(st.value)
                    read(st.target.indices)
                    write(st.target)
                else:
                    read(st)
        elif type(node) is n.ForLoop:
            read([node.start, node.end, node.step])
            write(node.var)
        else:
            read([getattr(node, a, None) for a in ("cond", "subject", "start", "end", "step")])
    return reads


PARAMETERS = "#parameters"      # in a unit's plan: the keys its calls pass, in parameter order


def own_frame_parameters(keys: set, body: list, calls: list) -> Optional[list]:
    """The parameters of a subprogram every call of which opens a new frame with its arguments
    (Fagor #PCALL / #MCALL: A..Z = P0..P25): the keys the calls bind, in number order; None where
    a call shares the caller's frame, the body reads a user variable of its caller (V.) or a local
    before setting it that some call does not pass (Fagor stops there; a parameter would read 0)."""
    if not calls or any(c.kind != "pcall" or c.args or c.repeat is not None for c in calls):
        return None
    if any(k.startswith("V.") for k in keys):
        return None
    bound = [{str(v.key).upper() for v in c.bindings.values() if type(v) is n.Var and v.space == "local"}
             for c in calls]
    if any(len(b) != len(c.named_args) for b, c in zip(bound, calls)):
        return None
    if not _first_reads(body) <= set.intersection(*bound):
        return None
    return sorted(set().union(*bound), key=lambda k: (len(k), k))


def _body(body):
    from nctrans.dialects.base import CompactBody
    if type(body) is CompactBody:
        return body.items               # its runs of plain lines hold no variable
    return body if type(body) is list else None


def plan(program: n.Program) -> dict[Optional[str], dict[str, str]]:
    """{unit (None: the main body, else a subprogram's name): {local key: declared name}} for the
    call-frame locals each unit may declare as its own variables; a unit left out keeps them
    unexpressed (see the module). A subprogram's locals are its own where it sets each before
    reading it, no call passes it arguments, and no other unit names them (a call that shares the
    frame would otherwise let the caller see them)."""
    units: dict[Optional[str], dict] = {}
    for name, body in [(None, program.body)] + [(k, s.body) for k, s in (program.subprograms or {}).items()]:
        b = _body(body)
        if b is None:
            return {}                   # a streamed body: its variables cannot be seen ahead
        found: dict = {}
        bad: list = []
        _locals_in(b, found, bad)
        if bad:
            return {}                   # a computed parameter number (P[expr])
        units[name] = {"body": b, "keys": set(found)}
    main = units.pop(None)
    calls = [s for body in [main["body"]] + [u["body"] for u in units.values()]
             for blk in walk.blocks(body) for s in blk.body if type(s) is n.SubCall]
    out: dict[Optional[str], dict[str, str]] = {}
    for name, u in units.items():
        if not u["keys"]:
            continue
        mine = [c for c in calls if c.name == name]
        given = own_frame_parameters(u["keys"], u["body"], mine)
        if given is not None:
            out[name] = {k: identifier(k) for k in sorted(u["keys"] | set(given))}
            out[name][PARAMETERS] = given
            continue
        others = main["keys"].union(*(v["keys"] for k, v in units.items() if k != name))
        if u["keys"] & others or any(c.named_args or c.args for c in mine) or _first_reads(u["body"]) & u["keys"]:
            return {}                   # it reaches a frame it shares: not its own alone
        if any(lasting(k) for k in u["keys"]):
            return {}
        out[name] = {k: identifier(k) for k in sorted(u["keys"])}
    shares = any(c.kind in SHARED_FRAME_CALLS and c.name not in units for c in calls)
    mine: dict[str, str] = {}
    for key in sorted(main["keys"]):
        if lasting(key):
            continue
        if key.startswith("V.P.") and any(c.name not in units for c in calls):
            continue                    # V.P. is seen by the subroutines it calls (not all seen here)
        if not key.startswith("V.") and shares:
            continue                    # P0..P99 shared with a subroutine that is not here
        mine[key] = identifier(key)
    if mine:
        out[None] = mine
    if any(len({v for k, v in m.items() if k != PARAMETERS}) != len(m) - (PARAMETERS in m)
           for m in out.values()):
        return {}                       # two spellings meet in one name
    return out
