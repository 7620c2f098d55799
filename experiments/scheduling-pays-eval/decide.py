"""The setting rule of run.sh, applied to the replay bench's output on development curves.

Usage: ``python decide.py OUT`` where OUT holds ``replay-<setting>.json`` (``lerobot-mtdagger replay
--output``) for each candidate setting. Prints ``decision.txt``'s lines: every candidate's numbers, the
rule's verdict for each, and the chosen setting (or ``setting: none``).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from lerobot_mtdagger.analysis.replay import ONLINE_ORACLE, STATIC_ORACLE, UNIFORM, seeds_for_half_width

# Fixed in run.sh before any run: cost of one evaluation seed (all arms) in core-hours, the cap, the
# seeds available, the least share of the oracle's headroom the best scheduler must capture, and the
# smallest SD over seeds of a paired difference the power uses (the measured one of the regime).
CORE_HOURS_PER_SEED = {"paper": 2.6, "pixels": 7.0}
CAP_CORE_HOURS = 30.0
SEEDS_AVAILABLE = 15  # evaluation seeds 5-19
LEAST_SHARE = 0.5
MEASURED_SEED_SD = {"paper": 0.017, "pixels": 0.0074}


def judge(name: str, replay: dict) -> tuple[bool, list[str]]:
    """Whether a setting qualifies, and the lines that say why."""
    arms = {arm["label"]: arm for arm in replay["arms"]}
    # Eligible: the registered methods at their defaults (variants with options are shown, not chosen).
    schedulers = [a for label, a in arms.items() if label not in (UNIFORM, ONLINE_ORACLE, STATIC_ORACLE)]
    schedulers = [a for a in schedulers if ":" not in a["label"]]
    best = max(schedulers, key=lambda arm: arm["vs_uniform"][0])
    effect, share = best["vs_uniform"][0], best["share"][0]
    sd = max(best["replicate_sd"], MEASURED_SEED_SD[name])
    seeds = seeds_for_half_width(effect, sd)
    affordable = int(CAP_CORE_HOURS // CORE_HOURS_PER_SEED[name])
    lines = [
        f"{name}: curves {replay['source']}",
        f"{name}: online oracle - uniform {arms[ONLINE_ORACLE]['vs_uniform'][0]:+.4f}, static "
        f"{arms[STATIC_ORACLE]['vs_uniform'][0]:+.4f}; best scheduler {best['label']} {effect:+.4f} "
        f"({share:.0%} of the online oracle's)",
        f"{name}: seeds for a 95% half-width of half the effect at SD {sd:.4f}: {seeds}; affordable "
        f"within {CAP_CORE_HOURS:g} core-hours: {affordable} ({CORE_HOURS_PER_SEED[name]} per seed)",
    ]
    reasons = []
    if share < LEAST_SHARE:
        reasons.append(f"the best scheduler captures {share:.0%} < {LEAST_SHARE:.0%} of the headroom")
    if seeds is None or seeds > min(affordable, SEEDS_AVAILABLE):
        reasons.append(f"it needs {seeds} seeds, more than the {min(affordable, SEEDS_AVAILABLE)} affordable")
    lines.append(f"{name}: {'qualifies' if not reasons else 'does not qualify: ' + '; '.join(reasons)}")
    return not reasons, lines


def main(folder: Path) -> None:
    """Prints the decision for the replays in ``folder``."""
    chosen, lines = [], []
    for name in CORE_HOURS_PER_SEED:
        path = folder / f"replay-{name}.json"
        if not path.is_file():
            lines.append(f"{name}: no replay yet ({path})")
            continue
        replay = json.loads(path.read_text())
        ok, why = judge(name, replay)
        lines += why
        if ok:
            labels = {a["label"]: a for a in replay["arms"] if ":" not in a["label"]}
            effects = [
                a["vs_uniform"][0] for k, a in labels.items() if k not in (ONLINE_ORACLE, STATIC_ORACLE)
            ]
            chosen.append((max(effects), name))
    lines.append(f"setting: {max(chosen)[1] if chosen else 'none'}")
    print("\n".join(lines))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
