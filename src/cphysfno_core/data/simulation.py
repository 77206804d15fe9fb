"""Simulation of one chunk of records: truth and physics responses, with every record that
fails (an exception, or NaN/Inf in its output) found and named, and every plugin output
checked for its shape."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..api.registry import get_registry
from ..config.calibration_surface import CalibrationSurface, member_preprocessor
from ..config.uncertainty import distinct_draws, with_values
from ..signals import GroundMotions
from ..signals.errors import PluginError


@dataclass
class ChunkResult:
    """What one chunk produced.

    Attributes:
        u: ``[n, T, n_out]`` truth in m (NaN rows for failed records).
        extras: extra structural channels, ``[n, T, k]`` each.
        z: preprocessor name -> ``[n, T, n_out]`` physics responses in m.
        failures: index within the chunk -> cause, for the records that failed.
        collapsed: ``[n]`` whether each record collapsed the structure (its truth holds NaN
            after the collapse; not a failure).
        messages: index within the chunk -> what the simulator printed for that record.
        non_converged: index within the chunk -> cause, for the records whose analysis
            stopped converging below the collapse (their truth holds NaN after the stop;
            not a failure, not a collapse).
        recoveries: index within the chunk -> the hardest measure its analysis needed to
            converge (:attr:`~cphysfno_core.Responses.recoveries`).
    """

    u: np.ndarray
    extras: dict[str, np.ndarray]
    z: dict[str, np.ndarray]
    failures: dict[int, str] = field(default_factory=dict)
    collapsed: np.ndarray | None = None
    messages: dict[int, str] = field(default_factory=dict)
    non_converged: dict[int, str] = field(default_factory=dict)
    recoveries: dict[int, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.collapsed is None:
            self.collapsed = np.zeros(self.u.shape[0], dtype=bool)


class _Parts:
    """Structure and fitted preprocessors rebuilt from their names and parameters; a
    preprocessor with a calibration surface (of a family, by name) is fitted from the
    calibration there at the structure's parameter ``values``."""

    def __init__(
        self,
        structure_spec: dict[str, Any],
        preprocessor_specs: list[dict[str, Any]],
        surfaces: dict[str, CalibrationSurface] | None = None,
        values: dict[str, float] | None = None,
    ):
        registry = get_registry()
        spec = dict(structure_spec)
        self.structure_entry = registry.entry("structure", spec.pop("name"))
        self.structure = registry.create("structure", self.structure_entry.name, **spec)
        self.preprocessors = {}
        for pp_spec in preprocessor_specs:
            name = pp_spec["name"]
            surface = (surfaces or {}).get(name)
            fitted = member_preprocessor(pp_spec, self.structure, values or {}, surface)
            self.preprocessors[name] = (registry.entry("preprocessor", name), fitted)

    def run(self, motions: GroundMotions) -> ChunkResult:
        """Simulate ``motions``; a malformed plugin output raises naming its provider."""
        shape = (motions.n_records, motions.n_steps, self.structure.n_outputs)
        responses = self.structure.simulate(motions)
        _check_shape(responses.displacement, shape, self.structure_entry, "displacement")
        extras = {}
        for name, values in responses.extras.items():
            _check_shape(values, shape[:2] + np.shape(values)[2:], self.structure_entry, name)
            extras[name] = np.asarray(values)
        z = {}
        for name, (entry, preprocessor) in self.preprocessors.items():
            z[name] = np.asarray(preprocessor.transform(motions), dtype=np.float64)
            _check_shape(z[name], shape, entry, "z")
        result = ChunkResult(
            responses.displacement,
            extras,
            z,
            dict(responses.failures),
            responses.collapsed,
            dict(responses.messages),
            dict(responses.non_converged),
            dict(responses.recoveries),
        )
        for i in result.failures:
            _blank(result, i)
        return result


def _check_shape(values: Any, shape: tuple, entry: Any, what: str) -> None:
    found = np.shape(values)
    if found != shape or np.ndim(values) < 3:
        raise PluginError(
            f"{entry.kind} '{entry.name}' from {entry.distribution} returned {what} of shape "
            f"{found}, expected {shape}"
        )


def _non_finite_causes(result: ChunkResult) -> dict[int, str]:
    """Record index -> what holds NaN or Inf, for the records with any non-finite output.
    A collapsed or non-converged record is left out of everything: its truth ends in NaN
    by design, and its physics responses (a coarse model of it may collapse too) are not
    checked."""
    causes: dict[int, str] = {}
    ended = result.collapsed.copy()
    ended[list(result.non_converged)] = True
    outputs = [("the response (the simulation diverged)", result.u)]
    outputs += [
        (f"the '{name}' physics response (its simulation failed or diverged)", values)
        for name, values in result.z.items()
    ]
    for what, values in outputs:
        finite = np.isfinite(values).all(axis=tuple(range(1, values.ndim)))
        for i in np.flatnonzero(~finite & ~ended):
            causes.setdefault(int(i), f"NaN or Inf in {what}")
    return causes


def simulate_chunk(
    structure_spec: dict[str, Any],
    preprocessor_specs: list[dict[str, Any]],
    acceleration: np.ndarray,
    dt: float,
    parameters: tuple[str, ...] = (),
    draws: np.ndarray | None = None,
    surfaces: dict[str, dict[str, Any]] | None = None,
) -> ChunkResult:
    """Truth and physics responses of one chunk of records; runs in a worker process.

    Components are rebuilt here from their names and parameters, so nothing but plain data
    crosses the process boundary. A record that comes out with NaN or Inf is listed as
    failed, its cause naming the output; if the chunk raises, the records are simulated one
    at a time to find which fail and why. A failed record's rows are NaN and its cause is
    in ``failures``.

    A preprocessor with a calibration surface in ``surfaces`` (preprocessor name ->
    surface document) is made from the calibration there instead of being fitted: for a
    fixed structure, the calibration the parent fitted once. With random parameters (their
    dotted ``parameters`` paths in ``structure_spec``, whose distributions they name, and
    ``draws [n, k]`` their values for each record), each distinct draw builds its own
    structure and fits (or makes) its own preprocessors, and simulates the records that
    drew it.
    """
    motions = GroundMotions(acceleration, dt)
    surfaces = {name: CalibrationSurface.from_dict(s) for name, s in (surfaces or {}).items()}
    if not parameters:
        return _simulate(_Parts(structure_spec, preprocessor_specs, surfaces, {}), motions)
    pieces = []
    for row, rows in distinct_draws(draws):
        values = dict(zip(parameters, row.tolist(), strict=True))
        parts = _Parts(with_values(structure_spec, values), preprocessor_specs, surfaces, values)
        pieces.append((rows, _simulate(parts, motions[rows])))
    return _gather(pieces, motions.n_records)


def _simulate(parts: _Parts, motions: GroundMotions) -> ChunkResult:
    """:func:`simulate_chunk` of one structure."""
    try:
        result = parts.run(motions)
    except PluginError:
        raise
    except Exception:  # noqa: BLE001 - the records are rerun one by one to find the cause
        return _record_by_record(parts, motions)
    for i, cause in _non_finite_causes(result).items():
        if i not in result.failures:
            result.failures[i] = cause
            _blank(result, i)
    return result


def _gather(pieces: list[tuple[np.ndarray, ChunkResult]], n: int) -> ChunkResult:
    """One result of ``n`` records from the results of groups of them, each with its
    record indices ``[m]``; an extra channel a group lacks (all its records failed) is NaN
    there (False for a flag)."""

    def place(pick) -> np.ndarray:
        known = [(rows, pick(result)) for rows, result in pieces if pick(result) is not None]
        template = known[0][1]
        blank = False if template.dtype == bool else np.nan
        out = np.full((n, *template.shape[1:]), blank, dtype=template.dtype)
        for rows, values in known:
            out[rows] = values
        return out

    def renumber(pick) -> dict[int, str]:
        return {int(rows[i]): text for rows, result in pieces for i, text in pick(result).items()}

    extras = {name for _, result in pieces for name in result.extras}
    first = pieces[0][1]
    return ChunkResult(
        place(lambda r: r.u),
        {name: place(lambda r, k=name: r.extras.get(k)) for name in sorted(extras)},
        {name: place(lambda r, k=name: r.z[k]) for name in first.z},
        renumber(lambda r: r.failures),
        place(lambda r: r.collapsed),
        renumber(lambda r: r.messages),
        renumber(lambda r: r.non_converged),
        renumber(lambda r: r.recoveries),
    )


def _blank(result: ChunkResult, i: int) -> None:
    """NaN in every output row of record ``i``."""
    for values in (result.u, *result.extras.values(), *result.z.values()):
        values[i] = np.nan


def _record_by_record(parts: _Parts, motions: GroundMotions) -> ChunkResult:
    results: list[ChunkResult | None] = []
    failures: dict[int, str] = {}
    messages: dict[int, str] = {}
    recoveries: dict[int, str] = {}
    for i in range(motions.n_records):
        try:
            single = parts.run(motions[i])
        except PluginError:
            raise
        except Exception as error:  # noqa: BLE001 - a failed record is listed with its cause
            failures[i] = f"{type(error).__name__}: {error}"
            results.append(None)
            continue
        if 0 in single.messages:
            messages[i] = single.messages[0]
        if 0 in single.recoveries:
            recoveries[i] = single.recoveries[0]
        if single.failures:
            failures[i] = single.failures[0]
            results.append(None)
            continue
        causes = _non_finite_causes(single)
        if causes:
            failures[i] = causes[0]
            results.append(None)
            continue
        results.append(single)
    collapsed = np.array([r is not None and bool(r.collapsed[0]) for r in results])
    stopped = {i: r.non_converged[0] for i, r in enumerate(results) if r and r.non_converged}
    template = next((r for r in results if r is not None), None)
    if template is None:
        shape = (motions.n_records, motions.n_steps, parts.structure.n_outputs)
        nan = np.full(shape, np.nan)
        z = {name: nan.copy() for name in parts.preprocessors}
        return ChunkResult(nan, {}, z, failures, collapsed, messages, stopped, recoveries)

    def stack(pick) -> np.ndarray:
        rows = [pick(r) if r is not None else np.full_like(pick(template), np.nan) for r in results]
        return np.concatenate(rows, axis=0)

    return ChunkResult(
        stack(lambda r: r.u),
        {name: stack(lambda r, n=name: r.extras[n]) for name in template.extras},
        {name: stack(lambda r, n=name: r.z[n]) for name in template.z},
        failures,
        collapsed,
        messages,
        stopped,
        recoveries,
    )
