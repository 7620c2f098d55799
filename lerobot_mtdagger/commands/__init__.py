"""The ``lerobot-mtdagger`` commands, one module each: its options and its body (``cli.py`` dispatches).

A command whose config a lower wing reads too (``run``: ``runner.configs.RunConfig``; ``compare``,
``push``, ``plan``) imports it from there. Heavy libraries (torch, LeRobot) are imported inside the
functions that need them, so that ``--help`` and a refused option answer at once.
"""
