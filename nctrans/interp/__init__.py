"""The interpreter: IR Program -> stream of ToolpathRecord (canonical motions).

Entry point (streaming; memory does not grow with program length):

    interpret(program, machine=None, *, diagnostics, resolver=None, max_steps=...)
        -> Iterator[ToolpathRecord]

- `machine`: nctrans.machine.Machine (default mill when None): work offsets, tool table.
- `diagnostics`: a list the interpreter appends Diagnostic records to (NC1xx undefined names,
  NC2xx modal/arc problems, "analysis truncated at line N" when the step budget runs out).
- `resolver`: finds subprograms not defined in the program (other files on a search path).
- The initial modal state comes from `program.meta["defaults"]` ({group: value}, from the
  dialect's rules table), so the interpreter stays dialect-neutral.
"""

from nctrans.interp.interpreter import interpret

__all__ = ["interpret"]
