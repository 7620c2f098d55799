"""The package's prose: docstrings say what a user needs, once; history lives in ``docs/``.

Docstring lines are counted as Python sees them: a module's, class's or function's first statement
when it is a string, and a string right after an assignment (an attribute's docstring).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

import lerobot_mtdagger

PACKAGE_ROOT = Path(lerobot_mtdagger.__file__).parent

MAX_DOCSTRING_SHARE = 0.20
"""Docstring lines over all lines of the package (LeRobot 0.4.4: 15%)."""

MAX_MODULE_DOCSTRING_LINES = 25
"""A module's docstring says what the module is for and how to use it; details go to ``docs/``."""

HISTORY = re.compile(r"\b20\d\d-\d\d-\d\d\b|experiments/[\w-]+-(?:dev|eval)\b")
"""Dates and study folders: a product docstring names neither (``docs/changes.md``, ``docs/results.md``)."""

DATED_MODULES = {"datasets/migrations.py"}
"""The rules about older runs: each says when the option it migrates changed."""


def _docstrings(tree: ast.Module) -> list[ast.Expr]:
    """Every docstring statement of a module: first string statements, and strings after assignments."""
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for position, statement in enumerate(node.body):
            is_string = isinstance(statement, ast.Expr) and isinstance(statement.value, ast.Constant)
            if not (is_string and isinstance(statement.value.value, str)):
                continue
            previous = node.body[position - 1] if position else None
            if position == 0 or isinstance(previous, (ast.Assign, ast.AnnAssign)):
                found.append(statement)
    return found


def _lines(statement: ast.stmt) -> int:
    return (statement.end_lineno or statement.lineno) - statement.lineno + 1


def _modules() -> list[Path]:
    return sorted(PACKAGE_ROOT.rglob("*.py"))


def test_docstrings_are_at_most_a_fifth_of_the_package():
    total = documented = 0
    for path in _modules():
        text = path.read_text()
        total += len(text.splitlines())
        documented += sum(_lines(statement) for statement in _docstrings(ast.parse(text)))
    share = documented / total
    assert share <= MAX_DOCSTRING_SHARE, f"docstrings are {share:.1%} of {total} lines"


@pytest.mark.parametrize("path", _modules(), ids=lambda path: str(path.relative_to(PACKAGE_ROOT)))
def test_a_module_docstring_is_short_and_names_no_date_or_study(path):
    tree = ast.parse(path.read_text())
    module_docstring = ast.get_docstring(tree, clean=False)
    if module_docstring is not None:
        lines = _lines(tree.body[0])
        assert lines <= MAX_MODULE_DOCSTRING_LINES, f"{lines} lines: move the details to docs/"
    if str(path.relative_to(PACKAGE_ROOT)) in DATED_MODULES:
        return
    for statement in _docstrings(tree):
        found = HISTORY.search(statement.value.value)  # type: ignore[attr-defined]
        assert found is None, f"line {statement.lineno} names {found.group()}: say it in docs/ instead"
