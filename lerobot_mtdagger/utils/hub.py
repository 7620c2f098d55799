"""Whether a Hub repo id can be read: asked once, without retries, before a command loads anything.

A command given a repo id (``eval --policy_path=owner/name``, ``plan --datasets='[owner/name]'``)
looks it up here first, so that a mistyped id, a mistyped local path that reads as an id
(``data/sesion1``) or a Hub out of reach is one line naming the fix, in a second, instead of the
loader's retries and traceback. The look-up honours ``HF_HUB_OFFLINE`` (nothing is sent; the repo
must be in the cache) and ``HF_ENDPOINT``.

huggingface_hub 0.x (the LeRobot 0.4 line) sends with requests, 1.x (the 0.6 line) with httpx; a
connection failure is either library's exception (``network_errors``). huggingface_hub, requests
and httpx are imported when a repo id is looked up, not with this module: the command-line configs
import it, and their ``--help`` and local-path refusals need none of them.
"""

from __future__ import annotations

import functools
import logging
import os
import re
from pathlib import Path

from lerobot_mtdagger.utils.errors import UserError

logger = logging.getLogger(__name__)

HUB_ID_PATTERN = re.compile(r"[A-Za-z0-9][\w.-]*/[A-Za-z0-9][\w.-]*")
"""A Hub repo id, ``owner/name``."""

LOOKUP_TIMEOUT_S = 3.0
"""Seconds the one look-up request may take (connecting, then answering)."""

REPO_TYPES: tuple[str, ...] = ("model", "dataset")
"""The repo types looked up: policies are model repos, LeRobot datasets dataset repos."""


def is_hub_id(text: str | Path) -> bool:
    """Whether ``text`` has the shape of a Hub repo id (``owner/name``)."""
    return HUB_ID_PATTERN.fullmatch(str(text)) is not None


@functools.cache
def network_errors() -> tuple[type[Exception], ...]:
    """The exceptions of a request that got no answer: connection failures and timeouts.

    requests' (huggingface_hub 0.x) and httpx's (1.x), of those installed; huggingface_hub's
    ``OfflineModeIsEnabled`` (a request attempted with ``HF_HUB_OFFLINE`` set) is one of requests'
    ``ConnectionError`` in 0.x and a builtin ``ConnectionError`` in 1.x, both included.
    """
    errors: list[type[Exception]] = [ConnectionError, TimeoutError]
    try:
        import requests
    except ImportError:
        pass
    else:
        errors += [requests.ConnectionError, requests.Timeout]
    try:
        import httpx
    except ImportError:
        pass
    else:
        errors.append(httpx.TransportError)  # ConnectError, TimeoutException, ProxyError, ...
    return tuple(errors)


def hub_offline() -> bool:
    """Whether ``HF_HUB_OFFLINE`` is set (huggingface_hub reads it when imported)."""
    from huggingface_hub import constants

    return bool(constants.HF_HUB_OFFLINE)


def in_hub_cache(repo_id: str, repo_type: str) -> bool:
    """Whether the Hub cache (``HF_HUB_CACHE``) holds a snapshot of the repo."""
    from huggingface_hub import constants
    from huggingface_hub.file_download import repo_folder_name

    repo_folder = Path(constants.HF_HUB_CACHE) / repo_folder_name(repo_id=repo_id, repo_type=repo_type)
    snapshots = repo_folder / "snapshots"
    return snapshots.is_dir() and any(snapshots.iterdir())


def lerobot_dataset_cache(repo_id: str) -> Path:
    """Where LeRobot keeps a Hub dataset it read: ``$HF_LEROBOT_HOME/<repo_id>``.

    ``HF_LEROBOT_HOME`` defaults to ``$HF_HOME/lerobot``, as in ``lerobot.utils.constants`` (read here
    from the environment at each call, without importing LeRobot).
    """
    from huggingface_hub import constants

    home = os.environ.get("HF_LEROBOT_HOME", str(Path(constants.HF_HOME) / "lerobot"))
    return Path(home).expanduser() / repo_id


def check_hub_repo(repo_id: str, repo_type: str, option: str, cached: bool) -> None:
    """Refuses a repo id the Hub does not have, or cannot be asked about and is not cached.

    One request (``HfApi.repo_info``, no retries, ``LOOKUP_TIMEOUT_S``), none with ``HF_HUB_OFFLINE``.

    Args:
        repo_id: The repo id given, ``owner/name``.
        repo_type: ``model`` or ``dataset``.
        option: The option that gave it (``--policy_path``), for the message.
        cached: Whether the reader finds the repo on disk without the Hub: then a Hub out of reach is
            no error (the cached copy is read, with a warning), only a Hub that says it has no such repo.

    Raises:
        UserError: In one line naming the repo id and the fix.
    """
    from huggingface_hub import HfApi
    from huggingface_hub.errors import HfHubHTTPError, RepositoryNotFoundError

    if repo_type not in REPO_TYPES:
        raise ValueError(f"repo_type must be one of {list(REPO_TYPES)}, got {repo_type!r}.")
    where = f"{option}={repo_id} is not a local path"
    if hub_offline():
        if not cached:
            raise UserError(
                f"{where}, and the {repo_type} repo of that id is not in the cache while HF_HUB_OFFLINE is "
                "set: check the path, download the repo while online, or unset HF_HUB_OFFLINE."
            )
        return
    try:
        HfApi().repo_info(repo_id, repo_type=repo_type, timeout=LOOKUP_TIMEOUT_S)
    except RepositoryNotFoundError:
        raise UserError(
            f"{where}, and the Hub has no {repo_type} repo of that id (or it is private or gated: log in "
            "with `hf auth login` or set HF_TOKEN): check the path or the repo id."
        ) from None
    except network_errors() + (HfHubHTTPError,) as error:
        reason = _unanswered(error)
        if not cached:
            raise UserError(
                f"{where}, and the Hub cannot be asked about a {repo_type} repo of that id ({reason}): check "
                "the path, or the network (or HF_ENDPOINT) and try again."
            ) from None
        logger.warning(
            "The Hub cannot be asked about %s (%s): reading the cached copy (HF_HUB_OFFLINE=1 skips asking).",
            repo_id,
            reason,
        )


def _unanswered(error: Exception) -> str:
    """Why a look-up got no answer: the HTTP status, or the exception's class name."""
    response = getattr(error, "response", None)
    status = getattr(response, "status_code", None)
    return f"HTTP {status}" if status is not None else type(error).__name__
