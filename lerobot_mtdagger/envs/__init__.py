"""Task suites (MetaWorld, drawers) with state, RGB and point-cloud observations."""
