"""Sphinx configuration of the bayesgrasp documentation (built offline by ``make docs``).

Nothing is fetched at build time: no intersphinx, no CDN. Mathematics is converted to MathML
(which browsers render natively) by the local extension ``docs/_ext/bayesgrasp_docs.py``,
which also generates the command-line reference from the typer app and runs the commands
whose output the reference shows.
"""

from __future__ import annotations

import sys
from importlib.metadata import version as _version
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent / "_ext"))

project = "bayesgrasp"
author = "the bayesgrasp authors"
copyright = "the bayesgrasp authors"
release = _version("bayesgrasp")
version = release

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx_gallery.gen_gallery",
    "bayesgrasp_docs",
]

# Pages are Markdown (MyST) or reStructuredText.
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
exclude_patterns = [
    "_build",
    "screenshots",
    "tutorials/README.txt",
    "tutorials/GALLERY_HEADER.rst",
    "**.ipynb_checkpoints",
]

# The tutorials are sphinx-gallery scripts under docs/tutorials/, run at build time; their
# pages (with the figures they draw) are written to docs/auto_tutorials/.
sphinx_gallery_conf = {
    "examples_dirs": "tutorials",
    "gallery_dirs": "auto_tutorials",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "write_computation_times": False,  # its page loads jQuery and DataTables from CDNs
    "show_signature": False,
    "min_reported_time": 10**9,  # no timing lines: they would change with every build
}

html_theme = "furo"
html_title = f"bayesgrasp {release}"
html_static_path = ["_static"]
templates_path = ["_templates"]
html_css_files = ["bayesgrasp.css"]
# Mathematics as MathML, converted at build time (no MathJax from a CDN).
html_math_renderer = "mathml"
html_last_updated_fmt = None
html_show_sourcelink = False
html_copy_source = False

# The API reference: autosummary pages of the public names, numpydoc sections.
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options: dict[str, bool] = {}
autodoc_typehints = "none"  # numpydoc's Parameters sections say the types
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# A transcript's output is not always valid for its lexer (a quote in a part's name, "..."
# standing for lines left out): it is shown unhighlighted, which is not worth a warning.
suppress_warnings = ["misc.highlighting_failure"]
