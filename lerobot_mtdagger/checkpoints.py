"""Loading policy folders safely: a checkpoint never names Python code to import.

LeRobot's processor loader (``DataProcessorPipeline.from_pretrained``) builds every step of
``policy_preprocessor.json`` / ``policy_postprocessor.json`` either from LeRobot's step registry
(``"registry_name"``) or by importing and calling any ``"class"`` the file names: a folder with
``{"class": "os.system", ...}`` runs a shell command when it is loaded. ``check_policy_folder``
refuses such a folder before LeRobot reads it, unless the user says the checkpoint is trusted: every
step must name a registered processor step and nothing else. The weights are safetensors and the
policy config resolves its ``type`` through LeRobot's config registry, so neither can run code.
"""

from __future__ import annotations

import json
from pathlib import Path

from lerobot.processor.pipeline import ProcessorStepRegistry

PROCESSOR_FILES = ("policy_preprocessor.json", "policy_postprocessor.json")

TRUST_HINT = "load only checkpoints you trust, with --trust_checkpoint=true"


class UntrustedCheckpointError(ValueError):
    """A policy folder asks to import code, or is not a processor config this toolkit can read."""


def check_processor_config(path: Path) -> None:
    """Refuses a processor config whose steps are not all LeRobot registry names.

    Raises:
        UntrustedCheckpointError: Naming the file, the step and what it asks for.
    """
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
    """Checks the processor configs of a local policy folder (those it has).

    Raises:
        UntrustedCheckpointError: If a processor config names code to import.
    """
    for name in PROCESSOR_FILES:
        path = Path(folder) / name
        if path.is_file():
            check_processor_config(path)


def check_hub_policy(repo_id: str) -> None:
    """Downloads (into the Hub cache LeRobot reads from) and checks a Hub policy's processor configs.

    Raises:
        UntrustedCheckpointError: If a processor config names code to import.
    """
    from huggingface_hub import hf_hub_download

    for name in PROCESSOR_FILES:
        check_processor_config(Path(hf_hub_download(repo_id, name)))
