"""The runner: the DAgger loop, collection, env workers, mixing, training, evaluation, students."""
