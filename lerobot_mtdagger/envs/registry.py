"""The suite registry: which factory builds the suite of a name.

A factory ``factory(options: SuiteOptions) -> TaskSuite`` is registered as a callable or a lazily
imported ``"module:attribute"`` (so the toy suite never imports MuJoCo)::

    register_suite("my-suite", lambda options: MySuite(options.tasks or MY_TASKS, options.observation))

Installed packages register by entry point (group ``lerobot_mtdagger.suites``).
"""

from __future__ import annotations

import importlib
import logging
from collections.abc import Callable, Iterable
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
        tasks: The tasks in order (empty: the suite's own).
        observation: What the envs show the policy.
        max_episode_steps: Truncation length (None: each task's own horizon).
        placement: Drawer placement (None: the default); other suites refuse one (``refuse_placement``).
    """

    name: str
    tasks: tuple[str, ...] = ()
    observation: ObservationConfig = field(default_factory=ObservationConfig)
    max_episode_steps: int | None = None
    placement: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "tasks", tuple(self.tasks or ()))

    def task_list(self, default: Iterable[str]) -> list[str]:
        """The tasks asked for, or ``default`` (the suite's own list) when none were."""
        return list(self.tasks) if self.tasks else list(default)

    def refuse_placement(self) -> None:
        """Refuses a placement, for a suite without placements (``UserError`` if one was given)."""
        if self.placement is not None:
            raise UserError(
                f"placement={self.placement!r} applies to the drawers suite only; drop it for {self.name!r}."
            )


SuiteFactory = Callable[[SuiteOptions], TaskSuite]
"""``factory(options) -> TaskSuite``."""

SUITES: Registry[str, SuiteFactory] = Registry(
    "suite",
    entry_point_group=SUITE_ENTRY_POINTS,
    refusal=lambda name, factory: (
        f"The factory of suite {name!r} must be callable or a 'module:attribute' string, got {factory!r}."
    ),
)
"""The suite factories by name."""


def register_suite(name: str, factory: SuiteFactory | str) -> None:
    """Registers the factory of a suite name (``--suite.name=<name>``, ``make_suite(name)``).

    ``factory`` is ``factory(options: SuiteOptions) -> TaskSuite`` or its ``"module:attribute"``.

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
        UserError: On an unregistered name (one line listing the registered names).
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
    """Imports ``module`` (``--suite.module``), which registers its suites (``UserError`` if it fails)."""
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
