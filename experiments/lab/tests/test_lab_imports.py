"""The studies' shared code imports neither torch nor LeRobot: a table script answers in about a second,
not 15-20 s (the package's saved-records reader and statistics are kept apart from its LeRobot code)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXPERIMENTS = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("module", ["lab.paired", "lab.passes", "lab.bc_choice"])
def test_a_lab_module_imports_neither_torch_nor_lerobot(module):
    code = f"import sys, {module}\nprint(sorted(m for m in ('torch', 'lerobot') if m in sys.modules))"
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True, cwd=EXPERIMENTS
    )
    assert result.stdout.strip().splitlines()[-1] == "[]", result.stdout[-2000:]
