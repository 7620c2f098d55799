"""``lerobot-mtdagger compare``: every method over every seed, and BC at every budget, then the table.

Its options are ``CompareConfig`` (``analysis/compare.py``); any other option goes to every run.
"""

from __future__ import annotations

from lerobot_mtdagger.analysis.compare import compare
from lerobot_mtdagger.commands.configs.compare import CompareConfig

__all__ = ["CompareConfig", "compare_command"]


def compare_command(config: CompareConfig, run_args: list[str]) -> list[dict]:
    """Runs every method over every seed (and BC at every budget) and writes the results table."""
    rows = compare(config, run_args)
    runs = len({row["experiment"] for row in rows})
    print(f"{runs} runs, {len(rows)} evaluated rounds: {config.output_dir / 'results.csv'}")
    return rows
