"""LeRobot policy plugins (``--policy.discover_packages_path=lerobot_mtdagger.policies``).

Importing this package registers the ``mtdagger`` policy type with LeRobot.
"""

from lerobot_mtdagger.policies.mtdagger import (
    MTDAggerConfig,
    MTDAggerPolicy,
    make_mtdagger_pre_post_processors,
)

__all__ = ["MTDAggerConfig", "MTDAggerPolicy", "make_mtdagger_pre_post_processors"]
