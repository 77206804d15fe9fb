"""How the bridge's columns are discretised and its equations solved: numerics, not
physics (the defaults were chosen by measurement, see the plugin's README)."""

from __future__ import annotations

from dataclasses import dataclass, field

from ..convergence import ConvergenceParams


@dataclass(frozen=True)
class Numerics:
    """How the columns are discretised and the equations solved; none of it is physics.

    Attributes:
        sectors: fibres around the circumference of the column section.
        core_rings: Gauss fibre rings across the confined core.
        cover_rings: Gauss fibre rings across the cover (2 or more integrate the elastic
            stiffness exactly).
        integration_points: Gauss-Lobatto points of each force-based column.
        substeps: Newmark steps per sample interval of the record (the record is linear
            between its samples).
        tolerance: Newton convergence on the norm of the displacement increment, m.
        max_iterations: Newton iterations per attempt.
        system: OpenSees linear system of equations.
        numberer: OpenSees DOF numberer.
        algorithm: OpenSees solution algorithm (``ops.algorithm`` arguments).
        convergence: the convergence ladder of a step that does not converge in OpenSees.
        iterative_elements: in the compiled engine, every column's state determination
            iterates to convergence at every Newton iteration, as OpenSees'
            ``forceBeamColumn`` does (True: OpenSees' iterates exactly), or takes one
            iteration per Newton iteration and converges along with the structure
            (False, Neuenhofer and Filippou's non-iterative form: 1.2 times faster).
    """

    sectors: int = 16
    core_rings: int = 10
    cover_rings: int = 3
    integration_points: int = 5
    substeps: int = 2
    tolerance: float = 1e-6
    max_iterations: int = 25
    system: str = "BandGeneral"
    numberer: str = "RCM"
    algorithm: tuple[str, ...] = ("Newton",)
    convergence: ConvergenceParams = field(default_factory=ConvergenceParams)
    iterative_elements: bool = False
