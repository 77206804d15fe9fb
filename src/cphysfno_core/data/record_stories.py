"""The story heights of each record of a family of structures (random structural
parameters): the drift ratios of a record are its drifts over its own structure's heights.

A random parameter may move the stories (a shear building's ``story_heights``, an OpenSees
script's keyword that sets its nodes' elevations) or not (a yield strength). Which ones do
is found by building the structure with each parameter alone at its drawn value farthest
from the nominal one; the structures of the distinct draws of those parameters alone are
then built once each and their heights kept. A parameter that moves the heights only
beyond that value (a step in the script) would go unseen.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..api.interfaces import Structure
from ..api.registry import get_registry
from ..config.uncertainty import distinct_draws, per_record, value_at, with_values
from ..signals import Stories
from ..signals.errors import InputError


class RecordStories:
    """Each record's story heights for a structure whose parameters are drawn per record.

    Args:
        structure: the family's nominal structure (its stories name the floors; the drawn
            parameters are dotted paths of its ``get_params()`` table).

    Attributes:
        structure: the nominal structure.
        stories: its stories.
    """

    def __init__(self, structure: Structure) -> None:
        self.structure = structure
        self._name = structure.name
        self._table = structure.get_params()
        self.stories = structure.stories()
        self._nominal = np.asarray(self.stories.heights_m, dtype=np.float64)
        self._moves: dict[str, bool] = {}
        self._built: dict[tuple[tuple[str, float], ...], np.ndarray] = {}

    def heights(self, params: Mapping[str, np.ndarray] | None, n: int) -> np.ndarray | None:
        """``[n, n_stories]`` each record's story heights in m (``nan`` for a story without
        height), or None where every record has the nominal structure's.

        Args:
            params: parameter path -> ``[n]`` (or a scalar) each record's value, in the
                structure's units; None or empty for the nominal structure.
            n: the number of records.

        Raises:
            InputError: a drawn structure's stories bound other outputs than the nominal
                one's (its drift ratios would not be comparable).
        """
        if not params:
            return None
        columns = per_record(params, n)
        movers = [path for path, values in columns.items() if self._moves_heights(path, values)]
        if not movers:
            return None
        draws = np.column_stack([columns[path] for path in movers])
        found = np.empty((n, self.stories.n_stories))
        for row, rows in distinct_draws(draws):
            found[rows] = self._heights_at(dict(zip(movers, row.tolist(), strict=True)))
        return found

    def _moves_heights(self, path: str, values: np.ndarray) -> bool:
        """Whether the parameter ``path`` moves the story heights: the structure with it
        alone at the drawn value farthest from its nominal one has other heights (found
        once, at the first values away from the nominal one)."""
        if path in self._moves:
            return self._moves[path]
        nominal = value_at(self._table, path)
        farthest = float(values[np.argmax(np.abs(values - nominal))])
        if farthest == nominal:  # every record at the nominal value: nothing to find yet
            return False
        heights = self._heights_at({path: farthest})
        self._moves[path] = not np.array_equal(heights, self._nominal, equal_nan=True)
        return self._moves[path]

    def _heights_at(self, values: dict[str, float]) -> np.ndarray:
        """``[n_stories]`` the story heights (m) of the structure at ``values``."""
        key = tuple(sorted(values.items()))
        if key not in self._built:
            table = with_values(self._table, values)
            structure = get_registry().create("structure", self._name, **table)
            stories = structure.stories()
            if (stories.lower, stories.upper) != (self.stories.lower, self.stories.upper):
                drawn = ", ".join(f"{path} = {value:.6g}" for path, value in values.items())
                raise InputError(
                    f"the structure at {drawn} has stories between other outputs than its "
                    f"nominal one ({_ends(stories)} against {_ends(self.stories)}): the "
                    "records' drift ratios would not be of the same stories"
                )
            self._built[key] = np.asarray(stories.heights_m, dtype=np.float64)
        return self._built[key]


def _ends(stories: Stories) -> str:
    """The outputs each story spans, ``ground-0, 0-1, ...``."""
    return ", ".join(
        f"{'ground' if low is None else low}-{top}"
        for low, top in zip(stories.lower, stories.upper, strict=True)
    )
