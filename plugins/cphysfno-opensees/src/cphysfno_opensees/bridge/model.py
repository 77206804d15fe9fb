"""The bridge built in OpenSees: fibre-section columns or their elastic twins.

Tags: girder nodes ``1..n`` from west to east; abutment ground nodes 9001 (west) and 9002
(east); column top ``1000 + 10 b + s`` and base ``2000 + 10 b + s`` of bent ``b`` (0..4)
and side ``s`` (0 south, ``y < 0``; 1 north). Output ``2 b + s`` is column ``1000 + 10 b +
s``'s top.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from .column import column_materials, section_fibres, shear_and_torsion_stiffness
from .design import GRAVITY, BridgeDesign
from .numerics import Numerics

Columns = Literal["fibre", "elastic"]

TRANSVERSE = 2
"""Global direction of the excitation and of the outputs (Y, across the girder)."""

DECK_TRANSFORM, CAP_TRANSFORM, COLUMN_TRANSFORM = 1, 2, 3
CORE, COVER, STEEL, SHEAR, FIBRE_SECTION, COLUMN_SECTION = range(1, 7)
COLUMN_INTEGRATION = 1
ELASTIC_SECTION = 7
ABUTMENT_LONGITUDINAL, ABUTMENT_TRANSVERSE = 11, 12


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


def _shear_and_torsion(ops: Any, design: BridgeDesign) -> tuple[float, float]:
    """The elastic shear material (tag) and the torsional stiffness GJ (N m^2) of a column."""
    shear, torsion = shear_and_torsion_stiffness(design)
    ops.uniaxialMaterial("Elastic", SHEAR, shear)
    return SHEAR, torsion


def _fibre_section(ops: Any, design: BridgeDesign, numerics: Numerics) -> None:
    """Confined core, unconfined cover and reinforcing bars, with elastic shear and torsion."""
    materials = column_materials(design)
    materials.core.define(ops, CORE)
    materials.cover.define(ops, COVER)
    materials.bars.define(ops, STEEL)
    shear, torsion = _shear_and_torsion(ops, design)
    ops.section("Fiber", FIBRE_SECTION, "-GJ", torsion)
    groups = zip((CORE, COVER, STEEL), section_fibres(design, numerics), strict=True)
    for material, fibres in groups:
        for y, z, area in fibres:
            ops.fiber(float(y), float(z), float(area), material)
    ops.section("Aggregator", COLUMN_SECTION, shear, "Vy", shear, "Vz", "-section", FIBRE_SECTION)


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


def tangent_stiffness(ops: Any) -> np.ndarray:
    """``[n_eq, n_eq]`` tangent stiffness of the current state (N/m, N, N m), symmetrised;
    the static analysis that formed it stays defined, its equations numbered in order."""
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.test("NormDispIncr", 1e-12, 10)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 0.0)
    ops.analysis("Static")
    if ops.analyze(1) != 0:
        raise RuntimeError("could not form the tangent of the elastic bridge")
    values = np.asarray(ops.printA("-ret"), dtype=np.float64)
    n = int(round(math.sqrt(values.size)))
    matrix = values.reshape(n, n)
    return 0.5 * (matrix + matrix.T)


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
