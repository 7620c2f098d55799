"""LeRobot policy plugins (``--policy.discover_packages_path=lerobot_mtdagger.policies``).

Importing this package registers the ``mtdagger`` policy type and the one-hot task processor step.
"""

from lerobot_mtdagger.policies.mtdagger import (
    MTDAggerConfig,
    MTDAggerPolicy,
    make_mtdagger_pre_post_processors,
)
from lerobot_mtdagger.policies.task_conditioning import TASK_FEATURE, TaskOneHotProcessorStep

__all__ = [
    "TASK_FEATURE",
    "MTDAggerConfig",
    "MTDAggerPolicy",
    "TaskOneHotProcessorStep",
    "make_mtdagger_pre_post_processors",
]
