"""The warning this distribution gives when a request is met only in part."""

from __future__ import annotations

from cphysfno_core.signals.errors import CphysfnoWarning


class GroundMotionWarning(CphysfnoWarning):
    """Records were dropped, padded or fewer than asked: the message names them and says why."""
