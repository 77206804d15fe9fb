"""Figures of a study (the paper's Figs. 2b–7), each written to a PNG file.

Time histories are ``[T]`` or ``[T, dof]`` arrays in m with their time vector in s.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import NullLocator
from scipy.signal import welch

from ..model.labels import ModelLabel
from ..signals.intensity import STANDARD_GRAVITY, SpectrumBand, response_spectrum
from .baselines import BASELINES

DPI = 130


def _subplots(*grid: int, figsize: tuple[float, float], **options):
    """A figure and its axes, drawn without pyplot (matplotlib's backend is left as the
    user set it)."""
    figure = Figure(figsize=figsize)
    return figure, figure.subplots(*grid, **options)


def _save(fig: Figure, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    return path


def trajectories(
    time: np.ndarray,
    truth: np.ndarray,
    prediction: np.ndarray,
    names: list[str],
    label: str,
    path: Path,
) -> Path:
    """Predicted vs true displacement of every DOF (left) and the absolute error (right)."""
    n = truth.shape[1]
    fig, axes = _subplots(n, 2, figsize=(11, 1.6 * n + 1), sharex=True, squeeze=False)
    for i in range(n):
        ax = axes[n - 1 - i, 0]
        ax.plot(time, truth[:, i], color="k", lw=0.9, label="truth")
        ax.plot(time, prediction[:, i], color="tab:red", lw=0.8, ls="--", label=label)
        ax.set_ylabel(f"{names[i]}\nu (m)")
        err = axes[n - 1 - i, 1]
        err.plot(time, np.abs(truth[:, i] - prediction[:, i]), color="tab:blue", lw=0.7)
        err.set_ylabel("|u - û| (m)")
    axes[0, 0].legend(loc="upper right", fontsize=8)
    axes[0, 0].set_title("displacement")
    axes[0, 1].set_title("absolute error")
    axes[-1, 0].set_xlabel("t (s)")
    axes[-1, 1].set_xlabel("t (s)")
    return _save(fig, path)


def model_comparison(
    time: np.ndarray,
    truth: np.ndarray,
    predictions: dict[str, np.ndarray],
    name: str,
    path: Path,
) -> Path:
    """One DOF (usually the top story) predicted by every model, one panel per model."""
    labels = list(predictions)
    fig, axes = _subplots(
        len(labels), 1, figsize=(10, 1.7 * len(labels) + 0.8), sharex=True, squeeze=False
    )
    for ax, label in zip(axes[:, 0], labels, strict=True):
        ax.plot(time, truth, color="k", lw=0.9, label="truth")
        ax.plot(time, predictions[label], color="tab:red", lw=0.8, ls="--", label=label)
        ax.set_ylabel("u (m)")
        ax.legend(loc="upper right", fontsize=8)
    axes[0, 0].set_title(f"{name}: all models, one test record")
    axes[-1, 0].set_xlabel("t (s)")
    return _save(fig, path)


def refined_band(
    time: np.ndarray,
    truth: np.ndarray,
    mean: np.ndarray,
    std: np.ndarray,
    label: str,
    name: str,
    path: Path,
) -> Path:
    """Refined mean with its ±1σ band against the truth."""
    fig, ax = _subplots(figsize=(10, 3.2))
    ax.fill_between(time, mean - std, mean + std, color="tab:orange", alpha=0.35, label="±1σ")
    ax.plot(time, truth, color="k", lw=0.9, label="truth")
    ax.plot(time, mean, color="tab:red", lw=0.8, ls="--", label=f"{label} mean")
    ax.set_xlabel("t (s)")
    ax.set_ylabel(f"{name} u (m)")
    ax.legend(loc="upper right", fontsize=8)
    return _save(fig, path)


MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")
LINESTYLES = ("-", "--", "-.", ":")
COLOURS = tuple(f"C{i}" for i in range(10))


def model_styles(n: int) -> list[dict[str, str]]:
    """``n`` distinct styles (colour, marker, line style) for the models of one figure: the
    ten default colours first, then the same colours with the next marker and line style, so
    that no two of up to 80 models look alike."""
    return [
        {
            "color": COLOURS[i % len(COLOURS)],
            "marker": MARKERS[(i // len(COLOURS)) % len(MARKERS)],
            "linestyle": LINESTYLES[(i // len(COLOURS)) % len(LINESTYLES)],
        }
        for i in range(n)
    ]


def peaks(
    true_peak: np.ndarray, predicted_peaks: dict[str, np.ndarray], name: str, path: Path
) -> Path:
    """Scatter of predicted vs true peak |u| across records, and their distributions; each
    model in its own colour, marker and line style (:func:`model_styles`)."""
    many = len(predicted_peaks) > 6
    fig, (scatter, hist) = _subplots(1, 2, figsize=(13 if many else 11, 4.8 if many else 4.2))
    upper = max([true_peak.max(), *[p.max() for p in predicted_peaks.values()]]) * 1.05
    scatter.plot([0, upper], [0, upper], color="k", lw=0.8)
    bins = np.linspace(0, upper, 30)
    hist.hist(true_peak, bins=bins, density=True, histtype="stepfilled", color="0.8", label="truth")
    styles = model_styles(len(predicted_peaks))
    for (label, peak), style in zip(predicted_peaks.items(), styles, strict=True):
        scatter.scatter(
            true_peak,
            peak,
            s=9,
            alpha=0.7,
            color=style["color"],
            marker=style["marker"],
            label=label,
        )
        hist.hist(
            peak,
            bins=bins,
            density=True,
            histtype="step",
            lw=1.2,
            color=style["color"],
            linestyle=style["linestyle"],
            label=label,
        )
    scatter.set_xlabel(f"true peak |u| {name} (m)")
    scatter.set_ylabel("predicted peak |u| (m)")
    scatter.set_xlim(0, upper)
    scatter.set_ylim(0, upper)
    hist.set_xlabel(f"peak |u| {name} (m)")
    hist.set_ylabel("density")
    if many:  # one legend beside the two panels, in columns
        handles, labels = scatter.get_legend_handles_labels()
        fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=7, frameon=False)
        fig.tight_layout(rect=(0, 0.06 * (1 + len(labels) // 4), 1, 1))
        fig.savefig(path, dpi=DPI)
        return path
    scatter.legend(fontsize=7)
    hist.legend(fontsize=7)
    return _save(fig, path)


def edp_scatter(
    true_pid: np.ndarray,
    predicted_pid: dict[str, np.ndarray],
    story_names: list[str],
    path: Path,
) -> Path:
    """Predicted vs simulated peak story drift ratio (in %) across records, one panel per
    story, every model in its own colour and marker (:func:`model_styles`); arrays are
    ``[n_records, n_stories]``, dimensionless."""
    n = true_pid.shape[1]
    columns = min(n, 5)
    rows = -(-n // columns)
    width = 2.8 * columns + 0.4
    legend_columns = max(1, min(len(predicted_pid), int(width // 2.7)))
    legend_rows = -(-len(predicted_pid) // legend_columns)
    height = 2.7 * rows + 0.3 + 0.22 * legend_rows
    fig, axes = _subplots(rows, columns, figsize=(width, height), squeeze=False)
    styles = model_styles(len(predicted_pid))
    for story, ax in enumerate(axes.flat):
        if story >= n:
            ax.set_visible(False)
            continue
        values = [true_pid[:, story], *(p[:, story] for p in predicted_pid.values())]
        finite = [v[np.isfinite(v)] for v in values]
        upper = 100 * 1.05 * max((float(v.max()) for v in finite if v.size), default=0.0)
        upper = upper if np.isfinite(upper) and upper > 0 else 1.0
        ax.plot([0, upper], [0, upper], color="k", lw=0.8)
        for (label, pid), style in zip(predicted_pid.items(), styles, strict=True):
            ax.scatter(
                100 * true_pid[:, story],
                100 * pid[:, story],
                s=9,
                alpha=0.7,
                color=style["color"],
                marker=style["marker"],
                label=label,
            )
        ax.set_xlim(0, upper)
        ax.set_ylim(0, upper)
        ax.set_title(story_names[story], fontsize=9)
        if story % columns == 0:
            ax.set_ylabel("predicted PID (%)")
        if story >= n - columns:
            ax.set_xlabel("simulated PID (%)")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=legend_columns, fontsize=7)
    fig.tight_layout(rect=(0, (0.22 * legend_rows + 0.1) / height, 1, 1))
    fig.savefig(path, dpi=DPI)
    return path


def hysteresis(
    drift: np.ndarray, shear: np.ndarray, stories: list[int], names: list[str], path: Path
) -> Path:
    """Story shear vs interstory drift loops (``[T, n]`` arrays, m and N)."""
    fig, axes = _subplots(1, len(stories), figsize=(5 * len(stories), 4), squeeze=False)
    for ax, story in zip(axes[0], stories, strict=True):
        ax.plot(drift[:, story] * 1e3, shear[:, story] / 1e3, color="tab:blue", lw=0.6)
        ax.set_xlabel("interstory drift (mm)")
        ax.set_ylabel("story shear (kN)")
        ax.set_title(names[story])
    return _save(fig, path)


def spectra(
    ag: np.ndarray, z: np.ndarray, u: np.ndarray, dt: float, time: np.ndarray, name: str, path: Path
) -> Path:
    """Time histories and Welch PSDs of a_g, z, u and the residual u - z (one DOF)."""
    fig, axes = _subplots(2, 2, figsize=(11, 6.5))
    axes[0, 0].plot(time, ag, color="0.3", lw=0.5)
    axes[0, 0].set_ylabel("a_g (m/s²)")
    axes[0, 1].plot(time, u, color="k", lw=0.8, label="u")
    axes[0, 1].plot(time, z, color="tab:green", lw=0.8, ls="--", label="z")
    axes[0, 1].set_ylabel(f"{name} (m)")
    axes[0, 1].legend(fontsize=8)
    axes[1, 0].plot(time, u - z, color="tab:purple", lw=0.6)
    axes[1, 0].set_ylabel("residual u - z (m)")
    for ax in (axes[0, 0], axes[0, 1], axes[1, 0]):
        ax.set_xlabel("t (s)")
    psd = axes[1, 1]
    segment = min(512, len(ag))
    for signal, label, color in (
        (ag, "a_g", "0.5"),
        (z, "z", "tab:green"),
        (u, "u", "k"),
        (u - z, "u - z", "tab:purple"),
    ):
        f, p = welch(signal, fs=1.0 / dt, nperseg=segment)
        peak = max(float(np.max(p[1:])), np.finfo(float).tiny)  # u - z may vanish
        psd.semilogy(f[1:], p[1:] / peak, label=label, color=color, lw=0.9)
    psd.set_xlabel("frequency (Hz)")
    psd.set_ylabel("PSD / max")
    psd.legend(fontsize=8)
    return _save(fig, path)


def motion_spectra(
    acceleration: np.ndarray,
    dt: float,
    path: Path,
    *,
    target: SpectrumBand | None = None,
    periods: np.ndarray | None = None,
    damping: float = 0.05,
    title: str = "",
) -> Path:
    """Every record's pseudo-spectral acceleration (in g, log-log) with the target's median
    and band when given, else the records' own median and 2.5-97.5 % band (paper Fig. 10(b)).

    Args:
        acceleration: ``[n, T]`` ground accelerations in m/s^2.
        dt: time step in s.
        path: PNG file to write (its folder is created).
        target: the spectrum the records were made to follow.
        periods: ``[P]`` periods in s of the records' spectra; default 60 spread
            log-uniformly over the target's periods, else from 0.02 s to 5 s.
        damping: damping ratio of the records' spectra.
        title: figure title.
    """
    if periods is None:
        low, high = (target.periods[0], target.periods[-1]) if target is not None else (0.02, 5)
        periods = np.geomspace(low, high, 60)
    psa = response_spectrum(acceleration, dt, periods, damping).pseudo_acceleration
    g = STANDARD_GRAVITY
    fig, ax = _subplots(figsize=(6.0, 4.5))
    for row in psa:
        ax.loglog(periods, row / g, color="0.65", lw=0.5, alpha=0.6)
    ax.plot([], [], color="0.65", lw=0.8, label=f"{psa.shape[0]} records")
    if target is None:
        reference = SpectrumBand(
            periods, *np.percentile(psa, [50.0, 2.5, 97.5], axis=0), damping, "records' 2.5-97.5 %"
        )
        name = "records' median"
    else:
        reference, name = target, "target median"
    ax.loglog(reference.periods, reference.median / g, color="k", lw=2, label=name)
    for edge, label in ((reference.lower, reference.label), (reference.upper, None)):
        ax.loglog(reference.periods, edge / g, color="k", ls="--", lw=1.5, label=label)
    ax.set_xlabel("period T (s)")
    ax.set_ylabel(f"Sa (g), {damping:.0%} damping")
    ax.set_xlim(periods.min(), periods.max())
    ax.grid(True, which="both", lw=0.3)
    ax.legend(loc="lower left", fontsize=8)
    if title:
        ax.set_title(title, fontsize=10)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return _save(fig, path)


def training_curves(histories: dict[str, dict], path: Path) -> Path:
    """Training and validation relative L2 per epoch of every model."""
    fig, ax = _subplots(figsize=(7, 4))
    for i, (label, history) in enumerate(histories.items()):
        color = f"C{i}"
        epochs = np.arange(1, len(history["train_loss"]) + 1)
        ax.plot(epochs, history["train_loss"], color=color, lw=0.9, label=f"{label} train")
        ax.plot(epochs, history["val_loss"], color=color, lw=0.9, ls="--", label=f"{label} val")
    ax.set_xlabel("epoch")
    ax.set_ylabel("relative L2")
    ax.set_yscale("log")
    ax.legend(fontsize=7)
    return _save(fig, path)


def sweep_boxes(
    values: list,
    errors: dict[str, dict[str, list[list[float]]]],
    dofs: list[int],
    names: list[str],
    axis_label: str,
    path: Path,
) -> Path:
    """Box plots of relative L2 over seeds against a swept setting (paper Figs. 8–9).

    Args:
        values: the swept values, in order.
        errors: model label -> str(value) -> per-seed ``[n_dof]`` relative L2.
        dofs: which outputs get a panel each.
        names: output names.
        axis_label: the sweep's axis label.
    """
    fig, axes = _subplots(1, len(dofs), figsize=(4.2 * len(dofs), 3.8), squeeze=False)
    labels = list(errors)
    width = 0.8 / max(len(labels), 1)
    for ax, dof in zip(axes[0], dofs, strict=True):
        for k, label in enumerate(labels):
            color = f"C{k}"
            positions = np.arange(len(values)) + (k - (len(labels) - 1) / 2) * width
            data = [[seed[dof] for seed in errors[label].get(str(v), [])] for v in values]
            boxes = ax.boxplot(
                data,
                positions=positions,
                widths=width * 0.9,
                patch_artist=True,
                manage_ticks=False,
                medianprops={"color": color, "lw": 1.5},
                boxprops={"edgecolor": color},
                whiskerprops={"color": color},
                capprops={"color": color},
                flierprops={"markeredgecolor": color},
            )
            for box in boxes["boxes"]:
                box.set_facecolor(color)
                box.set_alpha(0.35)
            for x, seeds in zip(positions, data, strict=True):  # every seed, as few as they are
                ax.plot([x] * len(seeds), seeds, "o", color=color, ms=3)
            means = [np.mean(seeds) if seeds else np.nan for seeds in data]
            ax.plot(positions, means, color=color, lw=1, label=f"{label} (mean)")
        ax.set_xticks(np.arange(len(values)), [str(v) for v in values])
        ax.set_xlabel(axis_label)
        ax.set_ylabel("relative L2 error (test)")
        ax.set_title(names[dof])
        ax.legend(fontsize=7)
    return _save(fig, path)


def learning_curve(
    values: list, errors: dict[str, dict[str, list[dict[str, list[float]]]]], path: Path
) -> Path:
    """EDP error against the number of training simulations: the mean over stories (PID)
    and over floors (PFA) of the median test ``|ln(predicted / simulated)|``, one line per
    model and baseline (the mean over seeds, bars from the least to the largest seed).

    Args:
        values: the training sizes, in order.
        errors: label -> str(size) -> per-seed ``{"PID": [n_stories], "PFA": [n_floors]}``.
    """
    fig, axes = _subplots(1, 2, figsize=(10.0, 4.0), squeeze=False)
    sizes = np.asarray(values, dtype=np.float64)
    for ax, key in zip(axes[0], ("PID", "PFA"), strict=True):
        for (label, by_size), style in zip(errors.items(), model_styles(len(errors)), strict=True):
            seeds = [[np.nanmean(seed[key]) for seed in by_size.get(str(v), [])] for v in values]
            mean = np.array([np.mean(s) if s else np.nan for s in seeds])
            low = np.array([np.min(s) if s else np.nan for s in seeds])
            high = np.array([np.max(s) if s else np.nan for s in seeds])
            if label in BASELINES:
                style = {**style, "linestyle": "--", "marker": "x"}
            elif ModelLabel.parse(label).is_physics:
                style = {**style, "linestyle": ":", "marker": "."}
            spread = np.clip([mean - low, high - mean], 0.0, None)  # equal seeds: round-off
            ax.errorbar(sizes, mean, yerr=spread, label=label, capsize=2, **style)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_minor_locator(NullLocator())
        ax.set_xticks(sizes, [str(v) for v in values])
        ax.set_xlabel("training simulations")
        ax.set_ylabel(f"median |ln(pred / sim)| of {key}, mean over locations")
        ax.set_title(key)
        ax.legend(fontsize=7)
    return _save(fig, path)


def parameter_draws(
    draws: dict[str, np.ndarray], names: list[str], units: list[str], path: Path
) -> Path:
    """Histograms of random structural parameters' draws: one panel a parameter, one
    colour a group of records (``draws``: group name -> ``[n, k]``, the columns in the
    order of ``names``, each in its unit of ``units``)."""
    k = len(names)
    fig, axes = _subplots(1, k, figsize=(3.2 * k, 2.8), squeeze=False)
    every = np.concatenate(list(draws.values()))
    for j, (ax, name, unit) in enumerate(zip(axes[0], names, units, strict=True)):
        low, high = every[:, j].min(), every[:, j].max()
        bins = np.linspace(low, high, 16) if high > low else 1
        for group, values in draws.items():
            ax.hist(values[:, j], bins=bins, alpha=0.5, label=group)
        ax.set_xlabel(name + (f" ({unit})" if unit else ""))
        ax.set_ylabel("records")
    axes[0][0].legend(fontsize=8)
    path.parent.mkdir(parents=True, exist_ok=True)
    return _save(fig, path)
