"""Build of the one native extension; everything else is declared in pyproject.toml.

nctrans._plainrun runs plain ISO blocks straight from the source text (see nctrans/plainrun.py).
It is optional: without a C compiler the install still succeeds and the same work runs in Python.
"""
from setuptools import Extension, setup

setup(ext_modules=[Extension("nctrans._plainrun", ["nctrans/_plainrun.c"], optional=True)])
