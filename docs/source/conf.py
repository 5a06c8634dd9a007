"""Sphinx configuration of the skyradar documentation (``make docs``).

The build is offline: no intersphinx inventories are fetched and no page loads anything from the
network at build time. The results page, the CLI reference, the scenario reference, the output
tables and the API reference are generated from the project itself by the directives in
``_ext/skyradar_docs.py``.
"""

import sys
from pathlib import Path

import skyradar

sys.path.insert(0, str(Path(__file__).resolve().parent / "_ext"))

project = "skyradar"
author = "the skyradar developers"
copyright = "2026, the skyradar developers"
release = version = skyradar.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "matplotlib.sphinxext.plot_directive",
    "skyradar_docs",
]
# The examples gallery: examples/*.py at the repository's root, run at every build (a script is run
# again only when it changed); its pages are generated into gallery/, which git ignores.
# Figures of the how-it-works pages, drawn by the library at every build; the code stays in the source.
plot_include_source = False
plot_html_show_source_link = False
plot_html_show_formats = False
plot_formats = [("png", 110)]
sphinx_gallery_conf = {
    "examples_dirs": "../../examples",
    "gallery_dirs": "gallery",
    "filename_pattern": r"plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "show_memory": False,
    "matplotlib_animations": False,
}
# No sphinx.ext.intersphinx: it would fetch other projects' inventories at build time.

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "gallery/*.ipynb", "gallery/*.py", "gallery/*.codeobj.json", "gallery/*.md5"]
templates_path: list[str] = []

# API reference: numpydoc docstrings, read leniently (no per-docstring validation).
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the numpydoc Parameters sections give the types
autodoc_default_options = {"show-inheritance": True}
autosummary_generate = False  # the module tables link to sections on the same page; no stub files
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()
numpydoc_xref_param_type = False

myst_heading_anchors = 3
highlight_language = "none"  # plain literal blocks are diagrams and YAML; code-block names its language
smartquotes = False  # keep ``--option`` and quotes as typed (command lines, help texts)

html_theme = "pydata_sphinx_theme"
html_title = f"skyradar {release}"
html_theme_options = {
    "header_links_before_dropdown": 7,
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "show_nav_level": 1,
    "navbar_end": ["theme-switcher"],
    "secondary_sidebar_items": {"**": ["page-toc"], "results": []},  # the results tables get the width
    "footer_start": ["copyright"],
    "footer_end": [],
}
# Pages without sub-pages need no section navigation: their tables get the width.
html_sidebars = {page: [] for page in ("index", "getting-started", "cli", "results", "changelog", "citing")}
html_static_path = ["_static"]
html_css_files = ["skyradar.css"]
html_show_sourcelink = False
html_copy_source = False
