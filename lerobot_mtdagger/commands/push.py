"""``lerobot-mtdagger push``: an experiment's round datasets and policies to the Hub.

Its options are ``PushConfig`` (``datasets/push_config.py``); the work is ``datasets/hub.py``'s.
"""

from __future__ import annotations

from lerobot_mtdagger.commands.configs.push import PushConfig
from lerobot_mtdagger.datasets.hub import push_command as push
from lerobot_mtdagger.runner.configs import RunConfig

__all__ = ["PushConfig", "push_command"]


def push_command(config: PushConfig) -> dict[str, dict[str, str]]:
    """Pushes an experiment's rounds (and policies) to the Hub (``datasets/hub.py``)."""
    return push(config, RunConfig.option_defaults())
