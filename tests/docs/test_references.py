"""Every dotted name ``rftstatic.x.y`` that the documentation, the README or the package's own docstrings and
comments mention resolves: to a module, or to an attribute of one (importlib), so no page or docstring points
at a module that moved."""

from __future__ import annotations

import importlib
import inspect
import io
import re
import tokenize
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOTTED = re.compile(r"(?<![\w/.\-])rftstatic(?:\.[A-Za-z_]\w*)+")
CITED_FILE = re.compile(r"(?<![\w/.\-])((?:[\w\-]+/)*[\w\-]+\.md)\b")
PLACEHOLDERS = ("NAME", "DIR")  # ``validate`` writes NAME.md into DIR


def _prose(path: Path) -> str:
    """The docstrings (every string literal) and comments of a Python file, or a text file's whole text."""
    text = path.read_text(encoding="utf-8")
    if path.suffix != ".py":
        return text
    parts = []
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type in (tokenize.STRING, tokenize.COMMENT):
            parts.append(tok.string)
        elif getattr(tokenize, "FSTRING_MIDDLE", None) == tok.type:
            parts.append(tok.string)
    return "\n".join(parts)


def _sources() -> list[Path]:
    files = [ROOT / "README.md", ROOT / "DEVELOPERS.md"]
    docs = ROOT / "docs"
    if docs.is_dir():
        files += sorted(p for p in docs.rglob("*") if p.suffix in (".md", ".py", ".rst")
                        and "_build" not in p.parts and "_generated" not in p.parts)
    files += sorted((ROOT / "rftstatic").rglob("*.py"))
    return [p for p in files if p.is_file()]


@cache
def resolves(name: str) -> bool:
    """True when ``name`` is an importable module, or an attribute chain on the longest importable prefix."""
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            if hasattr(obj, attr):
                obj = getattr(obj, attr)
            elif inspect.isclass(obj) and _instance_attribute(obj, attr):
                return True  # an attribute of the class's instances: nothing further to resolve
            else:
                return False
        return True
    return False


def _instance_attribute(cls: type, attr: str) -> bool:
    """``attr`` is a dataclass field, an annotated attribute or set as ``self.attr`` by ``cls`` or a base."""
    for klass in cls.__mro__:
        if attr in getattr(klass, "__dataclass_fields__", {}) or attr in vars(klass).get("__annotations__", {}):
            return True
        try:
            if re.search(rf"\bself\.{re.escape(attr)}\s*=", inspect.getsource(klass)):
                return True
        except (OSError, TypeError):
            continue
    return False


def stale_references() -> dict[str, list[str]]:
    """``{dotted name: [files naming it]}`` for every name that does not resolve."""
    stale: dict[str, list[str]] = {}
    for path in _sources():
        for name in sorted(set(DOTTED.findall(_prose(path)))):
            if not resolves(name):
                stale.setdefault(name, []).append(str(path.relative_to(ROOT)))
    return stale


def test_the_scanner_finds_and_checks_names():
    assert DOTTED.findall("see rftstatic.solvers.loop.newton_loop, not ~/.config/rftstatic.yaml.") == [
        "rftstatic.solvers.loop.newton_loop"]
    assert resolves("rftstatic.solvers.loop.newton_loop")
    assert resolves("rftstatic.contact.obstacles")
    assert not resolves("rftstatic.solvers.no_such_module")
    assert not resolves("rftstatic.optionspec.no_such_name")
    assert resolves("rftstatic.model.state.State.contact_history")  # a dataclass field
    assert not resolves("rftstatic.model.state.State.no_such_field")


def test_every_dotted_reference_resolves():
    stale = stale_references()
    assert not stale, "stale dotted references:\n" + "\n".join(f"  {k}: {', '.join(v)}" for k, v in stale.items())


def missing_citations() -> dict[str, list[str]]:
    """``{file name: [files citing it]}`` for every ``*.md`` file that a page or the package's prose names and that
    the repository does not have (looked up from the repository root, ``validation/``, ``docs/`` and the citing
    file's folder)."""
    missing: dict[str, list[str]] = {}
    for path in _sources():
        for name in sorted(set(CITED_FILE.findall(_prose(path)))):
            if re.split(r"[/.]", name)[0] in PLACEHOLDERS or path.parent.name == "_ext":
                continue  # a placeholder, or a page the docs extension writes at build time
            places = (ROOT, ROOT / "validation", ROOT / "docs", path.parent, path.parent / "data")
            if not any((base / name).exists() for base in places):
                missing.setdefault(name, []).append(str(path.relative_to(ROOT)))
    return missing


def test_no_citation_of_a_file_the_repository_does_not_have():
    missing = missing_citations()
    assert not missing, "cited but missing:\n" + "\n".join(f"  {k}: {', '.join(v)}" for k, v in missing.items())


if __name__ == "__main__":  # pragma: no cover
    for k, v in {**stale_references(), **missing_citations()}.items():
        print(k, v)
