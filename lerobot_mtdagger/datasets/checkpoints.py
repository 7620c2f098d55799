"""Loading policy folders safely: a checkpoint never names Python code to import.

LeRobot's processor loader builds each step of ``policy_preprocessor.json`` and
``policy_postprocessor.json`` from its registry or by importing any ``"class"`` the file names
(``{"class": "os.system", ...}`` runs a command on load). Unless the checkpoint is trusted, every
step must name a registered processor step.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from lerobot.configs.policies import PreTrainedConfig
from lerobot.policies.factory import get_policy_class, make_pre_post_processors
from lerobot.processor.pipeline import ProcessorStepRegistry

from lerobot_mtdagger.datasets.experiment_files import POLICY_PATH_TAKES
from lerobot_mtdagger.datasets.student_types import student_policy_types
from lerobot_mtdagger.policies import MTDAggerPolicy
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.hub import is_hub_id, network_errors
from lerobot_mtdagger.utils.quiet import quiet_third_party

PROCESSOR_FILES = ("policy_preprocessor.json", "policy_postprocessor.json")
POLICY_TYPE = "mtdagger"
"""``owner/name``: a ``--policy_path`` of this form that is not a local folder is read from the Hub."""

TRUST_HINT = "load only checkpoints you trust, with --trust_checkpoint=true"


class UntrustedCheckpointError(UserError):
    """A policy folder asks to import code, or is not a processor config this toolkit can read."""


def check_processor_config(path: Path) -> None:
    """Refuses a processor config whose steps are not all LeRobot registry names, naming file and step."""
    try:
        config = json.loads(Path(path).read_text())
    except json.JSONDecodeError as error:
        raise UntrustedCheckpointError(
            f"{path} is not valid JSON ({error}); the checkpoint is corrupt."
        ) from None
    steps = config.get("steps") if isinstance(config, dict) else None
    if not isinstance(steps, list):
        raise UntrustedCheckpointError(f"{path} has no list of processor steps; the checkpoint is corrupt.")
    registered = set(ProcessorStepRegistry.list())
    for position, step in enumerate(steps):
        if not isinstance(step, dict):
            raise UntrustedCheckpointError(f"Step {position} of {path} is not an object.")
        if "class" in step:
            raise UntrustedCheckpointError(
                f"Step {position} of {path} names the Python class {step['class']!r}: loading it would "
                f"import and call that class ({TRUST_HINT})."
            )
        name = step.get("registry_name")
        if name not in registered:
            raise UntrustedCheckpointError(
                f"Step {position} of {path} names {name!r}, which is not a registered LeRobot processor "
                f"step ({TRUST_HINT}, after installing the package that registers it)."
            )


def check_policy_folder(folder: Path) -> None:
    """Checks the processor configs a local policy folder has (``UntrustedCheckpointError``)."""
    for name in PROCESSOR_FILES:
        path = Path(folder) / name
        if path.is_file():
            check_processor_config(path)


def check_hub_policy(repo_id: str) -> None:
    """Downloads (into LeRobot's Hub cache) and checks a Hub policy's processor configs."""
    from huggingface_hub import hf_hub_download

    for name in PROCESSOR_FILES:
        check_processor_config(Path(hf_hub_download(repo_id, name)))


def check_policy_path(path: str | Path) -> None:
    """Refuses a path that is neither a loadable policy folder nor a Hub id (``UserError`` naming the fix)."""
    folder = Path(path)
    if folder.exists():
        check_local_policy(folder)
    elif not is_hub_id(str(path)):
        raise UserError(f"{path} does not exist: --policy_path takes {POLICY_PATH_TAKES}.")


def check_local_policy(folder: Path) -> None:
    """Checks that a folder is a complete policy of a student's type, its files readable (``UserError``)."""
    if not folder.is_dir():
        raise UserError(f"{folder} is a file: --policy_path takes a policy folder or a Hub id owner/name.")
    if (folder / "policies").is_dir():
        phases = sorted(p.name for p in (folder / "policies").glob("round-*"))
        example = folder / "policies" / (phases[-1] if phases else "round-000")
        raise UserError(f"{folder} is an experiment folder: pass one of its policies, e.g. {example}.")
    config = folder / "config.json"
    if not config.is_file():
        kind = "a LeRobot dataset" if (folder / "meta" / "info.json").is_file() else "not a policy folder"
        raise UserError(
            f"{folder} is {kind} (no config.json): pass a policy folder, "
            "e.g. <experiment>/policies/round-003."
        )
    try:
        policy_type = json.loads(config.read_text()).get("type")
    except (json.JSONDecodeError, AttributeError):
        raise UserError(
            f"{config} is not a policy config (unreadable JSON); the checkpoint is corrupt."
        ) from None
    if policy_type not in student_policy_types():
        raise UserError(
            f"{config} describes a {policy_type!r} policy; this command evaluates "
            f"{list(student_policy_types())} "
            "policies (stock lerobot-eval evaluates the others)."
        )
    if not (folder / "model.safetensors").is_file():
        raise UserError(f"{folder / 'model.safetensors'} is missing: the checkpoint is incomplete.")
    for weights in sorted(folder.glob("*.safetensors")):
        _check_safetensors(weights)


def _check_safetensors(path: Path) -> None:
    """Refuses a truncated or garbled safetensors file, naming it."""
    from safetensors import SafetensorError, safe_open

    try:
        with safe_open(str(path), "pt") as handle:
            handle.keys()
    except (SafetensorError, OSError) as error:
        raise UserError(
            f"{path} is not a readable safetensors file ({error}): the checkpoint is incomplete or "
            "corrupt; copy it again or retrain it."
        ) from None


def load_policy(
    path: str | Path, device: str = "cpu", trust_checkpoint: bool = False
) -> tuple[Any, Any, Any]:
    """Loads a policy folder or Hub id (a student's type) with its saved processors, after the checks above.

    ``trust_checkpoint`` lets the processor configs name Python classes to import.

    Returns:
        The policy (in eval mode, on ``device``), its pre-processor and its post-processor.

    Raises:
        UntrustedCheckpointError: If a processor config names code and the checkpoint is not trusted.
        UserError: If the path is not a complete policy folder or a reachable Hub policy.
    """
    check_policy_path(path)
    if Path(path).exists():
        return _load_checked(path, device, trust_checkpoint)
    from huggingface_hub.errors import HfHubHTTPError, LocalEntryNotFoundError

    try:
        return _load_checked(path, device, trust_checkpoint)
    except (HfHubHTTPError, LocalEntryNotFoundError, OSError) + network_errors() as error:
        raise UserError(
            f"Cannot load the Hub policy {path} ({type(error).__name__}): check the repo id, the "
            "network and HF_TOKEN, or pass a local policy folder."
        ) from None


def _load_checked(path: str | Path, device: str, trust_checkpoint: bool) -> tuple[Any, Any, Any]:
    """Loads a checked policy path (see ``load_policy``)."""
    if not trust_checkpoint:
        if Path(path).is_dir():
            check_policy_folder(Path(path))
        else:
            check_hub_policy(str(path))
    with quiet_third_party():  # LeRobot prints "Loading weights from local directory"
        config = PreTrainedConfig.from_pretrained(str(path))
        policy_class = MTDAggerPolicy if config.type == POLICY_TYPE else get_policy_class(config.type)
        policy = policy_class.from_pretrained(str(path), config=config)
    policy.config.device = device
    policy.to(device)
    overrides = {"device_processor": {"device": device}}
    pre, post = make_pre_post_processors(
        policy.config, pretrained_path=str(path), preprocessor_overrides=overrides
    )
    return policy.eval(), pre, post
