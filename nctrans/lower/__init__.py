"""Lowering passes: rewrite an IR Program into a simpler one a target dialect can express.

- `flatten`: plain motion only (loops unrolled, calls and cycles expanded, expressions evaluated,
  frames and local offsets folded into coordinates), built from the interpreter's own run.
"""
