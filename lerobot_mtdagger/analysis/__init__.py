"""The multi-run analysis: grids of runs (``compare``), results, curves, figures, summaries, statistics."""
