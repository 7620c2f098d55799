"""Learning curves of experiments: evaluation success against expert demonstrations, method by method.

Reads only committed training phases (``policies/round-XXX/training.json``): after phase k the policy
was trained on rounds 0..k, which hold ``demos_per_task`` expert-labelled episodes per task. Runs of the
same method with different seeds are grouped; a curve point is the mean and the sample standard
deviation over seeds at the same round (the same number of demos for every seed of a method).
"""

from __future__ import annotations

import json
import math
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lerobot_mtdagger.errors import UserError
from lerobot_mtdagger.rounds import CONFIG_FILE, ExperimentDir

PER_RUN_FIELDS = ("seed", "output_dir", "resume", "progress", "workers")
"""Config fields that may differ between the runs of one method (they never change a result, or are
what the runs are repeated over)."""

BC_BUDGET_FIELDS = ("rounds", "scheduler")
"""Fields that may also differ between BC runs: the budget (``rounds``) and the unused scheduler."""


@dataclass
class CurvePoint:
    """Evaluation success of one method after one round, over seeds."""

    method: str
    round: int
    demos_per_task: float
    mean: float
    std: float
    seeds: int


@dataclass(frozen=True)
class RunProgress:
    """How far one run has got: its committed rounds and training phases against its last phase.

    Attributes:
        root: The experiment folder.
        rounds: Committed rounds (0 for a run that has just started).
        phases: Indices of the committed training phases.
        last_phase: The phase the run ends with: 0 for BC, ``rounds`` for DAgger (its config).
    """

    root: Path
    rounds: int
    phases: tuple[int, ...]
    last_phase: int

    @property
    def finished(self) -> bool:
        """Whether the last phase is committed."""
        return self.last_phase in self.phases

    def describe(self) -> str:
        """One line for a report: the run's folder name and how far it has got."""
        done = f"phases 0-{max(self.phases)}" if self.phases else "no phase yet"
        return f"{self.root.name}: {done} of 0-{self.last_phase}"


def run_progress(root: Path) -> RunProgress:
    """How far the run in ``root`` has got (a run still being written is read as it stands).

    Raises:
        UserError: If ``root`` has no ``config.json`` or holds a corrupt round.
    """
    path = Path(root) / CONFIG_FILE
    if not path.is_file():
        raise UserError(f"{root} is not a lerobot-mtdagger experiment (no {CONFIG_FILE}).")
    config = json.loads(path.read_text())
    experiment = ExperimentDir(root)
    last_phase = 0 if config.get("mode") == "bc" else int(config.get("rounds") or 0)
    return RunProgress(
        root=Path(root),
        rounds=len(experiment.committed_rounds()),
        phases=tuple(experiment.committed_phases()),
        last_phase=last_phase,
    )


RunPoints = tuple[str, int, list[tuple[int, float, float]]]
"""``(method, seed, [(round, mean demos per task, mean eval success), ...])`` of one run."""


def experiment_curve(root: Path, label: str | None = None) -> RunPoints:
    """The evaluated points of one experiment folder.

    Args:
        root: The experiment folder.
        label: The method name to report it under (default: its method, ``bc`` for BC).
    """
    experiment = ExperimentDir(root)
    record = experiment.read_round_record(0)
    points = []
    for round_index in experiment.committed_phases():
        phase = experiment.read_phase_record(round_index)
        if phase.eval_mean is not None:
            points.append((round_index, float(np.mean(phase.demos_per_task)), phase.eval_mean))
    name = _curve_name(label or record.method, record.method == "bc", float(np.mean(record.demos_so_far)))
    return name, record.seed, points


def _curve_name(method: str, is_bc: bool, demos_per_task: float) -> str:
    """BC at several budgets is one group per budget (a point each), named with its budget."""
    return f"{method} ({demos_per_task:g} demos/task)" if is_bc else method


def learning_curves(roots: Sequence[Path], labels: Mapping[Path, str] | None = None) -> list[CurvePoint]:
    """Groups experiments by method and averages their curves over seeds, round by round.

    Args:
        roots: Experiment folders.
        labels: Method name per folder where it is not the run's own (a variant of a method, e.g.
            BC with balanced sampling reported as ``bc-balanced`` beside ``bc``).

    Raises:
        ValueError: If two runs of one method used the same seed (a duplicate would bias the mean),
            their configs differ in more than the seed (``check_comparable``), or no run has an
            evaluated phase.
    """
    labels = labels or {}
    check_comparable(roots, labels)
    return average_runs([experiment_curve(Path(root), labels.get(Path(root))) for root in roots])


def is_bc(row: Mapping[str, Any]) -> bool:
    """Whether a results row comes from a one-round BC run (under any label)."""
    return bool(row.get("bc", row["method"] == "bc"))


def curves_from_rows(rows: Sequence[Mapping]) -> list[CurvePoint]:
    """The learning curves of a saved results table (``results.read_results``), as ``learning_curves``.

    Raises:
        ValueError: As ``average_runs``.
    """
    runs: dict[tuple[str, int], list[tuple[int, float, float]]] = defaultdict(list)
    for row in rows:
        name = _curve_name(row["method"], is_bc(row), float(row["demos_per_task_mean"]))
        point = (int(row["round"]), float(row["demos_per_task_mean"]), float(row["eval_success_mean"]))
        runs[(name, int(row["seed"]))].append(point)
    return average_runs([(name, seed, sorted(points)) for (name, seed), points in runs.items()])


def average_runs(runs: Sequence[RunPoints]) -> list[CurvePoint]:
    """Averages the runs of each method over seeds, round by round (mean and sample std).

    Raises:
        ValueError: If two runs of one method have the same seed, or no run has an evaluated point.
    """
    grouped: dict[str, dict[int, list[tuple[int, float, float]]]] = defaultdict(dict)
    for method, seed, points in runs:
        if seed in grouped[method]:
            raise UserError(f"Two {method} experiments with seed {seed}; give each run its own seed.")
        grouped[method][seed] = points
    curves = []
    for method, seeds in sorted(grouped.items()):
        by_round: dict[int, list[tuple[float, float]]] = defaultdict(list)
        for points in seeds.values():
            for round_index, demos, success in points:
                by_round[round_index].append((demos, success))
        for round_index, values in sorted(by_round.items()):
            demos = float(np.mean([d for d, _ in values]))
            successes = [s for _, s in values]
            std = float(np.std(successes, ddof=1)) if len(successes) > 1 else math.nan
            curves.append(
                CurvePoint(method, round_index, demos, float(np.mean(successes)), std, len(successes))
            )
    if not curves:
        raise UserError(
            f"None of the {len(runs)} experiment(s) has an evaluated phase (they ran with "
            "--eval_episodes=0?): evaluate their policies with `lerobot-mtdagger eval` or rerun them "
            "with --eval_episodes > 0."
        )
    return curves


def check_comparable(roots: Sequence[Path], labels: Mapping[Path, str] | None = None) -> dict[str, dict]:
    """Refuses to group runs of one method whose configs differ in more than ``PER_RUN_FIELDS``.

    BC runs may also differ in ``BC_BUDGET_FIELDS`` (one BC run per budget). A run given a label in
    ``labels`` is grouped under that label, not under its method.

    Returns:
        The config each method's runs share (without those fields), by method name.

    Raises:
        ValueError: Naming the method, the differing fields with their values and two such runs.
    """
    first_of_method: dict[str, tuple[Path, dict]] = {}
    for root in roots:
        root = Path(root)
        path = root / CONFIG_FILE
        if not path.is_file():
            raise UserError(f"{root} is not a lerobot-mtdagger experiment (no {CONFIG_FILE}).")
        config = json.loads(path.read_text())
        is_bc = config.get("mode") == "bc"
        method = (labels or {}).get(root) or ("bc" if is_bc else config.get("scheduler", {}).get("type"))
        ignored = PER_RUN_FIELDS + (BC_BUDGET_FIELDS if is_bc else ())
        shared = {key: value for key, value in config.items() if key not in ignored}
        if method not in first_of_method:
            first_of_method[method] = (root, shared)
            continue
        other_root, other = first_of_method[method]
        differing = config_differences(other, shared)
        if differing:
            raise UserError(
                f"Refusing to average {method} runs with different configs ({differing}) in {other_root} "
                f"and {root}: report them separately, give one set a label of its own (report "
                "--variants), or rerun them with the same options."
            )
    return {method: shared for method, (_, shared) in first_of_method.items()}


def config_differences(first: Mapping, second: Mapping) -> str:
    """``"key: a vs b, ..."`` for every top-level key whose value differs (empty when none does)."""
    differing = sorted(key for key in set(first) | set(second) if first.get(key) != second.get(key))
    return ", ".join(f"{key}: {first.get(key)!r} vs {second.get(key)!r}" for key in differing)


def markdown_table(curves: Sequence[CurvePoint]) -> str:
    """The curves as a markdown table (one row per method and round)."""
    lines = ["| method | round | expert demos per task | eval success (mean) | std over seeds | seeds |"]
    lines.append("|---|---:|---:|---:|---:|---:|")
    for point in curves:
        std = "n/a" if math.isnan(point.std) else f"{point.std:.3f}"
        cells = [
            point.method,
            point.round,
            f"{point.demos_per_task:.1f}",
            f"{point.mean:.3f}",
            std,
            point.seeds,
        ]
        lines.append("| " + " | ".join(str(c) for c in cells) + " |")
    return "\n".join(lines)
