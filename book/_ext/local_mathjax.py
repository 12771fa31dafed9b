"""Sphinx extension: the book's MathJax comes from the installed Python package, not a CDN.

The pinned PyPI package ``django-static-mathjax`` (see requirements.txt) ships the MathJax 3
browser build (``mathjax/static/mathjax/es5``). After an HTML build this extension copies that
directory to ``_build/html/_static/mathjax/``; ``mathjax_path`` in ``_config.yml`` names a file
in it (relative to ``_static``), so every page loads MathJax, its fonts and its extensions from
the build itself and reads offline. A remote or missing ``mathjax_path`` stops the build.
"""
import re
import shutil
from importlib.util import find_spec
from pathlib import Path

from sphinx.errors import ConfigError

STATIC_SUBDIR = "mathjax"  # _static/<this>/ holds the copy


def mathjax_es5_dir() -> Path:
    """The installed MathJax browser build (directory with ``tex-mml-chtml.js``)."""
    spec = find_spec("mathjax")
    locations = list(spec.submodule_search_locations or []) if spec else []
    for loc in locations:
        es5 = Path(loc) / "static" / "mathjax" / "es5"
        if (es5 / "startup.js").is_file():
            return es5
    raise ConfigError("MathJax is not installed: the book needs the PyPI package "
                      "django-static-mathjax pinned in requirements.txt (run `make venv`)")


def _check(app, config):
    path = config.mathjax_path
    if re.match(r"^\s*([a-z][a-z0-9+.-]*:)?//", path, re.I):
        raise ConfigError(f"_config.yml: sphinx.config.mathjax_path = {path!r} is a remote URL; "
                          f"expected a file under {STATIC_SUBDIR}/ (the local MathJax copy)")
    head, _, rest = path.partition("/")
    if head != STATIC_SUBDIR or not (mathjax_es5_dir() / rest).is_file():
        raise ConfigError(f"_config.yml: sphinx.config.mathjax_path = {path!r}; expected "
                          f"{STATIC_SUBDIR}/<file of {mathjax_es5_dir()}>, e.g. "
                          f"{STATIC_SUBDIR}/tex-mml-chtml.js")


def _copy(app, exception):
    if exception is None and app.builder.format == "html":
        shutil.copytree(mathjax_es5_dir(), Path(app.outdir) / "_static" / STATIC_SUBDIR,
                        dirs_exist_ok=True)


def setup(app):
    app.connect("config-inited", _check)
    app.connect("build-finished", _copy)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
