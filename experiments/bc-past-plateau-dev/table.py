"""The four BC trainings' success by budget and seed, and the decision rule of ``run.sh``, applied.

Usage: (``lab`` on the path: ``PYTHONPATH=experiments``)
``.venv/bin/python experiments/bc-past-plateau-dev/table.py experiments/bc-past-plateau-dev/records``
(the folder ``save_records.sh`` fills: ``<training>/bc-<budget>demos-seed<seed>/...``). Written on
2026-11-27, after run.sh was fixed and before any of its runs finished; it applies the rule as run.sh
states it (``experiments/lab/bc_choice.py``): the best BC is the training with the highest 3-seed
mean success over 33-63 demos per task among those whose mean at 63 is not below their mean at 33 by
more than 0.01; if none qualifies, the highest mean, said so. Its last line,
``Decision: the best BC is <training>.``, is what ``../beyond-plateau-best-bc/run.sh`` reads.
"""

from __future__ import annotations

import sys
from pathlib import Path

from lab.bc_choice import choice_report, read_bc_records

BUDGETS = (33, 45, 63)
SEEDS = (100, 101, 102)
TRAININGS = ("plain", "balanced", "cosine", "plateau")


def main() -> None:
    """Prints the table and the decision for the records folder given as the only argument."""
    results = read_bc_records(Path(sys.argv[1]))
    lines = choice_report(
        results, TRAININGS, BUDGETS, SEEDS, label="training", decision="the best BC is {}", none_word="none"
    )
    print("\n".join(lines))


if __name__ == "__main__":
    main()
