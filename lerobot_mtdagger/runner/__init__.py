"""The runner: the DAgger loop, its configs and the ``Student`` contract; ``rollout/`` and ``training/``."""
