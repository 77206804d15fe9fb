"""Figures of ground motions: response spectra against a target (paper Fig. 10(b)) and
acceleration histories. Drawn with matplotlib's Agg backend into PNG files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from cphysfno_core import GroundMotions
from cphysfno_core.signals.intensity import STANDARD_GRAVITY

from .target import TargetSpectrum


def _figure(width: float, height: float):
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), dpi=120)


def plot_spectra(
    motions: GroundMotions,
    path: str | Path,
    *,
    periods: np.ndarray | None = None,
    target: TargetSpectrum | None = None,
    damping: float = 0.05,
    title: str = "",
) -> Path:
    """Every record's pseudo-spectral acceleration (in g, log-log) with the target's median
    and 2.5-97.5% band (or, without a target, the records' own); written as a PNG to
    ``path`` by :func:`cphysfno_core.plugin.motion_spectra`.

    Args:
        motions: the records.
        path: PNG file to write (its folder is created).
        periods: ``[P]`` periods in s of the records' spectra; default 60 spread
            log-uniformly over the target's periods, else from 0.02 s to 5 s.
        target: the target spectrum to draw over the records.
        damping: damping ratio of the spectra.
        title: figure title.

    Returns:
        The path written.
    """
    from cphysfno_core.plugin import motion_spectra

    band = None if target is None else target.band()
    return motion_spectra(
        motions.acceleration,
        motions.dt,
        Path(path),
        target=band,
        periods=periods,
        damping=damping,
        title=title,
    )


def plot_records(
    motions: GroundMotions, path: str | Path, *, count: int = 4, title: str = ""
) -> Path:
    """Acceleration histories (in g) of the first ``count`` records, one panel each, each
    titled from its metadata; written as a PNG to ``path``."""
    count = max(1, min(count, motions.n_records))
    figure = _figure(7.0, 1.6 * count + 0.6)
    axes = np.atleast_1d(figure.subplots(count, 1, sharex=True))
    for i, ax in enumerate(axes):
        meta = motions.metadata[i] if motions.metadata else {}
        ax.plot(motions.time, motions.acceleration[i] / STANDARD_GRAVITY, linewidth=0.6)
        ax.set_ylabel("a (g)")
        label = meta.get("name") or f"{meta.get('source', 'record')} {i}"
        ax.set_title(str(label), fontsize=8, loc="left")
    axes[-1].set_xlabel("time (s)")
    if title:
        figure.suptitle(title)
    figure.tight_layout()
    return _save(figure, path)


def _save(figure, path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path)
    return path
