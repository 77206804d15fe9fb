"""Wording shared by the progress lines of long work (generation, training)."""

from __future__ import annotations


def time_left(seconds: float) -> str:
    """``"about 40 s left"``, ``"about 38 min left"`` or ``"about 1.6 h left"``."""
    if seconds < 90:
        return f"about {seconds:.0f} s left"
    if seconds < 5400:
        return f"about {seconds / 60:.0f} min left"
    return f"about {seconds / 3600:.1f} h left"
