"""Sphinx configuration of posturelab's documentation site.

Build from the repository root with
``.venv/bin/python -m sphinx -W --keep-going -b html docs docs/_build/html``.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
os.environ.setdefault("MPLBACKEND", "Agg")

import posturelab  # noqa: E402

project = "posturelab"
author = "posturelab developers"
copyright = "posturelab developers, MIT licence"
version = release = posturelab.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "README-build.txt",
                    "auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip",
                    "auto_examples/*.md5", "auto_examples/*.json"]
html_static_path = ["_static"]

# ---- theme -------------------------------------------------------------------------
html_theme = "furo"
html_title = f"posturelab {release}"

# ---- API reference -------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "none"          # numpydoc sections carry the types and units
autodoc_inherit_docstrings = False
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

# ---- markdown (the existing pages in docs/) ------------------------------------------
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3
suppress_warnings = ["myst.header"]

# ---- gallery ---------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(HERE.parent / "examples"),
    "gallery_dirs": "auto_examples",
    # shown but not executed: the HTML report, the GIF and the two-minute coverage run
    "filename_pattern": r"/(?!(reproduce_paper|animate_fig09_fall|fit_coverage|frf_fit_coverage)\.py)[^/]+\.py$",
    "image_scrapers": ("pl_gallery.figure_scraper",),
    "reset_argv": "pl_gallery.reset_argv",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": False,
    "only_warn_on_example_error": False,
}


# ---- docstrings: |x| is an absolute value, not a reST substitution ---------------------
_INLINE_LITERAL = re.compile(r"(``.+?``)")


def _escape_bars(line: str) -> str:
    """Escape ``|`` outside inline literals, so that ``|θ_i|`` reads as an absolute value."""
    parts = _INLINE_LITERAL.split(line)
    return "".join(p if i % 2 else re.sub(r"(?<!\\)\|", r"\\|", p)
                   for i, p in enumerate(parts))


def escape_absolute_values(app, what, name, obj, options, lines):
    """autodoc-process-docstring: posturelab's docstrings write |x| for an absolute value
    and use no substitutions or grid tables; escape the bars outside literal blocks."""
    literal_indent = None
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if literal_indent is not None:
            if not stripped or indent > literal_indent:
                continue
            literal_indent = None
        if stripped.startswith((">>>", "...")):
            continue
        lines[i] = _escape_bars(line)
        if line.rstrip().endswith("::"):
            literal_indent = indent


def setup(app):
    app.connect("autodoc-process-docstring", escape_absolute_values, priority=600)
