"""A family model's structural parameters: which ones it knows, their scale as operator
input channels, and the range it was trained on.

A model trained on records whose structures drew random parameters (a family of
structures) takes each record's values at prediction: they rebuild that record's structure
for its physics response, and, with ``formulation.parameter_input``, they also enter the
operator as constant input channels, standardised by the training draws' mean and
standard deviation.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..signals.errors import ExtrapolationWarning, InputError

ParameterValues = Mapping[str, Any]
"""Parameter path -> its value for each record: ``[n]`` values, or one value for all."""


@dataclass(frozen=True)
class ParameterScale:
    """The structural parameters a family model knows.

    Attributes:
        names: their dotted paths in the structure's table (``story_law.fy``), ``k``.
        units: the unit label of each (empty where none was given).
        mean: ``[k]`` mean of the training draws, in the parameters' units.
        std: ``[k]`` their standard deviation (1 where every draw was the same).
        low: ``[k]`` smallest training draw.
        high: ``[k]`` largest training draw.
    """

    names: tuple[str, ...]
    units: tuple[str, ...]
    mean: np.ndarray
    std: np.ndarray
    low: np.ndarray
    high: np.ndarray

    @classmethod
    def fit(
        cls, params: ParameterValues, n: int, units: Mapping[str, str] | None = None
    ) -> ParameterScale:
        """The scale of the training draws ``params`` (path -> ``[n]`` values) of ``n``
        records, in the order of ``params``.

        Raises:
            InputError: ``params`` is empty, or a value is not finite or has another length.
        """
        if not params:
            raise InputError("params names no parameter: give path -> [n] values")
        names = tuple(params)
        values = np.column_stack([_column(params[name], n, name) for name in names])
        std = values.std(axis=0)
        return cls(
            names,
            tuple((units or {}).get(name, "") for name in names),
            values.mean(axis=0),
            np.where(std > 0, std, 1.0),
            values.min(axis=0),
            values.max(axis=0),
        )

    def values(
        self, params: ParameterValues | None, n: int, nominal: Mapping[str, float]
    ) -> np.ndarray:
        """``[n, k]`` the values of ``n`` records, the columns in the order of
        :attr:`names`; a parameter ``params`` leaves out (or ``params`` None) takes its
        ``nominal`` value.

        Raises:
            InputError: ``params`` names a parameter the model does not know, leaves out
                one without a nominal value, or a value is not finite or has another
                length than ``n``.
        """
        params = dict(params or {})
        unknown = sorted(set(params) - set(self.names))
        if unknown:
            raise InputError(
                f"unknown structural parameters {', '.join(unknown)}: this model knows "
                f"{', '.join(self.names)}"
            )
        missing = [name for name in self.names if name not in params and name not in nominal]
        if missing:
            raise InputError(f"give the values of the structural parameters {', '.join(missing)}")
        columns = [
            _column(params[name] if name in params else nominal[name], n, name)
            for name in self.names
        ]
        return np.column_stack(columns) if columns else np.zeros((n, 0))

    def encode(self, values: np.ndarray) -> np.ndarray:
        """``[n, k]`` the standardised values ``(values - mean) / std``."""
        return (np.asarray(values, dtype=np.float64) - self.mean) / self.std

    def warn_outside(self, values: np.ndarray, label: str) -> None:
        """Warn (:class:`ExtrapolationWarning`) when records' values ``[n, k]`` lie outside
        the training draws' range: the model extrapolates there."""
        below, above = values < self.low, values > self.high
        outside = (below | above).any(axis=1)
        if not outside.any():
            return
        named = [
            f"{name} ({self.low[j]:.4g} to {self.high[j]:.4g}{_unit(self.units[j])})"
            for j, name in enumerate(self.names)
            if (below[:, j] | above[:, j]).any()
        ]
        warnings.warn(
            f"{int(outside.sum())} of {len(values)} records have structural parameters "
            f"outside the range model '{label}' was trained on: {', '.join(named)}; its "
            "predictions for them are extrapolations",
            ExtrapolationWarning,
            stacklevel=3,
        )

    def description(self) -> dict[str, Any]:
        """The names and units, for ``model.json``."""
        return {"names": list(self.names), "units": list(self.units)}

    def arrays(self) -> dict[str, np.ndarray]:
        """The fitted arrays, for ``arrays.npz``."""
        return {"mean": self.mean, "std": self.std, "low": self.low, "high": self.high}

    @classmethod
    def restore(
        cls, description: Mapping[str, Any], arrays: Mapping[str, np.ndarray]
    ) -> ParameterScale:
        """The scale saved as :meth:`description` and :meth:`arrays`."""
        return cls(
            tuple(description["names"]),
            tuple(description["units"]),
            *(np.asarray(arrays[key], dtype=np.float64) for key in ("mean", "std", "low", "high")),
        )


def _unit(unit: str) -> str:
    return f" {unit}" if unit else ""


def _column(value: Any, n: int, name: str) -> np.ndarray:
    """``[n]`` float64 values of parameter ``name``: ``value`` is one number for every
    record or ``n`` of them."""
    column = np.asarray(value, dtype=np.float64)
    if column.ndim == 0:
        column = np.full(n, float(column))
    if column.shape != (n,):
        raise InputError(
            f"structural parameter {name}: give one value or {n} (one a record), got shape "
            f"{column.shape}"
        )
    if not np.isfinite(column).all():
        raise InputError(f"structural parameter {name} holds NaN or Inf")
    return column
