"""The progress lines of long work (generation, training): their wording and where they go."""

from __future__ import annotations

import os
import sys


def time_left(seconds: float) -> str:
    """``"about 40 s left"``, ``"about 38 min left"`` or ``"about 1.6 h left"``."""
    if seconds < 90:
        return f"about {seconds:.0f} s left"
    if seconds < 5400:
        return f"about {seconds / 60:.0f} min left"
    return f"about {seconds / 3600:.1f} h left"


QUIET = "CPHYSFNO_QUIET"
"""Environment variable: ``1`` silences the progress lines of this process and of the
worker processes it starts (``cphysfno -q`` sets it)."""


def show_progress(message: str) -> None:
    """One progress line on standard error, unless ``CPHYSFNO_QUIET=1``."""
    if os.environ.get(QUIET) != "1":
        print(message, file=sys.stderr, flush=True)
