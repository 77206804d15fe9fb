"""Figures of a fragility analysis: the curves from simulation and from the surrogate
together, and the cloud of demands against intensity."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from .fragility import Fragility

SOURCES = {
    "simulation": {"color": "black", "linestyle": "-"},
    "surrogate": {"color": "tab:blue", "linestyle": "--"},
    "surrogate-large": {"color": "tab:orange", "linestyle": ":"},
    "surrogate-large-medians": {"color": "tab:green", "linestyle": "-."},
}
"""How each source of a curve is drawn."""


def plot_fragility(
    curves: dict[str, dict[str, Fragility]],
    intensities: np.ndarray,
    intensity_label: str,
    path: Path,
) -> Path:
    """One panel per limit state: each source's lognormal curve against intensity, with
    the test records' intensities as ticks along the bottom.

    Args:
        curves: limit state name -> source (simulation, surrogate, surrogate-large,
            surrogate-large-medians) -> fragility (none for a limit state no source could
            fit).
        intensities: ``[n]`` the test records' intensity measures.
        intensity_label: the measure with its unit, for the axis.
        path: the PNG to write.
    """
    n = len(curves)
    columns = min(n, 3)
    rows = -(-n // columns)
    fig = Figure(figsize=(4.2 * columns, 3.4 * rows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, columns, squeeze=False)).ravel()
    x = np.geomspace(max(intensities.min() / 3.0, 1e-6), intensities.max() * 3.0, 300)
    for ax, (name, sources) in zip(axes, curves.items(), strict=False):
        for source, fragility in sources.items():
            label = f"{source}: median {fragility.median:.3g}, beta {fragility.beta:.2f}"
            ax.plot(x, fragility.probability(x), label=label, **SOURCES.get(source, {}))
        ax.plot(intensities, np.zeros_like(intensities), "|", color="0.4", markersize=8)
        ax.set_xscale("log")
        ax.set_ylim(-0.03, 1.0)
        ax.set_title(name)
        ax.set_xlabel(intensity_label)
        ax.set_ylabel("probability of exceedance")
        if sources:
            ax.legend(fontsize=7, loc="upper left")
        else:
            ax.text(0.5, 0.5, "no fit: see fragility.json", ha="center", transform=ax.transAxes)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.savefig(path, dpi=120)
    return path


def plot_demand_cloud(
    clouds: dict[str, tuple[np.ndarray, np.ndarray]],
    intensity_label: str,
    demand_label: str,
    path: Path,
) -> Path:
    """Demand against intensity for each source, on log axes.

    Args:
        clouds: source -> (intensities ``[n]``, demands ``[n]``).
        intensity_label: the measure with its unit.
        demand_label: the demand with its unit.
        path: the PNG to write.
    """
    fig = Figure(figsize=(6.0, 4.5), layout="constrained")
    ax = fig.subplots()
    styles = {"simulation (test)": ("o", "black", 14), "surrogate (test)": ("x", "tab:blue", 14)}
    for source, (x, y) in clouds.items():
        marker, color, size = styles.get(source, (".", "tab:orange", 3))
        keep = np.isfinite(y) & (y > 0)
        ax.scatter(x[keep], y[keep], s=size, marker=marker, color=color, label=source,
                   alpha=0.6 if size < 10 else 0.9, linewidths=0.8)  # fmt: skip
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(intensity_label)
    ax.set_ylabel(demand_label)
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=120)
    return path
