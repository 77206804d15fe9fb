"""Recorded accelerograms (:class:`cphysfno_core.signals.Record`) and how messages name them."""

from __future__ import annotations

from cphysfno_core.signals import Record

__all__ = ["Record", "describe"]


def describe(names: list[str], limit: int = 8) -> str:
    """``names`` for a message: the first ``limit`` of them and a count of the rest."""
    more = f" and {len(names) - limit} more" if len(names) > limit else ""
    return ", ".join(names[:limit]) + more
