"""``lerobot-mtdagger plan``: the paper's scheduler for data collected outside the simulated runner.

A LeRobot user collecting with a teleoperator (``lerobot-record``, or LeRobot 0.6's
``lerobot-rollout --strategy.type=dagger``, which marks the frames a person took over in a boolean
``intervention`` column) asks the paper's question each session: which tasks get the next hour of
operator time? ``plan`` reads the LeRobot datasets of the current policy's episodes on each task
(``episodes.py``), measures each task's success from the episodes where the policy acted alone,
feeds them to the same scheduler a run uses (``lerobot_mtdagger.scheduler``), and writes a plan file
holding the allocation, the scheduler's state (the next ``plan`` continues its Kalman filters) and
every input it read, with checksums, so ``plan --verify`` can recompute it (``plan.py``).
"""
