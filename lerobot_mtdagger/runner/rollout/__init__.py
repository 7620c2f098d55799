"""Rollouts: collection with the expert mixed in, env workers (local or Ray), evaluation, expert check."""
