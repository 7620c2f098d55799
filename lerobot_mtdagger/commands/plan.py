"""``lerobot-mtdagger plan``: the next collection session's episodes per task, or a plan checked.

Its options are ``PlanConfig`` (``planning/plan.py``).
"""

from __future__ import annotations

from lerobot_mtdagger.planning.plan import PlanConfig

__all__ = ["PlanConfig", "plan_command"]


def plan_command(config: PlanConfig) -> dict | list[str]:
    """Prints and writes the next session's plan, or (``--verify``) checks a plan; exits 1 on a problem."""
    from lerobot_mtdagger.planning.plan import make_plan, plan_table, verify_plan, write_plan

    if config.verify is not None:
        problems = verify_plan(config.verify)
        for problem in problems:
            print(f"PROBLEM {problem}")
        print(f"verified plan {config.verify}: {len(problems)} problem(s)")
        if problems:
            raise SystemExit(1)
        return problems
    plan = make_plan(config)
    write_plan(plan, config.output)
    print(plan_table(plan))
    print(f"plan file: {config.output}")
    return plan
