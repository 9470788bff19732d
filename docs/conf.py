"""Sphinx configuration of the bayesgrasp documentation (built offline by ``make docs``)."""

from __future__ import annotations

from importlib.metadata import version as _version

project = "bayesgrasp"
author = "the bayesgrasp authors"
release = _version("bayesgrasp")
version = release

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
]

# Pages are Markdown (MyST) or reStructuredText.
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
exclude_patterns = ["_build", "tutorials/README.txt", "**.ipynb_checkpoints"]

# The tutorials are sphinx-gallery scripts under docs/tutorials/, run at build time; their
# pages (with the figures they draw) are written to docs/auto_tutorials/.
sphinx_gallery_conf = {
    "examples_dirs": "tutorials",
    "gallery_dirs": "auto_tutorials",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
}

html_theme = "furo"
html_title = "bayesgrasp"
html_static_path: list[str] = []

# No network at build time: no intersphinx, MathJax from the theme only where it is bundled.
numpydoc_show_class_members = False
autosummary_generate = True
