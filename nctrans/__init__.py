"""nctrans: a transpiler and static analyzer between CNC part-program dialects.

The public API (semantic versioning applies to these names; see CHANGELOG.md)::

    import nctrans
    nctrans.transpile(text, read="iso-m", write="sinumerik").text
    nctrans.lint(pathlib.Path("programs/"))
    for record in nctrans.toolpath(pathlib.Path("part.nc")): ...
    nctrans.equiv(original, converted)
"""
from __future__ import annotations

__version__ = "0.1.0"

__all__ = [
    "Conversion", "Diagnostic", "Equivalence", "ErrorLevel", "Guess", "Machine", "NCError",
    "NCInputError", "NCProgramError", "Program", "Toolpath", "ToolpathRecord", "UnknownDialectError",
    "__version__", "detect", "dialects", "equiv", "lint", "parse", "toolpath", "transpile",
]

# The API is bound eagerly: `nctrans.toolpath` names both the API function and the module of the
# record type, and a submodule loaded after the package binds itself over the package attribute of
# its name. Importing the API here loads every module it needs first, then binds the functions
# (tests/test_api.py checks they survive importing every submodule). The CLI imports the same
# modules, so this costs no start-up time.
from nctrans.api import (Conversion, Equivalence, ErrorLevel, NCError, NCInputError,  # noqa: E402
                         NCProgramError, Toolpath, UnknownDialectError, detect, dialects, equiv, lint,
                         parse, toolpath, transpile)
from nctrans.detection import Guess  # noqa: E402
from nctrans.diagnostics import Diagnostic  # noqa: E402
from nctrans.ir.nodes import Program  # noqa: E402
from nctrans.machine import Machine  # noqa: E402
from nctrans.toolpath import ToolpathRecord  # noqa: E402
