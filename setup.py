"""Build steps pyproject.toml cannot declare: the native extension and the data directories.

nctrans._plainrun runs plain ISO blocks straight from the source text (see nctrans/plainrun.py).
It is optional: without a C compiler the install still succeeds and the same work runs in Python.

rules/, grammars/ and backplot/ stay top-level directories in the repository; a built package
carries them as nctrans/_data/<kind>/ (read through nctrans/resources.py).
"""
import os
import shutil

from setuptools import Extension, setup
from setuptools.command.build_py import build_py

DATA_DIRS = ("rules", "grammars", "backplot")
HERE = os.path.dirname(os.path.abspath(__file__))


class build_py_with_data(build_py):
    """build_py that also copies the top-level data directories into the built package."""

    def run(self):
        super().run()
        if getattr(self, "editable_mode", False):
            return          # an editable install reads them from the checkout
        for kind in DATA_DIRS:
            src = os.path.join(HERE, kind)
            if not os.path.isdir(src):
                raise SystemExit(f"setup.py: data directory {kind}/ is missing")
            dest = os.path.join(self.build_lib, "nctrans", "_data", kind)
            shutil.rmtree(dest, ignore_errors=True)
            shutil.copytree(src, dest, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", ".*"))


setup(
    ext_modules=[Extension("nctrans._plainrun", ["nctrans/_plainrun.c"], optional=True)],
    cmdclass={"build_py": build_py_with_data},
)
