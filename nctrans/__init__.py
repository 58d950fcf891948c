"""nctrans: a transpiler and static analyzer between CNC part-program dialects."""
__version__ = "0.1.0"
