"""Sphinx configuration of the spine_mj site (``make docs``).

Pages written from the data before Sphinx reads anything (``docs/tools``): the API
reference's package pages (every name in each package's ``__all__``), the results pages
(from the committed ``analysis/reports/``) and the command-line reference (from the click
commands' help). The gallery's scripts in ``examples/`` run at every build.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "tools"))

import generate  # noqa: E402  (docs/tools/generate.py)

import spine_mj  # noqa: E402

generate.write_all(HERE)

project = "spine_mj"
author = "spine_mj developers"
copyright = "spine_mj developers, MIT licence"
release = spine_mj.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "tools", "**/README.md", "gallery/*.ipynb", "gallery/*.py"]
templates_path = ["_templates"]

# Markdown pages: $...$ and $$...$$ maths, ``{toctree}`` fences, heading anchors for links
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# API reference: one page per public name, written by autosummary from the package pages
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": False}
autodoc_typehints = "none"
add_module_names = False

# numpydoc renders the docstrings. Their validation (every parameter documented, ...) is a
# test of `make test` (tests/docs/test_docs_docstrings.py, docs/tools/docstrings.py), so that
# whoever adds a public name sees it before landing, not only when the site is built.
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()


sphinx_gallery_conf = {
    "examples_dirs": str(HERE.parent / "examples"),
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "download_all_examples": True,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "show_memory": False,
    "min_reported_time": 1,
    "abort_on_example_error": True,
}

html_theme = "pydata_sphinx_theme"
html_title = "spine_mj"
html_static_path = []
html_theme_options = {
    "navigation_depth": 2,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": [],
    "navbar_align": "left",
}
html_show_sourcelink = False
html_sidebars = {"index": [], "changelog": []}

# Cross-references in docstrings to private modules stay plain text; every link of the
# built pages is checked by tests/test_docs.py (internal links and anchors resolve).
nitpicky = False
suppress_warnings = ["myst.header"]
