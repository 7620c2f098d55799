"""Code the studies' scripts share (their tables and choices); not part of the package.

A study script puts ``experiments/`` on its path and imports ``lab.<module>``.
"""
