"""The pixel BC samplings' success by budget and seed, and the decision rule of ``run.sh``, applied.

Usage: (``lab`` on the path: ``PYTHONPATH=experiments``)
``.venv/bin/python experiments/pixels-bc-dev/table.py experiments/pixels-bc-dev/records``
(the folder ``save_records.sh`` fills:
``<sampling>/bc-<budget>demos-seed<seed>/policies/round-000/training.json``).

The rule, as fixed in ``run.sh`` before any run: the evaluation study's BC takes the sampling with
the highest 3-seed mean success over the three budgets among those whose mean at 60 is not below
their mean at 10 by more than 0.01; if neither qualifies, the highest mean, said so. It is applied
only when every (sampling, budget, seed) run has finished (``experiments/lab/bc_choice.py``).
"""

from __future__ import annotations

import sys
from pathlib import Path

from lab.bc_choice import choice_report, read_bc_records

BUDGETS = (10, 30, 60)
SEEDS = (100, 101, 102)
SAMPLINGS = ("balanced", "uniform")


def main() -> None:
    """Prints the table and the decision for the records folder given as the only argument."""
    results = read_bc_records(Path(sys.argv[1]))
    lines = choice_report(
        results, SAMPLINGS, BUDGETS, SEEDS, label="sampling", decision="BC samples {}", none_word="neither"
    )
    print("\n".join(lines))


if __name__ == "__main__":
    main()
