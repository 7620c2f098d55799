"""Data-efficient multitask DAgger for LeRobot.

Distils many task-specific expert policies into one multitask policy, spending expert
demonstrations where the policy needs them (see ``lerobot_mtdagger.scheduler``).
"""

__version__ = "0.1.0"
