"""Sphinx configuration of the rftstatic documentation (``python -m sphinx -W -b html docs docs/_build/html``).

The reference pages (scene keys, command line), the examples' printed output and the validation reports are
written into ``_generated/`` at build time by the local extension ``_ext/rftstatic_docs.py``.
"""

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))
sys.path.insert(0, str(DOCS.parent))  # the checkout's package, whatever is installed

project = "rftstatic"
author = "the rftstatic developers"
copyright = "2026, the rftstatic developers"  # noqa: A001 (Sphinx's name)

extensions = ["myst_parser", "rftstatic_docs"]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "examples/*.py", "Thumbs.db", ".DS_Store"]
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3
suppress_warnings = ["myst.header"]  # the validation reports start at a level-2 heading under their title

html_theme = "alabaster"
html_title = "rftstatic"
html_static_path = []
html_theme_options = {"page_width": "1240px", "sidebar_width": "240px"}  # room for the reference tables and code
