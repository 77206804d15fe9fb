"""The physics preprocessor of every member of a family of structures from a few fitted ones.

A preprocessor whose fit is an analysis of its own (a stick: a monotonic and a cyclic
pushover, some seconds for an OpenSees frame) is too dear to fit to every record's draw.
Its :meth:`~cphysfno_core.plugin.PhysicsPreprocessor.calibration` (the numbers of its fit:
a stick's masses, story stiffnesses and law parameters) is instead fitted at ``2 k + 1``
members: the nominal structure and, along each of the ``k`` parameters alone, one member
below and one above it. Each number of the calibration is then a sum over the parameters
of a quadratic through the three members on that parameter's line (in the logarithm of
the number where it is positive at all three), continued as a straight line beyond the
outer members; :meth:`CalibrationSurface.calibration_at` gives any member's calibration
and :meth:`CalibrationSurface.preprocessor_at` the preprocessor fitted from it.

The sum leaves out how parameters act together (a strength change whose effect depends
on the stiffness), and a number that jumps between members (a law's parameter pinned at a
bound in one and not the other) is smoothed over: compare members fitted the real way at
draws of the family before trusting it (``benchmarks/calibration_surface.py``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..api.interfaces import PhysicsPreprocessor, Structure
from ..api.registry import get_registry
from ..signals.errors import ConfigError
from .uncertainty import numbers_in, value_at, with_values

ANCHOR_Z = 2.0
"""Where the outer members stand: each parameter's value at this many standard deviations
(its standard normal number) below and above the median."""


@dataclass(frozen=True, eq=False)
class CalibrationSurface:
    """A preprocessor's calibration over a family's parameters.

    Attributes:
        preprocessor: the preprocessor's registry name and parameters (``name`` and the
            others), those :meth:`~cphysfno_core.plugin.PhysicsPreprocessor.refit_params`
            gave at the nominal member.
        names: ``[k]`` the parameters' dotted paths in the structure's table.
        centre: ``[k]`` the nominal member's values.
        below, above: ``[k]`` the outer members' values on each parameter's line.
        reference: the nominal member's calibration.
        paths: ``[m]`` the dotted paths of the calibration's floats.
        at_centre: ``[m]`` those floats at the nominal member.
        at_below, at_above: ``[k, m]`` at the outer members.
    """

    preprocessor: dict[str, Any]
    names: tuple[str, ...]
    centre: np.ndarray
    below: np.ndarray
    above: np.ndarray
    reference: dict[str, Any]
    paths: tuple[str, ...]
    at_centre: np.ndarray
    at_below: np.ndarray
    at_above: np.ndarray

    @property
    def logged(self) -> np.ndarray:
        """``[m]`` whether each float is interpolated in its logarithm: positive at every
        member."""
        members = np.vstack([self.at_centre[None], self.at_below, self.at_above])
        return np.all(members > 0.0, axis=0)

    def numbers_at(self, values: np.ndarray) -> np.ndarray:
        """``[m]`` the calibration's floats at the parameter ``values [k]`` (a surface over
        no parameters: its one member's, exactly)."""
        if not self.names:
            return self.at_centre.copy()
        logged = self.logged

        def space(x: np.ndarray) -> np.ndarray:
            return np.where(logged, np.log(np.where(logged, x, 1.0)), x)

        centre = space(self.at_centre)
        found = centre.copy()
        for i in range(len(self.names)):
            offsets = (self.below[i] - self.centre[i], self.above[i] - self.centre[i])
            rises = (space(self.at_below[i]) - centre, space(self.at_above[i]) - centre)
            found += _along(float(values[i] - self.centre[i]), offsets, rises)
        return np.where(logged, np.exp(np.where(logged, found, 0.0)), found)

    def calibration_at(self, values: Mapping[str, float]) -> dict[str, Any]:
        """The calibration of the member of the family at ``values`` (parameter path ->
        value; a parameter left out is at its nominal value).

        Raises:
            ConfigError: a parameter the surface does not span.
        """
        unknown = sorted(set(values) - set(self.names))
        if unknown:
            raise ConfigError(
                f"the calibration surface spans {', '.join(self.names)}, not {', '.join(unknown)}"
            )
        x = np.array(
            [float(values.get(n, c)) for n, c in zip(self.names, self.centre, strict=True)]
        )
        return with_values(
            self.reference, dict(zip(self.paths, self.numbers_at(x).tolist(), strict=True))
        )

    def preprocessor_at(
        self, structure: Structure, values: Mapping[str, float]
    ) -> PhysicsPreprocessor:
        """The preprocessor of the member ``structure`` (the family's structure at
        ``values``), fitted from its interpolated calibration."""
        spec = dict(self.preprocessor)
        name = spec.pop("name")
        preprocessor = get_registry().create("preprocessor", name, **spec)
        return preprocessor.calibrated(structure, self.calibration_at(values))

    def to_dict(self) -> dict[str, Any]:
        """Everything as JSON-compatible values."""
        return {
            "preprocessor": self.preprocessor,
            "names": list(self.names),
            "centre": self.centre.tolist(),
            "below": self.below.tolist(),
            "above": self.above.tolist(),
            "reference": self.reference,
            "paths": list(self.paths),
            "at_centre": self.at_centre.tolist(),
            "at_below": self.at_below.tolist(),
            "at_above": self.at_above.tolist(),
        }

    @classmethod
    def from_dict(cls, document: Mapping[str, Any]) -> CalibrationSurface:
        """The surface :meth:`to_dict` wrote."""
        m = len(document["paths"])
        arrays = {
            key: np.asarray(document[key], dtype=np.float64).reshape(-1, m)
            for key in ("at_below", "at_above")
        }
        return cls(
            dict(document["preprocessor"]),
            tuple(document["names"]),
            np.asarray(document["centre"], dtype=np.float64),
            np.asarray(document["below"], dtype=np.float64),
            np.asarray(document["above"], dtype=np.float64),
            document["reference"],
            tuple(document["paths"]),
            np.asarray(document["at_centre"], dtype=np.float64),
            arrays["at_below"],
            arrays["at_above"],
        )


def member_preprocessor(
    spec: Mapping[str, Any],
    structure: Structure,
    values: Mapping[str, float],
    surface: CalibrationSurface | None,
) -> PhysicsPreprocessor:
    """The preprocessor ``spec`` (its registry name and parameters) of ``structure``, the
    member of a family at the parameter ``values``: made from ``surface``'s calibration
    there where there is a surface, else fitted to the member."""
    if surface is not None:
        return surface.preprocessor_at(structure, values)
    params = dict(spec)
    name = params.pop("name")
    return get_registry().create("preprocessor", name, **params).fit(structure)


def _along(
    d: float, offsets: tuple[float, float], rises: tuple[np.ndarray, np.ndarray]
) -> np.ndarray:
    """The quadratic ``p d + r d^2`` through ``(0, 0)`` and ``(offsets[j], rises[j])``
    (offsets below and above 0), continued by its tangent beyond them; 0 where the two
    offsets are 0 (a parameter without spread)."""
    low, high = offsets
    if not low < 0.0 < high:
        return np.zeros_like(rises[0])
    # p low + r low^2 = rises[0], p high + r high^2 = rises[1]
    r = (rises[1] / high - rises[0] / low) / (high - low)
    p = rises[1] / high - r * high
    edge = min(max(d, low), high)
    return p * edge + r * edge**2 + (p + 2.0 * r * edge) * (d - edge)


def fit_surface(
    preprocessor: Mapping[str, Any],
    structure: Structure,
    names: Sequence[str],
    below: Sequence[float],
    above: Sequence[float],
    progress: Callable[[str], None] | None = None,
) -> CalibrationSurface | None:
    """The :class:`CalibrationSurface` of the preprocessor ``preprocessor`` (its registry
    name and parameters) over the family of ``structure`` (the nominal member) whose
    parameters ``names`` range over ``below`` to ``above``; None for a preprocessor
    without a calibration (it is fitted to each member instead).

    Fits ``2 k + 1`` members, each with the nominal member's choices
    (:meth:`~cphysfno_core.plugin.PhysicsPreprocessor.refit_params`); ``progress`` is
    told of each.

    Raises:
        ConfigError: a member's calibration differs from the nominal one in more than its
            floats (another law chosen, other lengths), or an outer member is not on its
            side of the nominal one.
    """
    spec = dict(preprocessor)
    name = spec.pop("name")
    registry = get_registry()
    table = structure.get_params()
    nominal = registry.create("preprocessor", name, **spec).fit(structure)
    reference = nominal.calibration()
    if reference is None:
        return None
    like = nominal.refit_params()
    paths, at_centre = _floats(reference)
    centre = np.array([value_at(table, n) for n in names])
    below, above = np.asarray(below, dtype=np.float64), np.asarray(above, dtype=np.float64)
    if not (np.all(below < centre) and np.all(centre < above)):
        raise ConfigError(
            f"calibration surface of '{name}': the outer members {below.tolist()} and "
            f"{above.tolist()} must lie below and above the nominal values {centre.tolist()}"
        )
    skeleton = _skeleton(reference)
    members = np.empty((2, len(names), len(paths)))
    for i, path in enumerate(names):
        for side, value in enumerate((below[i], above[i])):
            if progress is not None:
                progress(f"  calibrating '{name}' at {path} = {value:.6g}")
            member = registry.create(
                "structure", structure.name, **with_values(table, {path: value})
            )
            found = registry.create("preprocessor", name, **like).fit(member).calibration()
            if _skeleton(found) != skeleton:
                raise ConfigError(
                    f"calibration surface of '{name}': the member at {path} = {value:.6g} "
                    "differs from the nominal one in more than its numbers; narrow the "
                    "family, or fit the preprocessor to each member"
                )
            members[side, i] = _floats(found)[1]
    return CalibrationSurface(
        {"name": name, **like}, tuple(names), centre, below, above, reference, paths,
        at_centre, members[0], members[1],
    )  # fmt: skip


def _floats(calibration: Mapping[str, Any]) -> tuple[tuple[str, ...], np.ndarray]:
    """The dotted paths and values of a calibration's floats."""
    found = {p: v for p, v in numbers_in(calibration).items() if isinstance(v, float)}
    return tuple(found), np.array(list(found.values()), dtype=np.float64)


def _skeleton(calibration: Mapping[str, Any]) -> dict[str, Any]:
    """A calibration with every float set to 0: its choices and shapes."""
    return with_values(calibration, dict.fromkeys(_floats(calibration)[0], 0.0))
