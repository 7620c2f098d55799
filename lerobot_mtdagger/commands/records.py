"""``lerobot-mtdagger records``: a study's run records saved and compacted (``analysis.record_saving``).

Its options are ``RecordsConfig`` (``configs/records.py``).
"""

from __future__ import annotations

from lerobot_mtdagger.analysis.record_saving import compact, save_compares, save_runs
from lerobot_mtdagger.commands.configs.records import RecordsConfig

__all__ = ["RecordsConfig", "records_command"]


def records_command(config: RecordsConfig) -> list[str]:
    """Does ``--action`` and prints one line per thing written."""
    assert config.source is not None  # RecordsConfig refuses a missing --source
    if config.action == "save":
        assert config.dest is not None  # RecordsConfig refuses save without --dest
        lines = [f"{config.dest}/{name}" for name in save_runs(config.source, config.dest)]
    elif config.action == "compact":
        lines = [str(archive) for archive in compact(config.source)]
        lines = lines or [f"{config.source} holds no runs' records folders: nothing to compact"]
    else:
        assert config.dest is not None  # RecordsConfig refuses save_compares without --dest
        lines = save_compares(config.source, config.dest)
    for line in lines:
        print(line)
    return lines
