"""The plugin's tests import their shared helpers (``sac9_pulses``) from this folder."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
