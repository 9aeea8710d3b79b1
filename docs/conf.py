"""Sphinx configuration of the ipmc_asym documentation (``python -m sphinx -W docs docs/_build/html``)."""

import os
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("MPLBACKEND", "Agg")

import ipmc_asym  # noqa: E402

project = "ipmc_asym"
author = "ipmc_asym developers"
release = version = ipmc_asym.__version__
copyright = "ipmc_asym developers, MIT licence"

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "sphinx.ext.mathjax",
    # MathJax copied into _static and loaded from there: equations render without a network
    "sphinx-mathjax-offline",
    "sphinx_gallery.gen_gallery",
    "myst_parser",
]
# docs/design.md is a page of its own (Markdown read by MyST), not a source listing
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
myst_heading_anchors = 3


def setup(app):
    # design.md's machine-readable blocks (```layers, ```studies: read by tests/integration/test_layers.py)
    # are plain text to the highlighter
    from pygments.lexers.special import TextLexer
    from sphinx.highlighting import lexers

    for name in ("layers", "studies"):
        lexers[name] = TextLexer()

exclude_patterns = ["_build", "**.ipynb_checkpoints", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.json", "sg_execution_times.rst"]
templates_path = []
html_static_path = ["_static"]
# furo: code blocks with a readable contrast that scroll rather than cut, a content column wide
# enough for the command tables
html_theme = "furo"
html_title = f"ipmc_asym {release}"

autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": False}
autodoc_typehints = "none"
# signatures as written in the source (``material=NAFION_LI``), not the expanded default object
autodoc_preserve_defaults = True
numpydoc_show_class_members = False
numpydoc_validation_checks = set()
numpydoc_xref_param_type = False
nitpicky = False

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples" / "gallery"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "download_all_examples": False,
    "write_computation_times": False,
    "within_subsection_order": "FileNameSortKey",
    "plot_gallery": "True",
}
