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

To test a model on structures outside the family it was trained on, ``test_tails = c``
draws the training and validation records' parameters from their central ranges (every
standard normal number within ``[-c, c]``) and the test records' from their tails (every
one beyond ``c`` in magnitude, on either side).
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

    def describe(self) -> str:
        """The distribution in a few words: ``lognormal, median 4e+07, β 0.3``."""
        bounds = [
            f"{sign} {value:.4g}"
            for sign, value in (("≥", self.lower), ("≤", self.upper))
            if value is not None
        ]
        truncation = f", truncated {' and '.join(bounds)}" if bounds else ""
        return f"{self.dist}, {self._fields()}{truncation}"

    def _fields(self) -> str:
        """Its own fields in words."""
        raise NotImplementedError

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

    def _fields(self) -> str:
        return f"mean {self.mean:.4g}, σ {self.std:.4g}"


class LogNormal(_Gaussian):
    """Lognormal: ``median exp(beta x)``."""

    dist: Literal["lognormal"]
    median: Finite = Field(gt=0.0)
    beta: Finite = Field(gt=0.0, description="standard deviation of the logarithm")

    def _standard(self, value: float) -> float:
        return math.log(value / self.median) / self.beta if value > 0 else -math.inf

    def _from_standard(self, x: np.ndarray) -> np.ndarray:
        return self.median * np.exp(self.beta * x)

    def _fields(self) -> str:
        return f"median {self.median:.4g}, β {self.beta:.3g}"


class Uniform(_Distribution):
    """Uniform on ``[low, high]``, truncated: uniform on its intersection with
    ``[lower, upper]``."""

    dist: Literal["uniform"]
    low: Finite
    high: Finite

    def _fields(self) -> str:
        return f"{self.low:.4g} to {self.high:.4g}"

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


def _walk(tree: Any, visit: Callable[[str, Any], Any], path: tuple[str, ...] = ()) -> Any:
    """``tree`` (tables, lists, numbers) with every leaf that is a distribution or a number,
    ``leaf`` at dotted path ``p``, replaced by ``visit(p, leaf)``."""
    if is_distribution(tree) or _is_number(tree):
        return visit(".".join(path), tree)
    if isinstance(tree, dict):
        return {key: _walk(item, visit, (*path, str(key))) for key, item in tree.items()}
    if isinstance(tree, list | tuple):
        return [_walk(item, visit, (*path, str(i))) for i, item in enumerate(tree)]
    return tree


def numbers_in(tree: Any) -> dict[str, Any]:
    """Dotted path -> every number of ``tree`` (tables, lists, numbers), in order."""
    found: dict[str, Any] = {}

    def keep(path: str, leaf: Any) -> Any:
        if not is_distribution(leaf):
            found[path] = leaf
        return leaf

    _walk(tree, keep)
    return found


def _order(path: str) -> tuple[Any, ...]:
    """Sort key of a dotted path: list positions in numeric order."""
    return tuple((0, int(part), "") if part.isdigit() else (1, 0, part) for part in path.split("."))


def random_parameters(params: Mapping[str, Any], where: str = "structure") -> list[RandomParameter]:
    """The random parameters of a structure's table ``params``, sorted by path.

    Raises:
        ConfigError: a distribution is unknown, lacks a field or has an invalid one; the
            message names ``where.path``.
    """
    found: list[RandomParameter] = []

    def parse(path: str, table: Any) -> Any:
        if not is_distribution(table):
            return table
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
        return table

    _walk(dict(params), parse)
    return sorted(found, key=lambda parameter: _order(parameter.path))


def with_values(params: Mapping[str, Any], values: Mapping[str, float]) -> dict[str, Any]:
    """A copy of the structure's table ``params`` with the value at each dotted path of
    ``values`` (a distribution or a number) replaced by its value there (a plain
    ``float``).

    Raises:
        ConfigError: a path of ``values`` names no number or distribution of ``params``,
            or a distribution is left without a value.
    """
    found: set[str] = set()

    def replace(path: str, leaf: Any) -> Any:
        if path in values:
            found.add(path)
            return float(values[path])
        if is_distribution(leaf):
            raise ConfigError(f"structure.{path}: a distribution was given no value")
        return leaf

    replaced = _walk(dict(params), replace)
    missing = sorted(set(values) - found, key=_order)
    if missing:
        raise ConfigError(
            f"the structure has no number at {', '.join(missing)}: a parameter is named by "
            "its dotted path in the structure's table (story_law.yield_displacement, "
            "stiffnesses.0)"
        )
    return replaced


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float | np.number) and not isinstance(value, bool)


def value_at(params: Mapping[str, Any], path: str) -> float:
    """The number at the dotted ``path`` of the structure's table ``params``.

    Raises:
        ConfigError: ``path`` names no number there.
    """
    node: Any = params
    for part in path.split("."):
        if isinstance(node, dict) and part in node:
            node = node[part]
        elif isinstance(node, list | tuple) and part.isdigit() and int(part) < len(node):
            node = node[int(part)]
        else:
            node = None
            break
    if not _is_number(node):
        raise ConfigError(f"the structure has no number at {path}")
    return float(node)


def per_record(params: Mapping[str, Any] | None, n: int) -> dict[str, np.ndarray]:
    """Parameter path -> ``[n]`` each record's value of ``params`` (path -> ``[n]`` values,
    or one value for every record); empty for None."""
    return {
        path: np.broadcast_to(np.asarray(v, dtype=np.float64), (n,))
        for path, v in (params or {}).items()
    }


def distinct_draws(draws: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The distinct rows of ``draws [n, k]``, each with the indices ``[m]`` of the records
    that drew it, in the order of the rows' first records."""
    distinct, first, which = np.unique(
        np.asarray(draws, dtype=np.float64), axis=0, return_index=True, return_inverse=True
    )
    which = which.ravel()
    return [(distinct[d], np.flatnonzero(which == d)) for d in np.argsort(first)]


def into_regions(z: np.ndarray, n_central: int, edge: float) -> np.ndarray:
    """Standard normal numbers ``z [n, k]`` carried through their probabilities ``u =
    Phi(z)``, order kept: those of the first ``n_central`` rows into the central range
    ``[-edge, edge]``, the others into the tails beyond ``edge`` (``u < 1/2`` the lower
    tail, else the upper); each row stays as likely within its region as in the whole."""
    u = ndtr(z)
    tail = ndtr(-edge)
    out = np.empty_like(z)
    out[:n_central] = ndtri(tail + u[:n_central] * (1.0 - 2.0 * tail))
    rest = u[n_central:]
    lower = rest < 0.5
    out[n_central:] = np.where(
        lower, ndtri(2.0 * tail * rest), -ndtri(2.0 * tail * (1.0 - rest))
    )
    return out


@dataclass(frozen=True)
class UncertainParameters:
    """The random parameters of a structure and their correlations (Gaussian copula).

    Attributes:
        parameters: the random parameters, sorted by path (``k`` of them).
        correlation: ``[k, k]`` correlation of their standard normal numbers, symmetric
            positive definite (the identity when none is given).
        test_tails: where the central ranges of the training draws end and the tails of
            the test draws begin, in standard deviations of the standard normal numbers
            (None: every record draws from the whole distributions).
    """

    parameters: tuple[RandomParameter, ...]
    correlation: np.ndarray
    test_tails: float | None = None

    @classmethod
    def of(
        cls,
        params: Mapping[str, Any],
        correlations: Sequence[tuple[str, str, float]] = (),
        where: str = "structure",
        test_tails: float | None = None,
    ) -> UncertainParameters:
        """The random parameters of the structure's table ``params`` with the
        ``correlations`` ``(path, path, rho)`` between pairs of them (and ``test_tails``,
        see the class).

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
        return cls(parameters, correlation, test_tails)

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

    def draw(self, n: int, seed: int, n_central: int | None = None) -> np.ndarray:
        """``[n, k]`` float64 draws, one row a record, in the parameters' units.

        The stream is ``numpy.random.SeedSequence(seed, spawn_key=(PARAMETER_STREAM,))``;
        record ``i`` takes the ``i``-th ``k`` standard normal numbers, correlated by the
        Cholesky factor of :attr:`correlation`, so a record's draw does not depend on ``n``.
        With :attr:`test_tails` and ``n_central`` (the training and validation records,
        the first), each of those numbers is carried, rank kept, into its central range
        for the first ``n_central`` records and into its tails for the others
        (:func:`into_regions`).
        """
        k = len(self.parameters)
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(PARAMETER_STREAM,)))
        z = rng.standard_normal((n, k)) @ np.linalg.cholesky(self.correlation).T
        if self.test_tails is not None and n_central is not None:
            z = into_regions(z, n_central, self.test_tails)
        draws = np.empty((n, k))
        for j, parameter in enumerate(self.parameters):
            draws[:, j] = parameter.distribution.values(z[:, j])
        return draws

    def values_at(self, z: float) -> np.ndarray:
        """``[k]`` each parameter's value at the standard normal number ``z`` of its own
        distribution (``z = 0``: the medians)."""
        return np.array([float(p.distribution.values(np.array([z]))[0]) for p in self.parameters])

    def columns(self, draws: np.ndarray) -> dict[str, np.ndarray]:
        """Path -> ``[n]`` values of draws ``[n, k]``."""
        return {name: draws[:, j] for j, name in enumerate(self.names)}

    def values_of(self, row: np.ndarray) -> dict[str, float]:
        """Path -> value of one draw ``row [k]``."""
        return dict(zip(self.names, (float(v) for v in row), strict=True))
