"""The suite registry: which factory builds the suite of a name.

A suite is registered by name with a factory ``factory(options: SuiteOptions) -> TaskSuite``, as a
callable or as a ``"module:attribute"`` entry point imported on first use. The built-in suites
register themselves that way (``toy``, ``drawers`` and the MetaWorld lists), so building the toy
suite never imports MuJoCo or MetaWorld::

    register_suite("my-suite", lambda options: MySuite(options.tasks or MY_TASKS, options.observation))

``build_suite(options)`` then builds the suite ``options.name`` names; ``--suite.name`` takes any
registered name, and ``--suite.module`` imports a module (one that registers suites) before the suite
is built (``import_suite_module``). An installed package registers its suites by entry point (group
``lerobot_mtdagger.suites``, ``utils.plugins``).
"""

from __future__ import annotations

import importlib
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from lerobot_mtdagger.envs.base import ObservationConfig, TaskSuite
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.plugins import SUITE_ENTRY_POINTS
from lerobot_mtdagger.utils.registry import Registry

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class SuiteOptions:
    """What a suite factory is asked to build.

    Attributes:
        name: The registered name asked for (one factory may serve several names).
        tasks: The tasks, in order (a subset of the suite's, or its extra tasks); empty: the suite's own.
        observation: What the envs show the policy.
        max_episode_steps: Truncation length (None: each task's own horizon).
        placement: How resets move and recolour the drawers (``kitchen``, ``narrow``; None: the
            default); a suite without placements refuses one (``refuse_placement``).
    """

    name: str
    tasks: tuple[str, ...] = ()
    observation: ObservationConfig = field(default_factory=ObservationConfig)
    max_episode_steps: int | None = None
    placement: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "tasks", tuple(self.tasks or ()))

    def task_list(self, default: Sequence[str]) -> list[str]:
        """The tasks asked for, or ``default`` (the suite's own list) when none were."""
        return list(self.tasks) if self.tasks else list(default)

    def refuse_placement(self) -> None:
        """Refuses a placement, for a suite without placements.

        Raises:
            UserError: If a placement was given.
        """
        if self.placement is not None:
            raise UserError(
                f"placement={self.placement!r} applies to the drawers suite only; drop it for {self.name!r}."
            )


SuiteFactory = Callable[[SuiteOptions], TaskSuite]
"""``factory(options) -> TaskSuite``."""

SUITES: Registry[SuiteFactory] = Registry(
    "suite",
    entry_point_group=SUITE_ENTRY_POINTS,
    refusal=lambda name, factory: (
        f"The factory of suite {name!r} must be callable or a 'module:attribute' string, got {factory!r}."
    ),
)
"""The suite factories by name."""


def register_suite(name: str, factory: SuiteFactory | str) -> None:
    """Registers the factory of a suite name (``--suite.name=<name>``, ``make_suite(name)``).

    Args:
        name: The suite's name.
        factory: ``factory(options: SuiteOptions) -> TaskSuite``, or its ``"module:attribute"`` entry
            point (imported when the suite is first built).

    Raises:
        UserError: If ``name`` is already registered (a ``ValueError``).
        TypeError: If ``factory`` is neither callable nor an entry-point string.
    """
    SUITES.register(name, factory)


def suite_names() -> list[str]:
    """Every registered suite name, in the order of registration (the built-in suites first)."""
    return SUITES.names()


def build_suite(options: SuiteOptions) -> TaskSuite:
    """The suite ``options.name`` names, built by its registered factory.

    Raises:
        UserError: On a name no factory is registered for (one line listing the registered names).
        ValueError: On a task or observation setting the suite refuses.
    """
    if options.name not in SUITES:
        raise UserError(
            f"Unknown suite {options.name!r}; available suites: {', '.join(suite_names())} (a suite from "
            "outside the package is registered with lerobot_mtdagger.envs.register_suite by the module "
            "--suite.module names, or installed by a package's entry point in the group "
            f"{SUITE_ENTRY_POINTS!r})."
        )
    return SUITES.get(options.name)(options)


def import_suite_module(module: str) -> None:
    """Imports ``module`` (``--suite.module``), whose import registers its suites.

    Raises:
        UserError: If the module cannot be imported.
    """
    try:
        importlib.import_module(module)
    except ImportError as error:
        raise UserError(
            f"--suite.module={module} cannot be imported ({type(error).__name__}: {error}): give an "
            "importable module that registers its suites with lerobot_mtdagger.envs.register_suite."
        ) from None
    logger.debug("Imported suite module %s; registered suites: %s", module, suite_names())


BUILT_IN_SUITES: dict[str, str] = {
    "metaworld-mt10": "lerobot_mtdagger.envs.metaworld:build_metaworld_suite",
    "metaworld-mt25": "lerobot_mtdagger.envs.metaworld:build_metaworld_suite",
    "metaworld-mt50": "lerobot_mtdagger.envs.metaworld:build_metaworld_suite",
    "metaworld": "lerobot_mtdagger.envs.metaworld:build_metaworld_suite",
    "drawers": "lerobot_mtdagger.envs.drawers.suite:build_drawer_suite",
    "toy": "lerobot_mtdagger.envs.toy:build_toy_suite",
}
"""The package's suites by name, and the entry point of each one's factory."""

for _name, _entry_point in BUILT_IN_SUITES.items():
    register_suite(_name, _entry_point)
SUITES.load_entry_points(register_suite)
