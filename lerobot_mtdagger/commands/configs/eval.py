"""Options of ``lerobot-mtdagger eval``: the policy, the suite, the episodes and the env workers.

``shift`` takes the same options (``configs/shift.py``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from lerobot_mtdagger.datasets.experiment_files import POLICY_PATH_TAKES
from lerobot_mtdagger.envs.config import SuiteConfig
from lerobot_mtdagger.runner.option_groups import WorkerOptions
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.hub import check_hub_repo, in_hub_cache, is_hub_id
from lerobot_mtdagger.utils.paths import check_output_file

HELDOUT_TASKS = "heldout"
"""``--suite.tasks='[heldout]'``: the suite's unseen tasks (``eval``, ``shift``)."""
UNSEEN_RULES: tuple[str, ...] = ("shared", "nearest")
"""``eval --unseen_rule``: how a policy acts on a task it was not trained on (``EvalConfig``)."""


def _eval_suite() -> SuiteConfig:
    """``eval``'s default suite: MT10, its observations those the policy was trained on."""
    return SuiteConfig(name="metaworld-mt10")


@dataclass
class EvalTarget:
    """The policy evaluated, on which suite, over which episodes (``EvalConfig``'s first options).

    Attributes:
        policy_path: Pretrained model folder or Hub id (with its processors).
        suite: The suite (``SuiteConfig``, spelt as for ``run``: ``--suite.name=drawers``).
            ``--suite.tasks='[heldout]'`` evaluates the suite's unseen tasks, which a policy trained
            with ``task_dropout > 0`` acts on with its shared embedding. ``suite.tasks``,
            ``suite.obs_mode``, ``suite.num_points`` and ``suite.image_size`` default to what the
            policy was trained on (its tasks that the suite has, else all the suite's).
        episodes: Episodes per task.
        seed: Seed of the evaluation episodes.
        output: Optional JSON file for the results.
    """

    policy_path: str | None = None
    suite: SuiteConfig = field(default_factory=_eval_suite)
    episodes: int = 10
    seed: int = 0
    output: Path | None = None


@dataclass
class EvalConfig(WorkerOptions, EvalTarget):
    """Options of ``lerobot-mtdagger eval``: success per task of a policy (mtdagger, ACT, Diffusion).

    The options of ``EvalTarget``, then the env workers (``WorkerOptions``, as ``run``'s
    ``--rollout.*``; the same episodes on any backend), then these: a dataclass takes the fields of
    its last base first, which keeps this order in ``--help``.

    Attributes:
        trust_checkpoint: Let the policy's processor configs name Python classes, which LeRobot's
            loader imports and calls (default: only LeRobot registry names are accepted).
        unseen_rule: How the policy acts on a task it was not trained on (an unseen drawer):
            ``shared`` with its shared "any task" embedding (a policy trained with task dropout;
            what a run's unseen-drawer evaluation does), ``nearest`` with the task input of the
            training task most like it (the drawers: the same handle type, the nearest handle size
            and height; ``docs/drawers.md``).
        unverified: Evaluate a policy whose files differ from the checksums its ``training.json``
            carries, or a policy of an experiment that fails verification, as it is (with a warning; the
            output lists the problems under ``unverified``); by default it is refused before loading.
        allow_changed_policy: The former spelling of ``unverified``.
    """

    trust_checkpoint: bool = False
    unseen_rule: str = "shared"
    unverified: bool = False
    allow_changed_policy: bool = False

    def __post_init__(self) -> None:
        self.check_workers()  # before anything runs
        if self.policy_path is None:
            raise ValueError("--policy_path is required (a pretrained model folder or a Hub id).")
        if self.output is not None:  # before evaluating, not after: the results would be lost
            check_output_file(self.output, "--output")
        if self.episodes <= 0:
            raise ValueError(f"episodes must be > 0, got {self.episodes}.")
        if self.unseen_rule not in UNSEEN_RULES:
            raise ValueError(f"unseen_rule must be one of {list(UNSEEN_RULES)}, got {self.unseen_rule!r}.")
        if self.suite.name is None:  # draccus builds a SuiteConfig of class defaults when one field is given
            self.suite.name = _eval_suite().name
        self.suite.check()

    def check_paths(self) -> None:
        """Refuses a ``--policy_path`` that is neither on disk nor a Hub id the Hub has or the cache holds.

        A local folder is checked file by file before it is loaded (``datasets.checkpoints``); a Hub
        id is looked up once, without retries (``utils.hub``).

        Raises:
            UserError: Naming the path and the fix.
        """
        path = str(self.policy_path)
        if Path(path).exists():
            return
        if not is_hub_id(path):
            raise UserError(f"{path} does not exist: --policy_path takes {POLICY_PATH_TAKES}.")
        check_hub_repo(path, "model", "--policy_path", cached=in_hub_cache(path, "model"))
