"""The project's rule: no function takes more than 12 parameters (positional and keyword-only, ``self`` and
``cls``, ``*args`` and ``**kwargs`` not counted; a ``**kwargs`` pass-through does not get a function under it).
Related parameters are grouped into a small frozen options dataclass instead
(:class:`rftstatic.study.runner.Execution`).

Checked in the packages that keep it; the solvers, the remeshing drivers, the self-contact grid and the
compiled kernels are still being grouped (issue 33) and join :data:`KEPT` when they do.
"""

from __future__ import annotations

import ast
from pathlib import Path

import rftstatic

PACKAGE = Path(rftstatic.__file__).resolve().parent
MAX_PARAMETERS = 12
KEPT = ("study", "scenes", "mesh", "contact/obstacles", "io", "post")
"""Folders of the package whose every function keeps to :data:`MAX_PARAMETERS`."""
EXCEPT = ("scenes/options.py",)
"""Modules of those folders left to the ``[solver]`` options' own refactoring."""


def parameters(node: ast.FunctionDef | ast.AsyncFunctionDef) -> list[str]:
    """The named parameters of a function, without ``self`` and ``cls``."""
    a = node.args
    return [p.arg for p in (*a.posonlyargs, *a.args, *a.kwonlyargs) if p.arg not in ("self", "cls")]


def test_parameters_counts_positional_and_keyword_only_but_not_star_args():
    tree = ast.parse("def f(self, a, /, b, *args, c, d=1, **kwargs): pass")
    assert parameters(tree.body[0]) == ["a", "b", "c", "d"]


def test_no_function_over_12_parameters():
    many = {}
    for folder in KEPT:
        for path in sorted((PACKAGE / folder).rglob("*.py")):
            if str(path.relative_to(PACKAGE)) in EXCEPT:
                continue
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and len(parameters(node)) > MAX_PARAMETERS:
                    many[f"{path.relative_to(PACKAGE)}:{node.name}"] = len(parameters(node))
    assert not many, f"functions over {MAX_PARAMETERS} parameters (group them into an options dataclass): {many}"
