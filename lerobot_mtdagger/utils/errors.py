"""Errors caused by what the user gave (an option, a path, a file), as opposed to bugs of ours.

The command line prints a :class:`UserError` as one line, ``error: <what> <how to fix>``, and exits
with status 2; any other exception is a bug and keeps its traceback (``--debug`` shows it for both).
"""

from __future__ import annotations


class UserError(ValueError):
    """A problem with the user's input, whose message names the input and the fix (a ``ValueError``)."""


class NotAnExperimentError(UserError):
    """A folder given as an experiment is missing or holds no lerobot-mtdagger experiment."""


class CorruptExperimentError(UserError):
    """A committed file of an experiment changed or disappeared after it was committed."""
