"""A stand-in for ``openseespy.opensees`` whose steps converge or fail as a test says, for
the tests of :func:`cphysfno_opensees.transient.integrate` and its convergence ladder."""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple


class Attempt(NamedTuple):
    """One ``analyze(1, step)``: the time at its start and the step (s, rounded to 1e-9),
    the algorithm in words and the test's tolerance (None before any ``test``)."""

    time: float
    step: float
    algorithm: str
    tolerance: float | None


class ScriptedOps:
    """Time advances by the step asked for, unless ``fails(attempt)`` says that attempt
    does not converge; every attempt is kept in ``attempts``."""

    def __init__(self, fails: Callable[[Attempt], bool]) -> None:
        self.fails = fails
        self.time = 0.0
        self.current: tuple = ("Newton",)
        self.tested: tuple | None = None
        self.attempts: list[Attempt] = []

    def algorithm(self, *arguments) -> None:
        self.current = arguments

    def test(self, *arguments) -> None:
        self.tested = arguments

    def analyze(self, n: int, step: float) -> int:
        assert n == 1
        tolerance = None if self.tested is None else self.tested[1]
        attempt = Attempt(round(self.time, 9), round(step, 9), " ".join(self.current), tolerance)
        self.attempts.append(attempt)
        if self.fails(attempt):
            return -3
        self.time += step
        return 0

    def getTime(self) -> float:  # noqa: N802 - the OpenSees name
        return self.time
