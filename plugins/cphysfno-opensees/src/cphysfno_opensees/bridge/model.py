"""The bridge built in OpenSees: fibre-section columns or their elastic twins.

Tags: girder nodes ``1..n`` from west to east; abutment ground nodes 9001 (west) and 9002
(east); column top ``1000 + 10 b + s`` and base ``2000 + 10 b + s`` of bent ``b`` (0..4)
and side ``s`` (0 south, ``y < 0``; 1 north). Output ``2 b + s`` is column ``1000 + 10 b +
s``'s top.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from .bridge_design import GRAVITY, BridgeDesign

Columns = Literal["fibre", "elastic"]

DECK_TRANSFORM, CAP_TRANSFORM, COLUMN_TRANSFORM = 1, 2, 3
CORE, COVER, STEEL, SHEAR, FIBRE_SECTION, COLUMN_SECTION = range(1, 7)
COLUMN_INTEGRATION = 1
ELASTIC_SECTION = 7
ABUTMENT_LONGITUDINAL, ABUTMENT_TRANSVERSE = 11, 12


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
    iterative_elements: bool = False


@dataclass(frozen=True)
class ElasticSection:
    """Axial and bending stiffness of an elastic column section.

    Attributes:
        axial: EA, N.
        bending: EI about either axis, N m^2 (the section is circular).
    """

    axial: float
    bending: float


@dataclass(frozen=True)
class Layout:
    """Node tags and positions of a built bridge."""

    girder_x: tuple[float, ...]
    bents: tuple[int, ...]
    column_tops: tuple[int, ...]

    @property
    def girder_nodes(self) -> tuple[int, ...]:
        return tuple(range(1, len(self.girder_x) + 1))


def layout(design: BridgeDesign) -> Layout:
    """Girder node positions (m), the girder node of each bent and the column top tags."""
    x = [0.0]
    per_span = design.deck_elements_per_span
    for span in design.spans:
        x += [x[-1] + span * (k + 1) / per_span for k in range(per_span)]
    bents = tuple(per_span * (i + 1) + 1 for i in range(len(design.spans) - 1))
    tops = tuple(1000 + 10 * b + s for b in range(len(bents)) for s in (0, 1))
    return Layout(tuple(x), bents, tops)


def build(
    ops: Any,
    design: BridgeDesign,
    numerics: Numerics,
    columns: Columns,
    elastic: ElasticSection | None = None,
    gravity: bool = True,
) -> Layout:
    """Build the bridge in a wiped OpenSees domain and bring it to rest under gravity.

    Args:
        ops: ``openseespy.opensees``.
        design: the bridge.
        numerics: fibre mesh and integration points of the columns.
        columns: ``"fibre"`` for the nonlinear columns, ``"elastic"`` for their elastic
            twins of section stiffness ``elastic``.
        elastic: needed with ``columns="elastic"`` (see :func:`elastic_section`).
        gravity: ``False`` leaves the unloaded model (see :func:`apply_gravity`).

    After the call the gravity loads are constant, the analysis time is 0 and no analysis
    is defined.
    """
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    where = layout(design)
    _girder(ops, design, where)
    _abutments(ops, design, where)
    if columns == "fibre":
        _fibre_section(ops, design, numerics)
    else:
        if elastic is None:
            raise ValueError("elastic columns need their ElasticSection")
        _elastic_section(ops, design, elastic)
    ops.beamIntegration("Lobatto", COLUMN_INTEGRATION, COLUMN_SECTION, numerics.integration_points)
    _bents(ops, design, where)
    if gravity:
        apply_gravity(ops, where)
    return where


def _girder(ops: Any, design: BridgeDesign, where: Layout) -> None:
    """Girder nodes with their tributary masses and elastic girder elements."""
    x = np.asarray(where.girder_x)
    tributary = np.zeros_like(x)
    tributary[:-1] += np.diff(x) / 2.0
    tributary[1:] += np.diff(x) / 2.0
    for node, (position, length) in enumerate(zip(x, tributary, strict=True), start=1):
        ops.node(node, float(position), 0.0, 0.0)
        mass = design.deck_mass_per_length * length
        if node in where.bents:
            mass += design.diaphragm_mass
        ops.mass(node, mass, mass, mass, 0.0, 0.0, 0.0)
    ops.geomTransf("Linear", DECK_TRANSFORM, 0.0, 0.0, 1.0)
    shear_modulus = design.deck_modulus / (2.0 * (1.0 + design.deck_poisson))
    for node in where.girder_nodes[:-1]:
        ops.element(
            "elasticBeamColumn",
            node,
            node,
            node + 1,
            design.deck_area,
            design.deck_modulus,
            shear_modulus,
            design.deck_torsion_constant,
            design.deck_vertical_inertia,
            design.deck_lateral_inertia,
            DECK_TRANSFORM,
        )


def _abutments(ops: Any, design: BridgeDesign, where: Layout) -> None:
    """Seat-type abutments: vertical and torsional restraint, horizontal springs."""
    ops.uniaxialMaterial("Elastic", ABUTMENT_LONGITUDINAL, design.abutment_longitudinal)
    ops.uniaxialMaterial("Elastic", ABUTMENT_TRANSVERSE, design.abutment_transverse)
    ends = ((9001, where.girder_nodes[0]), (9002, where.girder_nodes[-1]))
    for ground, girder in ends:
        ops.node(ground, where.girder_x[girder - 1], 0.0, 0.0)
        ops.fix(ground, 1, 1, 1, 1, 1, 1)
        ops.fix(girder, 0, 0, 1, 1, 0, 0)
        materials = (ABUTMENT_LONGITUDINAL, ABUTMENT_TRANSVERSE)
        ops.element(
            "zeroLength", ground, ground, girder, "-mat", *materials, "-dir", 1, 2,
            "-doRayleigh", 1,
        )  # fmt: skip


def shear_and_torsion_stiffness(design: BridgeDesign) -> tuple[float, float]:
    """The elastic shear stiffness GA (N, each of Vy and Vz) and torsional stiffness GJ
    (N m^2) of a column."""
    shear_modulus = design.concrete_modulus / 2.4
    polar = np.pi * design.column_diameter**4 / 32.0
    return (
        shear_modulus * design.shear_area_factor * design.gross_area,
        design.column_torsion_factor * shear_modulus * polar,
    )


def _shear_and_torsion(ops: Any, design: BridgeDesign) -> tuple[float, float]:
    """The elastic shear material (tag) and the torsional stiffness GJ (N m^2) of a column."""
    shear, torsion = shear_and_torsion_stiffness(design)
    ops.uniaxialMaterial("Elastic", SHEAR, shear)
    return SHEAR, torsion


def section_fibres(
    design: BridgeDesign, numerics: Numerics
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(core, cover, bars)``: ``[n, 3]`` fibres ``(y, z, area)`` (m, m, m^2) of the column
    section, each group of one material."""
    core_radius = design.core_diameter / 2.0
    outer = design.column_diameter / 2.0
    core = polar_gauss(0.0, core_radius, numerics.core_rings, numerics.sectors)
    cover = polar_gauss(core_radius, outer, numerics.cover_rings, numerics.sectors)
    angles = 2.0 * np.pi * np.arange(design.longitudinal_bars) / design.longitudinal_bars
    bars = np.stack(
        [
            design.bar_radius * np.cos(angles),
            design.bar_radius * np.sin(angles),
            np.full(angles.size, design.bar_area),
        ],
        axis=1,
    )
    return np.array(core), np.array(cover), bars


def material_arguments(
    design: BridgeDesign,
) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
    """OpenSees' arguments of the core and cover ``Concrete04`` (``fc epsc epscu Ec fct
    et``, compression negative) and of the bars' ``Steel02`` (``Fy E0 b R0 cR1 cR2``), SI."""
    core = design.confined_concrete()
    tension = design.concrete_tensile_strength
    cracking = tension / design.concrete_modulus
    hardening = (design.steel_ultimate - design.steel_yield) / (
        design.steel_modulus
        * (design.steel_ultimate_strain - design.steel_yield / design.steel_modulus)
    )
    return (
        (-core.strength, -core.peak_strain, -core.ultimate_strain, design.concrete_modulus,
         tension, cracking),
        (-design.concrete_strength, -design.concrete_peak_strain, -design.cover_spalling_strain,
         design.concrete_modulus, tension, cracking),
        (design.steel_yield, design.steel_modulus, hardening, 20.0, 0.925, 0.15),
    )  # fmt: skip


def _fibre_section(ops: Any, design: BridgeDesign, numerics: Numerics) -> None:
    """Confined core, unconfined cover and reinforcing bars, with elastic shear and torsion."""
    core, cover, steel = material_arguments(design)
    ops.uniaxialMaterial("Concrete04", CORE, *core)
    ops.uniaxialMaterial("Concrete04", COVER, *cover)
    ops.uniaxialMaterial("Steel02", STEEL, *steel)
    shear, torsion = _shear_and_torsion(ops, design)
    ops.section("Fiber", FIBRE_SECTION, "-GJ", torsion)
    groups = zip((CORE, COVER, STEEL), section_fibres(design, numerics), strict=True)
    for material, fibres in groups:
        for y, z, area in fibres:
            ops.fiber(float(y), float(z), float(area), material)
    ops.section("Aggregator", COLUMN_SECTION, shear, "Vy", shear, "Vz", "-section", FIBRE_SECTION)


def polar_gauss(
    inner: float, outer: float, rings: int, sectors: int
) -> list[tuple[float, float, float]]:
    """Fibres ``(y, z, area)`` (m, m, m^2) of the annulus ``inner <= r <= outer``.

    Gauss-Legendre points in the radius (weight ``r dr``) times ``sectors`` equal angles
    (the midpoint rule, exact for trigonometric polynomials of degree below ``sectors``):
    the areas sum to the annulus's, and the second moments are exact from 2 rings and 3
    sectors up, so the elastic stiffness does not depend on the mesh. Angles sit at the
    middle of the sectors, symmetric about both axes when ``sectors`` is even.
    """
    nodes, weights = np.polynomial.legendre.leggauss(rings)
    half = 0.5 * (outer - inner)
    radii = inner + half * (nodes + 1.0)
    widths = 2.0 * np.pi / sectors
    fibres = []
    for radius, weight in zip(radii, weights * half, strict=True):
        for j in range(sectors):
            angle = (j + 0.5) * widths
            area = weight * radius * widths
            fibres.append((float(radius * np.cos(angle)), float(radius * np.sin(angle)), area))
    return fibres


def _elastic_section(ops: Any, design: BridgeDesign, elastic: ElasticSection) -> None:
    """The elastic twin of the fibre section: EA and EI given, GJ and shear the same."""
    shear, torsion = _shear_and_torsion(ops, design)
    ops.section("Elastic", ELASTIC_SECTION, 1.0, elastic.axial, elastic.bending,
                elastic.bending, 1.0, torsion)  # fmt: skip
    ops.section("Aggregator", COLUMN_SECTION, shear, "Vy", shear, "Vz", "-section", ELASTIC_SECTION)


def _bents(ops: Any, design: BridgeDesign, where: Layout) -> None:
    """Bent caps from the girder to the column tops, and the force-based columns."""
    ops.geomTransf("Linear", CAP_TRANSFORM, 0.0, 0.0, 1.0)
    ops.geomTransf("PDelta", COLUMN_TRANSFORM, 1.0, 0.0, 0.0)
    cap_shear = design.concrete_modulus / 2.4
    column_mass = design.concrete_density * design.gross_area
    for b, (girder, height) in enumerate(zip(where.bents, design.pier_heights, strict=True)):
        x = where.girder_x[girder - 1]
        for s, y in enumerate((-design.column_spacing / 2.0, design.column_spacing / 2.0)):
            top, base = 1000 + 10 * b + s, 2000 + 10 * b + s
            ops.node(top, x, y, 0.0)
            ops.node(base, x, y, -height)
            ops.fix(base, 1, 1, 1, 1, 1, 1)
            mass = 0.5 * column_mass * height
            ops.mass(top, mass, mass, mass, 0.0, 0.0, 0.0)
            ops.element(
                "elasticBeamColumn", 3000 + 10 * b + s, girder, top, design.cap_area,
                design.concrete_modulus, cap_shear, design.cap_torsion_constant,
                design.cap_inertia, design.cap_inertia, CAP_TRANSFORM,
            )  # fmt: skip
            ops.element(
                "forceBeamColumn", 4000 + 10 * b + s, base, top, COLUMN_TRANSFORM,
                COLUMN_INTEGRATION,
            )  # fmt: skip


def apply_gravity(ops: Any, where: Layout) -> None:
    """Weights of every lumped mass, applied in 10 load steps and then held constant."""
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    for node in (*where.girder_nodes, *where.column_tops):
        ops.load(node, 0.0, 0.0, -ops.nodeMass(node, 3) * GRAVITY, 0.0, 0.0, 0.0)
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-12, 50)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 0.1)
    ops.analysis("Static")
    if ops.analyze(10) != 0:
        raise RuntimeError("the bridge does not carry its own weight: check the design")
    ops.loadConst("-time", 0.0)
    ops.wipeAnalysis()


def elastic_section(ops: Any, design: BridgeDesign, numerics: Numerics) -> ElasticSection:
    """EA and EI of the fibre section at zero strain (its initial stiffness), read back
    from OpenSees.

    Builds one fibre column alone (the domain is wiped before and after).
    """
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    _fibre_section(ops, design, numerics)
    ops.beamIntegration("Lobatto", COLUMN_INTEGRATION, COLUMN_SECTION, numerics.integration_points)
    ops.geomTransf("Linear", COLUMN_TRANSFORM, 1.0, 0.0, 0.0)
    ops.node(1, 0.0, 0.0, 0.0)
    ops.node(2, 0.0, 0.0, 1.0)
    ops.fix(1, 1, 1, 1, 1, 1, 1)
    ops.element("forceBeamColumn", 1, 1, 2, COLUMN_TRANSFORM, COLUMN_INTEGRATION)
    tangent = np.asarray(ops.sectionStiffness(1, 1))
    size = int(round(np.sqrt(tangent.size)))
    tangent = tangent.reshape(size, size)
    ops.wipe()
    return ElasticSection(axial=float(tangent[0, 0]), bending=float(tangent[1, 1]))
