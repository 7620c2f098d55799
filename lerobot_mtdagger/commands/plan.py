"""``lerobot-mtdagger plan``: the next collection session's episodes per task, or a plan checked.

Its options are ``PlanConfig`` (``configs/plan.py``; defined in ``planning/plan.py``).
"""

from __future__ import annotations

from pathlib import Path

from lerobot_mtdagger.analysis.headroom import TaskPoint, best_splits, fit_curves, headroom_at
from lerobot_mtdagger.commands.configs.plan import PlanConfig
from lerobot_mtdagger.planning.plan import make_plan, plan_table, read_plan, verify_plan, write_plan
from lerobot_mtdagger.utils.errors import UserError

__all__ = ["PlanConfig", "plan_command"]


def plan_command(config: PlanConfig) -> dict | list[str]:
    """Prints and writes the next session's plan, or (``--verify``) checks a plan; exits 1 on a problem."""
    if config.verify is not None:
        problems = verify_plan(config.verify)
        for problem in problems:
            print(f"PROBLEM {problem}")
        print(f"verified plan {config.verify}: {len(problems)} problem(s)")
        if problems:
            raise SystemExit(1)
        return problems
    assert config.output is not None  # PlanConfig refuses a plan without --output
    plan = make_plan(config)
    write_plan(plan, config.output)
    print(plan_table(plan))
    print("\n".join(history_headroom_lines(plan)))
    print(f"plan file: {config.output}")
    return plan


def history_headroom_lines(plan: dict) -> list[str]:
    """The headroom of the sessions so far (``analysis/headroom.py``), or one line saying why not yet.

    Each plan of the chain (this one and its ``--previous`` ones) gives one point per task: the success
    of the session's policy over its own episodes, at the expert demos it was trained on.
    """
    points: list[TaskPoint] = []
    session: dict | None = plan
    while session is not None:
        measured, demos = session["measurements"], session.get("demos")
        for task, (n, successes, d) in enumerate(
            zip(measured["policy_episodes"], measured["successes"], demos or [], strict=False)
        ):
            if n > 0:
                points.append(TaskPoint(task, 0, int(round(d)), successes / n, n))
        previous = session.get("previous")
        try:
            session = None if previous is None else read_plan(Path(previous["path"]))
        except UserError as error:
            return [f"headroom: the chain of plans is broken ({error})"]
    try:
        splits = best_splits(fit_curves(points, plan["tasks"]))
    except UserError as error:
        return [
            f"headroom: not yet ({error}); it needs two or more sessions of each task, with --initial_demos."
        ]
    curves = splits.curves
    budget = min(max(int(round(sum(plan["demos"]) / len(plan["demos"]))), curves.low), curves.high)
    headroom = headroom_at(splits, budget)
    match = "n/a" if headroom.demos_to_match is None else f"{headroom.demos_to_match:.1f}"
    return [
        f"headroom at {budget} demos per task (curves of {len({p.demos for p in points})} budgets, "
        f"measured {curves.low}-{curves.high}): an even split {headroom.even:.3f}, the best split of the "
        f"same demos {headroom.best:.3f} ({headroom.gain:+.3f}), which matches the even split with {match} "
        "per task; a scheduler can gain at most this."
    ]
