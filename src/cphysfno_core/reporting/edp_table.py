"""The engineering demand parameters, each defined once: its name, what a column of it is
(a story, a floor, an output, a named response), its unit, how it is computed and what
pelicun calls it. :func:`cphysfno_core.edp.compute`, the error tables of the report and
``metrics.json``, fragility and the pelicun writer all iterate :data:`EDP_TABLE`; a name
that is not in it is an error (:func:`definition`).

A new EDP is one more :class:`EDPDefinition` in :data:`EDP_TABLE`: a function from the
:class:`EDPInputs` of a batch of records to its ``[n_records, n_columns]`` values (or None
where the responses do not hold what it needs).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..signals import GroundMotions, ResponseChannel, Stories
from ..signals.errors import ConfigError
from ..signals.intensity import velocity_displacement

Axis = Literal["story", "floor", "output", "response"]
"""What a column of an EDP is: a story (bottom-up), a floor level (column 0 the ground,
then the floors of :attr:`Stories.floors`), an output of the structure, or a named
response (:class:`~cphysfno_core.signals.ResponseChannel`)."""


@dataclass(frozen=True, eq=False)
class EDPInputs:
    """What the EDPs of a batch of records are computed from.

    Attributes:
        displacement: ``[n, T, n_outputs]`` displacements relative to the ground, m (rad
            for rotations).
        acceleration: ``[n, T, n_outputs]`` absolute accelerations, m/s^2, or None where
            only displacements are known.
        motions: the ``[n, T]`` ground accelerations (m/s^2) on the same grid.
        stories: the structure's stories.
        heights: ``[n, n_stories]`` each record's story heights in m (``nan`` for a story
            without height), or None where every record has the stories' own.
        residual: the samples whose mean drift is the residual drift.
        responses: name -> ``[n, T]`` history of each named response, in its channel's
            unit.
        channels: the named responses' channels, in the order of their columns.
    """

    displacement: np.ndarray
    acceleration: np.ndarray | None
    motions: GroundMotions
    stories: Stories
    heights: np.ndarray | None
    residual: slice
    responses: Mapping[str, np.ndarray]
    channels: tuple[ResponseChannel, ...]

    def drift_ratios(self) -> np.ndarray:
        """``[n, T, n_stories]`` story drifts over the story heights (m/m; m for a story
        without height)."""
        divisor = per_metre(self.stories, self.heights)
        if divisor.ndim == 2:
            divisor = divisor[:, None, :]
        return self.stories.drifts(self.displacement) / divisor

    def floor_absolute_acceleration(self) -> np.ndarray:
        """``[n, T', n_floors]`` absolute accelerations of the floors, m/s^2: the recorded
        (or predicted) ones, else the centred second difference of the displacement plus
        the ground's acceleration averaged with the same triangle (``T' = T - 2``, see
        :func:`cphysfno_core.edp.compute`)."""
        floors = list(self.stories.floors)
        if self.acceleration is not None:
            return self.acceleration[:, :, floors]
        u, ag, dt = self.displacement[:, :, floors], self.motions.acceleration, self.motions.dt
        relative = (u[:, 2:] - 2.0 * u[:, 1:-1] + u[:, :-2]) / dt**2
        ground = (ag[:, :-2] + 4.0 * ag[:, 1:-1] + ag[:, 2:]) / 6.0
        return relative + ground[:, :, None]

    def ground_velocity(self) -> np.ndarray:
        """``[n, T]`` the ground's velocity in m/s from rest, the exact integral of the
        acceleration linear between samples (trapezoidal rule)."""
        return velocity_displacement(self.motions.acceleration, self.motions.dt)[0]


@dataclass(frozen=True, eq=False)
class EDPDefinition:
    """One engineering demand parameter.

    Attributes:
        name: its key in :data:`EDP_TABLE`, ``metrics.json`` and ``EDPs`` (``"PID"``).
        title: what it is, in words.
        axis: what a column is (:data:`Axis`).
        unit: the unit of its values (a named response's peak has its channel's unit).
        method: how it is computed, in words.
        pelicun_type: pelicun's demand type for it, or None where it has none (a named
            response's channel says its own).
        scored: whether the error tables score it (``|ln(predicted / simulated)|``).
        peak_of: the function of :class:`EDPInputs` giving ``[n, n_columns]``, or None
            where the inputs lack what it needs.
    """

    name: str
    title: str
    axis: Axis
    unit: str
    method: str
    pelicun_type: str | None
    scored: bool
    peak_of: Callable[[EDPInputs], np.ndarray | None]

    @property
    def first_location(self) -> int:
        """The first column that is the structure's: 1 where column 0 is the ground's own
        value (a floor EDP's), which the error tables, baselines and fragility leave out;
        else 0."""
        return 1 if self.axis == "floor" else 0


def per_metre(stories: Stories, heights: np.ndarray | None = None) -> np.ndarray:
    """What a drift (m) is divided by: the height in m, or 1 for a story without height
    (whose "ratio" is then its drift in m): ``[n_stories]`` for the stories' own heights,
    ``[n, n_stories]`` for each record's ``heights [n, n_stories]``."""
    heights = np.asarray(stories.heights_m if heights is None else heights, dtype=np.float64)
    return np.where(np.isnan(heights), 1.0, heights)


def _pid(inputs: EDPInputs) -> np.ndarray:
    return np.max(np.abs(inputs.drift_ratios()), axis=1)


def _rid(inputs: EDPInputs) -> np.ndarray:
    return np.abs(np.mean(inputs.drift_ratios()[:, inputs.residual], axis=1))


def _pfa(inputs: EDPInputs) -> np.ndarray:
    ground = np.max(np.abs(inputs.motions.acceleration), axis=1)
    return np.column_stack([ground, np.max(np.abs(inputs.floor_absolute_acceleration()), axis=1)])


def _pfv(inputs: EDPInputs) -> np.ndarray:
    floors = list(inputs.stories.floors)
    u, dt = inputs.displacement[:, :, floors], inputs.motions.dt
    ground = inputs.ground_velocity()
    relative = (u[:, 2:] - u[:, :-2]) / (2.0 * dt)
    absolute = relative + ground[:, 1:-1, None]
    return np.column_stack([np.max(np.abs(ground), axis=1), np.max(np.abs(absolute), axis=1)])


def _pd(inputs: EDPInputs) -> np.ndarray:
    return np.max(np.abs(inputs.displacement), axis=1)


def _pr(inputs: EDPInputs) -> np.ndarray | None:
    if not inputs.channels:
        return None
    return np.column_stack(
        [np.max(np.abs(inputs.responses[c.name]), axis=1) for c in inputs.channels]
    )


EDP_TABLE: dict[str, EDPDefinition] = {
    d.name: d
    for d in (
        EDPDefinition(
            "PID",
            "peak story drift ratio",
            "story",
            "m/m",
            "max over t of |u_top - u_bottom| / story height (m for a story without height)",
            "PID",
            True,
            _pid,
        ),
        EDPDefinition(
            "RID",
            "residual story drift ratio",
            "story",
            "m/m",
            "|drift| at the last sample, or its mean over the second half of a free "
            "vibration that ends the record, over the story height",
            "RID",
            False,
            _rid,
        ),
        EDPDefinition(
            "PFA",
            "peak absolute floor acceleration",
            "floor",
            "m/s^2",
            "max over t of |absolute acceleration|: recorded or predicted where known, "
            "else the centred second difference of the displacement plus the ground's; "
            "column 0 is the peak ground acceleration",
            "PFA",
            True,
            _pfa,
        ),
        EDPDefinition(
            "PFV",
            "peak absolute floor velocity",
            "floor",
            "m/s",
            "max over t of |(u[k+1] - u[k-1]) / (2 dt) + v_g[k]|, v_g the ground's "
            "velocity from rest (trapezoidal integral of a_g); column 0 is the peak "
            "ground velocity",
            "PFV",
            True,
            _pfv,
        ),
        EDPDefinition(
            "PD",
            "peak displacement of each output relative to the ground",
            "output",
            "m",
            "max over t of |u| (rad for a rotation); at an isolation level, the isolator's "
            "peak displacement",
            None,
            True,
            _pd,
        ),
        EDPDefinition(
            "PR",
            "peak of each named response the structure records (base shear, element force)",
            "response",
            "the response's own unit",
            "max over t of |r|; a surrogate predicts it only where it learns the named "
            "responses (formulation.responses)",
            None,
            True,
            _pr,
        ),
    )
}
"""Every EDP by name, in the order tables list them."""


def definition(name: str) -> EDPDefinition:
    """The EDP called ``name`` (case does not matter).

    Raises:
        ConfigError: no EDP has that name (the message lists those that do).
    """
    found = EDP_TABLE.get(str(name).upper())
    if found is None:
        raise ConfigError(
            f"unknown EDP '{name}': the EDPs are "
            + ", ".join(f"{d.name} ({d.title})" for d in EDP_TABLE.values())
        )
    return found


def column_names(
    what: EDPDefinition,
    stories: Stories,
    output_names: tuple[str, ...],
    channels: tuple[ResponseChannel, ...],
) -> tuple[str, ...]:
    """The names of ``what``'s columns: the stories', ``ground`` and the floors' output
    names, the outputs' names, or the named responses'."""
    if what.axis == "story":
        return tuple(stories.names)
    if what.axis == "floor":
        return ("ground", *(output_names[i] for i in stories.floors))
    if what.axis == "output":
        return tuple(output_names)
    return tuple(c.name for c in channels)


def column_units(
    what: EDPDefinition,
    stories: Stories,
    n_columns: int,
    channels: tuple[ResponseChannel, ...],
) -> tuple[str, ...]:
    """The unit of each of ``what``'s columns: a story without height has its drift in m,
    a named response its channel's unit."""
    if what.axis == "response":
        return tuple(c.unit for c in channels)
    if what.axis == "story":
        return tuple("m" if np.isnan(h) else what.unit for h in stories.heights_m)
    return (what.unit,) * n_columns
