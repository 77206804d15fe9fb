"""``cphysfno fragility RUN``: fragility curves of a trained run, from simulation and from
the surrogate, side by side.

On the run's test records the curves are fitted twice, from the simulated truth and from
the surrogate's prediction of the same records; then from the surrogate alone on a large
number of new motions drawn from the run's ground-motion source (or read from a file).
Each curve is a lognormal fragility fitted by maximum likelihood on exceedance
(:mod:`cphysfno_core.reporting.fragility`) against an intensity measure: Sa(T1, 5 %) at
the structure's first elastic period, Sa at any period, Sa_avg over a period range, PGA or
PGV (:mod:`cphysfno_core.reporting.intensity_measures`).

The demand of a record is the largest over stories of its peak story drift ratio (PID),
or the largest over floors of its peak absolute floor acceleration (PFA, m/s^2). A record
that collapsed the structure exceeds every limit state in the simulation curves; one whose
analysis stopped converging below the collapse is left out of them, or counted as a
collapse (``non_converged``).

For a run whose structure has random parameters (a model of a family), each test record
is predicted on its own drawn structure, and each record of the large set draws its
parameters from the config's distributions: its curves carry record-to-record and
modelling dispersion. The large set is then predicted a second time with every parameter
at its median (``surrogate-large-medians``: record-to-record dispersion alone), and each
limit state's ``dispersion`` splits the total β into the two,
``β_modelling = sqrt(β_total² - β_record-to-record²)``.

The surrogate does not predict the structure's collapse: its curves combine the
probability of collapse, fitted against the intensity measure on the simulated records,
with the surrogate's demands by total probability, ``P(C) + (1 - P(C)) P(exceed | no
collapse)``, summarised by the lognormal closest to that curve; their intervals are those
of the non-collapse part. A record whose physics input collapses (a stick whose story
law lost its strength) exceeds every limit state in the surrogate's demands, as a
simulated collapse does in the simulation's (``surrogate_collapses`` counts them); a
record whose prediction fails is left out (``skipped_records``).
"""

from __future__ import annotations

import json
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..api.registry import get_registry
from ..config.experiment import load_config, parse_config
from ..config.uncertainty import UncertainParameters
from ..data.datasets import load_dataset
from ..data.layout import CONFIG, DATASET, MODELS, run_file
from ..data.record_stories import RecordStories
from ..model.composite import CompositeModel
from ..model.extrapolation import EXTRAPOLATION_FACTOR, outside_training
from ..model.labels import ModelLabel
from ..model.prediction_files import read_motions
from ..model.skipping import predict_skipping_failures
from ..reporting import edp
from ..reporting.evaluation import simulated_edps
from ..reporting.fragility import (
    Fragility,
    fit_lognormal,
    fit_with_intervals,
    lognormal_through,
    with_collapse,
)
from ..reporting.fragility_figures import plot_demand_cloud, plot_fragility
from ..reporting.intensity_measures import IntensityMeasure, intensity_measure
from ..signals import GroundMotions
from ..signals.errors import ConfigError, CphysfnoWarning, ExtrapolationWarning, InputError
from ..signals.progress import show_progress
from .metrics_document import MetricsDocument

NON_CONVERGED = ("exclude", "collapse")
"""What fragility may make of a record that did not converge below the collapse."""

CHUNK = 500
"""Records predicted at a time for the large analysis (bounded memory)."""


@dataclass(frozen=True)
class LimitState:
    """A threshold on a demand.

    Attributes:
        demand: the EDP's name, lower case (``"pid"``, ``"pfa"``, ``"pfv"``, ``"pd"``,
            ``"rid"``: :data:`~cphysfno_core.edp.EDP_TABLE`).
        threshold: the value exceeded, in the EDP's unit (drift ratio, m/s^2, m/s, m).
        column: the one column (story, floor, output) it applies to, or None for the
            largest over them (the ground's own column left out).
    """

    demand: str
    threshold: float
    column: str | None = None

    @property
    def name(self) -> str:
        where = "" if self.column is None else f":{self.column}"
        return f"{self.demand}{where} > {self.threshold:g}"

    @property
    def needs_ratios(self) -> bool:
        """Whether the demand is a story drift ratio (which needs story heights)."""
        return edp.definition(self.demand).axis == "story"


def parse_limit_states(text: str) -> list[LimitState]:
    """``"pid=0.005,0.01;pfa=5;pd:isolator=0.3"`` as limit states: ``demand[:column]=
    value[,value...]``, the demand any EDP a surrogate predicts.

    Raises:
        ConfigError: an unknown demand or a threshold that is not a number > 0.
    """
    states = []
    for part in filter(None, (p.strip() for p in text.split(";"))):
        target, _, values = part.partition("=")
        demand, _, column = target.strip().partition(":")
        demand = demand.strip().lower()
        if not demand or not values:
            raise ConfigError(
                f"limit states: '{part}' is not demand[:column]=value[,value...] "
                "(e.g. pid=0.005,0.01,0.02 or pd:isolator=0.3)"
            )
        edp.definition(demand)
        for value in values.split(","):
            try:
                threshold = float(value)
            except ValueError:
                raise ConfigError(f"limit states: '{value}' is not a number") from None
            if not threshold > 0:
                raise ConfigError(f"limit states: thresholds must be > 0, got {threshold}")
            states.append(LimitState(demand, threshold, column.strip() or None))
    if not states:
        raise ConfigError("limit states: give at least one, e.g. pid=0.005,0.01,0.02")
    return states


def default_model(metrics: MetricsDocument, demands: tuple[str, ...] = ("PID", "PFA")) -> str:
    """The model a fragility or a demand sample uses unless told: the trained model with
    the lowest validation EDP error, the mean over stories and floors of the median
    ``|ln(predicted / simulated)|`` of the ``demands`` (``validation_edp`` in
    ``metrics.json``; a model that does not predict a scored demand, such as a named
    response's peak, comes last), a refined one where they tie. A run without EDP errors
    (a structure without stories) chooses by the mean validation relative L2 instead. The
    refiner is not preferred for itself: fitted on the training split, it can make a model
    worse on new records (the SAC frame's: validation 0.21 refined against 0.18 without,
    and drift fragility medians 30-50 % off against within 10 %).

    Raises:
        ConfigError: the run has no trained model.
    """
    rows = {
        label: row for label, row in metrics.models.items() if ModelLabel.parse(label).is_trained
    }
    if not rows:
        raise ConfigError("this run has no trained model: run `cphysfno train` first")

    def score(label: str) -> tuple[float, bool]:
        row = rows[label]
        if row.validation_edp is not None:
            errors = row.validation_edp
            medians = [v for key in demands if key in errors for v in errors[key]["median"]]
            lacking = any(k not in errors and edp.EDP_TABLE[k].scored for k in demands)
            found = np.isfinite(medians).any() and not lacking
            value = float(np.nanmean(medians)) if found else np.inf
        else:
            value = float(np.mean(row.validation_rel_l2 or row.rel_l2))
        return value, not ModelLabel.parse(label).refined

    return min(rows, key=score)


@dataclass(frozen=True)
class TrainedRun:
    """A finished run with one of its saved models.

    Attributes:
        config: the run's experiment config.
        label: the model's label under ``RUN/models``.
        model: the model.
        structure: the run's structure, built from its config.
    """

    config: Any
    label: str
    model: CompositeModel
    structure: Any


def load_trained_run(
    run: Path,
    model_label: str | None,
    demands: tuple[str, ...] = ("PID", "PFA"),
    config_path: Path | None = None,
) -> TrainedRun:
    """The run's config (or the config file ``config_path``, an edited one), the model
    ``model_label`` (default :func:`default_model` on the ``demands``) and the structure.

    Raises:
        ConfigError: the run is not finished, has no such model (the message lists those
            it has), or the config file does not validate.
    """
    for needed in (CONFIG, "metrics.json"):
        if not run_file(run, needed).is_file():
            raise ConfigError(f"{run} is not a finished run: it has no {needed}")
    if config_path is None:
        config = parse_config(json.loads(run_file(run, CONFIG).read_text()))
    else:
        config = load_config(config_path)
    label = model_label or default_model(MetricsDocument.read(run / "metrics.json"), demands)
    folder = run / MODELS / label
    if not (folder / "model.json").is_file():
        known = sorted(p.name for p in (run / MODELS).iterdir() if (p / "model.json").is_file())
        raise ConfigError(
            f"no saved model '{label}' in {run / MODELS}: use one of {', '.join(known)}"
        )
    spec = config.structure
    structure = get_registry().create("structure", spec.name, **spec.params)
    return TrainedRun(config, label, CompositeModel.load(folder), structure)


def surrogate_pfa_source(model: CompositeModel, label: str) -> str:
    """How the surrogate's floor accelerations are obtained: ``"predicted acceleration"``
    for a model that learns them, else ``"displacement"`` (the second difference of its
    predicted displacement), with a :class:`~cphysfno_core.CphysfnoWarning` saying why
    that is unreliable."""
    if model.formulation.accelerations:
        return "predicted acceleration"
    warnings.warn(
        f"model '{label}' does not learn floor accelerations: its PFA comes from the second "
        "difference of its predicted displacement, where a wiggle of e m makes up to "
        "4 e / dt^2 m/s^2 (an order of magnitude off on a fibre frame); train it with "
        "formulation.accelerations = true on a structure that records them",
        CphysfnoWarning,
        stacklevel=3,
    )
    return "displacement"


def demand_values(demands: edp.EDPs, state: LimitState) -> np.ndarray:
    """``[n]`` the demand of each record that ``state`` is set on: its column's value, or
    the largest over the columns (the ground's own left out).

    Raises:
        ConfigError: ``state.column`` is not a column of the demand (the message lists
            them).
    """
    what = edp.definition(state.demand)
    values, columns = demands[what.name], demands.columns[what.name]
    if state.column is not None:
        if state.column not in columns:
            raise ConfigError(
                f"limit state {state.name}: '{state.column}' is not a column of "
                f"{state.demand}; its columns are {', '.join(columns)}"
            )
        return values[:, columns.index(state.column)]
    return np.max(values[:, what.first_location :], axis=1)


def run_fragility(
    run: Path,
    *,
    limit_states: list[LimitState],
    records: int = 10_000,
    motions_file: Path | None = None,
    model_label: str | None = None,
    measure: str = "sa-t1",
    n_bootstrap: int = 200,
    seed: int = 0,
    progress: bool = True,
    out: Path | None = None,
    config_path: Path | None = None,
    non_converged: str = "exclude",
) -> dict[str, Any]:
    """Fit the fragility curves of a trained run and write ``RUN/fragility/`` (or ``out``):
    ``fragility.json``, ``fragility.png``, ``edp-im.png``.

    A record whose prediction fails is left out of the fits and counted
    (``skipped_records``); one whose physics input collapses exceeds every limit state
    (``surrogate_collapses``); a limit state that no record reaches (or every
    record exceeds) gets no curve and a ``note`` while the others are fitted; a fit the
    records may not determine is flagged (``flags``:
    :func:`~cphysfno_core.reporting.fragility.fit_flags`).

    Args:
        run: a folder written by ``cphysfno run`` (``config.json``, ``metrics.json``,
            ``dataset.h5``, ``models/``), or one run of a study (``STUDY/runs/...``, whose
            dataset and config are the study's: :func:`~cphysfno_core.data.layout.run_file`).
        limit_states: the thresholds to fit.
        records: motions of the large analysis, drawn from the run's ground-motion source
            with ``seed`` (ignored with ``motions_file``).
        motions_file: motions of the large analysis from a file instead (as
            ``cphysfno predict`` reads them).
        model_label: the model under ``models/``; default :func:`default_model` on the
            limit states' demands.
        measure: the intensity measure's name
            (:func:`~cphysfno_core.reporting.intensity_measures.intensity_measure`).
        n_bootstrap: bootstrap resamples of each fit.
        seed: seeds the draw of motions and the bootstrap.
        progress: print progress lines.
        out: the folder to write to instead of ``RUN/fragility``.
        config_path: a config file to use instead of the run's own ``config.json`` (for
            its structure and ground-motion source).
        non_converged: what a test record whose analysis stopped converging below the
            collapse is in the simulation curves: ``"exclude"`` (left out, the default) or
            ``"collapse"`` (counted as a collapse); ``non_converged_test_records`` says
            which.

    Returns:
        The document written to ``fragility.json``.

    Raises:
        ConfigError: the run is not finished, the model or intensity measure is unknown.
    """
    run = Path(run)
    if non_converged not in NON_CONVERGED:
        raise ConfigError(f"--non-converged {non_converged}: use one of {', '.join(NON_CONVERGED)}")
    if not run_file(run, DATASET).is_file():
        raise ConfigError(f"{run} is not a finished run: it has no {DATASET}")
    demands = tuple(dict.fromkeys(state.demand.upper() for state in limit_states))
    trained = load_trained_run(run, model_label, demands, config_path)
    config, label, model, structure = (
        trained.config,
        trained.label,
        trained.model,
        trained.structure,
    )
    if any(state.needs_ratios for state in limit_states):
        edp.require_heights(edp.stories_of(structure), "a fragility on story drift ratios")
    if "PR" in demands and not model.response_names:
        raise ConfigError(
            f"limit states on named responses (PR) need a model that learns them: '{label}' "
            "does not (train it with formulation.responses = true)"
        )
    t1 = float(structure.periods(1)[0])
    im = intensity_measure(measure, t1)
    data = load_dataset(run_file(run, DATASET))

    rows = data._split_rows("test")
    motions = GroundMotions(data.ag[rows], data.dt)
    stopped = np.isin(rows, list(data.non_converged))
    collapsed = data.collapsed[rows] | (stopped if non_converged == "collapse" else False)
    failed = np.isin(rows, list(data.failures))
    standing = ~collapsed & ~stopped & ~failed
    counted = ~failed & (~stopped if non_converged == "exclude" else True)
    im_test = im.of(motions)
    family = RecordStories(structure)
    heights = family.heights(data.draws_of(rows), len(rows))
    truth = simulated_edps(data, rows, family.stories, heights)
    for state in limit_states:  # an unknown column is refused before any prediction
        demand_values(truth, state)
    kept = motions[np.flatnonzero(standing)]
    drawn = data.draws_of(rows[standing]) if model.parameters is not None else None
    responses, test_failures = predict_skipping_failures(model, kept, drawn)
    predicted = edp.compute(
        responses, structure, kept, heights=None if heights is None else heights[standing]
    )

    space = modelling_uncertainty(model, config)
    started = time.perf_counter()
    large = _large_analysis(
        model, family, config, records, motions_file, im, seed, progress, space
    )
    large_seconds = time.perf_counter() - started
    large_sets = {"surrogate-large": (large.demands, large.collapsed)}
    if large.median_demands is not None:
        large_sets["surrogate-large-medians"] = (large.median_demands, large.median_collapsed)

    rng = np.random.default_rng(seed)
    collapse = None
    if collapsed[counted].any() and not collapsed[counted].all():
        collapse = fit_lognormal(im_test[counted], collapsed[counted], what="collapse")
    document: dict[str, Any] = {
        "run": str(run),
        "model": label,
        "surrogate_pfa_from": surrogate_pfa_source(model, label) if "PFA" in demands else None,
        "intensity_measure": {**im.to_dict(), "t1_s": t1},
        "test_records": int(rows.size),
        "collapsed_test_records": int(data.collapsed[rows].sum()),
        "non_converged_test_records": {
            "count": int(stopped.sum()),
            "treated_as": "left out" if non_converged == "exclude" else "collapse",
        },
        "large_records": int(large.intensity.size),
        "large_seconds": round(large_seconds, 1),
        "large_source_records": large.distinct,
        "large_extrapolated": large.extrapolated,
        "modelling_uncertainty": None
        if space is None
        else {"parameters": list(space.names), "units": list(space.units)},
        "skipped_records": _skipped_records(test_failures, standing, large),
        "surrogate_collapses": _surrogate_collapses(responses.collapsed, large),
        "collapse": None
        if collapse is None
        else {"median": collapse.median, "beta": collapse.beta},
        "limit_states": {},
    }
    _say_skipped(document["skipped_records"], progress)
    known = np.isfinite(large.intensity)
    grid = np.geomspace(
        min(im_test.min(), large.intensity[known].min(initial=np.inf)) / 3.0,
        max(im_test.max(), large.intensity[known].max(initial=0.0)) * 3.0,
        400,
    )
    curves = {}
    sources = ("simulation", "surrogate", *large_sets)
    for state in limit_states:
        what = f"{state.name} ({measure})"
        simulated = np.where(collapsed, True, demand_values(truth, state) > state.threshold)
        simulation = _fit_or_note(
            im_test[counted], simulated[counted], rng, n_bootstrap, what + ", simulation"
        )
        known, exceeded = surrogate_outcomes(predicted, responses.collapsed, state)
        surrogate = _surrogate_fit(
            im_test[standing][known], exceeded[known],
            collapse, grid, rng, n_bootstrap, what + ", surrogate",
        )  # fmt: skip
        fits = {"simulation": simulation, "surrogate": surrogate}
        for source, (demands, fell) in large_sets.items():
            known, exceeded = surrogate_outcomes(demands, fell, state)
            fits[source] = _surrogate_fit(
                large.intensity[known], exceeded[known],
                collapse, grid, rng, n_bootstrap, f"{what}, {source}",
            )  # fmt: skip
        if "surrogate-large-medians" in fits:
            fits["dispersion"] = dispersion_split(
                fits["surrogate-large"], fits["surrogate-large-medians"]
            )
        document["limit_states"][state.name] = fits
        curves[state.name] = {}
        for source in sources:
            fit = fits[source]
            if fit["median"] is not None:
                curves[state.name][source] = Fragility(fit["median"], fit["beta"])
    out = run / "fragility" if out is None else Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "fragility.json").write_text(json.dumps(document, indent=2) + "\n")
    axis = f"{im.description}, {im.unit}"
    plot_fragility(curves, im_test, axis, out / "fragility.png")
    first = limit_states[0]
    what = edp.definition(first.demand)
    plot_demand_cloud(
        {"simulation (test)": (im_test, demand_values(truth, first)),
         "surrogate (test)": (im_test[standing], demand_values(predicted, first)),
         "surrogate (large)": (large.intensity, demand_values(large.demands, first))},
        axis, f"{what.title}{'' if first.column is None else ', ' + first.column}, {what.unit}",
        out / "edp-im.png",
    )  # fmt: skip
    return document


def modelling_uncertainty(model: CompositeModel, config: Any) -> UncertainParameters | None:
    """The random parameters the large set draws: the config's, for a model of a family
    (None for a model of one structure, or a config without distributions).

    Raises:
        ConfigError: the config draws a parameter the model does not take.
    """
    space = config.uncertain_parameters()
    if model.parameters is None or not space.parameters:
        return None
    unknown = sorted(set(space.names) - set(model.parameters.names))
    if unknown:
        raise ConfigError(
            f"the config draws {', '.join(unknown)}, which the model does not take (it takes "
            f"{', '.join(model.parameters.names)}): fix them in the config, or train on them"
        )
    return space


def dispersion_split(drawn: dict[str, Any], medians: dict[str, Any]) -> dict[str, Any]:
    """The total β of the fit with drawn parameters split into the record-to-record β (the
    fit with every parameter at its median) and the modelling β, combined as the square
    root of the sum of squares (FEMA P-58's way of adding dispersions):
    ``β_modelling = sqrt(β_total² - β_record-to-record²)``, 0 where the total is the smaller
    (with ``note``); ``median_shift`` is the ratio of the medians, drawn over medians.
    None values where a fit is missing."""
    total, record = drawn.get("beta"), medians.get("beta")
    found: dict[str, Any] = {
        "beta_total": total,
        "beta_record_to_record": record,
        "beta_modelling": None,
        "median_shift": None,
    }
    if total is None or record is None:
        return found
    found["beta_modelling"] = float(np.sqrt(max(total**2 - record**2, 0.0)))
    found["median_shift"] = float(drawn["median"] / medians["median"])
    if total < record:
        found["note"] = (
            "the total β is below the record-to-record β: the modelling dispersion is within "
            "the fits' scatter"
        )
    return found


def surrogate_outcomes(
    demands: edp.EDPs, collapsed: np.ndarray, state: LimitState
) -> tuple[np.ndarray, np.ndarray]:
    """``([n] known, [n] exceeded)`` of the surrogate's records for ``state``: a record
    whose physics collapsed (``collapsed``) is known and exceeds every limit state, as a
    collapse in the simulation does; one whose prediction failed (NaN EDPs) is not
    known."""
    known = np.isfinite(demands.pid).all(axis=1) | collapsed
    exceeded = collapsed | (demand_values(demands, state) > state.threshold)
    return known, exceeded


def _surrogate_collapses(test: np.ndarray, large: LargeAnalysis) -> dict[str, int]:
    """How many records' physics collapsed (counted as exceeding every limit state), in
    the test records and the large set (and its prediction at the medians)."""
    found = {"test": int(test.sum()), "large": int(large.collapsed.sum())}
    if large.median_demands is not None:
        found["large-medians"] = int(large.median_collapsed.sum())
    return found


def _skipped_records(
    test_failures: dict[int, str], standing: np.ndarray, large: LargeAnalysis
) -> dict[str, dict[str, Any]]:
    """:func:`_skipped` of the test records (``standing [n]``: those predicted), of the
    large set, and of its prediction at the medians where it has one."""
    every = np.arange(large.intensity.size)
    found = {
        "test": _skipped(test_failures, np.flatnonzero(standing)),
        "large": _skipped(large.failures, every),
    }
    if large.median_demands is not None:
        found["large-medians"] = _skipped(large.median_failures, every)
    return found


def _skipped(failures: dict[int, str], records: np.ndarray) -> dict[str, Any]:
    """``{"count", "first"}``: how many records failed and the first few, by their record
    number among ``records``, with the cause."""
    first = dict(list(failures.items())[:5])
    return {
        "count": len(failures),
        "first": {str(int(records[i])): why for i, why in first.items()},
    }


def _say_skipped(skipped: dict[str, dict[str, Any]], progress: bool) -> None:
    for name, found in skipped.items():
        if found["count"] and progress:
            (record, why), *_ = found["first"].items()
            show_progress(
                f"  fragility: {found['count']} {name} records could not be predicted and are "
                f"left out of the fits (record {record}: {why})"
            )


def _fit_or_note(
    im: np.ndarray, exceeded: np.ndarray, rng: np.random.Generator, n_bootstrap: int, what: str
) -> dict[str, Any]:
    """The fit with its intervals and flags, or ``median`` and ``beta`` None with the
    reason in ``note`` when the records do not give both outcomes (a limit state that no
    record reaches is a finding, not an error)."""
    try:
        return fit_with_intervals(im, exceeded, rng, n_bootstrap, what=what).to_dict()
    except InputError as error:
        return {
            "median": None,
            "beta": None,
            "note": str(error),
            "n_records": int(np.size(im)),
            "n_exceeded": int(np.sum(exceeded)),
            "flags": [],
        }


def _surrogate_fit(
    im: np.ndarray,
    exceeded: np.ndarray,
    collapse: Fragility | None,
    grid: np.ndarray,
    rng: np.random.Generator,
    n_bootstrap: int,
    what: str,
) -> dict[str, Any]:
    """The surrogate's curve (:func:`_fit_or_note`): its non-collapse fit, combined with
    ``collapse`` when there is one and summarised by the closest lognormal."""
    result = _fit_or_note(im, exceeded, rng, n_bootstrap, what)
    if collapse is not None and result["median"] is not None:
        fit = Fragility(result["median"], result["beta"])
        combined = lognormal_through(with_collapse(fit, collapse, grid), grid)
        result.update(
            {
                "median": combined.median,
                "beta": combined.beta,
                "non_collapse": {"median": fit.median, "beta": fit.beta},
            }
        )
    return result


@dataclass(frozen=True)
class LargeAnalysis:
    """The surrogate's predictions of the large set.

    Attributes:
        intensity: ``[N]`` the intensity measure of each record.
        demands: the EDPs of each record (NaN for the records in ``failures``).
        distinct: the most records one draw of the source gave where that is fewer than
            asked (a finite set, see :func:`draw`), else None.
        extrapolated: how many records lie outside the model's training range
            (:func:`outside_training`).
        failures: record index -> why its prediction failed.
        collapsed: ``[N]`` whether each record's physics collapsed (its EDPs NaN).
        median_demands: for a model of a family whose records drew their parameters, the
            EDPs of the same records predicted with every parameter at its median (None
            otherwise).
        median_failures: record index -> why its prediction at the medians failed.
        median_collapsed: ``[N]`` whether each record's physics collapsed at the medians
            (None without ``median_demands``).
    """

    intensity: np.ndarray
    demands: edp.EDPs
    distinct: int | None
    extrapolated: int
    failures: dict[int, str]
    collapsed: np.ndarray
    median_demands: edp.EDPs | None = None
    median_failures: dict[int, str] = field(default_factory=dict)
    median_collapsed: np.ndarray | None = None


def _large_analysis(
    model: CompositeModel,
    family: RecordStories,
    config: Any,
    records: int,
    motions_file: Path | None,
    im: IntensityMeasure,
    seed: int,
    progress: bool,
    space: UncertainParameters | None = None,
) -> LargeAnalysis:
    """The large set predicted :data:`CHUNK` records at a time, with progress (records per
    second and time left) after each chunk; records outside the training range are said
    once at the end instead of warned for every chunk. With ``space``, each record draws
    its structural parameters from it (reproducibly by ``seed``) and is predicted again
    with every parameter at its median (:attr:`LargeAnalysis.median_demands`); without,
    a model of a family predicts every record at its parameters' medians. Each record's
    drift ratios are over its own structure's story heights (``family``)."""
    if motions_file is not None:
        source_motions = read_motions(motions_file)
        n = source_motions.n_records
    else:
        if records < 1:
            raise InputError(f"--records must be at least 1, got {records}")
        spec = config.ground_motion
        source = get_registry().create("ground_motion", spec.name, **spec.params)
        rng = np.random.default_rng([seed, 7919])
        n = records
    intensities, parts, median_parts, collapsed, median_collapsed = [], [], [], [], []
    started = time.perf_counter()
    distinct = None
    extrapolated = 0
    failures: dict[int, str] = {}
    median_failures: dict[int, str] = {}
    training_pga = getattr(model, "training_pga_", None)
    draws = None if space is None else space.draw(n, seed)
    for start in range(0, n, CHUNK):
        stop = min(start + CHUNK, n)
        if motions_file is not None:
            chunk = source_motions[start:stop]
        else:
            chunk, largest = draw(source, stop - start, rng)
            if largest < stop - start:
                distinct = largest if distinct is None else max(distinct, largest)
        extrapolated += int(outside_training(chunk, training_pga).sum())
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ExtrapolationWarning)
            params = None if draws is None else space.columns(draws[start:stop])
            responses, failed = predict_skipping_failures(model, chunk, params)
            collapsed.append(responses.collapsed)
            if draws is not None:
                at_medians, failed_at_medians = predict_skipping_failures(model, chunk)
                median_parts.append(edp.compute(at_medians, family.structure, chunk))
                median_collapsed.append(at_medians.collapsed)
                median_failures.update({start + i: why for i, why in failed_at_medians.items()})
        failures.update({start + i: why for i, why in failed.items()})
        heights = family.heights(params, chunk.n_records)
        parts.append(edp.compute(responses, family.structure, chunk, heights=heights))
        intensities.append(im.of(chunk))
        if progress:
            elapsed = time.perf_counter() - started
            rate = stop / max(elapsed, 1e-9)
            show_progress(
                f"  fragility: {stop}/{n} records predicted ({rate:.0f} records/s, about "
                f"{(n - stop) / rate:.0f} s left)"
            )
    demands = edp.EDPs.concatenate(parts)
    if extrapolated and progress:
        show_progress(
            f"  fragility: {extrapolated} of {n} records lie outside the PGA range the model "
            f"was trained on (more than {EXTRAPOLATION_FACTOR:g} times beyond it): their "
            "predictions are extrapolations"
        )
    if distinct is not None and progress:
        show_progress(
            f"  fragility: the ground-motion source gives at most {distinct} records a draw; "
            "the large set was drawn in rounds (a scaled source scales each round anew)"
        )
    medians = edp.EDPs.concatenate(median_parts) if median_parts else None
    return LargeAnalysis(
        np.concatenate(intensities),
        demands,
        distinct,
        extrapolated,
        failures,
        np.concatenate(collapsed),
        medians,
        median_failures,
        np.concatenate(median_collapsed) if median_collapsed else None,
    )


def draw(source: Any, n: int, rng: np.random.Generator) -> tuple[GroundMotions, int]:
    """``n`` records from ``source``, and the most one of its draws gave.

    A finite source (a set of recorded motions) gives at most the records it has in one
    draw; it is drawn again until there are ``n``: a source that scales its records (a
    ``scale_range`` or intensity scenarios) draws new factors every time, so the rounds
    are the same shapes at new intensities; an unscaled one repeats its records.
    """
    parts, got, largest = [], 0, 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CphysfnoWarning)
        while got < n:
            part = source.sample(n - got, rng)
            if part.n_records == 0:
                raise InputError(f"the ground-motion source gave no records for {n} asked")
            parts.append(part)
            got += part.n_records
            largest = max(largest, part.n_records)
    if len(parts) == 1:
        return parts[0], largest
    metadata = [meta for part in parts for meta in (part.metadata or [{}] * part.n_records)]
    acceleration = np.concatenate([part.acceleration for part in parts])
    return GroundMotions(acceleration, parts[0].dt, metadata), largest
