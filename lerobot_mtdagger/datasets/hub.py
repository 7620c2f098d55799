"""Pushing a Multitask DAgger experiment to the Hugging Face Hub, one git revision per round.

Round k is one commit of the dataset repo holding exactly round k's files and a card (``README.md``)
of rounds 0..k, tagged ``round-{k:03d}``: ``LeRobotDataset(repo_id, revision="round-002")`` loads
round 2. Training phase k goes to an optional model repo, tagged the same way. Other files in the
repos are kept. Re-pushing is allowed: an existing tag stays on its first commit, which holds the
same files, since committed rounds never change.
"""

from __future__ import annotations

import contextlib
import logging
import os
import shutil
import tempfile
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

from huggingface_hub import DatasetCardData, HfApi

from lerobot_mtdagger.datasets.experiment_dir import CONFIG_FILE, ExperimentDir, round_name
from lerobot_mtdagger.datasets.migrations import stored_option
from lerobot_mtdagger.datasets.push_config import PushConfig
from lerobot_mtdagger.datasets.records import PhaseRecord, RoundRecord
from lerobot_mtdagger.datasets_cards import card_template
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.hub import network_errors
from lerobot_mtdagger.utils.markdown import markdown_table

logger = logging.getLogger(__name__)

CARD_FILE = "README.md"
CARD_TAGS = ("LeRobot", "mtdagger", "dagger", "multitask")
DATASET_DELETE_PATTERNS = ("data/**", "meta/**", "videos/**")
POLICY_DELETE_PATTERNS = ("*.json", "*.safetensors")
NOT_AVAILABLE = "n/a"


# -------------------------------------------------------------------------------------------------
# Dataset card
# -------------------------------------------------------------------------------------------------


def card_metadata_yaml() -> str:
    """The card's YAML front matter (without the ``---`` fences), as LeRobot writes it for datasets."""
    card_data = DatasetCardData(
        license="apache-2.0",
        task_categories=["robotics"],
        tags=list(CARD_TAGS),
        configs=[{"config_name": "default", "data_files": "data/*/*.parquet"}],
    )
    return card_data.to_yaml()


def _cell(value: Any) -> str:
    """A card table cell: floats with three decimals, None as ``n/a`` (pipes are escaped by the table)."""
    if value is None:
        return NOT_AVAILABLE
    if isinstance(value, float):
        return f"{value:.3f}"
    return str(value)


def card_table(header: Sequence[Any], rows: Sequence[Sequence[Any]]) -> str:
    """A card's markdown table: floats with three decimals, None as ``n/a`` (``markdown.markdown_table``)."""
    return markdown_table([_cell(h) for h in header], [[_cell(v) for v in row] for row in rows])


def task_table(task_names: Sequence[str]) -> str:
    """Table of the task vocabulary: task_index and name."""
    return card_table(["task_index", "task"], [[i, name] for i, name in enumerate(task_names)])


def revision_table(records: Sequence[RoundRecord]) -> str:
    """Table of the rounds and their revisions: episodes, frames and the mixing coefficient beta."""
    rows = [
        [r.round, f"`{round_name(r.round)}`", sum(r.episodes_per_task), r.frames, r.beta] for r in records
    ]
    return card_table(["round", "revision", "episodes", "frames", "beta"], rows)


def allocation_table(task_names: Sequence[str], records: Sequence[RoundRecord]) -> str:
    """Expert-labelled episodes per task (rows) and round (columns), with a total row."""
    header = ["task", *(f"round {r.round}" for r in records)]
    rows = [[name, *(r.episodes_per_task[i] for r in records)] for i, name in enumerate(task_names)]
    rows.append(["**total**", *(sum(r.episodes_per_task) for r in records)])
    return card_table(header, rows)


def eval_table(task_names: Sequence[str], evals: dict[int, dict[str, Any] | None]) -> str:
    """Success per task (rows) of the policy of rounds 0..k (columns, from ``evals``), with a mean row."""
    if not any(evals.values()):
        return "No evaluation was recorded for these rounds."
    rounds = sorted(evals)
    header = ["task", *(f"round {k}" for k in rounds)]

    def success(k: int, i: int) -> float | None:
        entry = evals[k]
        return None if entry is None else float(entry["success"][i])

    def mean(k: int) -> float | None:
        entry = evals[k]
        return None if entry is None else float(entry["mean"])

    rows = [[name, *(success(k, i) for k in rounds)] for i, name in enumerate(task_names)]
    rows.append(["**mean**", *(mean(k) for k in rounds)])
    episodes = sorted({e for entry in evals.values() if entry for e in entry.get("episodes", [])})
    note = (
        "Column `round k` is the success rate of the policy trained on rounds 0..k (revision `round-{k:03d}` "
        "of the policy repo, if pushed)"
    )
    if episodes:
        note += f", over {'/'.join(map(str, episodes))} evaluation episode(s) per task"
    return f"{note}.\n\n{card_table(header, rows)}"


def _phase_eval(experiment: ExperimentDir, round_index: int) -> dict[str, Any] | None:
    """The ``eval`` entry of a committed training phase (None if not committed or not evaluated)."""
    if round_index not in experiment.committed_phases():
        return None
    return experiment.read_phase_record(round_index).eval


def render_dataset_card(experiment: ExperimentDir, repo_id: str, up_to_round: int | None = None) -> str:
    """The dataset card of ``repo_id`` for rounds 0..``up_to_round`` (None: all; ValueError if absent)."""
    committed = experiment.committed_rounds()
    if not committed:
        raise UserError(f"{experiment.root} has no committed round to describe.")
    last = committed[-1] if up_to_round is None else up_to_round
    if last not in committed:
        raise UserError(f"Round {last} is not committed in {experiment.root}; committed: {committed}.")
    records = [experiment.read_round_record(k) for k in range(last + 1)]
    latest = records[-1]
    config = latest.config or {}
    task_names = list(latest.task_names)
    values = {
        "card_data": card_metadata_yaml(),
        "repo_id": repo_id,
        "round": str(last),
        "revision": round_name(last),
        "suite": str(stored_option(config, "suite.name", NOT_AVAILABLE)),
        "obs_mode": str(stored_option(config, "suite.obs_mode", NOT_AVAILABLE)),
        "method": str(latest.method),
        "temperature": str(latest.temperature),
        "n_min": str(latest.n_min),
        "seed": str(latest.seed),
        "revision_table": revision_table(records),
        "task_table": task_table(task_names),
        "allocation_table": allocation_table(task_names, records),
        "eval_table": eval_table(task_names, {k: _phase_eval(experiment, k) for k in range(last + 1)}),
    }
    text = card_template()
    for key, value in values.items():
        text = text.replace("{{ " + key + " }}", value)
    return text


# -------------------------------------------------------------------------------------------------
# Pushing
# -------------------------------------------------------------------------------------------------


@contextlib.contextmanager
def folder_with_card(folder: Path, card: str) -> Iterator[Path]:
    """A temporary folder of file symlinks (or copies) mirroring ``folder``, plus ``card`` as README.md."""
    with tempfile.TemporaryDirectory(prefix="mtdagger-push-") as tmp:
        staged = Path(tmp) / folder.name
        staged.mkdir()
        for source in sorted(folder.rglob("*")):
            relative = source.relative_to(folder)
            if not source.is_file() or relative.as_posix() == CARD_FILE:
                continue
            target = staged / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            try:
                os.symlink(source.absolute(), target)
            except OSError:
                shutil.copy2(source, target)
        (staged / CARD_FILE).write_text(card, encoding="utf-8")
        yield staged


def upload_and_tag(
    api: HfApi,
    repo_id: str,
    repo_type: str,
    folder: Path,
    tag: str,
    commit_message: str,
    delete_patterns: Sequence[str],
) -> str:
    """Uploads ``folder`` as one commit (deleting remote ``delete_patterns``); returns the tag's commit."""
    info = api.upload_folder(
        repo_id=repo_id,
        repo_type=repo_type,
        folder_path=folder,
        commit_message=commit_message,
        delete_patterns=list(delete_patterns),
    )
    api.create_tag(repo_id, tag=tag, revision=info.oid, repo_type=repo_type, exist_ok=True)
    logger.info("Pushed %s to %s %s at commit %s", tag, repo_type, repo_id, info.oid)
    return info.oid


def round_commit_message(record: RoundRecord) -> str:
    """Commit message of a round: its episodes, frames and allocation."""
    episodes = record.episodes_per_task
    return (
        f"round {record.round}: {sum(episodes)} episodes, {record.frames} frames, "
        f"allocation {episodes} ({record.method})"
    )


def phase_commit_message(round_index: int, record: PhaseRecord) -> str:
    """Commit message of a training phase: the rounds it was trained on and its evaluation."""
    success = NOT_AVAILABLE if record.eval_mean is None else f"{record.eval_mean:.3f}"
    return f"round {round_index}: policy trained on rounds 0..{round_index}, eval success {success}"


def push_rounds(api: HfApi, experiment: ExperimentDir, repo_id: str, rounds: Sequence[int]) -> dict[str, str]:
    """Pushes rounds in order, one tagged commit each (dataset files plus card); returns tag -> commit."""
    pushed = {}
    for k in rounds:
        card = render_dataset_card(experiment, repo_id, up_to_round=k)
        message = round_commit_message(experiment.read_round_record(k))
        with folder_with_card(experiment.round_root(k), card) as folder:
            pushed[round_name(k)] = upload_and_tag(
                api, repo_id, "dataset", folder, round_name(k), message, DATASET_DELETE_PATTERNS
            )
    return pushed


def push_phases(api: HfApi, experiment: ExperimentDir, repo_id: str, phases: Sequence[int]) -> dict[str, str]:
    """Pushes training phases in order, one tagged commit each; returns tag -> commit."""
    return {
        round_name(k): upload_and_tag(
            api,
            repo_id,
            "model",
            experiment.policy_root(k),
            round_name(k),
            phase_commit_message(k, experiment.read_phase_record(k)),
            POLICY_DELETE_PATTERNS,
        )
        for k in phases
    }


def _pushable(experiment: ExperimentDir, with_policies: bool) -> tuple[list[int], list[int]]:
    """The committed rounds (and phases, if wanted) to push, checked before anything is sent."""
    if not (experiment.root / CONFIG_FILE).exists():
        raise UserError(
            f"{experiment.root} is not a lerobot-mtdagger experiment (no {CONFIG_FILE}): pass the "
            "--output_dir of a `lerobot-mtdagger run`."
        )
    rounds = experiment.committed_rounds()
    if not rounds:
        raise UserError(f"{experiment.root} has no committed round to push yet.")
    phases = experiment.committed_phases() if with_policies else []
    if with_policies and not phases:
        raise UserError(
            f"{experiment.root} has no committed training phase to push: drop the policy repo option."
        )
    return rounds, phases


def check_hub_access(api: HfApi) -> str:
    """The token's user name, once the Hub answers and accepts it (else a ``UserError`` saying the fix)."""
    from huggingface_hub.errors import HfHubHTTPError, LocalTokenNotFoundError

    try:
        return str(api.whoami().get("name", "?"))
    except LocalTokenNotFoundError:
        raise UserError(
            "No Hugging Face token: log in with `hf auth login` or set HF_TOKEN; nothing was pushed."
        ) from None
    except HfHubHTTPError as error:
        status = error.response.status_code if error.response is not None else "?"
        raise UserError(
            f"The Hub refused the token (HTTP {status}): set HF_TOKEN to a token with write access; "
            "nothing was pushed."
        ) from None
    except (OSError,) + network_errors() as error:  # requests' (huggingface_hub 0.x) or httpx's (1.x)
        raise UserError(
            f"Cannot reach the Hub ({type(error).__name__}): check the network (or HF_ENDPOINT) and "
            "push again; nothing was pushed."
        ) from None


def push_experiment(
    experiment_dir: Path | str,
    dataset_repo_id: str,
    policy_repo_id: str | None = None,
    *,
    private: bool = False,
    api: HfApi | None = None,
    added_defaults: Mapping[str, Any] | None = None,
) -> dict[str, dict[str, str]]:
    """Pushes every committed round (and optionally every training phase) to the Hub, one tag per round.

    Args:
        experiment_dir: Output directory of a ``lerobot-mtdagger run``.
        dataset_repo_id: Hub dataset repo, ``owner/name`` (created if needed).
        policy_repo_id: Hub model repo for the trained policies (None: policies are not pushed).
        private: Whether repos created by this call are private.
        api: The Hub client (default: a new ``HfApi()``, authenticated as usual, e.g. by ``HF_TOKEN``).
        added_defaults: ``RunConfig.option_defaults``, for the verification.

    Returns:
        ``{"dataset": {tag: commit_id}, "policy": {tag: commit_id}}``.

    Raises:
        UserError: If there is nothing to push, the experiment fails verification, or the Hub cannot be
            reached with the token; nothing is sent then.
    """
    from lerobot_mtdagger.datasets.verify import check_before_reading

    experiment = ExperimentDir(Path(experiment_dir))
    rounds, phases = _pushable(experiment, with_policies=policy_repo_id is not None)
    check_before_reading(experiment, added_defaults=added_defaults)  # never publish unverified records
    api = api or HfApi()
    user = check_hub_access(api)
    logger.info("Pushing to the Hub as %s", user)
    url = api.create_repo(dataset_repo_id, repo_type="dataset", private=private, exist_ok=True)
    dataset_repo_id = url.repo_id or dataset_repo_id
    logger.info("Pushing rounds %s of %s to dataset %s", rounds, experiment.root, dataset_repo_id)
    pushed = {"dataset": push_rounds(api, experiment, dataset_repo_id, rounds), "policy": {}}
    if policy_repo_id is not None:
        url = api.create_repo(policy_repo_id, repo_type="model", private=private, exist_ok=True)
        policy_repo_id = url.repo_id or policy_repo_id
        logger.info("Pushing training phases %s of %s to model %s", phases, experiment.root, policy_repo_id)
        pushed["policy"] = push_phases(api, experiment, policy_repo_id, phases)
    return pushed


# -------------------------------------------------------------------------------------------------
# Command
# -------------------------------------------------------------------------------------------------


def push_command(
    config: PushConfig, added_defaults: Mapping[str, Any] | None = None
) -> dict[str, dict[str, str]]:
    """Pushes the experiment as configured; returns what was pushed (see ``push_experiment``)."""
    assert config.experiment_dir is not None and config.repo_id is not None  # PushConfig refuses None
    return push_experiment(
        config.experiment_dir,
        config.repo_id,
        config.policy_repo_id,
        private=config.private,
        added_defaults=added_defaults,
    )
