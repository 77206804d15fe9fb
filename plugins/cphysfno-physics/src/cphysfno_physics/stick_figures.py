"""What a fitted stick shows of itself: its calibration as JSON, a Markdown summary and the
figure of the structure's story curves against the stick's."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from .stick_calibration import SPRINGS_ALONE, StickCalibration
from .stick_probes import FOLLOWS

FIT_WARNING = 0.10
"""Worst-story fit error (RMS shear error over peak shear on the monotonic and cyclic
pushovers) above which the summary says that the stick does not follow the structure
(where no refinement was kept; a refined stick's curves are shown beside it)."""

RESPONSE_WARNING = 0.30
"""Relative L2 of the stick's floor displacements against the structure's on the
refinement's held-out records above which the summary says that the stick does not follow
the structure under records (the accuracy asked of an RC frame's stick)."""


def write_stick_artifacts(calibration: StickCalibration, directory: Path) -> list[Path]:
    """``stick.json`` (the calibration, SI units), ``summary.md`` and ``stick.png`` (each
    story's monotonic and cyclic shear-drift curves, structure against stick) in
    ``directory``; the files written."""
    directory.mkdir(parents=True, exist_ok=True)
    document = directory / "stick.json"
    document.write_text(json.dumps(calibration.to_dict(), indent=2) + "\n")
    summary = directory / "summary.md"
    summary.write_text("\n".join(summary_lines(calibration)) + "\n")
    return [document, summary, plot_calibration(calibration, directory / "stick.png")]


def summary_lines(calibration: StickCalibration) -> list[str]:
    """The calibration in a few Markdown lines, with a warning where the chosen law does
    not follow the structure's curves (worst story beyond :data:`FIT_WARNING`, where no
    refinement was kept) or its response on the refinement's held-out records (beyond
    :data:`RESPONSE_WARNING`)."""
    chosen = calibration.fits[calibration.law]
    others = ", ".join(
        f"{name} {fit.worst:.3f}"
        for name, fit in calibration.fits.items()
        if name != calibration.law
    )
    periods = ", ".join(f"{p:.3f}" for p in calibration.periods)
    stick = ", ".join(f"{p:.3f}" for p in calibration.stick_periods)
    lines = [
        f"Stick: story law `{calibration.law}`, worst-story fit error {chosen.worst:.3f} (RMS "
        "shear error over the peak shear on the monotonic and cyclic pushovers"
        + (f"; the other laws: {others}" if others else "")
        + f"). Periods, structure: {periods} s; stick: {stick} s (stiffness scale "
        f"{calibration.stiffness_scale:.3f}; "
        + (
            "story springs alone"
            if calibration.coupling is None
            else "the structure's floor stiffness: springs and a coupling between floors"
        )
        + f"). Damping ratio {calibration.damping_ratio:.3f}"
        + (
            "."
            if calibration.rayleigh_modes is None
            else f", Rayleigh in modes {calibration.rayleigh_modes[0]} and "
            f"{calibration.rayleigh_modes[1]}."
        ),
    ]
    if calibration.dynamic_errors is not None:
        errors = ", ".join(f"{name} {e:.3f}" for name, e in calibration.dynamic_errors.items())
        lines += [
            "",
            "The law was chosen by its response to three probe pulses at the structure's "
            f"first period (relative L2 of each law's stick against the structure: {errors}).",
        ]
        lines += _cheaper_form_lines(calibration)
    refinement = calibration.refinement
    if refinement is not None:
        lines += ["", refinement_line(refinement)]
    if calibration.integrator_error is not None:
        lines += [
            "",
            f"Integrator: `{calibration.integrator}` (the stick on central difference is "
            f"{calibration.integrator_error:.4f} from itself on Runge-Kutta under the probe "
            "pulses, relative L2).",
        ]
    kept = refinement is not None and refinement["accepted"]
    if chosen.worst > FIT_WARNING and kept:
        lines += [
            "",
            f"The refined stick misses the pushovers' story shear by {chosen.worst:.0%} of the "
            "peak in the worst story: the refinement gave up some of the static fit for the "
            "response under records.",
        ]
    elif chosen.worst > FIT_WARNING:
        lines += [
            "",
            f"**The stick does not follow this structure closely**: its best law misses the "
            f"pushovers' story shear by {chosen.worst:.0%} of the peak in the worst story "
            f"(over {FIT_WARNING:.0%}); its z is a weak physics input here.",
        ]
    if refinement is not None:
        response = refinement["held_out_after" if kept else "held_out_before"]
        if response > RESPONSE_WARNING:
            lines += [
                "",
                "**The stick does not follow this structure closely under records**: on the "
                f"{refinement['held_out']} synthetic records held out its floor displacements "
                f"are {response:.2f} from the structure's (relative L2, over "
                f"{RESPONSE_WARNING}); its z is a weak physics input here.",
            ]
    return lines


def _cheaper_form_lines(calibration: StickCalibration) -> list[str]:
    """A paragraph where springs alone were kept although a coupled stick was closer
    under the probe pulses (both within :data:`~.stick_probes.FOLLOWS`), else none."""
    errors = calibration.dynamic_errors
    alone = errors.get(calibration.law + SPRINGS_ALONE)
    coupled = [e for name, e in errors.items() if not name.endswith(SPRINGS_ALONE)]
    if calibration.coupling is not None or alone is None or min(coupled) >= alone:
        return []
    return [
        "",
        f"Springs alone were kept although the coupled stick was closer under the probes "
        f"({min(coupled):.3f} against {alone:.3f}): both follow the structure within "
        f"{FOLLOWS}, and springs alone run faster. Their higher periods are the springs' "
        'own, so floor accelerations taken from z are less close; `coupling = "floors"` '
        "keeps the structure's.",
    ]


def refinement_line(refinement: dict) -> str:
    """What the refinement on synthetic records did, in one Markdown paragraph."""
    if "held_out_after" not in refinement:  # the pushovers' stick followed already
        return (
            f"The stick was checked on {refinement['records']} synthetic records and kept as "
            f"the pushovers fitted it: on the {refinement['held_out']} held out it is "
            f"{refinement['held_out_before']:.3f} from the structure (relative L2), within "
            f"{FOLLOWS:.0%}, so nothing was refined."
        )
    errors = (
        f"relative L2 against the structure on the {refinement['fitted']} records fitted "
        f"{refinement['fitted_before']:.3f} -> {refinement['fitted_after']:.3f}, on the "
        f"{refinement['held_out']} held out {refinement['held_out_before']:.3f} -> "
        f"{refinement['held_out_after']:.3f}"
    )
    if not refinement["accepted"]:
        return (
            f"The stick was refined on {refinement['records']} synthetic records ({errors}) "
            "and kept as the pushovers fitted it: the records held out do not favour the "
            "refinement."
        )
    factors = ", ".join(
        f"{k:.2f}/{y:.2f}"
        for k, y in zip(refinement["stiffness_factors"], refinement["yield_factors"], strict=True)
    )
    line = (
        f"The stick was refined on {refinement['records']} synthetic records ({errors}): "
        f"factors on each story's stiffness/yield drift {factors}"
    )
    held_out = refinement.get("held_out_by_refinement", {})
    if "whole law" not in held_out:
        return line + "."
    shape = "refitted too" if refinement["refined"] == "whole law" else "kept"
    return (
        f"{line}; the law's shape {shape} (held out: {held_out['backbone']:.3f} with the "
        f"backbone refined, {held_out['whole law']:.3f} with the whole law)."
    )


def plot_calibration(calibration: StickCalibration, path: Path) -> Path:
    """One column a story: the monotonic pushover (top) and the cyclic one (bottom), story
    shear against drift, the structure's curve and the stick's along the same drifts."""
    curves = [
        (curve, calibration.stick_shears(curve))
        for curve in (calibration.backbone, calibration.cyclic)
    ]
    stories = calibration.backbone.n_stories
    figure = Figure(figsize=(3.0 * stories, 5.6), layout="constrained")
    axes = np.atleast_2d(figure.subplots(2, stories, squeeze=False))
    for row, (curve, stick) in enumerate(curves):
        for story in range(stories):
            ax = axes[row, story]
            drift = 100 * curve.story_drift[:, story] / curve.heights[story]
            ax.plot(drift, curve.story_shear[:, story], color="k", lw=1.2, label="structure")
            ax.plot(drift, stick[:, story], color="C1", lw=1.0, ls="--", label="stick")
            ax.set_title(f"story {story + 1}, {'monotonic' if row == 0 else 'cyclic'}", fontsize=9)
            ax.set_xlabel("drift ratio (%)")
            ax.locator_params(axis="x", nbins=4)
    figure.supylabel("story shear (N, or the model's force unit)", fontsize=10)
    axes[0, 0].legend(fontsize=7)
    figure.savefig(path, dpi=120)
    return path
