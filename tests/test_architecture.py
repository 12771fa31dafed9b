"""The import graph of gaitlib points only down (ARCHITECTURE.md).

The graph is read from the source text (every ``import`` statement, at module level or
inside a function), so nothing the interpreter would import lazily is hidden from it. Each
module belongs to one layer; a module may import its own layer or a lower one, never a
higher one, and the graph has no cycle. Imports inside functions are allowed only in the
command line (:mod:`gaitlib.cli`: numpy must not load before :func:`gaitlib.blas.pin`,
and ``gaitlib --help`` stays fast) and for optional heavy packages (matplotlib, dask).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "gaitlib"

#: Layers, lowest first: (name, modules or packages in it). Must match ARCHITECTURE.md.
LAYERS = (
    ("base", ("gaitlib", "gaitlib.conventions", "gaitlib.blas")),
    ("data", ("gaitlib.tidy", "gaitlib.plausibility", "gaitlib.data")),
    ("physics", ("gaitlib.model", "gaitlib.contact", "gaitlib.mtg", "gaitlib.activation", "gaitlib.metabolics",
                 "gaitlib.kinematics", "gaitlib.jump", "gaitlib.params")),
    ("engine", ("gaitlib.collocation", "gaitlib.compiled", "gaitlib.ocp", "gaitlib.cache", "gaitlib.sweep")),
    ("effects", ("gaitlib.effects",)),
    ("problems", ("gaitlib.problems",)),
    ("checks", ("gaitlib.validity", "gaitlib.marks", "gaitlib.plots")),
    ("gap", ("gaitlib.gap",)),
    ("studies", ("gaitlib.studies",)),
    ("cli", ("gaitlib.cli", "gaitlib.__main__")),
)

#: Modules that may import inside functions (see the module docstring).
LAZY_OK = ("gaitlib.cli",)


def _modules() -> dict[str, Path]:
    out = {}
    for p in sorted(SRC.rglob("*.py")):
        parts = ("gaitlib",) + p.relative_to(SRC).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = p
    return out


MODULES = _modules()


def layer_of(mod: str) -> int:
    best, depth = None, -1
    for i, (_, members) in enumerate(LAYERS):
        for m in members:
            if (mod == m or mod.startswith(m + ".")) and len(m) > depth:
                best, depth = i, len(m)
    if best is None:
        raise AssertionError(f"{mod} belongs to no layer: add it to LAYERS and ARCHITECTURE.md")
    return best


def _targets(mod: str, path: Path, node) -> list[str]:
    """gaitlib modules an import statement loads."""
    if isinstance(node, ast.Import):
        names = [a.name for a in node.names]
    else:
        if node.level:
            pkg = mod.split(".") if path.name == "__init__.py" else mod.split(".")[:-1]
            base = ".".join(pkg[:len(pkg) - node.level + 1])
            src = f"{base}.{node.module}" if node.module else base
        else:
            src = node.module or ""
        names = [src] + [f"{src}.{a.name}" for a in node.names]
    return [n for n in names if n in MODULES and n != mod]


def imports() -> list[tuple[str, str, int, bool]]:
    """(importer, imported, line, at module level) for every gaitlib-internal import."""
    out = []
    for mod, path in MODULES.items():
        tree = ast.parse(path.read_text(), filename=str(path))
        top = {id(n) for n in tree.body}
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for t in _targets(mod, path, node):
                    out.append((mod, t, node.lineno, id(node) in top))
    return out


def test_every_module_has_a_layer():
    for mod in MODULES:
        layer_of(mod)


def test_no_import_points_up():
    bad = [f"{a} ({LAYERS[layer_of(a)][0]}) imports {b} ({LAYERS[layer_of(b)][0]}) at line {line}"
           for a, b, line, _ in imports() if layer_of(b) > layer_of(a)]
    assert not bad, "upward imports:\n" + "\n".join(bad)


def test_no_cycle():
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for a, b, _, _ in imports():
        graph[a].add(b)
    # a package's __init__ importing its own submodules is how packages work, not a cycle
    for a in graph:
        graph[a] = {b for b in graph[a] if not (b.startswith(a + ".") and MODULES[a].name == "__init__.py")}
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m):
        state[m] = 1
        stack.append(m)
        for n in sorted(graph[m]):
            if state.get(n) == 1:
                cycle = stack[stack.index(n):] + [n]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if n not in state:
                visit(n)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)


def test_imports_at_module_level():
    bad = [f"{a}:{line} imports {b} inside a function" for a, b, line, top in imports()
           if not top and not any(a == p or a.startswith(p + ".") for p in LAZY_OK)]
    assert not bad, f"{len(bad)} imports hidden in functions:\n" + "\n".join(bad)


def test_architecture_page_names_every_layer():
    page = (SRC.parents[1] / "ARCHITECTURE.md").read_text()
    for name, members in LAYERS:
        assert f"**{name}**" in page, f"ARCHITECTURE.md does not describe the {name} layer"
        for m in members:
            short = m.removeprefix("gaitlib.") if m != "gaitlib" else "gaitlib"
            assert f"`{short}`" in page, f"ARCHITECTURE.md does not place `{short}` ({name})"
