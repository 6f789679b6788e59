"""The package's architecture, checked on its import graph (grimp: function-level imports included).

- the layers contract of ``setup.cfg`` (import-linter, no ignored imports): a module imports only from
  its own layer and the layers below;
- no import cycle between modules;
- at most a dozen modules at the package root, no module over 500 lines, no function over 150 lines.
"""

from __future__ import annotations

import ast
import configparser
from pathlib import Path

import rftstatic

PACKAGE = Path(rftstatic.__file__).resolve().parent
SETUP_CFG = PACKAGE.parent / "setup.cfg"


def _graph():
    import grimp

    return grimp.build_graph("rftstatic", cache_dir=None)


def test_layers_contract_is_kept():
    from importlinter import configuration
    from importlinter.application.use_cases import lint_imports

    configuration.configure()

    cfg = configparser.ConfigParser()
    cfg.read(SETUP_CFG)
    contract = cfg["importlinter:contract:layers"]
    assert "ignore_imports" not in contract, "the layers contract must not ignore imports"
    assert contract.get("exhaustive", "").strip() == "true"
    assert lint_imports(config_filename=str(SETUP_CFG), cache_dir=None), \
        "import-linter: a layer imports from a layer above it (run `lint-imports` for the chain)"


def _cycles(graph) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan, iterative)."""
    index, low, on_stack, stack, out = {}, {}, set(), [], []
    counter = 0
    for root in sorted(graph.modules):
        if root in index:
            continue
        work = [(root, iter(sorted(graph.find_modules_directly_imported_by(root))))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            for w in children:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph.find_modules_directly_imported_by(w)))))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return out


def test_no_import_cycles():
    graph = _graph()
    # a package's __init__ importing its own children is not a cycle of the design; leave it out
    for m in list(graph.modules):
        for child in graph.find_children(m):
            if graph.direct_import_exists(importer=m, imported=child):
                graph.remove_import(importer=m, imported=child)
    cycles = _cycles(graph)
    assert not cycles, f"import cycles: {cycles}"


def _modules():
    return sorted(p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts)


def test_package_root_is_small():
    root = [p.name for p in PACKAGE.glob("*.py")]
    assert len(root) <= 12, f"{len(root)} modules at the package root: {sorted(root)}"


def test_no_module_over_500_lines():
    long = {str(p.relative_to(PACKAGE)): n for p in _modules() if (n := len(p.read_text().splitlines())) > 500}
    assert not long, f"modules over 500 lines: {long}"


def test_no_function_over_150_lines():
    long = {}
    for p in _modules():
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > 150:
                    long[f"{p.relative_to(PACKAGE)}:{node.name}"] = n
    assert not long, f"functions over 150 lines: {long}"
