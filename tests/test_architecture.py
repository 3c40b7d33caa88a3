"""The package's import structure: layers import only downwards, and no modules import each other in a cycle.

Every module under simdiff/ is parsed with ``ast``; imports inside functions count (a lazy import is still a
dependency), imports under ``if TYPE_CHECKING:`` do not (they never run). The layer order and its reasons are in
docs/design-notes.md ("Package layers").
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "simdiff"

LAYERS: tuple[tuple[str, ...], ...] = (
    ("simdiff", "simdiff.errors", "simdiff.fsio", "simdiff.licences", "simdiff.limits", "simdiff.runinfo"),
    ("simdiff.motion",),
    ("simdiff.sim",),
    ("simdiff.text",),
    ("simdiff.model",),
    ("simdiff.diffusion",),
    ("simdiff.data",),
    ("simdiff.baselines",),
    ("simdiff.inference",),
    ("simdiff.viz",),
    ("simdiff.eval",),
    ("simdiff.train",),
    ("simdiff.product",),
    ("simdiff.serve",),
    ("simdiff.cli", "simdiff.__main__"),
)
"""Low to high: a module may import its own layer and the layers before it. ``simdiff`` alone (the root package,
``__version__``) sits with the other foundation modules; its subpackages are matched by their own entries."""


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


MODULES: dict[str, Path] = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def layer_of(module: str) -> int:
    """Index in :data:`LAYERS` of the longest entry that is ``module`` or a package above it."""
    best, best_len = -1, -1
    for index, entries in enumerate(LAYERS):
        for entry in entries:
            matches = module == entry or (entry != "simdiff" and module.startswith(entry + "."))
            if matches and len(entry) > best_len:
                best, best_len = index, len(entry)
    if best < 0:
        raise AssertionError(f"{module} is in no layer: add its package to LAYERS")
    return best


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    skipped: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If):
            test = node.test
            name = test.id if isinstance(test, ast.Name) else test.attr if isinstance(test, ast.Attribute) else ""
            if name == "TYPE_CHECKING":
                for child in node.body:
                    skipped.update(id(n) for n in ast.walk(child))
    return skipped


def _resolve(name: str) -> str | None:
    """The simdiff module file that an imported dotted name lives in (None: not a simdiff module)."""
    while name:
        if name in MODULES:
            return name
        name = name.rpartition(".")[0]
    return None


def imports_of(module: str) -> set[str]:
    """simdiff modules that ``module`` imports: ``from a import b`` names ``a.b`` when that is a module, else ``a``."""
    path = MODULES[module]
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    skipped = _type_checking_nodes(tree)
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    found: set[str] = set()
    for node in ast.walk(tree):
        if id(node) in skipped:
            continue
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            names = [f"{source}.{alias.name}" if f"{source}.{alias.name}" in MODULES else source
                     for alias in node.names]
        for name in names:
            if name == "simdiff" or name.startswith("simdiff."):
                target = _resolve(name)
                if target is not None and target != module:
                    found.add(target)
    return found


GRAPH: dict[str, set[str]] = {m: imports_of(m) for m in MODULES}


def test_every_module_is_in_a_layer() -> None:
    for module in MODULES:
        layer_of(module)


def test_no_module_imports_a_higher_layer() -> None:
    upward = sorted(f"{a} (layer {layer_of(a)}) imports {b} (layer {layer_of(b)})"
                    for a, targets in GRAPH.items() for b in targets if layer_of(b) > layer_of(a))
    assert not upward, "upward imports:\n" + "\n".join(upward)


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan), each as a sorted list."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_no_import_cycles() -> None:
    found = cycles(GRAPH)
    lines = []
    for component in found:
        members = set(component)
        lines.append(" <-> ".join(component) + ": " + "; ".join(
            f"{a} -> {b}" for a in component for b in sorted(GRAPH[a] & members)))
    assert not found, "import cycles:\n" + "\n".join(lines)


@pytest.mark.parametrize("source, expect", [
    ("from simdiff.motion import features\n", {"simdiff.motion.features"}),
    ("def f():\n    from simdiff.sim.env import Environment\n", {"simdiff.sim.env"}),
    ("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from simdiff.sim.env import Environment\n", set()),
])
def test_the_parser_sees_lazy_imports_and_skips_type_checking(source: str, expect: set[str], tmp_path: Path,
                                                              monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(MODULES, "simdiff.viz", tmp_path / "__init__.py")
    (tmp_path / "__init__.py").write_text(source)
    assert imports_of("simdiff.viz") == expect
