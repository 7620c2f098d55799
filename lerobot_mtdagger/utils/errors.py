"""Errors caused by what the user gave (an option, a path, a file), as opposed to bugs of ours.

The command line prints a :class:`UserError` as one line, ``error: <what> <how to fix>``, and exits
with status 2; any other exception is a bug and keeps its traceback (``--debug`` shows the traceback
of a user error too). Every message names the option, path or file at fault and the fix.
"""

from __future__ import annotations


class UserError(ValueError):
    """A problem with the user's input, whose message names the input and the fix.

    A ``ValueError`` so that code catching bad values keeps working.
    """


class NotAnExperimentError(UserError):
    """A folder given as an experiment is missing or holds no lerobot-mtdagger experiment."""


class CorruptExperimentError(UserError):
    """A committed file of an experiment changed or disappeared after it was committed."""
