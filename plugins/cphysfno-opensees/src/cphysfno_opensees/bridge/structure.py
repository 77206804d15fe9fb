"""The Auburn Ravine type bridge of the paper's Example 2 (§5.2) as a cphysfno structure."""

from __future__ import annotations

import functools
from collections.abc import Callable
from functools import cached_property
from typing import Annotated, Literal

import numpy as np
from pydantic import Field

from cphysfno_core.plugin import LinearSystem, Rayleigh, Stories

from ..loader import import_opensees
from ..structure import OpenSeesParams, OpenSeesStructure
from .analysis import analyse
from .compiled import analyse as compiled_analysis
from .design import BridgeDesign
from .linear import Matrices, assemble
from .model import ElasticSection, elastic_section
from .numerics import Numerics

Height = Annotated[float, Field(gt=2.0, lt=30.0, allow_inf_nan=False)]

DESIGN = BridgeDesign()
NUMERICS = Numerics()


class AuburnRavineBridgeParams(OpenSeesParams):
    """Parameters of :class:`AuburnRavineBridge`; the defaults are the calibrated bridge
    (T1 = 0.38 s) and the fast, verified numerics (see the plugin's README)."""

    pier_heights: tuple[Height, Height, Height, Height, Height] = Field(
        DESIGN.pier_heights, description="clear column height of each bent, west to east, m"
    )
    longitudinal_bars: int = Field(
        DESIGN.longitudinal_bars, ge=8, le=60, description="#11 longitudinal bars per column"
    )
    damping_ratio: float = Field(
        DESIGN.damping_ratio,
        ge=0.0,
        lt=1.0,
        description="Rayleigh damping ratio at T1 and at damping_period",
    )
    damping_period: float = Field(
        DESIGN.damping_period, gt=0.0, description="second period of the Rayleigh damping, s"
    )
    columns: Literal["fibre", "elastic"] = Field(
        "fibre",
        description="fibre-section columns (the nonlinear model) or their elastic twins of "
        "the initial section stiffness (the linear representation, run through OpenSees)",
    )
    engine: Literal["compiled", "opensees"] = Field(
        "compiled",
        description="who analyses the fibre bridge: compiled code that solves the OpenSees "
        "model's equations (same answer, several times faster) or OpenSees itself",
    )
    sectors: int = Field(NUMERICS.sectors, ge=4, description="fibres around the section")
    core_rings: int = Field(NUMERICS.core_rings, ge=1, description="fibre rings in the core")
    cover_rings: int = Field(NUMERICS.cover_rings, ge=1, description="fibre rings in the cover")
    integration_points: int = Field(
        NUMERICS.integration_points, ge=3, le=10, description="Gauss-Lobatto points per column"
    )
    substeps: int = Field(
        NUMERICS.substeps, ge=1, le=20, description="Newmark steps per sample of the record"
    )
    tolerance: float = Field(
        NUMERICS.tolerance, gt=0.0, description="Newton tolerance on the displacement increment, m"
    )
    iterative_elements: bool = Field(
        NUMERICS.iterative_elements,
        description="compiled engine: iterate every column to convergence at every Newton "
        "iteration, as OpenSees does (its iterates exactly), instead of letting the columns "
        "converge along with the structure (1.2 times faster, an equally converged answer)",
    )


class AuburnRavineBridge(OpenSeesStructure):
    """Six-span prestressed box-girder bridge on five two-column bents (paper §5.2).

    The elastic girder is rigidly connected to the bents; each column is a force-based
    element with a fibre section (Mander confined core, unconfined cover, Menegotto-Pinto
    bars), elastic shear and torsion, and P-Delta; the abutments are transverse and
    longitudinal springs; damping is Rayleigh, 5 % at the first period and at 0.1 s. The
    ground moves across the girder (global Y); the outputs ``pier-1`` .. ``pier-10`` are
    the transverse displacements of the column tops relative to the ground, in m: pier
    ``2 b + 1`` is the south and pier ``2 b + 2`` the north column of bent ``b + 1``,
    bents numbered from the west abutment.

    Its linear representation (:meth:`linear_system`) is the same bridge with elastic
    columns of the fibre section's initial stiffness, under gravity, condensed exactly onto
    its 103 mass-carrying translations.
    """

    name = "auburn-ravine-bridge"
    Params = AuburnRavineBridgeParams
    capabilities = frozenset({"linear_system", "coarse_simulation", "stories"})

    @property
    def output_names(self) -> tuple[str, ...]:
        return tuple(f"pier-{i + 1}" for i in range(2 * len(self.params.pier_heights)))

    def stories(self) -> Stories:
        """One "story" per column, from the ground to its top (output ``pier-i``), over the
        clear column height of its bent (``pier_heights``, m): the drift ratio of a column
        is its top's displacement over its height."""
        heights = tuple(h for h in self.params.pier_heights for _column in ("south", "north"))
        return Stories((None,) * len(heights), tuple(range(len(heights))), heights)

    @cached_property
    def design(self) -> BridgeDesign:
        """The bridge these parameters describe."""
        p = self.params
        return BridgeDesign(
            pier_heights=tuple(p.pier_heights),
            longitudinal_bars=p.longitudinal_bars,
            damping_ratio=p.damping_ratio,
            damping_period=p.damping_period,
        )

    @cached_property
    def numerics(self) -> Numerics:
        """Fibre mesh, integration points and tolerance of the analyses."""
        p = self.params
        return Numerics(
            sectors=p.sectors,
            core_rings=p.core_rings,
            cover_rings=p.cover_rings,
            integration_points=p.integration_points,
            substeps=p.substeps,
            tolerance=p.tolerance,
            convergence=p.convergence,
            iterative_elements=p.iterative_elements,
        )

    @cached_property
    def elastic_section(self) -> ElasticSection:
        """EA and EI of the columns' fibre section at zero strain."""
        return elastic_section(import_opensees(), self.design, self.numerics)

    @cached_property
    def matrices(self) -> Matrices:
        """The elastic bridge under gravity, condensed onto its mass-carrying DOFs."""
        return assemble(import_opensees(), self.design, self.numerics, self.elastic_section)

    @cached_property
    def damping(self) -> Rayleigh:
        """Rayleigh factors of ``damping_ratio`` at T1 and at ``damping_period``."""
        return self.matrices.rayleigh(self.params.damping_ratio, self.params.damping_period)

    def analysis(self) -> Callable[[np.ndarray, float], np.ndarray]:
        """One record's analysis of the bridge with the chosen columns and engine."""
        if self.params.columns == "fibre" and self.params.engine == "compiled":
            return functools.partial(compiled_analysis, self.design, self.numerics, self.damping)
        elastic = self.elastic_section if self.params.columns == "elastic" else None
        return functools.partial(
            analyse, self.design, self.numerics, self.damping, self.params.columns, elastic
        )

    def linear_system(self) -> LinearSystem:
        """Lumped masses (kg), Rayleigh damping ``a0 M + a1 K0`` (N s/m), stiffness under
        gravity (N/m), ones on the transverse DOFs, and the map to the column tops."""
        return self.matrices.linear_system(self.damping)
