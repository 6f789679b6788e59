"""What the documentation pages show is true today: every complete scene in a ```toml block of the README or
``docs/`` (one with a ``title``) is a valid scene whose model builds, and every page the README and the docs link to exists."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


def _toml_scenes():
    for page in [ROOT / "README.md", *sorted(DOCS.rglob("*.md"))]:
        if "_build" in page.parts or "_generated" in page.parts:
            continue
        for i, block in enumerate(re.findall(r"```toml\n(.*?)```", page.read_text(encoding="utf-8"), re.S)):
            if re.search(r"^title\s*=", block, re.M):
                yield pytest.param(block, id=f"{page.relative_to(ROOT)}#{i}")


@pytest.mark.parametrize("block", list(_toml_scenes()))
def test_documented_scene_is_valid(block):
    from rftstatic import api

    scene = api.scene_from_dict(tomllib.loads(block), name="docs-scene")
    model, _extras = api.build_model(scene)
    assert model.mesh.X.shape[0] > 0


def test_readme_links_resolve():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    for target in re.findall(r"\]\(([^)#\s]+)", text):
        if "://" in target:
            continue
        assert (ROOT / target).exists(), f"README links to {target}, which the repository does not have"


def test_readme_is_short():
    assert len((ROOT / "README.md").read_text(encoding="utf-8").splitlines()) <= 200


def _obstacle_fragments():
    for page in sorted(DOCS.rglob("*.md")):
        if "_build" in page.parts or "_generated" in page.parts:
            continue
        for i, block in enumerate(re.findall(r"```toml\n(.*?)```", page.read_text(encoding="utf-8"), re.S)):
            if "[[obstacles]]" in block and not re.search(r"^title\s*=", block, re.M):
                yield pytest.param(block, id=f"{page.relative_to(ROOT)}#{i}")


@pytest.mark.parametrize("block", list(_obstacle_fragments()))
def test_documented_obstacles_build(block):
    """An ``[[obstacles]]`` fragment of a page, put in place of pedestal-square-20's obstacle, builds."""
    from rftstatic import api

    data = api.load_scene("pedestal-square-20").data
    data.pop("obstacles")
    data.update(tomllib.loads(block))
    _model, extras = api.build_model(api.scene_from_dict(data, name="docs-obstacles"))
    assert len(extras["obstacles"]) == len(tomllib.loads(block)["obstacles"])


def test_the_package_never_imports_the_docs_tools():
    import subprocess
    import sys

    code = ("import sys, rftstatic, rftstatic.api, rftstatic.cli; "
            "bad = sorted(m for m in sys.modules if m.split('.')[0] in ('sphinx', 'myst_parser', 'docutils')); "
            "assert not bad, bad")
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=False,
                          env={**__import__("os").environ, "PYTHONPATH": str(ROOT)})
    assert proc.returncode == 0, proc.stderr


def test_files_named_by_the_pages_exist():
    """A repository path a page or the README names (``tests/...py``, ``cases/...toml``, ``validation/...md``, ...)
    exists."""
    pattern = re.compile(r"(?<![\w/.\-])((?:tests|tools|cases|validation|docs|rftstatic)/[\w/.\-]*\.(?:py|toml|md|png))")
    pages = [ROOT / "README.md", ROOT / "DEVELOPERS.md",
             *(p for p in DOCS.rglob("*.md") if "_build" not in p.parts and "_generated" not in p.parts)]
    missing = sorted({(name, str(page.relative_to(ROOT))) for page in pages
                      for name in pattern.findall(page.read_text(encoding="utf-8"))
                      if "NAME" not in name and not (ROOT / name).exists()})  # NAME: a placeholder
    assert not missing, missing
