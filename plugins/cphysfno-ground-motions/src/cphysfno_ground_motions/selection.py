"""Record selection by earthquake magnitude, Joyner-Boore distance and V_S30 ranges."""

from __future__ import annotations

from dataclasses import dataclass

from cphysfno_core import DatasetError

from .record import Record

UNITS = {"magnitude": "", "rjb_km": " km", "vs30": " m/s"}


@dataclass(frozen=True)
class Criteria:
    """Closed ranges ``(low, high)`` a record's metadata must lie in; ``None`` accepts all.

    Attributes:
        magnitude: moment magnitude range.
        rjb_km: Joyner-Boore distance range in km.
        vs30: V_S30 range in m/s.
    """

    magnitude: tuple[float, float] | None = None
    rjb_km: tuple[float, float] | None = None
    vs30: tuple[float, float] | None = None

    def ranges(self) -> dict[str, tuple[float, float]]:
        """The criteria that are set, by metadata key."""
        return {key: getattr(self, key) for key in UNITS if getattr(self, key) is not None}

    def __str__(self) -> str:
        parts = [f"{k} in [{lo:g}, {hi:g}]{UNITS[k]}" for k, (lo, hi) in self.ranges().items()]
        return ", ".join(parts) or "no criteria"


def select(records: list[Record], criteria: Criteria, where: str) -> list[Record]:
    """The records whose metadata meet every criterion, in their order.

    A record that lacks a value a criterion needs is left out.

    Raises:
        DatasetError: no record is left; the message names ``where``, the criteria, and how
            many records each criterion turned away.
    """
    ranges = criteria.ranges()
    kept = []
    refused = {key: 0 for key in ranges}
    lacking = {key: 0 for key in ranges}
    for record in records:
        ok = True
        for key, (low, high) in ranges.items():
            value = record.metadata.get(key)
            if value is None:
                lacking[key] += 1
                ok = False
            elif not low <= value <= high:
                refused[key] += 1
                ok = False
        if ok:
            kept.append(record)
    if not kept:
        counts = "; ".join(
            f"{key}: {refused[key]} outside, {lacking[key]} without a value" for key in ranges
        )
        raise DatasetError(
            f"no record of {where} ({len(records)} records) matches {criteria} ({counts}): "
            "widen the ranges"
        )
    return kept
