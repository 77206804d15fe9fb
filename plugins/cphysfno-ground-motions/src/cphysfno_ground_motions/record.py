"""One recorded accelerogram at its native time step, with what is known about it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Record:
    """A single-component ground acceleration record.

    Attributes:
        acceleration: ``[T]`` acceleration in m/s^2.
        dt: time step in s.
        metadata: what is known of it; the keys this package fills are ``name`` (how
            messages call the record), ``event``, ``year``, ``magnitude``, ``station``,
            ``component``, ``mechanism``, ``vs30`` (m/s), ``rjb_km``, ``rrup_km``, ``rsn``
            (NGA record sequence number), ``file``.
    """

    acceleration: np.ndarray
    dt: float
    metadata: dict[str, Any] = field(default_factory=dict)

    @property
    def name(self) -> str:
        """How messages call this record."""
        return str(self.metadata.get("name", "record"))

    @property
    def duration(self) -> float:
        """Length in s (time of the last sample)."""
        return (self.acceleration.size - 1) * self.dt


def describe(names: list[str], limit: int = 8) -> str:
    """``names`` for a message: the first ``limit`` of them and a count of the rest."""
    more = f" and {len(names) - limit} more" if len(names) > limit else ""
    return ", ".join(names[:limit]) + more
