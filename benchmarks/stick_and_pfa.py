"""The ``stick`` physics and the surrogates' floor accelerations on two structures a user
writes: the fibre RC frame of examples/rc-frame.toml and the building on bilinear isolators
of examples/isolated-building.toml (both OpenSeesPy models, kN-m-tonne); the stick physics
also on the SAC nine-story frame in the paper's regime of Example 3
(examples/sac9-frame-paper-regime.toml, beside the exact linear system's ``els-exact``) and
on the published two-story IMK frame (examples/opensees-model-imk.toml).

Physics (``python -m benchmarks.stick_and_pfa``): for each config, records drawn from its
own ground-motion source (20 s at 0.01 s, seed 1, not the run's data seed) are analysed by
the structure; the ones that take it past yield are kept (RC frame: largest peak story
drift ratio from 0.5 % to 2 %; isolated building: every record, its isolators yield at
11 mm and move several times that). On them, the pooled relative L2 of ``z`` against the
structure's displacements (over every record, sample and output) of ``stick``, of the
``els`` of the initial stiffness and of ``relaxed`` (the structure itself at 5 dt), and
the stick's calibration: the law and form chosen (with every pair's probe error), every
law's fit error per story, the stick's
periods beside the structure's, what the refinement on synthetic records did, the
integrator chosen; beside the stick, the same stick on
Runge-Kutta (``stick on runge-kutta``).

Speed: per record of 20 s at 100 Hz, on one core (the process's CPU affinity cut to one
core, which the compiled kernels' threads follow), warm, the median of 5 runs over all the
kept records for ``stick`` and ``els``; the structure's own analysis and ``relaxed`` in
one OpenSees worker process on the same core, one run over 4 records (they take seconds a
record).

Surrogates (``--runs rc-frame=DIR isolated-building=DIR``): from the ``metrics.json`` of a
finished ``cphysfno run`` of each config, per floor the median over test records of
|ln(predicted / simulated)| of the peak floor acceleration (PFA) and of the peak story
drift (PID), for every model, every physics input and both baselines, and how each row's
PFA was obtained (``pfa_from``).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
import warnings
from pathlib import Path

import numpy as np
from cphysfno_physics.stick_figures import refinement_line

import cphysfno_core as cp
from cphysfno_core import CphysfnoWarning, GroundMotions, edp
from cphysfno_core.config import ExperimentConfig
from cphysfno_core.plugin import Structure
from cphysfno_core.reporting.metrics import relative_l2

from .common import Timing, load_average, machine, median_time, on_cores

EXAMPLES = Path(__file__).parents[1] / "examples"
CONFIGS = (
    "rc-frame",
    "isolated-building",
    "sac9-frame-paper-regime",
    "opensees-model-imk",
    "rc-frame-5story",
    "isolated-building-bouc-wen",
)


@dataclasses.dataclass(frozen=True)
class StructureClass:
    """What the stick is asked on a class of structures.

    Attributes:
        target: pooled relative L2 of the stick's z to reach.
        drift_window: ``(lower, upper)`` largest peak story drift ratio of a kept record
            (every record where None).
        isolated: whether the first story is an isolation layer (its peak drift is shown).
    """

    target: float
    drift_window: tuple[float, float] | None = None
    isolated: bool = False


RC_FRAME = StructureClass(0.30, drift_window=(0.005, 0.02))
ISOLATED = StructureClass(0.10, isolated=True)
CLASSES = {
    "rc-frame": RC_FRAME,
    "rc-frame-5story": RC_FRAME,
    "isolated-building": ISOLATED,
    "isolated-building-bouc-wen": ISOLATED,
}
"""The class of each config the stick has a target on (none where not given)."""
MORE_PHYSICS = {"sac9-frame-paper-regime": ("els-exact",)}
"""Physics inputs compared beside stick, els and relaxed."""
SEED = 1
TIMED_SIMULATIONS = 4


def pooled_l2(estimate: np.ndarray, truth: np.ndarray) -> float:
    """sqrt(sum (estimate - truth)^2 / sum truth^2) over every record, sample and output."""
    return float(np.sqrt(np.sum((estimate - truth) ** 2) / np.sum(truth**2)))


def _structure(config: ExperimentConfig, workers: int) -> Structure:
    return cp.create(
        "structure", config.structure.name, **{**config.structure.params, "workers": workers}
    )


def physics(name: str, n_records: int) -> dict:
    """Accuracy of the physics inputs on records past yield, the stick's calibration and
    the time per record of each (see the module's docstring)."""
    config = cp.load_config(EXAMPLES / f"{name}.toml")
    source = cp.create("ground_motion", config.ground_motion.name, **config.ground_motion.params)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CphysfnoWarning)
        motions = source.sample(n_records, np.random.default_rng(SEED))
    structure = _structure(config, workers=2)
    truth = structure.simulate(motions)
    pid = edp.compute(truth, structure, motions).pid
    largest = np.nanmax(pid, axis=1)
    kind = CLASSES.get(name)
    window = None if kind is None else kind.drift_window
    keep = np.isfinite(largest)
    if truth.collapsed is not None:
        keep &= ~truth.collapsed
    if window is not None:
        keep &= (largest >= window[0]) & (largest <= window[1])
    kept = GroundMotions(motions.acceleration[keep], motions.dt)
    u = truth.displacement[keep]

    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CphysfnoWarning)
        stick = cp.create("preprocessor", "stick").fit(structure)
    fit_s = time.perf_counter() - start
    els = cp.create("preprocessor", "els").fit(structure)
    relaxed = cp.create("preprocessor", "relaxed", factor=5).fit(structure)
    calibration = stick.calibration_
    on_runge_kutta = dataclasses.replace(calibration, integrator="runge-kutta").building()
    z = {
        "stick": stick.transform(kept),
        "stick on runge-kutta": on_runge_kutta.simulate(kept).displacement[:, :, stick.floors_],
        "els": els.transform(kept),
    }
    z["relaxed"] = relaxed.transform(kept)
    for label in MORE_PHYSICS.get(name, ()):
        z[label] = cp.create("preprocessor", label).fit(structure).transform(kept)
    result = {
        "records_drawn": n_records,
        "records_kept": int(keep.sum()),
        "kept_peak_drift_ratio": [float(largest[keep].min()), float(largest[keep].max())],
        "median_peak_drift_ratio_per_story": np.nanmedian(pid[keep], axis=0).tolist(),
        "pooled_rel_l2": {k: pooled_l2(v, u) for k, v in z.items()},
        "rel_l2_per_output": {k: relative_l2(v, u).tolist() for k, v in z.items()},
        "target": None if kind is None else kind.target,
        "calibration": {
            "law": calibration.law,
            "form": "springs alone" if calibration.coupling is None else "coupled",
            "dynamic_errors": calibration.dynamic_errors,
            "fit_errors": {law: fit.errors for law, fit in calibration.fits.items()},
            "periods": calibration.periods.tolist(),
            "stick_periods": calibration.stick_periods.tolist(),
            "stiffness_scale": calibration.stiffness_scale,
            "integrator": calibration.integrator,
            "integrator_error": calibration.integrator_error,
            "refinement": calibration.refinement,
            "fit_s": fit_s,
            "warnings": [str(w.message) for w in caught],
        },
    }
    if kind is not None and kind.isolated:
        peaks = np.abs(u[:, :, 0]).max(axis=1)
        result["isolator_peak_m"] = np.quantile(peaks, [0.0, 0.5, 1.0]).tolist()

    load_before = load_average()
    with on_cores(1):
        single = _structure(config, workers=1)
        one_relaxed = cp.create("preprocessor", "relaxed", factor=5).fit(single)
        few = GroundMotions(kept.acceleration[:TIMED_SIMULATIONS], kept.dt)
        timing = {}
        for label, function in (
            ("stick", lambda: stick.transform(kept)),
            ("stick on runge-kutta", lambda: on_runge_kutta.simulate(kept)),
            ("els", lambda: els.transform(kept)),
        ):
            seconds, how = median_time(function, runs=5, warmup=1)
            timing[label] = (seconds / kept.n_records, how)
        for label, function in (
            ("structure", lambda: single.simulate(few)),
            ("relaxed", lambda: one_relaxed.transform(few)),
        ):
            function()  # warm: the worker's model probed, OpenSees loaded
            start = time.perf_counter()
            function()
            seconds = time.perf_counter() - start
            timing[label] = (seconds / few.n_records, Timing(1, True, 1, "single"))
    result["seconds_per_record"] = {k: v[0] for k, v in timing.items()}
    result["timing"] = {k: str(v[1]) for k, v in timing.items()}
    result["load_average"] = [load_before, load_average()]
    result["n_steps"] = kept.n_steps
    return result


def surrogates(run: Path) -> dict:
    """Per floor PFA and per story PID median |ln| errors of every row of a run's
    metrics.json, with where each row's PFA came from."""
    metrics = json.loads((run / "metrics.json").read_text())
    rows = {}
    for label, row in {**metrics["models"], **metrics.get("baselines", {})}.items():
        errors = row.get("edp")
        if not errors:
            continue
        rows[label] = {
            "PFA": errors["PFA"]["median"],
            "PID": errors["PID"]["median"],
            "pfa_from": row.get("pfa_from", "-"),
        }
    return {"edp": metrics["edp"], "rows": rows}


def _physics_tables(name: str, r: dict) -> str:
    lines = [f"### {name}", ""]
    lines.append(
        f"{r['records_kept']} of {r['records_drawn']} records kept (largest peak story drift "
        f"{100 * r['kept_peak_drift_ratio'][0]:.2f}-{100 * r['kept_peak_drift_ratio'][1]:.2f} %)"
    )
    lines += ["", "| physics | pooled rel L2 | per output | target |", "|---|---|---|---|"]
    for label, value in r["pooled_rel_l2"].items():
        per = ", ".join(f"{v:.3f}" for v in r["rel_l2_per_output"][label])
        target = f"<= {r['target']}" if label == "stick" and r["target"] else ""
        lines.append(f"| {label} | {value:.3f} | {per} | {target} |")
    c = r["calibration"]
    lines += ["", f"law chosen: {c['law']}, {c['form']}; fit {c['fit_s']:.1f} s; integrator "
              f"{c['integrator']} (probe error {c['integrator_error']:.4f})", ""]  # fmt: skip
    if c.get("refinement"):
        lines += [refinement_line(c["refinement"]), ""]
    lines += ["| law | fit error per story |", "|---|---|"]
    for law, errors in c["fit_errors"].items():
        lines.append(f"| {law} | {', '.join(f'{e:.3f}' for e in errors)} |")
    lines.append("")
    lines.append(f"periods (s): structure {np.round(c['periods'], 4).tolist()}, "
                 f"stick {np.round(c['stick_periods'], 4).tolist()}")  # fmt: skip
    lines += ["", "| per record | s | timing |", "|---|---|---|"]
    for label, seconds in r["seconds_per_record"].items():
        lines.append(f"| {label} | {seconds:.4g} | {r['timing'][label]} |")
    lines.append(f"\nload average {r['load_average'][0]} before, {r['load_average'][1]} after")
    return "\n".join(lines)


def _surrogate_table(name: str, s: dict) -> str:
    floors = len(next(iter(s["rows"].values()))["PFA"])
    stories = len(next(iter(s["rows"].values()))["PID"])
    head = [f"PFA {i + 1}" for i in range(floors)] + [f"PID {i + 1}" for i in range(stories)]
    lines = [f"### {name}", "", "| row | " + " | ".join(head) + " | pfa_from |"]
    lines.append("|---" * (len(head) + 2) + "|")
    for label, row in s["rows"].items():
        values = " | ".join(f"{v:.3f}" for v in [*row["PFA"], *row["PID"]])
        lines.append(f"| {label} | {values} | {row['pfa_from']} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.stick_and_pfa", description=__doc__)
    parser.add_argument("--records", type=int, default=40, help="records drawn per config")
    parser.add_argument("--configs", nargs="*", default=list(CONFIGS), choices=CONFIGS)
    parser.add_argument(
        "--runs", nargs="*", default=[], metavar="CONFIG=DIR", help="finished runs to read"
    )
    parser.add_argument("--json", type=Path, help="write every number here")
    args = parser.parse_args(argv)
    print(f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} on {machine()}\n")
    found: dict = {"physics": {}, "surrogates": {}}
    for name in args.configs:
        found["physics"][name] = physics(name, args.records)
        print(_physics_tables(name, found["physics"][name]) + "\n", flush=True)
    for item in args.runs:
        name, folder = item.split("=", 1)
        found["surrogates"][name] = surrogates(Path(folder))
        print(_surrogate_table(name, found["surrogates"][name]) + "\n")
    if args.json is not None:
        args.json.write_text(json.dumps(found, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
