"""Time histories that travel with their time step: ground motions and structural responses."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import InputError


def check_time_step(dt: float, what: str = "dt") -> float:
    """Return ``dt`` as a float, or raise :class:`InputError` unless it is finite and > 0 s."""
    try:
        value = float(dt)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a number of seconds, got {dt!r}") from None
    if not np.isfinite(value) or value <= 0.0:
        raise InputError(f"{what} must be a finite time step > 0 s, got {dt!r}")
    return value


def check_finite(array: np.ndarray, what: str) -> None:
    """Raise :class:`InputError` naming the first record that holds NaN or Inf."""
    bad = ~np.isfinite(array)
    if bad.any():
        record = int(np.argwhere(bad)[0][0])
        raise InputError(f"{what} holds NaN or Inf (first in record {record}): remove or fix it")


@dataclass(frozen=True)
class TimeGrid:
    """A uniform time grid: ``n_steps`` samples every ``dt`` s from t = 0."""

    dt: float
    n_steps: int

    def __str__(self) -> str:
        return f"{self.n_steps} samples at dt = {self.dt:g} s"

    def matches(self, other: TimeGrid) -> bool:
        """Same number of samples and the same step (within the resampling tolerance)."""
        from .resampling import same_step

        return self.n_steps == other.n_steps and same_step(self.dt, other.dt)


@dataclass(frozen=True)
class GroundMotions:
    """A batch of ground acceleration records on one uniform time grid.

    Attributes:
        acceleration: ``[n_records, n_steps]`` ground acceleration in m/s^2 (float64).
            A 1-D array is taken as a single record.
        dt: time step in s.
        metadata: one mapping per record (event, station, scale factor, ...), or empty.
    """

    acceleration: np.ndarray
    dt: float
    metadata: Sequence[Mapping[str, Any]] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        if np.iscomplexobj(self.acceleration):
            raise InputError("acceleration must be real, got complex values")
        try:
            ag = np.asarray(self.acceleration, dtype=np.float64)
        except (TypeError, ValueError):
            raise InputError(
                "acceleration must be a numeric array [n_records, n_steps] in m/s^2"
            ) from None
        if ag.ndim == 1:
            ag = ag[None, :]
        if ag.ndim != 2:
            raise InputError(
                f"acceleration must have shape [n_records, n_steps], got shape {ag.shape}"
            )
        if ag.shape[1] < 2:
            raise InputError(f"acceleration needs at least 2 time steps, got {ag.shape[1]}")
        check_finite(ag, "acceleration")
        object.__setattr__(self, "acceleration", ag)
        object.__setattr__(self, "dt", check_time_step(self.dt))
        metadata = tuple(dict(m) for m in self.metadata)
        if metadata and len(metadata) != ag.shape[0]:
            raise InputError(
                f"metadata has {len(metadata)} entries for {ag.shape[0]} records: "
                "give one per record"
            )
        object.__setattr__(self, "metadata", metadata)

    @property
    def n_records(self) -> int:
        return self.acceleration.shape[0]

    @property
    def n_steps(self) -> int:
        return self.acceleration.shape[1]

    @property
    def time(self) -> np.ndarray:
        """``[n_steps]`` sample times in s, starting at 0."""
        return np.arange(self.n_steps) * self.dt

    @property
    def duration(self) -> float:
        """Length of the record in s (time of the last sample)."""
        return (self.n_steps - 1) * self.dt

    @property
    def grid(self) -> TimeGrid:
        """The time grid of the records."""
        return TimeGrid(self.dt, self.n_steps)

    def on_grid(self, grid: TimeGrid) -> GroundMotions:
        """The same motions on ``grid``: resampled with anti-aliasing to its step (see
        :func:`cphysfno_core.signals.resampling.resample`), then cut or zero-padded at the end to
        its number of samples.

        Raises:
            InputError: the two steps are not in a ratio of integers up to 1000.
        """
        from .resampling import resample

        ag = resample(self.acceleration, self.dt, grid.dt)
        if ag.shape[1] >= grid.n_steps:
            ag = ag[:, : grid.n_steps]
        else:
            ag = np.pad(ag, ((0, 0), (0, grid.n_steps - ag.shape[1])))
        return GroundMotions(ag, grid.dt, self.metadata)

    def __len__(self) -> int:
        return self.n_records

    def __getitem__(self, index: int | slice | np.ndarray) -> GroundMotions:
        """Select records (an int keeps the batch dimension)."""
        rows = np.arange(self.n_records)[index]
        rows = np.atleast_1d(rows)
        metadata = tuple(self.metadata[i] for i in rows) if self.metadata else ()
        return GroundMotions(self.acceleration[rows], self.dt, metadata)

    def resample(self, dt: float) -> GroundMotions:
        """The same motions sampled every ``dt`` s, linear between the original samples.

        The new grid starts at 0 and covers the record; its last point may lie past the
        original end, where the last sample is held.
        """
        dt = check_time_step(dt)
        n_new = int(np.ceil(self.duration / dt - 1e-9)) + 1
        t_new = np.arange(n_new) * dt
        t_old = self.time
        ag = np.stack([np.interp(t_new, t_old, row) for row in self.acceleration])
        return GroundMotions(ag, dt, self.metadata)


ACCELERATION_EXTRA = "absolute_acceleration"
"""Name of the extra response channel (``Responses.extras``) a structure may return with
the absolute (total) acceleration of each output, ``[n, T, n_outputs]`` in m/s^2."""


@dataclass(frozen=True)
class ResponseChannel:
    """A named response a structure records beside its displacements (a reaction, an
    element force, a deformation): the extra channel ``Responses.extras[name]``,
    ``[n_records, n_steps, 1]`` in ``unit``.

    Attributes:
        name: the channel's name (also the column of its peak in the EDP tables).
        unit: the unit its values are in, as the user stated it (``"kN"``, ``"m"``).
        description: what it is, in words.
        pelicun_type: the demand type its peak is written as in a pelicun demand sample
            (``"BRD"`` for a bearing's deformation, any acronym for another), or None to
            leave it out of the sample.
        pelicun_location: the location of that demand (pelicun's ``TYPE-LOC-DIR``).
    """

    name: str
    unit: str
    description: str = ""
    pelicun_type: str | None = None
    pelicun_location: int = 1

    def as_dict(self) -> dict[str, Any]:
        """The channel as JSON-ready values (the inverse of ``ResponseChannel(**d)``)."""
        return {
            "name": self.name,
            "unit": self.unit,
            "description": self.description,
            "pelicun_type": self.pelicun_type,
            "pelicun_location": self.pelicun_location,
        }


@dataclass(frozen=True)
class Responses:
    """Structural response histories on one uniform time grid.

    Attributes:
        displacement: ``[n_records, n_steps, n_outputs]`` output displacements in m,
            relative to the ground.
        dt: time step in s.
        extras: optional further channels, each ``[n_records, n_steps, k]``
            (for example ``"hysteretic_force"`` in N and ``"drift"`` in m).
        failures: record index -> why that record's analysis failed (for example
            ``"did not converge at t = 12.34 s"``); those records' rows are NaN. A
            structure that reports failures here spares the caller re-running the batch
            record by record to find them.
        collapsed: ``[n_records]`` bool, whether the record collapsed the structure (its
            analysis stopped converging, or a drift passed the structure's collapse
            limit). A collapse is data, not a failure: the record's rows hold the history
            up to the collapse and NaN after it; datasets keep the flag, training and error
            tables leave the record out and fragility counts it. ``None`` (the default)
            means no record collapsed.
        messages: record index -> what the simulator printed while analysing that record
            (its warnings), for the records it printed anything for; data generation
            shows each distinct message once with its count and keeps them in full in a
            log.
        non_converged: record index -> why, for the records whose analysis stopped
            converging before the structure collapsed (below its collapse drift): a
            numerical failure, not a collapse. Their rows hold the history up to the stop
            and NaN after it; they are not ``collapsed``, datasets keep them listed,
            training and error tables leave them out, and fragility treats them as the
            user chooses.
        recoveries: record index -> the hardest measure its analysis needed to converge,
            in words (an OpenSees structure's convergence ladder: ``"substeps dt/4"``,
            ``"KrylovNewton"``, ``"a looser test"``), for the records that needed one;
            data generation counts the records by it and the dataset keeps it.
    """

    displacement: np.ndarray
    dt: float
    extras: Mapping[str, np.ndarray] = field(default_factory=dict)
    failures: Mapping[int, str] = field(default_factory=dict)
    collapsed: np.ndarray | None = None
    messages: Mapping[int, str] = field(default_factory=dict)
    non_converged: Mapping[int, str] = field(default_factory=dict)
    recoveries: Mapping[int, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        u = np.asarray(self.displacement, dtype=np.float64)
        if u.ndim != 3:
            raise InputError(
                f"displacement must have shape [n_records, n_steps, n_outputs], got {u.shape}"
            )
        object.__setattr__(self, "displacement", u)
        object.__setattr__(self, "dt", check_time_step(self.dt))
        object.__setattr__(self, "extras", dict(self.extras))
        for name in ("failures", "messages", "non_converged", "recoveries"):
            object.__setattr__(self, name, _by_record(getattr(self, name), name, u.shape[0]))
        if self.collapsed is None:
            collapsed = np.zeros(u.shape[0], dtype=bool)
        else:
            collapsed = np.asarray(self.collapsed)
            if collapsed.shape != (u.shape[0],) or collapsed.dtype != np.bool_:
                raise InputError(
                    f"collapsed must be a bool array with one flag per record ({u.shape[0]}), "
                    f"got {collapsed.dtype} of shape {collapsed.shape}"
                )
        object.__setattr__(self, "collapsed", collapsed)

    @property
    def time(self) -> np.ndarray:
        """``[n_steps]`` sample times in s."""
        return np.arange(self.displacement.shape[1]) * self.dt


def _by_record(texts: Mapping[int, str], what: str, n_records: int) -> dict[int, str]:
    """``texts`` (record index -> text) as a plain dict, every index checked to be one of
    the ``n_records`` records."""
    checked = {int(i): str(text) for i, text in dict(texts).items()}
    outside = [i for i in checked if not 0 <= i < n_records]
    if outside:
        raise InputError(f"{what} names records {outside} outside 0..{n_records - 1}")
    return checked


@dataclass(frozen=True)
class Record:
    """A single-component ground acceleration record.

    Attributes:
        acceleration: ``[T]`` acceleration in m/s^2.
        dt: time step in s.
        metadata: what is known of it; the keys this package fills are ``name`` (how
            messages call the record), ``event``, ``year``, ``magnitude``, ``station``,
            ``component``, ``mechanism``, ``vs30`` (m/s), ``rjb_km``, ``rrup_km``, ``rsn``
            (NGA record sequence number), ``file``.
    """

    acceleration: np.ndarray
    dt: float
    metadata: dict[str, Any] = field(default_factory=dict)

    @property
    def name(self) -> str:
        """How messages call this record."""
        return str(self.metadata.get("name", "record"))

    @property
    def duration(self) -> float:
        """Length in s (time of the last sample)."""
        return (self.acceleration.size - 1) * self.dt


def as_ground_motions(motions: GroundMotions | np.ndarray, dt: float | None) -> GroundMotions:
    """``motions`` as :class:`GroundMotions`: given so, or made from an array of
    accelerations (m/s^2) and its ``dt`` (s).

    Raises:
        InputError: anything else, or an array without ``dt``, with what to pass instead.
    """
    if isinstance(motions, GroundMotions):
        if dt is not None and not np.isclose(dt, motions.dt):
            raise InputError(f"dt = {dt} s given for ground motions of dt = {motions.dt} s")
        return motions
    if isinstance(motions, np.ndarray | list):
        if dt is None:
            raise InputError(
                "an array of ground accelerations needs its time step: "
                "predict(accelerations, dt=0.01) with accelerations [n_records, n_steps] in "
                "m/s^2, or pass cphysfno_core.GroundMotions(accelerations, dt)"
            )
        return GroundMotions(np.atleast_2d(np.asarray(motions, dtype=np.float64)), dt)
    raise InputError(
        f"predict takes cphysfno_core.GroundMotions or a NumPy array [n_records, n_steps] of "
        f"accelerations in m/s^2 with dt=..., not {type(motions).__name__}; to read records "
        "from files use cphysfno_core.model.prediction_files.read_motions"
    )
