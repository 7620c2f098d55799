"""``pixels-dagger-epochs-dev/second_core.sh`` runs run.sh's very compares, in the other order."""

from __future__ import annotations

import re
from pathlib import Path

STUDY = Path(__file__).resolve().parents[2] / "pixels-dagger-epochs-dev"


def compares(script: Path) -> tuple[str, list[str]]:
    """The ``COMMON`` options and each ``compare`` line's own options, as written in ``script``."""
    text = script.read_text()
    common = re.search(r"^COMMON=\((.*?)\)$", text, flags=re.S | re.M).group(1)
    arms = re.findall(r'^"\$CLI" compare "\$\{COMMON\[@\]\}" (.*?--output_dir="[^"]+")', text, flags=re.M)
    return " ".join(common.split()), arms


def test_the_second_process_runs_the_same_compares_fixed_first():
    common, arms = compares(STUDY / "run.sh")
    second_common, second_arms = compares(STUDY / "second_core.sh")
    assert len(arms) == 2 and second_common == common
    assert second_arms == arms[::-1] and second_arms[0].endswith('--output_dir="$OUT/fixed"')
