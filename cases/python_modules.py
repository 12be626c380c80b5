"""Shared by the cases' post-processing scripts: stop with one line when a python module a script
needs is missing.

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    from python_modules import require
    require("matplotlib", "numpy")
"""
import importlib
import os
import sys

# The python partita's own plots use (app/process.cpp); the modules' Debian packages.
PARTITA_PYTHON = "/usr/bin/python3"
DEBIAN_PACKAGE = {"numpy": "python3-numpy", "matplotlib": "python3-matplotlib", "vtk": "python3-vtk9"}


def require(*modules):
    """Stop with one line when a module this script needs is missing: which one, its Debian
    package, the python that lacks it and the one partita's own plots use."""
    for m in modules:
        try:
            importlib.import_module(m)
        except ImportError:
            sys.exit(f"{os.path.basename(sys.argv[0])}: the python module {m} is missing in "
                     f"{sys.executable} (Debian package {DEBIAN_PACKAGE.get(m, m)}); run it with "
                     f"{PARTITA_PYTHON}, the python partita's own plots use, or install it there")
