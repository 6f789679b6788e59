"""Signatures and options stay small (issue 33): no function over 12 parameters except the compiled kernels,
which take flat arrays, and no options class over 15 fields (options are split by concern).

Both are checked on the source (AST), over the whole package.
"""

from __future__ import annotations

import ast
from pathlib import Path

import rftstatic

PACKAGE = Path(rftstatic.__file__).resolve().parent
MAX_PARAMETERS = 12
MAX_OPTION_FIELDS = 15


def _modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        yield path, ast.parse(path.read_text(encoding="utf-8"))


def _kernel_sources() -> set[Path]:
    """The modules whose functions numba compiles: those a ``_kernels_numba`` module imports from the package
    (it hands their functions to ``numba.njit``)."""
    out = set()
    for path, tree in _modules():
        if path.name != "_kernels_numba.py":
            continue
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("rftstatic"):
                for alias in node.names:
                    parts = (node.module.split(".")[1:] + [alias.name])
                    for candidate in (PACKAGE.joinpath(*parts).with_suffix(".py"),
                                      PACKAGE.joinpath(*parts[:-1]).with_suffix(".py")):
                        if candidate.is_file():
                            out.add(candidate)
    return out


def test_kernel_sources_are_found():
    sources = {p.relative_to(PACKAGE).as_posix() for p in _kernel_sources()}
    assert "element/kernels.py" in sources


def test_no_function_takes_more_than_twelve_parameters():
    exempt = _kernel_sources()
    offenders = []
    for path, tree in _modules():
        if path in exempt:
            continue
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                a = node.args
                names = [x.arg for x in (*a.posonlyargs, *a.args, *a.kwonlyargs) if x.arg not in ("self", "cls")]
                if len(names) > MAX_PARAMETERS:
                    offenders.append(f"{path.relative_to(PACKAGE)}:{node.lineno} {node.name} ({len(names)})")
    assert not offenders, "functions over 12 parameters (group them into an options object): " + ", ".join(offenders)


def test_no_options_class_has_more_than_fifteen_fields():
    offenders = []
    for path, tree in _modules():
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef) and node.name.endswith("Options"):
                fields = [s for s in node.body if isinstance(s, ast.AnnAssign)]
                if len(fields) > MAX_OPTION_FIELDS:
                    offenders.append(f"{path.relative_to(PACKAGE)}:{node.lineno} {node.name} ({len(fields)})")
    assert not offenders, "options classes over 15 fields (split them by concern): " + ", ".join(offenders)
