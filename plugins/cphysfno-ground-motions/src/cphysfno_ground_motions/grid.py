"""Putting records of various time steps and lengths on one time grid, resampled with
anti-aliasing by :func:`cphysfno_core.signals.resampling.resample`."""

from __future__ import annotations

import warnings

import numpy as np
from cphysfno_core import DatasetError, GroundMotions
from cphysfno_core.signals.intensity import arias_intensity
from cphysfno_core.signals.resampling import resample, same_step

from .errors import GroundMotionWarning
from .record import Record, describe

KEPT_SHAKING_WARNING = 0.5
"""Share of a record's Arias intensity (the integral of a^2) below which a cut to the
grid's duration warns: the record's strong motion lies mostly past the cut."""


def fit_length(acceleration: np.ndarray, steps: int) -> np.ndarray:
    """``[steps]``: the record cut after ``steps`` samples, or zero-padded up to them."""
    out = np.zeros(steps)
    keep = min(steps, acceleration.size)
    out[:keep] = acceleration[:keep]
    return out


def _common_step(
    records: list[Record], dt: float | None, resample_all: bool, where: str
) -> tuple[float, list[Record]]:
    """The grid step and the records that can be brought to it (warning about others)."""
    steps = sorted({r.dt for r in records})
    if dt is None:
        if not resample_all and any(not same_step(s, steps[0]) for s in steps):
            groups = {
                f"{s:g} s": describe([r.name for r in records if same_step(r.dt, s)], 3)
                for s in steps
            }
            raise DatasetError(
                f"{where} mixes time steps ({'; '.join(f'{k}: {v}' for k, v in groups.items())}) "
                "and resampling is off: set dt to resample them all or to keep one time step"
            )
        return steps[0], records
    if resample_all:
        return dt, records
    kept = [r for r in records if same_step(r.dt, dt)]
    dropped = [r for r in records if not same_step(r.dt, dt)]
    if not kept:
        raise DatasetError(
            f"no record of {where} has dt = {dt:g} s (they have "
            f"{', '.join(f'{s:g}' for s in steps)} s): allow resampling or choose one of those"
        )
    if dropped:
        warnings.warn(
            f"{where}: {len(dropped)} records left out because their dt is not {dt:g} s and "
            f"resampling is off: {describe([r.name for r in dropped])}",
            GroundMotionWarning,
            stacklevel=2,
        )
    return dt, kept


def common_grid(
    records: list[Record],
    *,
    dt: float | None,
    resample_all: bool,
    duration: float | None,
    pad_short: bool,
    where: str,
) -> GroundMotions:
    """The records on one grid: time step ``dt`` and ``round(duration / dt) + 1`` samples.

    Args:
        records: the records, each at its own time step.
        dt: grid step in s; ``None`` takes the finest step among the records.
        resample_all: bring records of another step to ``dt`` by anti-aliased resampling;
            otherwise leave them out (with a warning), or, with ``dt=None``, refuse a mix.
        duration: grid length in s; longer records are cut, shorter ones zero-padded;
            ``None`` takes the longest record.
        pad_short: zero-pad records shorter than ``duration`` (with a warning naming them);
            otherwise leave them out (with a warning).
        where: how messages call the record set.

    Returns:
        ``[m, T]`` accelerations in m/s^2 with each record's metadata plus ``native_dt``
        and ``native_duration`` (s).

    Raises:
        DatasetError: mixed steps with resampling off and no ``dt``, no record at ``dt``,
            or no record long enough when padding is off.
    """
    step, records = _common_step(records, dt, resample_all, where)
    resampled = [resample(r.acceleration, r.dt, step) for r in records]
    lengths = np.array([(a.size - 1) * step for a in resampled])
    if duration is None:
        n_steps = int(lengths.max() / step + 0.5) + 1
    else:
        n_steps = int(round(duration / step)) + 1
        short = lengths < (n_steps - 1) * step - 0.5 * step
        if short.any():
            names = describe(
                [
                    f"{r.name} ({length:.2f} s)"
                    for r, length, s in zip(records, lengths, short, strict=True)
                    if s
                ]
            )
            if not pad_short and short.all():
                raise DatasetError(
                    f"no record of {where} lasts {duration:g} s (the longest lasts "
                    f"{lengths.max():.2f} s): shorten duration or allow padding"
                )
            action = "zero-padded to" if pad_short else "left out as shorter than"
            warnings.warn(
                f"{where}: {int(short.sum())} records {action} {duration:g} s: {names}",
                GroundMotionWarning,
                stacklevel=2,
            )
            if not pad_short:
                keep = ~short
                records = [r for r, k in zip(records, keep, strict=True) if k]
                resampled = [a for a, k in zip(resampled, keep, strict=True) if k]
    acceleration = np.stack([fit_length(a, n_steps) for a in resampled])
    _warn_where_shaking_is_cut(records, resampled, acceleration, step, where)
    metadata = [{**r.metadata, "native_dt": r.dt, "native_duration": r.duration} for r in records]
    return GroundMotions(acceleration, step, metadata)


def _warn_where_shaking_is_cut(
    records: list[Record],
    resampled: list[np.ndarray],
    cut: np.ndarray,
    step: float,
    where: str,
) -> None:
    """Warn, naming them, about records whose cut to the grid keeps less than
    :data:`KEPT_SHAKING_WARNING` of their Arias intensity (a quiet beginning, as some
    Chi-Chi records that shake only after 20 s, which scaling to a target would then blow
    up into amplified noise)."""
    total = np.array([arias_intensity(a[None, :], step)[0] for a in resampled])
    kept = arias_intensity(cut, step) / np.where(total > 0.0, total, 1.0)
    duration = (cut.shape[1] - 1) * step
    low = (total > 0.0) & (kept < KEPT_SHAKING_WARNING)
    if not low.any():
        return
    names = describe(
        [f"{r.name} ({share:.0%})" for r, share, w in zip(records, kept, low, strict=True) if w]
    )
    warnings.warn(
        f"{where}: {int(low.sum())} records keep less than {KEPT_SHAKING_WARNING:.0%} of "
        f"their shaking (Arias intensity) within {duration:g} s: {names}; start each "
        "record at its shaking (the recorded source's pre_shaking) or lengthen duration",
        GroundMotionWarning,
        stacklevel=3,
    )
