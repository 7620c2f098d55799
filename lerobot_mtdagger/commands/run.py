"""``lerobot-mtdagger run``: one Multitask DAgger experiment, or the behaviour-cloning baseline.

Its options are ``RunConfig`` (``runner/configs.py``), which the runner reads too.
"""

from __future__ import annotations

from lerobot_mtdagger.commands.configs.run import RunConfig
from lerobot_mtdagger.runner.dagger import run
from lerobot_mtdagger.utils.parent import follow_parent

__all__ = ["RunConfig", "run_experiment"]


def run_experiment(config: RunConfig) -> list[str]:
    """Runs ``lerobot-mtdagger run`` and prints the per-round summary."""
    follow_parent()
    header = f"experiment {config.output_dir} ({config.method}, seed {config.seed}):"
    return run(
        config, on_summary=lambda line: print(line, flush=True), on_start=lambda: print(header, flush=True)
    )
