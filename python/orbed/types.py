"""The generated message types (package orbed_lcm, written by lcmtypes/gen_python.py at build time).

`import orbed_lcm` works when the build's python folder is on sys.path (PYTHONPATH=python:build/python).
lcm_types() also finds it without that: in $ORBED_BUILD_DIR/python, else <repo>/build/python.
"""
import importlib
import os
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def build_dir():
    """The build tree: $ORBED_BUILD_DIR, else <repo>/build."""
    return os.environ.get("ORBED_BUILD_DIR") or os.path.join(REPO, "build")


def lcm_types():
    """The orbed_lcm package (its message classes, and _structure.STRUCTS)."""
    try:
        return importlib.import_module("orbed_lcm")
    except ImportError:
        path = os.path.join(build_dir(), "python")
        if not os.path.isfile(os.path.join(path, "orbed_lcm", "__init__.py")):
            raise ImportError(f"orbed_lcm is not built in {path}: cmake --build build --target orbed_python_types")
        sys.path.append(path)
        return importlib.import_module("orbed_lcm")


def structs():
    """{struct name: ((type, field, dims, unit), ...)} of every message type."""
    lcm_types()
    return importlib.import_module("orbed_lcm._structure").STRUCTS


def type_by_fingerprint():
    """{8-byte packed fingerprint: message class} of every type."""
    package = lcm_types()
    return {getattr(package, name)._get_packed_fingerprint(): getattr(package, name) for name in structs()}
