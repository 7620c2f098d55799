"""Import shim of the frozen-code study runs: drops the editable install's import hook (see README)."""

import sys

sys.meta_path[:] = [f for f in sys.meta_path if "editable" not in getattr(f, "__module__", "")]
