"""The docs quote the numbers a run of the code gave, through the script that writes them.

``docs/dagger.md``'s default-run table is written by ``scripts/default_run_table.py --write`` from a
run of the README's main command, which also saves the numbers in ``docs/data/default-run.json``:
the page must hold exactly the table that record gives.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def load_script():
    """``scripts/default_run_table.py`` as a module (scripts/ is not a package)."""
    spec = importlib.util.spec_from_file_location(
        "default_run_table", ROOT / "scripts" / "default_run_table.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_default_run_table_is_the_one_its_saved_run_gives():
    script = load_script()
    run = json.loads(script.RECORD.read_text())
    page = script.PAGE.read_text()
    assert script.START in page and script.END in page, "docs/dagger.md lost its default-run markers"
    held = page.split(script.START, 1)[1].split(script.END, 1)[0]
    assert held == script.table(run), "docs/dagger.md's default-run table was edited: rerun the script"


def test_the_saved_run_is_a_whole_default_run():
    run = json.loads((ROOT / "docs" / "data" / "default-run.json").read_text())
    assert len(run["tasks"]) == 10 and len(run["episodes"]) == len(run["success"]) == len(run["mean"]) == 4
    for success, mean in zip(run["success"], run["mean"], strict=True):
        assert abs(sum(success) / len(success) - mean) < 1e-9
    assert run["made_with"]["commit"]
