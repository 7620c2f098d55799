"""Helpers shared by tests that tamper with committed experiments."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any


def edit_round_record(round_root: Path, edit: Callable[[dict[str, Any]], None]) -> None:
    """Applies ``edit`` to a committed round's record in ``meta/mtdagger.json`` and its info.json mirror."""
    sidecar = round_root / "meta" / "mtdagger.json"
    record = json.loads(sidecar.read_text())
    edit(record)
    sidecar.write_text(json.dumps(record))
    info_path = round_root / "meta" / "info.json"
    info = json.loads(info_path.read_text())
    info["mtdagger"] = record
    info_path.write_text(json.dumps(info))
