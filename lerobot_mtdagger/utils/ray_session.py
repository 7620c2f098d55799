"""Joining (or starting) a Ray cluster for ``compare --launcher=ray`` and ``--rollout.worker_backend=ray``.

Ray is optional (``pip install -e ".[ray]"``). A process joins at most once; later calls reuse the
connection.
"""

from __future__ import annotations

import importlib.util
import logging
import os
from types import ModuleType

from lerobot_mtdagger.utils.errors import UserError

logger = logging.getLogger(__name__)

RAY_MISSING = 'Ray is not installed: pip install -e ".[ray]" (or pip install "ray>=2.40,<3").'


def import_ray() -> ModuleType:
    """The ``ray`` module (a ``UserError`` naming the install command if Ray is missing)."""
    try:
        import ray
    except ImportError:
        raise UserError(RAY_MISSING) from None
    return ray


def check_ray_address(address: str | None, option: str) -> None:
    """Refuses a ``ray://`` address without the Ray Client's grpcio now, not on connecting."""
    if address is None or not address.startswith("ray://"):
        return
    if importlib.util.find_spec("grpc") is None:
        raise UserError(
            f'{option}={address} connects through the Ray Client, which needs pip install "ray[client]" '
            f"(not installed here); or run on a node of the cluster with {option}=auto."
        )


def connect(address: str | None) -> ModuleType:
    """The ``ray`` module, connected to ``address`` (``auto``, ``ray://host:10001``; None: a local Ray).

    Raises:
        UserError: If Ray is missing, or there is no cluster at ``address``.
    """
    ray = import_ray()
    if ray.is_initialized():
        return ray
    options: dict = {"include_dashboard": False, "log_to_driver": False}
    if address:
        options["address"] = address
    os.environ.setdefault("RAY_AUTH_MODE", "disabled")  # a local cluster of this user's processes
    # Ray runs its workers at nice 15 unless told otherwise; a run or an env worker is the work itself
    # (at 15 it starves beside any other job). Applies to a Ray this process starts; for a cluster
    # started with `ray start`, export RAY_worker_niceness=0 there (docs/cluster.md).
    os.environ.setdefault("RAY_worker_niceness", "0")
    try:
        ray.init(**options)
    except ConnectionError as error:
        raise UserError(
            f"No Ray cluster at {address!r} ({error}): start one with `ray start --head`, or drop the "
            "address to start a local Ray."
        ) from None
    resources = ray.cluster_resources()
    logger.info(
        "Ray: %d node(s), %g CPU(s), %g GPU(s)",
        len(ray.nodes()),
        resources.get("CPU", 0),
        resources.get("GPU", 0),
    )
    return ray
