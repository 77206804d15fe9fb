"""Uncertain structural parameters: a distribution in place of a number, one draw a record.

Any number among a structure's parameters, at any depth (a field, a key of a nested table,
an element of a list), may be a table ``{dist = "...", ...}`` instead:

- ``normal``: ``mean``, ``std`` (> 0);
- ``lognormal``: ``median`` (> 0), ``beta`` (> 0, the standard deviation of its logarithm);
- ``uniform``: ``low``, ``high`` (``low <= high``; ``low == high`` is one value);

each optionally truncated to ``[lower, upper]`` and labelled with a ``unit``. A random
parameter is named by its dotted path in the structure's table (``stiffnesses.0``,
``story_law.yield_displacement``). Every record gets its own draw: standard normal numbers,
correlated through a Gaussian copula (the ``correlations`` between named parameters), each
carried to its distribution through its cumulative distribution function.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator
from scipy.special import ndtr, ndtri

from ..api.interfaces import format_validation_error
from ..signals.errors import ConfigError

DIST_KEY = "dist"
"""The key that makes a table of a structure's parameters a distribution."""

PARAMETER_STREAM = 1
"""The spawn key, under ``data.seed``, of the random stream of the parameters: independent
of the ground motions' stream (``numpy.random.default_rng(data.seed)``)."""

FIXED_PARAMETERS = {
    "story_heights": "the drift ratios and EDPs of every record use one set of story heights",
}
"""Parameters that may not be random yet, with the reason."""

Finite = Annotated[float, Field(allow_inf_nan=False)]


class _Distribution(BaseModel):
    """A distribution of one real parameter, optionally truncated to ``[lower, upper]``."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    lower: Finite | None = Field(None, description="truncation: no draw below it")
    upper: Finite | None = Field(None, description="truncation: no draw above it")
    unit: str | None = Field(None, min_length=1, description="the unit of the values, a label")

    def values(self, z: np.ndarray) -> np.ndarray:
        """The values (the distribution's unit) at the standard normal numbers ``z``
        (any shape): ``F^-1(Phi(z))``, monotonic in ``z``."""
        raise NotImplementedError

    @property
    def nominal(self) -> float:
        """The median of the (truncated) distribution: the value at ``z = 0``."""
        return float(self.values(np.zeros(1))[0])

    def _clip(self, values: np.ndarray) -> np.ndarray:
        lower = -np.inf if self.lower is None else self.lower
        upper = np.inf if self.upper is None else self.upper
        return np.clip(values, lower, upper)

    def _no_mass(self) -> ValueError:
        bounds = " and ".join(
            f"{name} = {value}"
            for name, value in (("lower", self.lower), ("upper", self.upper))
            if value is not None
        )
        return ValueError(f"the truncation {bounds} leaves the distribution no probability")


class _Gaussian(_Distribution):
    """A distribution that is a monotonic function of one standard normal number ``x``;
    truncation bounds ``x`` to the bounds' images."""

    def _standard(self, value: float) -> float:
        """The ``x`` of a value."""
        raise NotImplementedError

    def _from_standard(self, x: np.ndarray) -> np.ndarray:
        """The value of ``x``."""
        raise NotImplementedError

    def _bounds(self) -> tuple[float, float]:
        low = -math.inf if self.lower is None else self._standard(self.lower)
        high = math.inf if self.upper is None else self._standard(self.upper)
        return low, high

    @model_validator(mode="after")
    def _has_mass(self) -> _Gaussian:
        low, high = self._bounds()
        if not ndtr(high) > ndtr(low):
            raise self._no_mass()
        return self

    def values(self, z: np.ndarray) -> np.ndarray:
        low, high = self._bounds()
        x = np.asarray(z, dtype=np.float64)
        if (low, high) != (-math.inf, math.inf):
            below, mass = ndtr(low), ndtr(high) - ndtr(low)
            x = np.clip(ndtri(below + ndtr(x) * mass), low, high)
        return self._clip(self._from_standard(x))


class Normal(_Gaussian):
    """Normal: ``mean + std x``."""

    dist: Literal["normal"]
    mean: Finite
    std: Finite = Field(gt=0.0)

    def _standard(self, value: float) -> float:
        return (value - self.mean) / self.std

    def _from_standard(self, x: np.ndarray) -> np.ndarray:
        return self.mean + self.std * x


class LogNormal(_Gaussian):
    """Lognormal: ``median exp(beta x)``."""

    dist: Literal["lognormal"]
    median: Finite = Field(gt=0.0)
    beta: Finite = Field(gt=0.0, description="standard deviation of the logarithm")

    def _standard(self, value: float) -> float:
        return math.log(value / self.median) / self.beta if value > 0 else -math.inf

    def _from_standard(self, x: np.ndarray) -> np.ndarray:
        return self.median * np.exp(self.beta * x)


class Uniform(_Distribution):
    """Uniform on ``[low, high]``, truncated: uniform on its intersection with
    ``[lower, upper]``."""

    dist: Literal["uniform"]
    low: Finite
    high: Finite

    def _support(self) -> tuple[float, float]:
        low = self.low if self.lower is None else max(self.low, self.lower)
        high = self.high if self.upper is None else min(self.high, self.upper)
        return low, high

    @model_validator(mode="after")
    def _has_mass(self) -> Uniform:
        if self.low > self.high:
            raise ValueError(f"low = {self.low} exceeds high = {self.high}")
        low, high = self._support()
        if low > high:
            raise self._no_mass()
        return self

    def values(self, z: np.ndarray) -> np.ndarray:
        low, high = self._support()
        return np.clip(low + ndtr(np.asarray(z, dtype=np.float64)) * (high - low), low, high)


Distribution = Normal | LogNormal | Uniform

DISTRIBUTIONS: dict[str, type[Distribution]] = {
    "normal": Normal,
    "lognormal": LogNormal,
    "uniform": Uniform,
}
"""The distributions by the name their ``dist`` key gives."""


@dataclass(frozen=True)
class RandomParameter:
    """One random parameter: its dotted path in the structure's table and its distribution."""

    path: str
    distribution: Distribution

    @property
    def unit(self) -> str:
        """Its unit label; empty when none was given."""
        return self.distribution.unit or ""


def is_distribution(value: Any) -> bool:
    """Whether a parameter's value is a distribution (a table with ``dist``)."""
    return isinstance(value, dict) and DIST_KEY in value


def _walk(tree: Any, visit: Callable[[str, dict], Any], path: tuple[str, ...] = ()) -> Any:
    """``tree`` (tables, lists, numbers) with every distribution ``d`` at dotted path ``p``
    replaced by ``visit(p, d)``."""
    if is_distribution(tree):
        return visit(".".join(path), tree)
    if isinstance(tree, dict):
        return {key: _walk(item, visit, (*path, str(key))) for key, item in tree.items()}
    if isinstance(tree, list | tuple):
        return [_walk(item, visit, (*path, str(i))) for i, item in enumerate(tree)]
    return tree


def _order(path: str) -> tuple[Any, ...]:
    """Sort key of a dotted path: list positions in numeric order."""
    return tuple((0, int(part), "") if part.isdigit() else (1, 0, part) for part in path.split("."))


def random_parameters(params: Mapping[str, Any], where: str = "structure") -> list[RandomParameter]:
    """The random parameters of a structure's table ``params``, sorted by path.

    Raises:
        ConfigError: a distribution is unknown, lacks a field or has an invalid one, or a
            parameter that may not be random is; the message names ``where.path``.
    """
    found: list[RandomParameter] = []

    def parse(path: str, table: dict) -> None:
        first = path.split(".")[0]
        if first in FIXED_PARAMETERS:
            raise ConfigError(f"{where}.{path}: may not be random: {FIXED_PARAMETERS[first]}")
        kind = DISTRIBUTIONS.get(table[DIST_KEY]) if isinstance(table[DIST_KEY], str) else None
        if kind is None:
            raise ConfigError(
                f"{where}.{path}.{DIST_KEY}: unknown distribution {table[DIST_KEY]!r}: use "
                f"one of {', '.join(DISTRIBUTIONS)}"
            )
        try:
            found.append(RandomParameter(path, kind.model_validate(table)))
        except ValidationError as error:
            raise ConfigError(format_validation_error(error, f"{where}.{path}")) from None

    _walk(dict(params), parse)
    return sorted(found, key=lambda parameter: _order(parameter.path))


def with_values(params: Mapping[str, Any], values: Mapping[str, float]) -> dict[str, Any]:
    """A copy of the structure's table ``params`` with the distribution at each path of
    ``values`` replaced by its value there (a plain ``float``)."""
    return _walk(dict(params), lambda path, table: float(values[path]))


@dataclass(frozen=True)
class UncertainParameters:
    """The random parameters of a structure and their correlations (Gaussian copula).

    Attributes:
        parameters: the random parameters, sorted by path (``k`` of them).
        correlation: ``[k, k]`` correlation of their standard normal numbers, symmetric
            positive definite (the identity when none is given).
    """

    parameters: tuple[RandomParameter, ...]
    correlation: np.ndarray

    @classmethod
    def of(
        cls,
        params: Mapping[str, Any],
        correlations: Sequence[tuple[str, str, float]] = (),
        where: str = "structure",
    ) -> UncertainParameters:
        """The random parameters of the structure's table ``params`` with the
        ``correlations`` ``(path, path, rho)`` between pairs of them.

        Raises:
            ConfigError: a distribution is invalid (:func:`random_parameters`), a
                correlation names no random parameter, pairs one with itself or a pair
                twice, or the correlations do not form a positive-definite matrix.
        """
        parameters = tuple(random_parameters(params, where))
        index = {p.path: i for i, p in enumerate(parameters)}
        correlation = np.eye(len(parameters))
        for n, (first, second, rho) in enumerate(correlations):
            at = f"uncertainty.correlations.{n}"
            for path in (first, second):
                if path not in index:
                    known = ", ".join(index) or "none"
                    raise ConfigError(
                        f"{at}: '{path}' is not a random parameter of the {where} "
                        f"(they are: {known})"
                    )
            i, j = index[first], index[second]
            if i == j:
                raise ConfigError(f"{at}: correlates '{first}' with itself")
            if correlation[i, j] != 0.0:
                raise ConfigError(f"{at}: '{first}' and '{second}' are correlated twice")
            correlation[i, j] = correlation[j, i] = rho
        try:
            np.linalg.cholesky(correlation)
        except np.linalg.LinAlgError:
            raise ConfigError(
                "uncertainty.correlations: the correlations do not form a positive-definite "
                "matrix (no joint distribution has them)"
            ) from None
        return cls(parameters, correlation)

    @property
    def names(self) -> tuple[str, ...]:
        """The paths of the parameters, in the order of the draws' columns."""
        return tuple(p.path for p in self.parameters)

    @property
    def units(self) -> tuple[str, ...]:
        """The unit label of each parameter (empty where none was given)."""
        return tuple(p.unit for p in self.parameters)

    def nominal(self) -> dict[str, float]:
        """Path -> the median of each parameter's distribution."""
        return {p.path: p.distribution.nominal for p in self.parameters}

    def draw(self, n: int, seed: int) -> np.ndarray:
        """``[n, k]`` float64 draws, one row a record, in the parameters' units.

        The stream is ``numpy.random.SeedSequence(seed, spawn_key=(PARAMETER_STREAM,))``;
        record ``i`` takes the ``i``-th ``k`` standard normal numbers, correlated by the
        Cholesky factor of :attr:`correlation`, so a record's draw does not depend on ``n``.
        """
        k = len(self.parameters)
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(PARAMETER_STREAM,)))
        z = rng.standard_normal((n, k)) @ np.linalg.cholesky(self.correlation).T
        draws = np.empty((n, k))
        for j, parameter in enumerate(self.parameters):
            draws[:, j] = parameter.distribution.values(z[:, j])
        return draws

    def values_of(self, row: np.ndarray) -> dict[str, float]:
        """Path -> value of one draw ``row [k]``."""
        return dict(zip(self.names, (float(v) for v in row), strict=True))
