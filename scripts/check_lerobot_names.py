"""Checks that every LeRobot name the package imports exists in a given LeRobot source tree or wheel.

Usage::

    .venv/bin/python scripts/check_lerobot_names.py .venv/lib/python3.11/site-packages   # installed
    .venv/bin/python scripts/check_lerobot_names.py lerobot-0.6.1-py3-none-any.whl       # a wheel

Every ``from lerobot.X import a`` in ``lerobot_mtdagger/`` (module and function level) is looked up by
reading the sources (nothing of LeRobot is imported, so a wheel for another Python can be checked):
``lerobot/X.py`` or ``lerobot/X/__init__.py`` must define or import ``a`` at module level. Imports in
a ``try`` whose handler catches ``ImportError`` are alternatives (``lerobot_compat``): a name passes
when one of its spellings exists. Prints one line per import and exits 1 when one is missing.
"""

from __future__ import annotations

import argparse
import ast
import re
import sys
import tempfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "lerobot_mtdagger"
IMPORT_ERRORS = {"ImportError", "ModuleNotFoundError"}


@dataclass
class Wanted:
    """One imported LeRobot name and its alternative spellings ``(module, name)``."""

    where: str
    spellings: list[tuple[str, str]] = field(default_factory=list)


def wanted_names(package: Path) -> list[Wanted]:
    """Every LeRobot name the package's modules import, with alternatives grouped."""
    wanted: list[Wanted] = []
    for path in sorted(package.rglob("*.py")):
        tree = ast.parse(path.read_text(), filename=str(path))
        grouped: set[int] = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.Try) and _catches_import_error(node):
                wanted += _alternatives(node, path, grouped)
        for node in ast.walk(tree):
            if _is_lerobot_import(node) and id(node) not in grouped:
                for alias in node.names:
                    wanted.append(
                        Wanted(
                            f"{path.relative_to(package.parent)}:{node.lineno}", [(node.module, alias.name)]
                        )
                    )
    return wanted


def _catches_import_error(node: ast.Try) -> bool:
    for handler in node.handlers:
        names = handler.type.elts if isinstance(handler.type, ast.Tuple) else [handler.type]
        if any(isinstance(n, ast.Name) and n.id in IMPORT_ERRORS for n in names):
            return True
    return False


def _alternatives(node: ast.Try, path: Path, grouped: set[int]) -> list[Wanted]:
    """The names a try/except-ImportError block imports, each with every spelling it tries."""
    by_name: dict[str, Wanted] = {}
    branches = [node.body, *(handler.body for handler in node.handlers)]
    for branch in branches:
        for statement in branch:
            if not _is_lerobot_import(statement):
                continue
            grouped.add(id(statement))
            for alias in statement.names:
                bound = alias.asname or alias.name
                entry = by_name.setdefault(
                    bound, Wanted(f"{path.relative_to(PACKAGE.parent)}:{statement.lineno}")
                )
                entry.spellings.append((statement.module, alias.name))
    return list(by_name.values())


def _is_lerobot_import(node: ast.AST) -> bool:
    return (
        isinstance(node, ast.ImportFrom)
        and node.level == 0
        and (node.module or "").split(".")[0] == "lerobot"
    )


def module_names(root: Path, module: str) -> set[str] | None:
    """Names defined or imported at module level by ``module`` under ``root`` (None: no such module)."""
    base = root.joinpath(*module.split("."))
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.is_file():
            names = _top_level_names(_parse(path))
            if path.name == "__init__.py":
                names |= {child.stem for child in base.iterdir() if child.suffix == ".py" or child.is_dir()}
            return names
    if base.is_dir():  # a namespace package (LeRobot 0.4's datasets/): its modules only
        return {child.stem for child in base.iterdir() if child.suffix == ".py" or child.is_dir()}
    return None


def _parse(path: Path) -> ast.Module:
    """Parses a module; Python 3.12 type-parameter syntax (LeRobot 0.5+) is rewritten for older parsers.

    ``class C[T](Base):`` and ``def f[T](x):`` lose their type parameters and ``type A = ...`` becomes an
    assignment, which leaves every module-level name as it is.
    """
    source = path.read_text()
    try:
        return ast.parse(source, filename=str(path))
    except SyntaxError:
        source = re.sub(r"^(\s*(?:async\s+)?(?:class|def)\s+\w+)\[[^\]]*\]", r"\1", source, flags=re.M)
        source = re.sub(r"^(\s*)type\s+(\w+)(?:\[[^\]]*\])?\s*=", r"\1\2 =", source, flags=re.M)
        return ast.parse(source, filename=str(path))


def _top_level_names(tree: ast.Module) -> set[str]:
    names: set[str] = set()
    for node in _module_level(tree.body):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names |= {(alias.asname or alias.name).split(".")[0] for alias in node.names}
        elif isinstance(node, ast.Assign):
            names |= {target.id for target in node.targets if isinstance(target, ast.Name)}
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return names


def _module_level(body: list[ast.stmt]) -> list[ast.stmt]:
    """Statements at module level, including those inside module-level if/try blocks."""
    statements: list[ast.stmt] = []
    for node in body:
        statements.append(node)
        if isinstance(node, ast.If):
            statements += _module_level(node.body) + _module_level(node.orelse)
        elif isinstance(node, ast.Try):
            statements += _module_level(node.body)
            for handler in node.handlers:
                statements += _module_level(handler.body)
            statements += _module_level(node.orelse) + _module_level(node.finalbody)
    return statements


def check(root: Path) -> int:
    """Prints every import's verdict against the LeRobot sources under ``root``; the number missing."""
    missing = 0
    cache: dict[str, set[str] | None] = {}
    for entry in wanted_names(PACKAGE):
        found = []
        for module, name in entry.spellings:
            if module not in cache:
                cache[module] = module_names(root, module)
            if cache[module] is not None and name in cache[module]:
                found.append(f"{module}.{name}")
        spelled = " | ".join(f"{m}.{n}" for m, n in entry.spellings)
        if found:
            print(f"ok       {spelled}  ({entry.where})")
        else:
            missing += 1
            print(f"MISSING  {spelled}  ({entry.where})")
    return missing


def main() -> int:
    """Checks the source given on the command line; exit status 1 when a name is missing."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("source", type=Path, help="folder holding lerobot/ (e.g. site-packages) or a wheel")
    args = parser.parse_args()
    if args.source.suffix == ".whl":
        with tempfile.TemporaryDirectory() as folder:
            with zipfile.ZipFile(args.source) as wheel:
                wheel.extractall(folder)
            missing = check(Path(folder))
    else:
        missing = check(args.source)
    print(f"{missing} missing")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
