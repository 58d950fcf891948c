"""Per-word absolute / incremental coordinates (Sinumerik `X=AC(5)`, `X=IC(5)`; ISO turning `U`,
`W`) written for ISO milling, whose distance mode is one for all axes (G90/G91).

- Where the word asks for the mode in force (AC under G90, IC under G91) it is the plain word.
- Where every axis word of a plain move asks for the other mode (`G1 X=IC(5) Y=IC(2)` under G90,
  ISO-T `G1 U-2.`), the block is written under that mode and the mode in force is written again
  after it: `G91 G1 X5. Y2.` then `G90`. Mixed words (`X=IC(5) Y10` under G90) stay refused: one
  block cannot hold both modes.

Both need the G90/G91 in force to be known on every path to the block: the emitter tracks it in
source order, starts a main program under G90 (the power-on mode) and forgets it wherever a place
is reached from elsewhere (a jump target, a structure, after a call, a subprogram's start).
DC/ACP/ACN (a rotary axis's direction of approach) have no ISO counterpart and stay refused.
"""
from __future__ import annotations

from typing import Optional

from nctrans.ir import nodes as n

_MODE = {"absolute": "abs", "incremental": "inc"}
_DISTANCE = {"abs": "absolute", "inc": "incremental"}


def starts_as_main(program: n.Program) -> Optional[bool]:
    """Whether the program's main body starts under the power-on G90 as far as the conversion can
    tell: it ends the program itself (M2/M30) at its top level. A file that returns (M17, M99,
    RET) runs in its caller's mode. None for a body streamed as it is parsed (not seen ahead)."""
    from nctrans.dialects.base import CompactBody
    body = program.body
    if type(body) is CompactBody:
        body = body.items                   # its runs of plain lines hold no program end
    elif type(body) is not list:
        return None
    for node in body:
        if type(node) is n.Block and any(type(s) is n.ProgramEnd and s.kind in ("end", "end_rewind")
                                         for s in node.body):
            return True
    return False


def plain_words(emitter, s: n.Motion) -> tuple[dict, list]:
    """(the axis words to write, the distance word the block must carry): the words without their
    per-word mode where that is exact (see the module), else the target unchanged (the emitter's
    axis writer refuses a per-word mode)."""
    modes = {av.mode for av in s.target.values()}
    if getattr(emitter, "dialect", "") != "iso-m" or not modes & {"abs", "inc"} \
            or modes - {None, "abs", "inc"}:
        return s.target, []
    if emitter.distance_known is None:
        from nctrans.dialects.base import CannotStream
        raise CannotStream("per-word coordinates before any G90/G91 of a streamed program")
    if not emitter.distance_known:
        return s.target, []
    modal = _MODE[emitter.distance]
    plain = {k: n.AxisValue(av.value) for k, av in s.target.items()}
    if modes <= {None, modal}:
        emitter.lowered("per-word absolute/incremental coordinates written as plain words: the "
                        f"{emitter.code_for('distance', emitter.distance)} in force means the same",
                        once="per-word-same")
        return plain, []
    other = "inc" if modal == "abs" else "abs"
    if modes == {other} and not s.machine_coords and not emitter.thread_mode \
            and emitter.named_cycle is None and emitter.restore_distance is None \
            and not emitter.restore_absolute:
        switch = emitter.code_for("distance", _DISTANCE[other])
        back = emitter.code_for("distance", emitter.distance)
        emitter.lowered(f"a move whose every axis word is {_DISTANCE[other]} written under {switch}, "
                        f"then {back} again", once="per-word-switch")
        emitter.restore_distance = emitter.distance
        return plain, [emitter.code_word("distance", _DISTANCE[other])]
    return s.target, []
