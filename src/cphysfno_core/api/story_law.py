"""The story law: the hysteresis of one story spring of a shear building.

A law gives the story shear ``F`` (N) as a function of the story's drift history ``v``
(m), in rate form, so that the framework integrates it together with the building, for a
batch of records, in compiled code:

    F = force(c, v, s),    s' = rate(c, v, v', s),    then settle(c, v, s) after each step

with ``c`` the law's coefficients of one story (a float64 vector, from
:meth:`StoryLaw.coefficients`) and ``s`` its internal state (``n_states`` floats, zero at
rest). ``settle`` puts the state back where the law allows it after each time step (on a
yield surface the rate form may cross by a rounding or a step), so laws with corners need
no event location. The three functions are ``numba.njit`` functions of scalars and small
float64 arrays; :func:`cphysfno_core.testing.check_story_law` checks a law's physics.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from typing import ClassVar, NamedTuple

import numpy as np

from ..signals.errors import ConfigError
from .interfaces import Component


class LawFunctions(NamedTuple):
    """The compiled functions of a story law (``numba.njit``, ``inline="always"`` is best).

    Attributes:
        force: ``force(c, v, s) -> F``: story shear in N from the coefficients ``c [n_c]``,
            the drift ``v`` (m) and the state ``s [n_states]``.
        rate: ``rate(c, v, v_dot, s, out)``: writes ``s'`` into ``out [n_states]`` from the
            drift ``v`` (m) and drift rate ``v_dot`` (m/s).
        settle: ``settle(c, v, s)``: corrects ``s`` in place after a time step (a no-op for
            smooth laws).
    """

    force: Callable
    rate: Callable
    settle: Callable


class StoryLaw(Component, ABC):
    """The force of one story spring as a function of its drift history (the sixth kind).

    Subclasses set :attr:`n_states` and :attr:`state_names`, implement
    :meth:`coefficients` and :meth:`functions`, and declare their parameters in ``Params``
    (a parameter that may differ between stories takes a scalar or one value per story:
    :func:`per_story` broadcasts it). At rest (``v = 0``, ``s = 0``) the tangent
    ``dF/dv`` must be the story's initial stiffness, which the building's linear system
    uses.

    Attributes:
        n_states: floats of internal state per story.
        state_names: what each state variable is, with its unit.
    """

    kind = "story_law"
    n_states: ClassVar[int] = 0
    state_names: ClassVar[tuple[str, ...]] = ()

    @abstractmethod
    def coefficients(self, stiffness: np.ndarray) -> np.ndarray:
        """``[d, n_c]`` float64 coefficients of each story, from its initial stiffness.

        Args:
            stiffness: ``[d]`` initial story stiffnesses in N/m, bottom story first.

        Raises:
            ConfigError: a per-story parameter has neither one value nor ``d`` values.
        """

    @abstractmethod
    def functions(self) -> LawFunctions:
        """The compiled force, rate and settle functions of the law."""

    def yield_drift(self, n_stories: int) -> np.ndarray | None:
        """``[d]`` drift (m) at which each story leaves its elastic range, or ``None`` for a
        law that stays elastic. The physics checks drive stories past it."""
        return None

    def strength_lost_drift(self, n_stories: int) -> np.ndarray:
        """``[d]`` the drift (m) beyond which a story has no strength left (a law that
        softens past yield), ``inf`` where it keeps some (the default): a shear building
        flags a record that drives a story past it as a collapse."""
        return np.full(n_stories, np.inf)


def per_story(value: float | Sequence[float], n_stories: int, field: str) -> np.ndarray:
    """``[n_stories]`` float64 values from a scalar or one value per story.

    Raises:
        ConfigError: ``value`` is a sequence whose length is not ``n_stories`` (the message
            names ``field``).
    """
    values = np.atleast_1d(np.asarray(value, dtype=np.float64))
    if values.ndim != 1 or values.shape[0] not in (1, n_stories):
        raise ConfigError(
            f"{field}: needs one value or one per story: got {values.shape[0]} values for "
            f"{n_stories} stories"
        )
    return np.broadcast_to(values, (n_stories,)).copy()
