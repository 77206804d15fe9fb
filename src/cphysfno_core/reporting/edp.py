"""Engineering demand parameters (EDPs) of a structure's response, the same way for every
structure, from simulation and from prediction: peak and residual story drift ratios,
peak absolute floor accelerations and velocities, peak output displacements and the peaks
of named responses, as :data:`~cphysfno_core.reporting.edp_table.EDP_TABLE` defines them.

A structure declares its stories (capability ``"stories"``, see
:class:`~cphysfno_core.signals.Stories`); :func:`compute` takes its displacement histories
(simulated :class:`~cphysfno_core.signals.Responses`, or a ``[n, T, n_outputs]`` array
such as a composite model's predicted mean) with the ground motions that caused them.
:func:`interval` bounds the drift EDPs of a prediction from its standard deviation,
:func:`log_errors` scores predicted EDPs against simulated ones.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..api.interfaces import Structure
from ..signals import GroundMotions, ResponseChannel, Responses, Stories
from ..signals.errors import ConfigError, InputError
from ..signals.histories import ACCELERATION_EXTRA
from .edp_table import (
    EDP_TABLE,
    EDPInputs,
    column_names,
    column_units,
    definition,
    per_metre,
)


@dataclass(frozen=True, eq=False)
class EDPs:
    """The EDPs of each record, one ``[n_records, n_columns]`` table per EDP of
    :data:`~cphysfno_core.reporting.edp_table.EDP_TABLE` that could be computed.

    Attributes:
        values: EDP name -> ``[n_records, n_columns]`` values (``"PID"``, ``"RID"``,
            ``"PFA"``, ``"PFV"``, ``"PD"``, and ``"PR"`` where named responses were
            recorded).
        stories: the stories they are computed for.
        columns: EDP name -> the name of each column (stories, ``ground`` and the floors,
            outputs, named responses).
        units: EDP name -> the unit of each column.
        channels: the named responses whose peaks are ``"PR"``.

    Records whose response holds NaN (failed or collapsed ones) have NaN EDPs.
    """

    values: Mapping[str, np.ndarray]
    stories: Stories
    columns: Mapping[str, tuple[str, ...]]
    units: Mapping[str, tuple[str, ...]]
    channels: tuple[ResponseChannel, ...] = ()

    def __getitem__(self, name: str) -> np.ndarray:
        """The values of the EDP ``name`` (any case).

        Raises:
            ConfigError: no EDP has that name, or these EDPs lack it (a named response's
                peak of a prediction, say).
        """
        key = definition(name).name
        if key not in self.values:
            raise ConfigError(
                f"EDP {key} ({EDP_TABLE[key].title}) was not computed for these responses: "
                f"they have {', '.join(self.values)}"
            )
        return self.values[key]

    @property
    def pid(self) -> np.ndarray:
        """``[n_records, n_stories]`` peak story drift ratio (m/m; m for a story without
        height)."""
        return self["PID"]

    @property
    def rid(self) -> np.ndarray:
        """``[n_records, n_stories]`` residual story drift ratio."""
        return self["RID"]

    @property
    def pfa(self) -> np.ndarray:
        """``[n_records, 1 + n_floors]`` peak absolute floor acceleration in m/s^2; column 0
        is the ground (the peak ground acceleration), column ``j + 1`` is output
        ``stories.floors[j]``."""
        return self["PFA"]

    @property
    def n_records(self) -> int:
        return next(iter(self.values.values())).shape[0]

    def with_values(self, values: Mapping[str, np.ndarray]) -> EDPs:
        """These EDPs with the tables of ``values`` instead (same columns): only the EDPs
        named there are kept."""
        return replace(self, values={key: np.asarray(v) for key, v in values.items()})

    def map(self, function: Callable[[np.ndarray], np.ndarray]) -> EDPs:
        """``function`` applied to every table (e.g. to select or spread records)."""
        return self.with_values({key: function(v) for key, v in self.values.items()})

    @classmethod
    def from_tables(
        cls,
        values: Mapping[str, np.ndarray],
        stories: Stories,
        *,
        output_names: Sequence[str] | None = None,
        channels: Sequence[ResponseChannel] = (),
    ) -> EDPs:
        """EDPs from their tables, the columns and units as :data:`EDP_TABLE` defines them.

        Args:
            values: EDP name -> ``[n_records, n_columns]``.
            stories: the stories they are of.
            output_names: the outputs' names (default ``output-1``, ...: as many as the
                stories name).
            channels: the named responses of ``"PR"``.

        Raises:
            ConfigError: an unknown EDP name.
            InputError: a table that is not ``[n_records, n_columns]`` with the EDP's
                columns, or tables of different numbers of records.
        """
        if output_names is None:
            n = 1 + max(i for i in (*stories.upper, *stories.lower) if i is not None)
            output_names = tuple(f"output-{i + 1}" for i in range(n))
        names, channels = tuple(output_names), tuple(channels)
        tables, columns, units = {}, {}, {}
        for name, table in values.items():
            what = definition(name)
            table = np.asarray(table, dtype=np.float64)
            columns[what.name] = column_names(what, stories, names, channels)
            expected = len(columns[what.name])
            if table.ndim != 2 or table.shape[1] != expected:
                raise InputError(
                    f"{what.name} has shape {table.shape}; it must be [n_records, {expected}]: "
                    + ", ".join(columns[what.name])
                )
            tables[what.name] = table
            units[what.name] = column_units(what, stories, expected, channels)
        if len({t.shape[0] for t in tables.values()}) > 1:
            shapes = ", ".join(f"{k} {t.shape}" for k, t in tables.items())
            raise InputError(f"EDP tables of different numbers of records: {shapes}")
        return cls(tables, stories, columns, units, channels)

    @classmethod
    def concatenate(cls, parts: Sequence[EDPs]) -> EDPs:
        """The records of ``parts`` (EDPs of one structure) one after the other."""
        first = parts[0]
        return first.with_values(
            {key: np.concatenate([p.values[key] for p in parts]) for key in first.values}
        )


@dataclass(frozen=True, eq=False)
class DriftInterval:
    """Bounds on the drift EDPs of each record, each ``[n_records, n_stories]``
    (dimensionless): ``pid_lower <= PID <= pid_upper`` and ``rid_lower <= RID <= rid_upper``
    for a response whose every floor stays within its band at every time (see
    :func:`band_interval`)."""

    pid_lower: np.ndarray
    pid_upper: np.ndarray
    rid_lower: np.ndarray
    rid_upper: np.ndarray

    def coverage(self, truth: EDPs) -> dict[str, list[float]]:
        """Fraction of records per story whose true PID (``"PID"``) and RID (``"RID"``)
        lie within the bounds (records with NaN left out)."""
        found = {}
        for key, value, lower, upper in (
            ("PID", truth.pid, self.pid_lower, self.pid_upper),
            ("RID", truth.rid, self.rid_lower, self.rid_upper),
        ):
            inside = (lower <= value) & (value <= upper)
            known = np.isfinite(value) & np.isfinite(lower) & np.isfinite(upper)
            found[key] = [
                float(np.mean(inside[known[:, s], s])) if known[:, s].any() else float("nan")
                for s in range(value.shape[1])
            ]
        return found


def stories_of(structure: Structure | Stories) -> Stories:
    """``structure.stories()``, or ``structure`` itself if it is :class:`Stories`.

    Raises:
        CapabilityError: the structure declares no stories.
    """
    if isinstance(structure, Stories):
        return structure
    return structure.stories()


def pad_free_vibration(motions: GroundMotions, seconds: float) -> GroundMotions:
    """``motions`` followed by ``seconds`` of zero ground acceleration, on the same grid:
    simulate (or predict) on these and pass ``free_vibration_s=seconds`` to :func:`compute`
    so that the residual drift is read once the structure has (nearly) come to rest.

    Raises:
        InputError: ``seconds`` is negative or not finite.
    """
    seconds = float(seconds)
    if not np.isfinite(seconds) or seconds < 0.0:
        raise InputError(f"free vibration must last a finite number of s >= 0, got {seconds}")
    extra = int(round(seconds / motions.dt))
    padded = np.pad(motions.acceleration, ((0, 0), (0, extra)))
    return GroundMotions(padded, motions.dt, motions.metadata)


def compute(
    responses: Responses | np.ndarray,
    structure: Structure | Stories,
    motions: GroundMotions,
    *,
    free_vibration_s: float = 0.0,
    output_names: Sequence[str] | None = None,
    channels: Sequence[ResponseChannel] | None = None,
    heights: np.ndarray | None = None,
) -> EDPs:
    """Every EDP of :data:`~cphysfno_core.reporting.edp_table.EDP_TABLE` that the
    responses allow, for every record: peak (PID) and residual (RID) story drift ratios,
    peak absolute floor accelerations (PFA) and velocities (PFV), peak output
    displacements (PD), and the peaks of the named responses (PR) the responses carry.

    Story ``s`` drifts by ``d_s(t) = u_upper(t) - u_lower(t)`` (``u_lower = 0`` for the
    ground), in m; ``PID_s = max_t |d_s(t)| / h_s`` (``h_s = 1`` for a story without
    height: its PID and RID are drifts in m).

    ``RID_s = |d_s(t_end)| / h_s``, where ``d_s(t_end)`` is the drift at the last sample
    (``free_vibration_s = 0``, the default) or, when the record ends with
    ``free_vibration_s`` seconds of zero ground acceleration (made by
    :func:`pad_free_vibration` before simulating or predicting), the mean drift over the
    second half of that free vibration: the structure oscillates about its permanent set
    there, and the mean over a window of ``W`` s misses that set by at most
    ``A T / (pi W)``, ``A`` the amplitude still left at the window's start and ``T`` the
    period it oscillates at (a last sample would miss it by up to ``A``). Allow several
    first-mode periods of free vibration.

    PFA of floor ``j`` is ``max_t |ü_j(t) + a_g(t)|`` in m/s^2: the absolute acceleration,
    from the extra channel :data:`ACCELERATION_EXTRA` when ``responses`` carry it, else
    from the displacement. The centred second difference ``(u[k+1] - 2 u[k] + u[k-1]) /
    dt^2`` is exactly the mean of ``ü`` over ``t[k] ± dt`` weighted by a triangle; the
    ground acceleration, linear between samples, is averaged with the same triangle,
    ``(a_g[k-1] + 4 a_g[k] + a_g[k+1]) / 6``, so that their sum is the absolute
    acceleration so averaged, at every sample but the first and the last. The averaging
    multiplies a component of frequency ``f`` by ``sinc^2(f dt) = 1 - (2 pi f dt)^2 / 12 +
    ...``: with ``dt = 0.01`` s, peaks 0.3 % low for absolute acceleration at 3 Hz, 0.8 %
    at 5 Hz, 3 % at 10 Hz (a structure's absolute acceleration lies mostly at its own
    frequencies; above them the relative and the ground acceleration cancel, and they
    cancel in the average too). Noise in a displacement (a prediction's wiggles) of size
    ``e`` in m enters as up to ``4 e / dt^2`` m/s^2.

    PFV of floor ``j`` is ``max_k |(u_j[k+1] - u_j[k-1]) / (2 dt) + v_g[k]|`` in m/s, the
    absolute velocity, with ``v_g`` the ground's velocity from rest (the exact integral of
    ``a_g`` linear between samples); column 0 is the peak ground velocity. The centred
    difference is the mean velocity over ``t[k] ± dt``: a component of frequency ``f`` is
    multiplied by ``sin(2 pi f dt) / (2 pi f dt)``, 1.5 % low at 5 Hz with ``dt = 0.01`` s.
    PD of an output is ``max_t |u(t)|`` (m, rad for a rotation); PR of a named response
    ``max_t |r(t)|`` in its channel's unit.

    Args:
        responses: displacement histories relative to the ground, ``[n, T, n_outputs]`` in
            m: :class:`Responses` (which may carry :data:`ACCELERATION_EXTRA`), or an array
            such as ``CompositeModel.predict(motions)[0]``.
        structure: a structure with the capability ``"stories"``, or its
            :class:`Stories`.
        motions: the ``[n, T]`` ground accelerations (m/s^2) on the responses' grid.
        free_vibration_s: seconds of zero ground acceleration that end every record (see
            above); 0 reads the residual drift at the last sample.
        output_names: the outputs' names, for the columns (default: the structure's, or
            ``output-1``, ... when ``structure`` is :class:`Stories`).
        channels: the named responses to take the peaks of (PR), each an extra channel
            of ``responses`` (default: the structure's :meth:`response_channels` that the
            responses carry).
        heights: ``[n, n_stories]`` each record's story heights in m, for records of
            structures of one family whose heights differ (see
            :class:`~cphysfno_core.data.record_stories.RecordStories`); ``nan`` where the
            stories have no height. Default: every record has the stories' own.

    Returns:
        :class:`EDPs`: ``pid`` and ``rid`` ``[n, n_stories]``, ``pfa`` ``[n, 1 + n_floors]``
        (floor 0 the ground) in m/s^2, and the other EDPs in ``values``.

    Raises:
        InputError: shapes or time steps that do not match, stories naming outputs the
            responses lack, ``free_vibration_s`` longer than the records or over a part
            where the ground still moves, or ``heights`` not of the records and stories.
        CapabilityError: the structure declares no stories.
    """
    stories = stories_of(structure)
    u, acceleration = _histories(responses, motions)
    stories.check_outputs(u.shape[2])
    heights = record_heights(heights, stories, u.shape[0])
    if output_names is None:
        output_names = (
            structure.output_names
            if isinstance(structure, Structure)
            else tuple(f"output-{i + 1}" for i in range(u.shape[2]))
        )
    channels = _channels(responses, structure, channels)
    inputs = EDPInputs(
        u,
        acceleration,
        motions,
        stories,
        heights,
        _residual_window(motions, free_vibration_s),
        {c.name: _channel_history(responses, c.name, u.shape[:2]) for c in channels},
        channels,
    )
    values = {name: what.peak_of(inputs) for name, what in EDP_TABLE.items()}
    return EDPs.from_tables(
        {k: v for k, v in values.items() if v is not None},
        stories,
        output_names=tuple(output_names),
        channels=channels,
    )


def _channels(
    responses: Responses | np.ndarray,
    structure: Structure | Stories,
    channels: Sequence[ResponseChannel] | None,
) -> tuple[ResponseChannel, ...]:
    """The named responses whose peaks are taken: those asked for, else the structure's
    that the responses carry."""
    if channels is not None:
        return tuple(channels)
    if not isinstance(responses, Responses) or not isinstance(structure, Structure):
        return ()
    return tuple(c for c in structure.response_channels() if c.name in responses.extras)


def _channel_history(
    responses: Responses | np.ndarray, name: str, shape: tuple[int, int]
) -> np.ndarray:
    """The ``[n, T]`` history of the named response ``name`` in ``responses``."""
    extras = responses.extras if isinstance(responses, Responses) else {}
    if name not in extras:
        raise InputError(f"the responses carry no named response '{name}' (extra channel)")
    values = np.asarray(extras[name], dtype=np.float64)
    if values.shape != (*shape, 1):
        raise InputError(
            f"named response '{name}' has shape {values.shape}, expected {(*shape, 1)}"
        )
    return values[:, :, 0]


def band_interval(
    lower: np.ndarray,
    upper: np.ndarray,
    structure: Structure | Stories,
    motions: GroundMotions,
    *,
    free_vibration_s: float = 0.0,
    heights: np.ndarray | None = None,
) -> DriftInterval:
    """Bounds on PID and RID from a band ``lower <= u(t) <= upper`` around each output's
    displacement history, by interval arithmetic: story ``s`` drifts within
    ``[lower_top - upper_bottom, upper_top - lower_bottom]`` at every time, so its peak
    ``|drift|`` lies between the least and the largest ``|drift|`` that band allows at the
    time it allows most, and its residual (the mean over the window of :func:`compute`)
    between the means of the band's edges.

    The bounds hold for every record whose displacements stay within the band at every
    time; a band that holds each point with probability ``p`` holds a whole history less
    often, while taking the floors' errors as free to be opposite widens the drift band
    (drift errors are the difference of correlated floor errors): measure the coverage
    (:meth:`DriftInterval.coverage`) on test records rather than assume ``p``.

    Args:
        lower, upper: ``[n, T, n_outputs]`` displacement band in m (for example a
            refiner's ``interval``).
        structure, motions, free_vibration_s, heights: as in :func:`compute`.
    """
    stories = stories_of(structure)
    low, _ = _histories(lower, motions)
    high, _ = _histories(upper, motions)
    if low.shape != high.shape:
        raise InputError(f"band edges {low.shape} and {high.shape} must have one shape")
    stories.check_outputs(low.shape[2])
    divisor = per_metre(stories, record_heights(heights, stories, low.shape[0]))
    window = _residual_window(motions, free_vibration_s)
    top = list(stories.upper)
    bottom_index = [0 if i is None else i for i in stories.lower]
    ground = np.array([i is None for i in stories.lower])
    bottom_low = np.where(ground, 0.0, low[:, :, bottom_index])
    bottom_high = np.where(ground, 0.0, high[:, :, bottom_index])
    drift_low = low[:, :, top] - bottom_high
    drift_high = high[:, :, top] - bottom_low
    pid_lower = np.max(_distance_from_zero(drift_low, drift_high), axis=1) / divisor
    pid_upper = np.max(np.maximum(np.abs(drift_low), np.abs(drift_high)), axis=1) / divisor
    mean_low = np.mean(drift_low[:, window], axis=1)
    mean_high = np.mean(drift_high[:, window], axis=1)
    rid_lower = _distance_from_zero(mean_low, mean_high) / divisor
    rid_upper = np.maximum(np.abs(mean_low), np.abs(mean_high)) / divisor
    return DriftInterval(pid_lower, pid_upper, rid_lower, rid_upper)


def interval(
    mean: np.ndarray,
    std: np.ndarray,
    structure: Structure | Stories,
    motions: GroundMotions,
    *,
    k: float = 1.0,
    free_vibration_s: float = 0.0,
    heights: np.ndarray | None = None,
) -> DriftInterval:
    """Bounds on PID and RID of a prediction ``(mean, std)`` (each ``[n, T, n_outputs]`` in
    m, as ``CompositeModel.predict`` returns them): :func:`band_interval` of the band
    ``mean ± k std`` of every history. No bound is given for PFA: a band on displacements
    does not bound their second derivative.

    Args:
        k: half-width of the band in standard deviations (1 is the paper's ``± σ``;
            1.645 holds each point with probability 0.9 for Gaussian errors).
    """
    if not np.isfinite(k) or k < 0.0:
        raise InputError(f"k must be a finite number of standard deviations >= 0, got {k}")
    mean = np.asarray(mean, dtype=np.float64)
    half = k * np.broadcast_to(np.asarray(std, dtype=np.float64), mean.shape)
    return band_interval(
        mean - half,
        mean + half,
        structure,
        motions,
        free_vibration_s=free_vibration_s,
        heights=heights,
    )


LOG_ERROR_QUANTILES = {"median": 0.5, "p90": 0.9}
"""The quantiles of ``|ln(predicted / true)|`` over records that :func:`log_errors` gives."""


def log_errors(predicted: EDPs, truth: EDPs) -> dict[str, dict[str, list[float]]]:
    """Median and 90th percentile over records of ``|ln(predicted / true)|`` of every
    scored EDP both hold (``EDPDefinition.scored``: PID per story, PFA and PFV per floor
    above the ground, whose ground column is the record's own, PD per output).

    Records where either value is NaN or not > 0 are left out of that column's quantiles
    (NaN if none is left).

    Returns:
        ``{"PID": {"median": [n_stories], "p90": [n_stories]}, "PFA": {"median":
        [n_floors], "p90": [n_floors]}, ...}``; 0.1 is about a 10 % error.
    """
    found = {}
    for key in scored_names(predicted, truth):
        start = EDP_TABLE[key].first_location
        pred, true = predicted.values[key][:, start:], truth.values[key][:, start:]
        if pred.shape != true.shape:
            raise InputError(f"predicted {key} {pred.shape} and true {true.shape} differ")
        valid = np.isfinite(pred) & np.isfinite(true) & (pred > 0) & (true > 0)
        ratio = np.full(pred.shape, np.nan)
        ratio[valid] = np.abs(np.log(pred[valid] / true[valid]))
        found[key] = {
            name: [_nanquantile(ratio[:, j], q) for j in range(ratio.shape[1])]
            for name, q in LOG_ERROR_QUANTILES.items()
        }
    return found


def scored_names(*edps: EDPs) -> list[str]:
    """The scored EDPs (:data:`EDP_TABLE` order) that every one of ``edps`` holds."""
    return [
        key for key, what in EDP_TABLE.items() if what.scored and all(key in e.values for e in edps)
    ]


def scored_columns(edps: EDPs) -> dict[str, list[str]]:
    """The columns :func:`log_errors` scores of each scored EDP of ``edps``: stories,
    floors above the ground, outputs."""
    return {
        key: list(edps.columns[key][EDP_TABLE[key].first_location :])
        for key in scored_names(edps)
    }


def record_heights(heights: np.ndarray | None, stories: Stories, n: int) -> np.ndarray | None:
    """``heights`` checked as each of ``n`` records' story heights ``[n, n_stories]`` in m
    (None stays None): finite and > 0 where ``stories`` have a height, ``nan`` where they
    have none.

    Raises:
        InputError: another shape, or a height that breaks that rule.
    """
    if heights is None:
        return None
    heights = np.asarray(heights, dtype=np.float64)
    if heights.shape != (n, stories.n_stories):
        raise InputError(
            f"story heights have shape {heights.shape}; they must be [n_records, n_stories] = "
            f"[{n}, {stories.n_stories}]"
        )
    without = np.isnan(np.asarray(stories.heights_m, dtype=np.float64))
    valid = np.where(without, np.isnan(heights), np.isfinite(heights) & (heights > 0.0))
    if not valid.all():
        record, story = (int(i[0]) for i in np.nonzero(~valid))
        raise InputError(
            f"record {record}'s height of story {story + 1} is {heights[record, story]}: a "
            "story's height must be finite and > 0 m, or nan where the stories have none"
        )
    return heights


def require_heights(stories: Stories, what: str) -> None:
    """Raise :class:`ConfigError` unless every story has a height: ``what`` needs drift
    ratios."""
    if not stories.has_heights:
        missing = ", ".join(stories.without_height())
        raise ConfigError(
            f"{what} needs story drift ratios, but {missing} of the structure have no height "
            "(their ends stand at one elevation, as zeroLength springs or an isolator do): "
            "give the structure story_heights or drift_pairs"
        )


def _nanquantile(values: np.ndarray, q: float) -> float:
    values = values[np.isfinite(values)]
    return float(np.quantile(values, q)) if values.size else float("nan")


def _histories(
    responses: Responses | np.ndarray, motions: GroundMotions
) -> tuple[np.ndarray, np.ndarray | None]:
    """The ``[n, T, n_outputs]`` displacements and absolute accelerations (or None), checked
    against the motions' records and grid."""
    acceleration = None
    if isinstance(responses, Responses):
        if not np.isclose(responses.dt, motions.dt, rtol=1e-9, atol=0.0):
            raise InputError(
                f"responses at dt = {responses.dt} s for motions at dt = {motions.dt} s: "
                "compute EDPs on the motions' own grid"
            )
        u = responses.displacement
        if ACCELERATION_EXTRA in responses.extras:
            acceleration = np.asarray(responses.extras[ACCELERATION_EXTRA], dtype=np.float64)
            if acceleration.shape != u.shape:
                raise InputError(
                    f"extra '{ACCELERATION_EXTRA}' {acceleration.shape} must have the "
                    f"displacement's shape {u.shape}"
                )
    else:
        u = np.asarray(responses, dtype=np.float64)
    if u.ndim != 3:
        raise InputError(f"displacements must be [n_records, n_steps, n_outputs], got {u.shape}")
    if u.shape[:2] != motions.acceleration.shape:
        raise InputError(
            f"displacements {u.shape} do not match motions {motions.acceleration.shape}: "
            "give the responses to these motions, record for record, on their grid"
        )
    if u.shape[1] < 3:
        raise InputError(f"EDPs need at least 3 time steps, got {u.shape[1]}")
    return u, acceleration


def _residual_window(motions: GroundMotions, free_vibration_s: float) -> slice:
    """The samples whose mean drift is the residual drift."""
    seconds = float(free_vibration_s)
    if not np.isfinite(seconds) or seconds < 0.0:
        raise InputError(f"free_vibration_s must be a finite number of s >= 0, got {seconds}")
    tail = int(round(seconds / motions.dt))
    if tail == 0:
        return slice(-1, None)
    if tail >= motions.n_steps - 1:
        raise InputError(
            f"free_vibration_s = {seconds} s is not shorter than the records ({motions.duration} s)"
        )
    ag = motions.acceleration
    moving = np.abs(ag[:, -tail:]).max(axis=1) > 1e-12 * np.abs(ag).max(axis=1)
    if moving.any():
        record = int(np.flatnonzero(moving)[0])
        raise InputError(
            f"the ground still moves in the last {seconds} s of record {record}: pad the "
            "records with edp.pad_free_vibration(motions, seconds) before simulating or "
            "predicting, and pass that many seconds"
        )
    return slice(-max(tail // 2, 1), None)


def _distance_from_zero(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """The least ``|x|`` over ``low <= x <= high``: 0 where the range holds 0."""
    return np.where(low > 0.0, low, np.where(high < 0.0, -high, 0.0))
