"""Frozen-code shim for the MT10 evaluation study: drop the editable finder of /work/main."""

import sys

sys.meta_path[:] = [f for f in sys.meta_path if "editable" not in getattr(f, "__module__", "")]
