"""Audits an experiment folder: every committed round against its data and its own record.

For each committed round ``verify_round`` checks the task vocabulary and its order, the episodes per
task actually stored, the cumulative demonstration counts, and for DAgger rounds that the allocation
recomputes from the record alone (``scheduler.allocation_mismatches``, through the method's
registered config class) and chains with the previous round: its measured success, the previous
phase's gain, the Kalman prior = the previous round's posterior.
"""

from __future__ import annotations

from pathlib import Path

from lerobot_mtdagger.records import RoundRecord
from lerobot_mtdagger.rounds import ExperimentDir, round_name
from lerobot_mtdagger.scheduler import allocation_mismatches


def stored_tasks(root: Path, num_tasks: int) -> tuple[list[str], list[int]]:
    """The task vocabulary (in task_index order) and the episodes per task index of a round dataset."""
    from lerobot.datasets.lerobot_dataset import LeRobotDatasetMetadata

    meta = LeRobotDatasetMetadata(f"local/{root.name}", root=root)
    order = [str(t) for t in meta.tasks.sort_values("task_index").index]
    lookup = {task: index for index, task in enumerate(order)}
    counts = [0] * num_tasks
    for tasks in meta.episodes["tasks"]:
        counts[lookup[tasks[0]]] += 1
    return order, counts


def verify_round(
    experiment: ExperimentDir, record: RoundRecord, previous: RoundRecord | None, committed_phases: set[int]
) -> list[str]:
    """Checks one committed round against its data and its own record.

    Args:
        experiment: The experiment folder.
        record: The round's record.
        previous: The previous round's record (None for round 0).
        committed_phases: Indices of the committed training phases.

    Returns:
        One message per problem, prefixed by the round's name; empty when the round checks out.
    """
    name = round_name(record.round)
    problems: list[str] = []
    order, stored = stored_tasks(experiment.round_root(record.round), len(record.task_names))
    if order != record.task_names:
        problems.append(f"task vocabulary {order} != record {record.task_names}")
    if stored != record.episodes_per_task:
        problems.append(f"dataset holds {stored} episodes per task, record says {record.episodes_per_task}")
    before = previous.demos_so_far if previous is not None else [0] * len(record.task_names)
    if record.demos_so_far != [a + b for a, b in zip(before, record.episodes_per_task, strict=True)]:
        problems.append("demos_so_far is not the running sum of episodes_per_task")
    if record.allocation is None:
        if record.round > 0:
            problems.append("a DAgger round without an allocation record")
    else:
        problems += allocation_mismatches(record.allocation)
        if record.allocation["episodes_per_task"] != record.episodes_per_task:
            problems.append(
                f"collected {record.episodes_per_task} != allocated {record.allocation['episodes_per_task']}"
            )
        problems += _chain_mismatches(experiment, record, previous, committed_phases)
    return [f"{name}: {problem}" for problem in problems]


def _chain_mismatches(
    experiment: ExperimentDir, record: RoundRecord, previous: RoundRecord | None, committed_phases: set[int]
) -> list[str]:
    """Checks that a round's scheduler inputs are the previous round's and phase's outputs."""
    problems = []
    k = record.round
    if k - 1 in committed_phases:
        gain = experiment.read_phase_record(k - 1).gain
        if record.gain != gain:
            problems.append(f"gain {record.gain} != phase {k - 1} gain {gain}")
    if k >= 2 and previous is not None:
        if record.success_rate != previous.learner_success:
            problems.append(
                f"success_rate {record.success_rate} != previous learner-only rollouts "
                f"{previous.learner_success}"
            )
        if previous.allocation is None or record.kalman_prior != previous.allocation["kalman_posterior"]:
            problems.append(f"Kalman prior is not round {k - 1}'s posterior")
    return problems


def verify_experiment(experiment: ExperimentDir) -> tuple[int, list[str]]:
    """Verifies every committed round of an experiment.

    Returns:
        The number of rounds verified and every problem found.
    """
    rounds = experiment.committed_rounds()
    phases = set(experiment.committed_phases())
    problems: list[str] = []
    previous = None
    for round_index in rounds:
        record = experiment.read_round_record(round_index)
        problems += verify_round(experiment, record, previous, phases)
        previous = record
    return len(rounds), problems
