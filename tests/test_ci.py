"""``.ci/run`` runs the whole slow set on both LeRobot lines, the Ray tests in one process.

Its ``slow_set`` function is run with stand-in interpreters that log their arguments, so the test
checks the commands CI runs, not the script's text.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CI_SCRIPT = ROOT / ".ci" / "run"
RAY_TESTS = "tests/test_ray.py"
LINES = (".venv312", ".venv")  # LeRobot 0.6 first, so that CI's last runner summary is line 1's


def slow_set_commands(tmp_path: Path) -> list[str]:
    """The interpreter calls ``.ci/run``'s ``slow_set`` calls make, as ``<venv> <arguments>`` lines."""
    script = CI_SCRIPT.read_text()
    function = re.search(r"^slow_set\(\) \{\n.*?^\}\n", script, re.DOTALL | re.MULTILINE)
    assert function is not None, ".ci/run defines no slow_set() function"
    calls = re.findall(r"^slow_set .*$", script, re.MULTILINE)
    log = tmp_path / "calls.log"
    for venv in LINES:
        python = tmp_path / venv / "bin" / "python"
        python.parent.mkdir(parents=True)
        python.write_text(f'#!/usr/bin/env bash\necho "{venv} $*" >> "{log}"\n')
        python.chmod(0o755)
    body = "\n".join(["set -euo pipefail", function.group(0), *calls])
    subprocess.run(["bash", "-c", body], cwd=tmp_path, check=True, capture_output=True, text=True)
    return log.read_text().splitlines()


def test_ci_runs_the_whole_slow_set_on_both_lines_with_ray_in_one_process(tmp_path):
    expected = []
    for venv in LINES:
        expected += [
            f"{venv} -m pytest -m slow -n 0 {RAY_TESTS}",
            f"{venv} -m pytest -m slow --ignore={RAY_TESTS}",
        ]
    assert slow_set_commands(tmp_path) == expected


def test_only_the_ray_test_file_uses_ray():
    """CI runs only ``tests/test_ray.py`` in one process: Ray tests elsewhere would run beside a worker."""
    uses_ray = re.compile(r"^\s*(import ray\b|from ray\b)|RayEnvWorkers|ray_workers", re.MULTILINE)
    tests = (path for path in (ROOT / "tests").glob("test_*.py") if path.name != Path(__file__).name)
    files = sorted(path.relative_to(ROOT).as_posix() for path in tests)
    assert [name for name in files if uses_ray.search((ROOT / name).read_text())] == [RAY_TESTS]
