"""The built book loads nothing from the internet: MathJax, styles and fonts are local.

A one-page book with the project's own _config.yml, extensions and static files is built
(no notebook, so nothing executes) and its HTML and CSS are scanned; the full build in
book/_build/html is scanned too when it exists. The browser check (tools/check_book.py,
`make check-book`) goes further and renders every page offline.
"""
from __future__ import annotations

import importlib.util
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from sphinx.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]
BOOK = ROOT / "book"


def _load(name, path):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


check_book = _load("check_book", ROOT / "tools" / "check_book.py")
local_mathjax = _load("local_mathjax", BOOK / "_ext" / "local_mathjax.py")

PAGE = r"""# Offline page

The misfit $z_j = (\mathrm{sim}_j - \mathrm{mean}_j) / \mathrm{SD}^*_j$ and a display equation

$$
E = \int_0^T \dot E \, \mathrm{d}t
$$

| channel | z |
|---|---|
| hip | 1.2 |

```python
print("code")
```
"""


@pytest.fixture(scope="module")
def tiny_book(tmp_path_factory):
    src = tmp_path_factory.mktemp("book")
    shutil.copy(BOOK / "_config.yml", src)
    for d in ("_ext", "_static"):
        shutil.copytree(BOOK / d, src / d)
    (src / "_toc.yml").write_text("format: jb-book\nroot: intro\n")
    (src / "intro.md").write_text(PAGE)
    jb = Path(sys.executable).with_name("jupyter-book")
    r = subprocess.run([str(jb), "build", str(src), "-W", "-n", "--keep-going"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return src / "_build" / "html"


def test_book_config_loads_nothing_remote(tiny_book):
    assert check_book.remote_references(tiny_book) == []
    page = (tiny_book / "intro.html").read_text()
    # MathJax is the local copy, with its fonts; no Thebe (live cells through a CDN)
    assert '<script defer="defer" src="_static/mathjax/tex-mml-chtml.js">' in page
    mj = tiny_book / "_static" / "mathjax"
    assert (mj / "tex-mml-chtml.js").is_file()
    assert (mj / "output" / "chtml" / "fonts" / "woff-v2" / "MathJax_Main-Regular.woff").is_file()
    assert "thebe" not in page.lower()
    assert "wide-content.css" in page


def test_built_book_loads_nothing_remote():
    html = BOOK / "_build" / "html"
    if not (html / "intro.html").is_file():
        pytest.skip("book not built (make book)")
    found = check_book.remote_references(html)
    assert found == [], (f"{html} references remote assets (a build from before the offline "
                         f"configuration? rebuild with make book): {found[:5]}")


def test_scanner_finds_every_kind_of_remote_asset(tmp_path):
    (tmp_path / "p.html").write_text("""<html><head>
<script src="https://cdn.example/mathjax.js"></script>
<script src="_static/local.js"></script>
<link rel="stylesheet" href="//fonts.example/css?family=X">
<link rel="preload" as="font" href="http://fonts.example/x.woff2">
<link rel="stylesheet" href="_static/local.css">
<link rel="next" href="https://example.org/next.html">
<style>@import url("https://cdn.example/a.css"); p { background: url(_images/ok.png) }</style>
<script>const THEBE_JS_URL = "https://unpkg.example/thebe@0.8.2/lib/index.js";</script>
</head><body>
<img src="https://img.example/fig.png"><img src="_images/fig.png">
<a href="https://doi.org/10.1000/x">a reference is a link, not an asset</a>
<div style="background-image: url('//img.example/bg.png')"></div>
</body></html>""")
    (tmp_path / "s.css").write_text("""/* url(https://commented.example/out.woff) */
@import 'https://cdn.example/b.css';
@font-face { src: url(https://fonts.example/f.woff2) format("woff2"), url(fonts/f.woff); }""")
    found = check_book.remote_references(tmp_path)
    assert found == [
        "p.html: <script src=https://cdn.example/mathjax.js>",
        "p.html: <link rel=stylesheet href=//fonts.example/css?family=X>",
        "p.html: <link rel=preload href=http://fonts.example/x.woff2>",
        'p.html: <style> url(https://cdn.example/a.css)',
        "p.html: <script> loads https://unpkg.example/thebe@0.8.2/lib/index.js",
        "p.html: <img src=https://img.example/fig.png>",
        "p.html: style url(//img.example/bg.png)",
        "s.css: url(https://cdn.example/b.css)",
        "s.css: url(https://fonts.example/f.woff2)",
    ]


def test_mathjax_path_must_name_the_local_copy():
    class Cfg:
        mathjax_path = "mathjax/tex-mml-chtml.js"

    local_mathjax._check(None, Cfg)  # the book's setting
    for bad in ("https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-mml-chtml.js",
                "//cdn.example/tex-mml-chtml.js", "mathjax/no-such-file.js", "tex-mml-chtml.js"):
        Cfg.mathjax_path = bad
        with pytest.raises(ConfigError, match="mathjax_path"):
            local_mathjax._check(None, Cfg)
