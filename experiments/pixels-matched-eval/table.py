"""run.sh's gate and outcomes for the pixel DAgger methods with matched training (evaluation seeds 0-2).

Written on 2026-11-28 with run.sh, before any of its runs and before ../pixels-dagger-epochs-dev had a
result. Two uses (``lab`` on the path: ``PYTHONPATH=experiments``), from the repository root:

- ``table.py --gate FILE`` reads ``../pixels-dagger-epochs-dev/table.py``'s output (FILE) and prints
  one line: ``run: ...`` when that study's rule switches the DAgger phases to epochs AND proposes a
  rerun of pixels-eval's DAgger methods; ``not run: matched training did not help by
  ../pixels-dagger-epochs-dev's rule ...`` when its final decision is anything else. Exit 1, saying
  why, while its output is not a final decision (no ``Decision:`` line, ``Decision: none yet``, or a
  decision resting on fewer than its 3 development seeds).
- ``table.py [FOLDER]`` prints the BC reuse check, the success table, the outcomes fixed in run.sh
  (each beside pixels-eval's fixed-steps number, the earlier protocol), each phase's passes per task
  and each task's loss before and after each phase. With FOLDER (``outputs/pixels-matched-eval``) it
  reads ``FOLDER/decision.txt`` and the runs in ``FOLDER/seed<k>/runs/``; without, the saved records
  here (``save_records.sh``): ``records/decision.txt`` and ``records/seed<k>/runs-records.tar.gz``.
  BC and the earlier protocol are read from ``../pixels-eval/records/``. Every outcome says
  "not finished" until all 9 runs (uniform, need, gain x seeds 0-2) have their phases 0-5. Where the
  gate proposed no rerun and ``gate-deviation.md`` says why the runs ran anyway (``one_run.sh``'s
  condition), it prints the gate's answer, then the outcomes, each reading marked as run by it.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
import sys
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lab.paired import paired_line
from lerobot_mtdagger.analysis.saved_records import ARCHIVE_NAME, saved_records_runs
from lerobot_mtdagger.analysis.stats import Interval, paired_difference
from lerobot_mtdagger.datasets.config_layout import flatten
from lerobot_mtdagger.datasets.experiment_dir import CONFIG_FILE
from lerobot_mtdagger.datasets.records import PhaseRecord
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.presets import preset_values

HERE = Path(__file__).resolve().parent
RECORDS = HERE / "records"
PIXELS_EVAL_RECORDS = HERE.parent / "pixels-eval" / "records"
DECISION_FILE = "decision.txt"
DEVIATION = HERE / "gate-deviation.md"  # why the runs ran though the gate proposed no rerun
PRESET = "metaworld-pixels"
METHODS = ("uniform", "need", "gain")
SEEDS = (0, 1, 2)
POINTS = (10, 20, 30, 40, 50, 60)  # demos per task: DAgger's phases 0-5, BC's budgets
WINDOW = (20, 30, 40, 50, 60)  # pixels-eval's window: DAgger's phases 1-5, BC's budgets 20-60
LAST = (60,)
PER_ROUND = 10  # demos per task: 10 in round 0, then 10 per round (the preset)
HARDEST = 3
CLAIM_SIZE = 0.05  # docs/results.md, "Verdicts": an interval narrow enough, about +-0.05, to have seen it
MATCHED = {"training.steps_rule": "epochs", "training.epochs": 10.0}
BC_TRAINING = {"training.sampling": "balanced", "training.steps_rule": "fixed"}
RUN_SPECIFIC = frozenset(
    {"mode", "output_dir", "seed", "resume", "progress", "scheduler.type", "dagger.rounds", "rollout.workers"}
)  # options that name a run rather than its training (BC at the budget of round k has k rounds), and
# the env worker count, which `compare` sets from the run's cores and which changes no collection or
# evaluation (tests/test_workers.py): the runs on both cores store 2 where pixels-eval's BC stored 0
FROM_COMMAND_LINE = frozenset({"dagger.rounds", "rollout.eval_episodes"})  # not the preset's values
NOT_FINISHED = "not finished"
EARLIER = "earlier protocol (pixels-eval, 1 500 fixed steps per phase)"
DAGGER_RUN = re.compile(r"(uniform|need|gain)-seed(\d+)")
BC_RUN = re.compile(r"bc-(\d+)demos-seed(\d+)")

# ../pixels-dagger-epochs-dev/table.py: the start of its decision() lines, and its paired lines.
DEV = "../pixels-dagger-epochs-dev"
DEV_SWITCH = "Decision: the preset's DAgger phases switch to epochs (10 passes)"
DEV_STAYS = "Decision: the preset stays fixed"
DEV_PROPOSED = "a pixels-eval rerun is proposed"
DEV_NOT_PROPOSED = "a pixels-eval rerun is not proposed"
DEV_PRIMARY = "primary: epochs - fixed: "
DEV_AGAINST_BC = "epochs - balanced BC: "
DEV_BC_GAP = re.compile(r"epochs - BC at 60 ([+-]\S+?):")
DEV_SEEDS = 3  # its development seeds 100, 101, 102
NOT_RUN = f"matched training did not help by {DEV}'s rule"


class NotDecidedError(ValueError):
    """The development study's output is not (yet) a final decision."""


@dataclass(frozen=True)
class Gate:
    """What run.sh does with the development study's decision.

    Attributes:
        run: Whether this study's runs start.
        line: The line run.sh logs (``run: ...`` or ``not run: ...``).
    """

    run: bool
    line: str


def seeds_behind(text: str, prefix: str) -> int:
    """How many per-seed differences the paired line starting with ``prefix`` holds (0: none)."""
    for line in text.splitlines():
        if line.startswith(prefix):
            per_seed, separator, _ = line[len(prefix) :].partition(";")
            return len(per_seed.split(" / ")) if separator else 0
    return 0


def gate(text: str) -> Gate:
    """run.sh's gate on ``../pixels-dagger-epochs-dev/table.py``'s output.

    Raises:
        NotDecidedError: While the output is not a final decision, saying why.
    """
    decisions = [line for line in text.splitlines() if line.startswith("Decision: ")]
    if len(decisions) != 1:
        raise NotDecidedError(f"{len(decisions)} 'Decision:' lines, where a final output has one")
    decision = decisions[0]
    seeds = seeds_behind(text, DEV_PRIMARY)
    if seeds < DEV_SEEDS:
        raise NotDecidedError(
            f"'{DEV_PRIMARY.strip()}' rests on {seeds} of its {DEV_SEEDS} seeds ({decision})"
        )
    if decision.startswith(DEV_STAYS):
        return Gate(
            False,
            f"not run: {NOT_RUN} (the preset stays fixed), so this study is not run. {decision}",
        )
    if not decision.startswith(DEV_SWITCH):
        raise NotDecidedError(f"an unknown decision: {decision}")
    against_bc = seeds_behind(text, DEV_AGAINST_BC)
    gap = DEV_BC_GAP.search(decision)
    if against_bc < DEV_SEEDS or gap is None or not math.isfinite(float(gap.group(1))):
        raise NotDecidedError(
            f"epochs - balanced BC at 60 rests on {against_bc} of {DEV_SEEDS} seeds ({decision})"
        )
    if DEV_NOT_PROPOSED in decision:
        return Gate(
            False,
            f"not run: {NOT_RUN} (the DAgger phases switch to epochs, but epochs' phase 5 is more than "
            f"0.02 below balanced BC at 60 demos per task, so the rule proposes no rerun of pixels-eval), "
            f"so this study is not run. {decision}",
        )
    if DEV_PROPOSED in decision:
        return Gate(
            True, f"run: {DEV} switches the DAgger phases to epochs and proposes this rerun. {decision}"
        )
    raise NotDecidedError(f"no rerun clause in: {decision}")


@dataclass
class Runs:
    """One study's runs, read from their records.

    Attributes:
        dagger: ``{(method, seed): {phase: record}}``.
        bc: ``{(seed, demos per task): the BC run's record}``.
        configs: ``{run name: its config.json, flattened to dotted options}``.
    """

    dagger: dict[tuple[str, int], dict[int, PhaseRecord]] = field(default_factory=dict)
    bc: dict[tuple[int, int], PhaseRecord] = field(default_factory=dict)
    configs: dict[str, dict[str, Any]] = field(default_factory=dict)


def read_runs(folders: Iterable[Path]) -> Runs:
    """The DAgger and BC runs among ``folders`` (each a run's records: config.json, policies/)."""
    runs = Runs()
    for folder in folders:
        dagger, bc = DAGGER_RUN.fullmatch(folder.name), BC_RUN.fullmatch(folder.name)
        if dagger is None and bc is None:
            continue
        runs.configs[folder.name] = flatten(json.loads((folder / CONFIG_FILE).read_text()))
        phases = {}
        for path in sorted(folder.glob("policies/round-*/training.json")):
            record = PhaseRecord.from_dict(json.loads(path.read_text()), where=str(path))
            phases[record.round] = record
        if dagger is not None:
            runs.dagger[(dagger.group(1), int(dagger.group(2)))] = phases
        elif 0 in phases:
            runs.bc[(int(bc.group(2)), int(bc.group(1)))] = phases[0]
    return runs


def study_run_folders(folder: Path | None) -> list[Path]:
    """This study's runs: ``folder/seed<k>/runs/*``, or the saved archives ``records/seed<k>/``."""
    if folder is not None:
        return sorted(p for p in folder.glob("seed*/runs/*") if (p / CONFIG_FILE).is_file())
    return [
        run
        for archive in sorted(RECORDS.glob(f"seed*/{ARCHIVE_NAME}"))
        for run in saved_records_runs(archive)
    ]


def record_at(runs: Runs, arm: str, seed: int, demos: int) -> PhaseRecord | None:
    """The evaluated phase of ``arm`` on ``seed`` at ``demos`` per task (DAgger: phase demos/10 - 1)."""
    if arm == "bc":
        record = runs.bc.get((seed, demos))
    else:
        record = runs.dagger.get((arm, seed), {}).get(demos // PER_ROUND - 1)
    return record if record is not None and record.eval is not None else None


def success(record: PhaseRecord, tasks: Sequence[int] | None = None) -> float:
    """Mean evaluation success over every task, or over ``tasks``."""
    per_task = record.eval["success"]
    return float(np.mean(per_task if tasks is None else [per_task[t] for t in tasks]))


def mean_over(runs: Runs, arm: str, seed: int, points: Sequence[int], tasks: Sequence[int] | None) -> float:
    """Mean success over ``points`` (demos per task); NaN unless every one was evaluated."""
    records = [record_at(runs, arm, seed, demos) for demos in points]
    if any(record is None for record in records):
        return math.nan
    return float(np.mean([success(record, tasks) for record in records]))


def missing_runs(runs: Runs) -> list[str]:
    """This study's runs without every evaluated phase 0-5, per method (``need seeds 1, 2 (phases 4, 5)``)."""
    missing = []
    for method in METHODS:
        absent_runs, cut_runs = [], []
        for seed in SEEDS:
            absent = [d // PER_ROUND - 1 for d in POINTS if record_at(runs, method, seed, d) is None]
            if len(absent) == len(POINTS):
                absent_runs.append(str(seed))
            elif absent:
                cut_runs.append(f"{method} seed {seed} (phases {', '.join(map(str, absent))})")
        if absent_runs:
            missing.append(f"{method} seed(s) {', '.join(absent_runs)}")
        missing += cut_runs
    return missing


def hardest_tasks(earlier: Runs) -> dict[int, list[int]]:
    """pixels-eval's rule on its own runs: per seed, its uniform phase 0's 3 lowest (ties: task order)."""
    hardest = {}
    for seed in SEEDS:
        first = earlier.dagger[("uniform", seed)][0].eval["success"]
        hardest[seed] = sorted(range(len(first)), key=lambda t: (first[t], t))[:HARDEST]
    return hardest


def task_names(runs: Runs) -> list[str]:
    """The suite's task names (from any evaluated phase)."""
    for record in [*runs.bc.values(), *(r for phases in runs.dagger.values() for r in phases.values())]:
        if record.eval is not None:
            return list(record.eval["task_names"])
    raise ValueError("no evaluated phase to read the task names from")


def short(name: str) -> str:
    """A task's name without its version (``push-v3`` -> ``push``)."""
    return re.sub(r"-v\d+$", "", name)


def run_defaults() -> dict[str, Any]:
    """Every option of a run at its default value (an option added since pixels-eval ran keeps it)."""
    return flatten(dataclasses.asdict(RunConfig()))


def differences(config: Mapping[str, Any], reference: Mapping[str, Any], skip: Iterable[str]) -> list[str]:
    """``option: value (reference value)`` for each option of ``reference`` that ``config`` sets otherwise."""
    skipped = set(skip)
    return [
        f"{key}: {config.get(key)!r} ({reference[key]!r})"
        for key in sorted(reference)
        if key not in skipped and config.get(key) != reference[key]
    ]


def bc_reuse_check(earlier: Runs, study: Runs) -> list[str]:
    """Why pixels-eval's BC can stand as this study's BC, checked on the stored configs; problems named.

    BC's training is unchanged when every BC run of pixels-eval stored the same options, sampled
    ``balanced`` with the fixed steps rule, today's preset still fills the values they stored in a BC
    run (its DAgger phases make 10 passes since the development study; its BC keeps fixed steps), and
    every run of this study stored them too but for the matched training (options added since
    pixels-eval ran at their defaults).

    Returns:
        The problems found (empty: the reuse holds).
    """
    bc = {name: config for name, config in earlier.configs.items() if BC_RUN.fullmatch(name)}
    if not bc:
        return ["pixels-eval's records hold no BC run's config.json"]
    reference_name = sorted(bc)[0]
    reference = bc[reference_name]
    problems = [
        f"{name} differs from {reference_name}: {difference}"
        for name, config in sorted(bc.items())
        for difference in differences(config, reference, RUN_SPECIFIC)
    ]
    problems += [
        f"BC's {key} is {reference.get(key)!r}, not {value!r}"
        for key, value in BC_TRAINING.items()
        if reference.get(key) != value
    ]
    problems += [
        f"today's {PRESET} preset fills {key}={value!r} for BC, BC's runs stored {reference.get(key)!r}"
        for key, value in preset_values(PRESET, "bc").items()
        if key not in FROM_COMMAND_LINE and reference.get(key) != value
    ]
    defaults = run_defaults()
    for name, config in sorted(study.configs.items()):
        problems += [f"{name} does not train matched: {d}" for d in differences(config, MATCHED, ())]
        problems += [
            f"{name} differs from BC: {d}" for d in differences(config, reference, {*RUN_SPECIFIC, *MATCHED})
        ]
        added = {key: defaults.get(key) for key in config if key not in reference and key not in RUN_SPECIFIC}
        problems += [
            f"{name} sets an option added since pixels-eval: {d}" for d in differences(config, added, ())
        ]
    return problems


def reading(interval: Interval) -> str:
    """run.sh's reading of a paired interval of ``method - baseline`` (the claim: method ahead)."""
    if interval.low > 0:
        return "reproduced (the interval is above 0)"
    if interval.high < 0:
        return "reversed (the interval is below 0, under matched training)"
    if interval.high < CLAIM_SIZE:
        return f"not reproduced (the interval holds 0 and lies below +{CLAIM_SIZE:.2f})"
    return f"inconclusive (the interval holds 0 and reaches +{CLAIM_SIZE:.2f} or more)"


@dataclass(frozen=True)
class Comparison:
    """One outcome fixed in run.sh: ``arm - baseline`` in mean success over ``points``.

    Attributes:
        kind: ``primary`` or ``secondary``.
        arm: The method.
        baseline: ``bc`` or ``uniform``.
        points: Demos per task averaged over.
        hardest: Over each seed's 3 hardest tasks only.
        added: Added here (not one of pixels-eval's outcomes).
    """

    kind: str
    arm: str
    baseline: str
    points: tuple[int, ...]
    hardest: bool = False
    added: bool = False

    @property
    def name(self) -> str:
        """The outcome's label."""
        baseline = "BC" if self.baseline == "bc" else self.baseline
        if self.hardest:
            where = f"the {HARDEST} hardest tasks of each seed at {self.points[-1]} demos per task"
        else:
            where = f"mean success over {self.points[0]}-{self.points[-1]} demos per task"
        note = " (added here)" if self.added else ""
        return f"{self.kind}{note}: {self.arm} - {baseline}, {where}"


COMPARISONS = (
    Comparison("primary", "need", "bc", WINDOW),
    Comparison("primary", "need", "uniform", WINDOW),
    Comparison("secondary", "gain", "bc", WINDOW),
    Comparison("secondary", "gain", "uniform", WINDOW),
    Comparison("secondary", "need", "uniform", LAST, hardest=True),
    Comparison("secondary", "gain", "uniform", LAST, hardest=True),
    Comparison("secondary", "need", "bc", LAST, hardest=True, added=True),
    Comparison("secondary", "uniform", "bc", LAST, hardest=True, added=True),
)


def pairs(runs: Runs, comparison: Comparison, hardest: Mapping[int, list[int]]) -> list[tuple[float, float]]:
    """``(arm, baseline)`` per seed for ``comparison`` (NaN where a point is missing)."""
    result = []
    for seed in SEEDS:
        tasks = hardest[seed] if comparison.hardest else None
        result.append(
            (
                mean_over(runs, comparison.arm, seed, comparison.points, tasks),
                mean_over(runs, comparison.baseline, seed, comparison.points, tasks),
            )
        )
    return result


def outcome_lines(
    comparison: Comparison,
    matched: Runs,
    earlier: Runs,
    hardest: Mapping[int, list[int]],
    blocked: str | None,
    caveat: str = "",
) -> list[str]:
    """One outcome under matched training, its reading, and pixels-eval's number beside it.

    Args:
        comparison: The outcome.
        matched: This study's DAgger runs with pixels-eval's BC.
        earlier: pixels-eval's runs.
        hardest: Each seed's hardest tasks.
        blocked: Why no number is given yet (``not finished (...)``), or ``None``.
        caveat: Appended to the reading (the gate deviation, where the runs ran by it).
    """
    earlier_line = paired_line(f"  {EARLIER}", pairs(earlier, comparison, hardest))
    if blocked is not None:
        return [f"{comparison.name}: {blocked}", "  reading: not finished", earlier_line]
    values = pairs(matched, comparison, hardest)
    first, second = zip(*values, strict=True)
    interval = paired_difference(first, second)
    return [paired_line(comparison.name, values), f"  reading: {reading(interval)}{caveat}", earlier_line]


def success_table(matched: Runs, earlier: Runs) -> list[str]:
    """Mean success over the 3 seeds at every point, per arm ("not finished" where a seed lacks it)."""
    rows = [(f"{method}, matched (epochs, 10 passes per phase)", matched, method) for method in METHODS] + [
        (f"{method}, {EARLIER}", earlier, method) for method in METHODS
    ]
    rows.append(("BC (pixels-eval's runs, reused)", earlier, "bc"))
    lines = [
        "| arm | " + " | ".join(str(p) for p in POINTS) + " |  (demos per task; mean success over seeds 0-2)",
        "|---|" + "---:|" * len(POINTS),
    ]
    for label, runs, arm in rows:
        cells = []
        for demos in POINTS:
            values = [mean_over(runs, arm, seed, (demos,), None) for seed in SEEDS]
            cells.append(NOT_FINISHED if any(math.isnan(v) for v in values) else f"{np.mean(values):.3f}")
        lines.append(f"| {label} | {' | '.join(cells)} |")
    return lines


def passes_over_frames(record: PhaseRecord, config: Mapping[str, Any]) -> float:
    """Passes over all the phase's frames: steps x batch / frames."""
    return record.steps * config["policy.batch_size"] / record.frames


def per_task_passes(record: PhaseRecord, tasks: Sequence[str], hardest: Sequence[int]) -> tuple[str, str]:
    """``mean [min-max]`` of the phase's passes per task, and the hardest tasks' ("-": not recorded)."""
    passes = record.passes_per_task
    if passes is None or any(p is None for p in passes):
        return "-", "-"
    summary = f"{np.mean(passes):.2f} [{min(passes):.2f}-{max(passes):.2f}]"
    return summary, ", ".join(f"{short(tasks[t])} {passes[t]:.2f}" for t in hardest)


def passes_table(study: Runs, tasks: Sequence[str], hardest: Mapping[int, list[int]]) -> list[str]:
    """Each phase of this study's runs: data, steps, passes over all frames and per task."""
    lines = [
        "| arm | seed | phase | demos/task | frames | steps | passes, all frames | passes per task: mean "
        "[min-max] | the seed's 3 hardest tasks |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for method in METHODS:
        for seed in SEEDS:
            config = study.configs.get(f"{method}-seed{seed}", {})
            for phase, record in sorted(study.dagger.get((method, seed), {}).items()):
                summary, hard = per_task_passes(record, tasks, hardest[seed])
                lines.append(
                    f"| {method} | {seed} | {phase} | {np.mean(record.demos_per_task):g} | {record.frames} | "
                    f"{record.steps} | {passes_over_frames(record, config):.2f} | {summary} | {hard} |"
                )
    return lines


def earlier_passes_table(earlier: Runs) -> list[str]:
    """pixels-eval's passes over all frames (steps x batch / frames): its records have no per-task passes."""
    lines = [
        "| arm | seed | " + " | ".join(str(p) for p in POINTS) + " |  (demos per task)",
        "|---|---:|" + "---:|" * len(POINTS),
    ]
    for arm in ("bc", *METHODS):
        for seed in SEEDS:
            cells = []
            for demos in POINTS:
                record = record_at(earlier, arm, seed, demos)
                name = f"bc-{demos}demos-seed{seed}" if arm == "bc" else f"{arm}-seed{seed}"
                cells.append(
                    "-" if record is None else f"{passes_over_frames(record, earlier.configs[name]):.2f}"
                )
            lines.append(f"| {'BC' if arm == 'bc' else arm} | {seed} | {' | '.join(cells)} |")
    return lines


def loss(value: float | None) -> str:
    """A per-task loss to 3 significant digits ("-": none)."""
    return "-" if value is None else f"{value:.3g}"


def loss_table(study: Runs, tasks: Sequence[str]) -> list[str]:
    """Each task's loss before each phase (phase 0 ``loss_start``, later ``loss_previous``) and after it."""
    lines = [
        "| arm | seed | phase | "
        + " | ".join(short(t) for t in tasks)
        + " |  (loss before -> after the phase)",
        "|---|---:|---:|" + "---:|" * len(tasks),
    ]
    for method in METHODS:
        for seed in SEEDS:
            for phase, record in sorted(study.dagger.get((method, seed), {}).items()):
                before = record.loss_start if phase == 0 else (record.loss_previous or [None] * len(tasks))
                cells = [f"{loss(b)} -> {loss(a)}" for b, a in zip(before, record.loss_end, strict=True)]
                lines.append(f"| {method} | {seed} | {phase} | {' | '.join(cells)} |")
    return lines


def deviation_lines(decided: Gate, deviation: Path | None) -> tuple[list[str], str] | None:
    """The lines saying the runs ran by ``deviation`` though the gate said no, and each reading's caveat.

    ``None`` where the gate's answer stands (it ran them, the preset stays fixed, or no deviation file):
    the cases ``one_run.sh`` runs by are the ones reported here.
    """
    if decided.run or deviation is None or DEV_NOT_PROPOSED not in decided.line:
        return None
    lines = [
        f"Gate (run.sh, pre-specified): {decided.line}",
        f"The runs ran anyway, by a deviation declared after the development result and before any run "
        f"({deviation.name}); every reading below carries it.",
    ]
    return lines, f" [run by the gate deviation, {deviation.name}]"


def report(decision_text: str, study: Runs, earlier: Runs, deviation: Path | None = None) -> list[str]:
    """Everything ``table.py [FOLDER]`` prints, as lines (the gate first).

    Args:
        decision_text: The development study's decision (``decision.txt``).
        study: This study's runs.
        earlier: pixels-eval's runs.
        deviation: The file that says why the runs ran though the gate proposed no rerun, if it exists.
    """
    decided = gate(decision_text)
    lines = [line for line in decision_text.splitlines() if line.startswith("Decision: ")]
    caveat = ""
    if not decided.run:
        by_deviation = deviation_lines(decided, deviation)
        if by_deviation is None:
            return [*lines, f"Verdict: {decided.line}"]
        lines += by_deviation[0]
        caveat = by_deviation[1]
    tasks = task_names(earlier)
    hardest = hardest_tasks(earlier)
    matched = Runs(dagger=study.dagger, bc=earlier.bc)
    problems = bc_reuse_check(earlier, study)
    check = "holds" if not problems else "FAILS: " + "; ".join(problems)
    lines += [
        f"BC reuse check (pixels-eval's BC configs, today's {PRESET} preset, this study's runs): {check}",
        "Hardest tasks (pixels-eval's rule on its uniform phase 0): "
        + "; ".join(f"seed {s} {', '.join(short(tasks[t]) for t in hardest[s])}" for s in SEEDS),
        "",
        *success_table(matched, earlier),
        "",
    ]
    missing = missing_runs(study)
    for comparison in COMPARISONS:
        blocked = f"{NOT_FINISHED} (missing: {'; '.join(missing)})" if missing else None
        if blocked is None and problems and comparison.baseline == "bc":
            blocked = "not read: the BC reuse check fails (above)"
        lines += outcome_lines(comparison, matched, earlier, hardest, blocked, caveat)
    lines += [
        "",
        "Passes per phase, this study (passes per task: the frames its steps drew over its frames):",
        *passes_table(study, tasks, hardest),
        "",
        f"Passes over all frames per phase, {EARLIER}:",
        *earlier_passes_table(earlier),
        "",
        "Loss per task before and after each phase, this study:",
        *loss_table(study, tasks),
    ]
    return lines


def main(argv: Sequence[str]) -> int:
    """``--gate FILE`` or ``[FOLDER]``; see the module's docstring."""
    if argv[:1] == ["--gate"]:
        try:
            decided = gate(Path(argv[1]).read_text())
        except NotDecidedError as error:
            print(f"{argv[1]}: no final decision of {DEV} yet: {error}", file=sys.stderr)
            return 1
        print(decided.line)
        return 0
    folder = Path(argv[0]) if argv else None
    decision_file = (folder if folder is not None else RECORDS) / DECISION_FILE
    if not decision_file.is_file():
        print(f"No decision yet: {decision_file} does not exist (run.sh writes it once {DEV} has decided).")
        return 0
    study = read_runs(study_run_folders(folder))
    earlier = read_runs(saved_records_runs(PIXELS_EVAL_RECORDS))
    deviation = DEVIATION if DEVIATION.is_file() else None
    print("\n".join(report(decision_file.read_text(), study, earlier, deviation)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
