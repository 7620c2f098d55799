"""The ``lerobot-mtdagger`` command.

Usage: ``lerobot-mtdagger <command> [--option=value ...]``. Options are parsed by draccus, so nested
configs are set with dots, for example ``--scheduler.type=need --scheduler.temperature=0.5``.
``COMMANDS`` names each command's modules and ``HELP`` is the page ``lerobot-mtdagger --help`` prints;
``docs/usage.md`` shows each command in use.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import Any

from lerobot_mtdagger.commands.configs import ChecksPaths
from lerobot_mtdagger.commands.console import configure_console_logging, error_line
from lerobot_mtdagger.runner.configs import RUN_OPTION_RENAMES, SUITE_OPTION_RENAMES, renamed_option_error
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.parsing import parse_options
from lerobot_mtdagger.utils.registry import resolve

COMMANDS_PACKAGE = "lerobot_mtdagger.commands"

COMMANDS: dict[str, tuple[str, str]] = {
    "run": ("configs.run:RunConfig", "run:run_experiment"),
    "compare": ("configs.compare:CompareConfig", "compare:compare_command"),
    "eval": ("configs.eval:EvalConfig", "eval:eval_command"),
    "shift": ("configs.shift:ShiftConfig", "shift:shift_command"),
    "verify": ("configs.verify:VerifyConfig", "verify:verify_command"),
    "merge": ("configs.merge:MergeConfig", "merge:merge_command"),
    "push": ("configs.push:PushConfig", "push:push_command"),
    "report": ("configs.report:ReportConfig", "report:report_command"),
    "plan": ("configs.plan:PlanConfig", "plan:plan_command"),
    "replay": ("configs.replay:ReplayConfig", "replay:replay_command"),
    "records": ("configs.records:RecordsConfig", "records:records_command"),
    "demo": ("configs.demo:DemoConfig", "demo:run_demo"),
}
"""Each command's options (``commands/configs/<command>.py``) and body (``commands/<command>.py``), as
``module:attribute`` under ``COMMANDS_PACKAGE``: the body is imported once the options parsed and checked."""


HELP = """Options are parsed by draccus: nested configs are set with dots (``--scheduler.temperature=0.5``).

Commands (``lerobot-mtdagger <command> --help`` lists a command's options):
    run: one Multitask DAgger experiment (``--preset``, ``--suite.name``, ``--scheduler.type``,
        ``--dagger.rounds``, ``--output_dir``, ``--resume``, ...), or behaviour cloning (``--mode=bc``).
    eval: success per task of a pretrained policy (``--policy_path``, ``--suite.name``, ``--episodes``).
    shift: a pretrained policy's action error on its own rollouts' states against on the expert's, per task.
    verify: recompute every round's allocation from its record (``--experiment_dir``).
    merge: rounds 0..k as one LeRobotDataset (``--experiment_dir``, ``--output``).
    compare: every method over every seed, and BC at every budget, as runs in a process pool, then
        the results table (``--methods``, ``--seeds``, ``--bc_budgets``, ``--jobs``, ``--output_dir``).
    report: eval success against expert demos per method over seeds, figures and paired differences.
    push: round datasets and policies to the Hub (``--experiment_dir``, ``--repo_id``, ``--policy_repo_id``).
    plan: the next collection session's episodes per task from LeRobot datasets of the policy's
        episodes (``--datasets``, ``--budget``, ``--output``); ``--verify=PLAN`` recomputes a plan.
    replay: the schedulers replayed against measured per-task learning curves (``--records``): the
        share of the headroom each captures and the seeds a study needs to see it.
    records: save and compact a study's run records (``--action``, ``--source``, ``--dest``).
    demo: the scheduler on synthetic tasks, each round's allocation (no simulator, no policy).
"""


def command_part(spec: str) -> Any:
    """The config class or body function a ``COMMANDS`` entry names, its module imported."""
    return resolve(f"{COMMANDS_PACKAGE}.{spec}")


def _usage() -> str:
    """The page of ``lerobot-mtdagger --help``: the command names, then ``HELP``."""
    names = ", ".join(COMMANDS)
    return f"usage: lerobot-mtdagger <command> [--option=value ...]\ncommands: {names}\n{HELP}"


OPTION_RENAMES: dict[str, dict[str, str]] = {
    "run": RUN_OPTION_RENAMES,
    "compare": RUN_OPTION_RENAMES,
    "eval": SUITE_OPTION_RENAMES,
    "shift": SUITE_OPTION_RENAMES,
}
"""Each command's options that moved into a group (refused with the new spelling named)."""

DEBUG_FLAG = "--debug"
"""Shows the traceback of a user error (for reporting a problem)."""


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the console script.

    A user error (``errors.UserError``: a bad option, path or file) prints one line
    ``lerobot-mtdagger <command>: error: <what and how to fix>`` and returns 2; with ``--debug`` it
    raises, with its traceback. Any other exception is a bug and raises.

    Args:
        argv: Arguments after the program name; ``sys.argv[1:]`` when None.

    Returns:
        The process exit status.
    """
    args = list(sys.argv[1:] if argv is None else argv)
    debug = DEBUG_FLAG in args
    args = [arg for arg in args if arg != DEBUG_FLAG]
    if not args or args[0] in ("-h", "--help", "help"):
        print(_usage())
        return 0
    command, options = args[0], args[1:]
    if command not in COMMANDS:
        print(f"unknown command {command!r}\n{_usage()}", file=sys.stderr)
        return 2
    renamed = renamed_option_error(options)
    if renamed is not None:
        print(error_line(command, renamed), file=sys.stderr)
        return 2
    configure_console_logging()
    try:
        run_command(command, options)
    except UserError as error:
        if debug:
            raise
        print(error_line(command, error), file=sys.stderr)
        return 2
    return 0


def run_command(command: str, options: list[str]) -> None:
    """Parses a command's options, checks the paths they name, then imports and runs its body.

    Raises:
        UserError: On a bad option, path or file.
    """
    config_spec, body_spec = COMMANDS[command]
    passed: list[str] = []
    if command == "compare" and ("--help" in options or "-h" in options):
        options = ["--help"]  # compare's own options; `run --help` lists those passed to each run
    elif command == "compare":  # compare's own options; every other option goes to each run
        options, passed = command_part("configs.compare:split_arguments")(options)
    renamed = renamed_option_error(passed if command == "compare" else options, OPTION_RENAMES.get(command))
    if renamed is not None:
        raise UserError(renamed)
    config = parse_options(command_part(config_spec), options, f"lerobot-mtdagger {command}")
    if isinstance(config, ChecksPaths):
        config.check_paths()
    function = command_part(body_spec)
    function(config, passed) if command == "compare" else function(config)


if __name__ == "__main__":
    sys.exit(main())
