"""Studies: grids of runs (``compare``), results tables, reports, figures, statistics, shift."""
