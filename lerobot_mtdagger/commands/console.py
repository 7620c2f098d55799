"""What every command shows on the console: its warnings, and a user error as one line."""

from __future__ import annotations

import logging

HUB_LOGGER = "huggingface_hub"
"""huggingface_hub's logger (its own console handler): errors only, not a warning per HTTP retry."""


def configure_console_logging() -> None:
    """Warnings and errors on the console; INFO records still reach file handlers (``run.log``).

    The console shows what the commands print (one summary line per round for ``run``), never the
    INFO chatter of the libraries underneath, nor huggingface_hub's warning at each HTTP retry (a
    Hub that cannot be reached is one error line of ours).
    """
    console = logging.StreamHandler()
    console.setLevel(logging.WARNING)
    console.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    # force: a library may have configured the root logger already (LeRobot logs at import time).
    logging.basicConfig(level=logging.INFO, handlers=[console], force=True)
    logging.getLogger(HUB_LOGGER).setLevel(logging.ERROR)


def error_line(command: str, message: object) -> str:
    """The one line printed for a user error: ``lerobot-mtdagger <command>: error: <message>``."""
    return f"lerobot-mtdagger {command}: error: {' '.join(str(message).split())}"
