"""A run that ends with the ``compare`` that started it, so a killed ``compare`` leaves no run writing on."""

from __future__ import annotations

import logging
import os
import signal
import threading
import time

logger = logging.getLogger(__name__)

PARENT_PID_ENV = "LEROBOT_MTDAGGER_PARENT_PID"
"""Set by ``compare`` in each run's environment: the process id the run must not outlive."""

PARENT_POLL_S = 0.5
"""Seconds between two checks of the parent process."""


def follow_parent(poll_s: float = PARENT_POLL_S) -> threading.Thread | None:
    """Ends this process (SIGTERM) once the ``compare`` that started it has ended, as a killed run ends.

    Without it, a killed ``compare``'s runs would write on into folders a new ``compare`` resumes.
    Returns the watching daemon thread, or None without ``PARENT_PID_ENV`` (a run started by hand).
    """
    expected = os.environ.get(PARENT_PID_ENV)
    if not expected:
        return None
    parent = int(expected)
    watcher = threading.Thread(
        target=_end_when_orphaned, args=(parent, poll_s), name="follow-parent", daemon=True
    )
    watcher.start()
    return watcher


def _end_when_orphaned(parent: int, poll_s: float) -> None:
    """Waits until this process's parent is no longer ``parent`` (it ended), then ends this process."""
    while os.getppid() == parent:
        time.sleep(poll_s)
    logger.error("compare (pid %d) has ended; ending this run, which compare resumes when run again.", parent)
    os.kill(os.getpid(), signal.SIGTERM)
