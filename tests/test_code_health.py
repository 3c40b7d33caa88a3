"""Layout rules of the package: no test helper imported by production code, no oversized module."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "simdiff"
PRODUCTION = sorted(p for p in PACKAGE.rglob("*.py") if p.name != "testing.py")


def _imported_modules(path: Path) -> list[str]:
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            out += [node.module] + [f"{node.module}.{a.name}" for a in node.names]
    return out


@pytest.mark.parametrize("path", PRODUCTION, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_production_code_imports_no_test_helper(path: Path) -> None:
    bad = [m for m in _imported_modules(path) if m.split(".")[-1] == "testing" and m.startswith("simdiff")]
    assert not bad, f"{path.relative_to(PACKAGE)} imports {bad[0]}"


MAX_LINES: int = 500
"""No module in simdiff/ over this many lines: a longer module mixes jobs and is hard to review and test."""
MODULES = sorted(PACKAGE.rglob("*.py"))


def test_the_package_has_modules() -> None:
    assert len(MODULES) > 50 and PACKAGE / "motion" / "flight.py" in MODULES


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_module_is_at_most_500_lines(path: Path) -> None:
    lines = len(path.read_text(encoding="utf-8").splitlines())
    assert lines <= MAX_LINES, f"{path.relative_to(PACKAGE)} has {lines} lines (> {MAX_LINES}): split it"
