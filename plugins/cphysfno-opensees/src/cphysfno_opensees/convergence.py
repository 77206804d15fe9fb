"""The convergence ladder: what an OpenSees transient analysis tries, in order, on a step
that does not converge with the caller's settings.

As collapse studies do, the ladder climbs from the cheapest change to the loosest:

1. *substeps*: the caller's algorithm over the step split into ``splits`` (``dt/2``,
   ``dt/4``, ``dt/10``), the finer only where the coarser fails;
2. *other algorithms*: each of ``algorithms`` but the caller's own, at the full step, then
   each over the step split into ``splits``;
3. *a looser test*: the caller's algorithm at the full step, then everything above again,
   with the convergence test's tolerance multiplied by ``looser_tolerance`` and its
   iterations by ``looser_iterations``.

A rung takes the step from where the rung before it stopped (a substep once completed is
kept), so a step is done by the rung that completes it: its hardest.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from itertools import pairwise
from typing import Any

from pydantic import Field, field_validator

from cphysfno_core.plugin import Params

ALGORITHMS = frozenset(
    {
        "Newton",
        "NewtonLineSearch",
        "ModifiedNewton",
        "KrylovNewton",
        "SecantNewton",
        "RaphsonNewton",
        "PeriodicNewton",
        "BFGS",
        "Broyden",
        "ExpressNewton",
    }
)
"""OpenSees' iterative solution algorithms (``ops.algorithm`` names)."""

TOLERANCES = {"FixedNumIter": 0, "NormDispAndUnbalance": 2, "NormDispOrUnbalance": 2}
"""Tolerances an OpenSees convergence test takes before its iterations, where not one."""


@dataclass(frozen=True)
class Rung:
    """One way of taking a step: an algorithm, over the step split into substeps, with a
    convergence test.

    Attributes:
        rank: its place on the ladder, from 0 (the easiest).
        algorithm: the ``ops.algorithm`` arguments.
        substeps: the step split into this many (1: the full step); the last one is
            shorter where less of the step is left.
        test: the ``ops.test`` arguments, or None for the caller's own test.
        words: the rung in words (``"substeps dt/4"``, ``"KrylovNewton at dt/2"``, ``"a
            looser test and Broyden"``).
    """

    rank: int
    algorithm: tuple[Any, ...]
    substeps: int
    test: tuple[Any, ...] | None
    words: str


class ConvergenceParams(Params):
    """The convergence ladder of every OpenSees transient (see
    :mod:`cphysfno_opensees.convergence` for its order). Empty ``splits`` and
    ``algorithms`` and both looser factors 1 leave no ladder: a step that fails ends the
    analysis."""

    splits: tuple[int, ...] = Field(
        (2, 4, 10),
        description="substeps a failed step is split into, in increasing order, each tried "
        "where the one before fails (2: two steps of dt/2)",
    )
    algorithms: tuple[str, ...] = Field(
        ("Newton", "NewtonLineSearch", "KrylovNewton", "ModifiedNewton", "Broyden"),
        description="OpenSees algorithms tried after the substeps, in order, the caller's own "
        "skipped; a name may be followed by its flags ('Newton -initial')",
    )
    looser_tolerance: float = Field(
        10.0,
        ge=1.0,
        description="factor on the convergence test's tolerance for the last rungs (1: kept)",
    )
    looser_iterations: int = Field(
        2,
        ge=1,
        description="factor on the convergence test's iterations for the last rungs (1: kept)",
    )

    @field_validator("splits")
    @classmethod
    def _increasing(cls, splits: tuple[int, ...]) -> tuple[int, ...]:
        if any(s < 2 for s in splits) or any(b <= a for a, b in pairwise(splits)):
            raise ValueError(
                f"give numbers of substeps of at least 2 in increasing order (2, 4, 10), "
                f"got {list(splits)}"
            )
        return splits

    @field_validator("algorithms")
    @classmethod
    def _known(cls, algorithms: tuple[str, ...]) -> tuple[str, ...]:
        for algorithm in algorithms:
            name, *flags = algorithm.split() or [""]
            if name not in ALGORITHMS:
                raise ValueError(
                    f"{algorithm!r} is not an iterative OpenSees algorithm: give one of "
                    f"{', '.join(sorted(ALGORITHMS))}"
                )
            if any(not flag.startswith("-") for flag in flags):
                raise ValueError(f"{algorithm!r}: after the name give only flags (-initial)")
        if len(set(algorithms)) != len(algorithms):
            raise ValueError(f"each algorithm may appear once, got {list(algorithms)}")
        return algorithms

    @property
    def loosens(self) -> bool:
        """Whether the ladder has looser-test rungs."""
        return self.looser_tolerance > 1.0 or self.looser_iterations > 1

    def loosened(self, test: Sequence[Any]) -> tuple[Any, ...]:
        """The ``ops.test`` arguments ``test`` with its tolerances multiplied by
        ``looser_tolerance`` and its iterations by ``looser_iterations``."""
        values = list(test)
        tolerances = TOLERANCES.get(str(values[0]), 1)
        for i in range(1, min(1 + tolerances, len(values))):
            values[i] = values[i] * self.looser_tolerance
        if len(values) > 1 + tolerances:
            values[1 + tolerances] = int(values[1 + tolerances]) * self.looser_iterations
        return tuple(values)

    def rungs(self, algorithm: Sequence[Any], test: Sequence[Any] | None) -> tuple[Rung, ...]:
        """The ladder for a caller whose step failed with ``algorithm`` and ``test`` (the
        ``ops`` arguments), in order; without ``test``, no looser-test rungs."""
        own = tuple(algorithm)
        plain = [(own, s, f"substeps dt/{s}") for s in self.splits]
        plain += [(a, s, _at(a, s)) for s in (1, *self.splits) for a in self._others(own)]
        ladder = [(a, s, None, words) for a, s, words in plain]
        if test is not None and self.loosens:
            looser = self.loosened(test)
            ladder.append((own, 1, looser, "a looser test"))
            ladder += [(a, s, looser, f"a looser test and {words}") for a, s, words in plain]
        return tuple(Rung(rank, *rung) for rank, rung in enumerate(ladder))

    def described(self, algorithm: Sequence[Any], test: Sequence[Any] | None, dt: float) -> str:
        """What the ladder of :meth:`rungs` tries on a step of ``dt`` s, in words."""
        splits = ", ".join(f"dt/{s}" for s in self.splits)
        over = f" and {splits}" if splits else ""
        parts = [f"{_named(algorithm)} at dt = {dt:g} s{over}"]
        others = self._others(tuple(algorithm))
        if others:
            parts.append(f"{', '.join(_named(a) for a in others)} at dt{over}")
        if test is not None and self.loosens:
            parts.append(
                f"all again with a looser test (tolerance x {self.looser_tolerance:g}, "
                f"iterations x {self.looser_iterations})"
            )
        return "; ".join(parts)

    def _others(self, own: tuple[Any, ...]) -> list[tuple[str, ...]]:
        """The ``ops.algorithm`` arguments of ``algorithms``, but ``own``."""
        return [words for words in (tuple(a.split()) for a in self.algorithms) if words != own]


def _named(algorithm: Sequence[Any]) -> str:
    """An algorithm's ``ops.algorithm`` arguments in words (``"Newton -initial"``)."""
    return " ".join(str(a) for a in algorithm)


def _at(algorithm: tuple[Any, ...], substeps: int) -> str:
    """``"KrylovNewton"`` at the full step, ``"KrylovNewton at dt/4"`` over substeps."""
    return _named(algorithm) if substeps == 1 else f"{_named(algorithm)} at dt/{substeps}"
