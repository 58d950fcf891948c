"""Small builders for hand-made IR programs used by the interpreter tests."""
from __future__ import annotations

from nctrans.interp import interpret
from nctrans.ir import nodes as n

F = "t.nc"


def num(v):
    return v if not isinstance(v, (int, float)) else n.Num(float(v))


def av(v, mode=None):
    return n.AxisValue(num(v), mode)


def mode(group, value):
    return n.ModeChange(group, value)


def move(mode_=None, center=None, radius=None, turns=None, machine=False, **axes):
    m = n.Motion({k: (v if isinstance(v, n.AxisValue) else av(v)) for k, v in axes.items()},
                 center={k: av(v) for k, v in center.items()} if center else None,
                 radius=num(radius) if radius is not None else None,
                 turns=num(turns) if turns is not None else None, machine_coords=machine)
    return ([n.ModeChange("motion", mode_)] if mode_ else []) + [m]


class B:
    """Collects blocks, one per line."""

    def __init__(self):
        self.blocks = []

    def __call__(self, *stmts, number=None, label=None):
        body = []
        for s in stmts:
            body.extend(s if isinstance(s, list) else [s])
        self.blocks.append(n.Block(n.Span(F, len(self.blocks) + 1), body, number=number, label=label))
        return self

    def node(self, node):
        self.blocks.append(node)
        return self

    def span(self):
        return n.Span(F, len(self.blocks) + 1)

    def program(self, defaults=None, subs=None):
        d = {"motion": "rapid", "plane": "XY", "distance": "absolute", "units": "mm",
             "feed_mode": "per_min", "work_offset": "G54"}
        d.update(defaults or {})
        return n.Program(F, "test", self.blocks, subprograms=subs or {}, meta={"defaults": d})


def run(prog, machine=None, **kw):
    diags = []
    recs = list(interpret(prog, machine, diagnostics=diags, **kw))
    return recs, diags


def moves(recs):
    return [r for r in recs if r.kind in ("rapid", "linear", "arc")]
