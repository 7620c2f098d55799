"""Each command's options, one module per command (``configs/<command>.py``), and nothing heavy.

``cli.py`` imports a command's config module to parse its options and check the paths they name
(``check_paths``), and only then the command's body (``commands/<command>.py``), which imports torch
and LeRobot at its top: ``--help``, a refused option and a missing path answer before either loads.
A config that a lower wing reads too (``run``: ``runner.configs.RunConfig``; ``compare``, ``push``,
``plan``) is defined there and named here.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable


@runtime_checkable
class ChecksPaths(Protocol):
    """A config whose options name inputs on disk or on the Hub, checked before the command runs."""

    def check_paths(self) -> None:
        """Refuses a path or repo id that is not there, in one line naming the option and the fix.

        Raises:
            UserError: Naming the option, the path and the fix.
        """
