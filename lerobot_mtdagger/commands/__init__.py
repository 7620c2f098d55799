"""The ``lerobot-mtdagger`` commands: each one's options in ``configs/<command>.py``, its body here.

``cli.py`` imports a command's options (light: no torch, no LeRobot) to parse and check them, and its
body module (``<command>.py``, which imports what it needs at its top) only once they are good, so
that ``--help``, a refused option and a missing path answer at once.
"""
