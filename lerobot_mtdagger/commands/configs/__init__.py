"""Each command's options, one module per command (``configs/<command>.py``), and nothing heavy.

``cli.py`` imports a command's config module to parse its options, and only then the command's body
(``commands/<command>.py``), which imports torch and LeRobot at its top: ``--help`` and a refused
option answer before either loads. A config that a lower wing reads too (``run``:
``runner.configs.RunConfig``; ``compare``, ``push``, ``plan``) is defined there and named here.
"""
