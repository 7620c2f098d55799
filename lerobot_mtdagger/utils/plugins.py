"""Plugins installed as Python packages: the entry points a registry reads at import.

A package adds a student, a suite or an expert type by declaring an entry point in its
``pyproject.toml``; the registry registers it lazily, as a ``"module:attribute"`` string::

    [project.entry-points."lerobot_mtdagger.students"]
    mtdagger-wide = "my_package.students:WideStudent"

    [project.entry-points."lerobot_mtdagger.suites"]
    my-suite = "my_package.suites:make_my_suite"

    [project.entry-points."lerobot_mtdagger.experts"]
    my-sac = "my_package.experts:sac_expert"
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Collection, Hashable
from importlib.metadata import entry_points

logger = logging.getLogger(__name__)

STUDENT_ENTRY_POINTS = "lerobot_mtdagger.students"
"""The entry-point group of installed students (``--policy.type`` -> ``"module:Student"``)."""

SUITE_ENTRY_POINTS = "lerobot_mtdagger.suites"
"""The entry-point group of installed suites (``--suite.name`` -> ``"module:factory"``)."""

EXPERT_ENTRY_POINTS = "lerobot_mtdagger.experts"
"""The entry-point group of installed expert types (``--expert.type`` -> ``"module:factory"``)."""


def register_installed(
    group: str, registered: Collection[Hashable], register: Callable[[str, str], None]
) -> list[str]:
    """Registers each entry point of ``group`` with ``register(name, "module:attribute")``; returns the names.

    Names already in ``registered`` are skipped (the built-in ones win; a clash is logged).
    """
    added = []
    for point in sorted(entry_points(group=group), key=lambda point: point.name):
        if point.name in registered or point.name in added:
            logger.warning(
                "Entry point %s = %s (group %s) is not registered: the name is taken; rename it in its "
                "package.",
                point.name,
                point.value,
                group,
            )
            continue
        register(point.name, point.value)
        added.append(point.name)
    return added
