"""Training phases: round data, normalisation, splits, steps, per-task loss, plateau, progress, provenance."""
