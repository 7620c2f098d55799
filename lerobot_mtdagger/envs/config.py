"""``SuiteConfig``: the suite and its observations, one config for every command that builds a suite.

``run``, ``eval``, ``shift`` (``--suite.*``) and LeRobot's env plugin (``--env.suite.*``) hold one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot_mtdagger.envs.drawers.variants import DEFAULT_PLACEMENT, PLACEMENTS
from lerobot_mtdagger.utils.errors import UserError

DEFAULT_NUM_POINTS = 1024
DEFAULT_IMAGE_SIZE = 84
MAX_IMAGE_SIZE = 480
"""The largest image side: MuJoCo's default offscreen buffer (MetaWorld's and the drawers') is 640x480."""
MAX_NUM_POINTS = 65_536
"""The largest point cloud: a round keeps every frame's cloud in memory (65 536 points: 768 kB a frame)."""
DRAWERS = "drawers"


@dataclass
class SuiteConfig:
    """A task suite and its observations.

    Attributes:
        name: A registered suite name (``metaworld-mt10``, ``drawers``, ``toy``, ..., or one that ``module``
            registers). None: the command's default.
        tasks: Subset of the suite's tasks (all when empty; ``eval`` and ``shift`` also take
            ``heldout``: the suite's unseen tasks).
        obs_mode: ``state``, ``rgb`` or ``pointcloud``. None: the command's default (``eval``: the policy's).
        num_points: Points per cloud (pointcloud mode). None: 1 024 (``eval``: the policy's).
        image_size: Image side (rgb mode). None: 84 (``eval``: the policy's).
        mesh_detail: Share of the arm meshes' faces the observation renderer keeps, in (0, 1] (1: the
            exact model; 0.2 renders about twice as fast on a CPU).
        placement: ``drawers`` only: how resets move and recolour the drawers (``kitchen`` when None, or
            ``narrow``).
        episode_length: Steps after which an episode is truncated (None: each task's own horizon).
        module: A module imported first that registers suites from outside the package, e.g.
            ``my_package.suites``.
    """

    name: str | None = None
    tasks: list[str] = field(default_factory=list)
    obs_mode: str | None = None
    num_points: int | None = None
    image_size: int | None = None
    mesh_detail: float = 1.0
    placement: str | None = None
    episode_length: int | None = None
    module: str | None = None

    def check(self) -> None:
        """Refuses options that cannot name a suite, before anything runs (``UserError``, one line)."""
        if self.placement is not None and self.name != DRAWERS:
            raise UserError(f"suite.placement applies to the drawers suite only; drop it for {self.name!r}.")
        if self.placement is not None and self.placement not in PLACEMENTS:
            raise UserError(
                f"Unknown drawer placement {self.placement!r}; choose --suite.placement from "
                f"{sorted(PLACEMENTS)}."
            )
        for name in ("num_points", "image_size", "episode_length"):
            value = getattr(self, name)
            if value is not None and value <= 0:
                raise UserError(f"suite.{name} must be > 0, got {value}.")
        for name, limit, why in (
            ("image_size", MAX_IMAGE_SIZE, "the suites' offscreen render buffer is 640x480"),
            ("num_points", MAX_NUM_POINTS, "a round keeps every frame's cloud in memory"),
        ):
            value = getattr(self, name)
            if value is not None and value > limit:
                raise UserError(f"suite.{name} must be <= {limit} ({why}), got {value}.")
        if not 0.0 < self.mesh_detail <= 1.0:
            raise UserError(f"suite.mesh_detail must be in (0, 1], got {self.mesh_detail}.")
        if self.module is not None and not all(part.isidentifier() for part in self.module.split(".")):
            raise UserError(
                f"suite.module must be a dotted module name (e.g. my_package.suites), got {self.module!r}."
            )

    def fill_defaults(self) -> None:
        """Gives unset observation options their defaults (1 024 points, 84 px images, ``kitchen``)."""
        if self.num_points is None:
            self.num_points = DEFAULT_NUM_POINTS
        if self.image_size is None:
            self.image_size = DEFAULT_IMAGE_SIZE
        if self.name == DRAWERS and self.placement is None:
            self.placement = DEFAULT_PLACEMENT
