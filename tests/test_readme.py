"""The README's Python snippets run as written (in order, in a fresh folder), and its links resolve."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_the_readme_snippets_run(tmp_path):
    """Start a run from Python, load its round with LeRobot, bring an expert: the toy suite, seconds."""
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.DOTALL)
    assert len(blocks) == 3
    script = tmp_path / "snippets.py"
    script.write_text("\n".join(blocks))
    result = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=600
    )
    assert result.returncode == 0, result.stderr[-3000:]
    assert "torchcodec" not in result.stderr, "no decoder probe warning (LeRobot 0.6 without FFmpeg)"
    assert "round 2:" in result.stdout
    assert (tmp_path / "outputs" / "toy-need" / "policies" / "round-002").is_dir()


def test_the_readme_is_short_and_its_links_resolve():
    text = README.read_text()
    assert len(text.splitlines()) <= 160
    for target in re.findall(r"\]\(((?!http)[^)#]+)\)", text):
        assert (README.parent / target).exists(), target


def test_the_changelog_lists_every_renamed_run_option():
    """Each option that moved into a group: its group, its name today and (if renamed) its old name."""
    from lerobot_mtdagger.datasets.migrations import FLAT_OPTION_PATHS

    changelog = README.read_text().split("## Changelog", 1)[1]
    words = set(re.findall(r"\w+", changelog))
    for old, new in FLAT_OPTION_PATHS.items():
        group, name = new.split(".")
        assert f"`--{group}.`" in changelog or f"`--{new}`" in changelog, new
        assert name in words, new
        if name != old:
            assert f"`--{old}`" in changelog, old
