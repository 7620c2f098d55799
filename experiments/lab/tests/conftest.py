"""The lab's own checks (``.ci/run`` runs them apart from the package's suite): ``lab`` importable."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # experiments/
