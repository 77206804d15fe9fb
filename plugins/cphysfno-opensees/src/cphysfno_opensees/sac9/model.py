"""The SAC nine-story frame built in OpenSees: nodes, sections, elements, masses and the
P-Delta effect of the gravity load, and its eigenvalues.

:func:`build_frame` defines the whole model in the (global) OpenSees domain and returns
the node tags the analyses read. Element and section choices are in :class:`FrameConfig`,
a small frozen record that travels to worker processes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from .. import matrices
from ..quadrature import lobatto
from .sections import (
    BAY_WIDTH,
    BEAM_YIELD_STRESS,
    BEAMS,
    COLUMN_YIELD_STRESS,
    FLOOR_MASSES,
    FRAMES_SHARING_MASS,
    GRAVITY,
    HARDENING_RATIO,
    N_BAYS,
    SHAPES,
    SPLICE_HEIGHT,
    SPLICE_STORIES,
    STEEL_MODULUS,
    WideFlange,
    column_shape,
    level_heights,
)

N_COLUMNS = N_BAYS + 1
FIRST_FLOOR = 2
"""Index of level 2 among the levels (0 column bases, 1 ground, 2 ... 10 roof)."""
PIN_NODE, LEANING_NODE, SPLICE_NODE = N_COLUMNS, N_COLUMNS + 1, 50
"""Offsets of node tags within a level's block of 100 (columns take 0 ... 5): the beam end
pinned at the rightmost column, the two nodes of the leaning-column spring above the level
(7 and 8), and the splices above the level."""


def node_tag(level: int, offset: int) -> int:
    """Tag of a node of ``level`` (0 column bases, 1 ground, ... 10 roof). Tags grow with
    height, so numbering the equations in tag order keeps the band narrow: a rigid
    diaphragm ties a level's nodes together, which a numbering of the element graph
    alone does not see."""
    return 100 * (level + 1) + offset


@dataclass(frozen=True)
class FrameConfig:
    """How the frame is modelled (the published data are fixed).

    Attributes:
        model: ``"fibre"``: force-based beam-columns with fibre sections of bilinear steel
            at Gauss-Lobatto points; ``"hinges"``: force-based beam-columns whose ends are
            bilinear moment-curvature hinges of length ``hinge_length`` times the depth
            (modified Gauss-Radau hinge integration) around an elastic interior.
        flange_fibres: fibres through the thickness of each flange (2 or more).
        web_fibres: fibres over the depth of the web, half in each half (4 or more, even).
        integration_points: Gauss-Lobatto points per fibre element.
        hinge_length: plastic hinge length over the member depth (``"hinges"``).
        elastic_interior: fibre sections at the two end points only and elastic sections
            of the same EA and EI at the interior points (``"fibre"``).
        element_iterations: most iterations of a force-based element's own state
            determination, and its tolerance.
        p_delta: columns with the P-Delta transformation and the leaning column's springs
            for the floors' weight; ``False``: first order.
        pinned_bay: the beams of the rightmost bay pinned at the exterior column.
        damping_ratio: Rayleigh damping ratio at the two modes of ``damping_modes``.
        damping_modes: the two modes (1-based) matched, of the model with P-Delta.
    """

    model: Literal["fibre", "hinges"] = "fibre"
    flange_fibres: int = 2
    web_fibres: int = 16
    integration_points: int = 5
    hinge_length: float = 0.5
    elastic_interior: bool = True
    element_iterations: tuple[int, float] = (10, 1e-12)
    p_delta: bool = True
    pinned_bay: bool = True
    damping_ratio: float = 0.03
    damping_modes: tuple[int, int] = (1, 3)


@dataclass
class Frame:
    """The floors of the model :func:`build_frame` defined.

    Attributes:
        floors: node tags of levels 2 ... roof whose horizontal displacement is the
            floor's (the masters of the rigid diaphragms).
        heights: ``[9]`` elevations of those levels above the ground, m.
        masses: ``[9]`` horizontal masses at those nodes, kg.
        members: the shape and steel of every member, by element tag.
    """

    floors: list[int]
    heights: np.ndarray
    masses: np.ndarray
    members: dict[int, Member]


@dataclass(frozen=True)
class Member:
    """A member's W shape and the yield stress of its steel, Pa."""

    shape: WideFlange
    yield_stress: float


def fibre_layout(shape: WideFlange, config: FrameConfig) -> list[tuple[float, float]]:
    """``(y, area)`` of every fibre of the shape's fibre section (m, m^2): fibres over the
    depth of four rectangles (the flanges and the two halves of the web) at Gauss-Legendre
    points, each carrying its share of the rectangle's area. The area, second moment and
    plastic modulus of the shape are exact for any count of two or more fibres per
    rectangle, so the fibre counts change only how yielding spreads through the depth."""
    half_depth, half_web = shape.depth / 2.0, shape.web_height / 2.0
    web_fibres = max(config.web_fibres // 2, 1)
    rectangles = (
        (half_web, half_depth, shape.flange_width, config.flange_fibres),
        (0.0, half_web, shape.web_thickness, web_fibres),
        (-half_web, 0.0, shape.web_thickness, web_fibres),
        (-half_depth, -half_web, shape.flange_width, config.flange_fibres),
    )
    layout = []
    for bottom, top, width, count in rectangles:
        points, weights = np.polynomial.legendre.leggauss(count)
        centre, half = (top + bottom) / 2.0, (top - bottom) / 2.0
        for point, weight in zip(points, weights, strict=True):
            layout.append((centre + half * point, width * half * weight))
    return layout


class _Tags:
    """Consecutive tags, one counter per kind of object."""

    def __init__(self) -> None:
        self.counters: dict[str, int] = {}

    def next(self, kind: str) -> int:
        self.counters[kind] = self.counters.get(kind, 0) + 1
        return self.counters[kind]


def build_frame(ops: Any, config: FrameConfig) -> Frame:
    """Wipe OpenSees and define the frame (2D, 3 DOF per node), at rest.

    Column bases are pinned, the ground level is restrained horizontally, the floors
    above are rigid diaphragms (horizontal DOF tied to the floor's rightmost column node,
    which carries the floor's mass and is tied to nothing itself), every member is one
    element (two in a spliced story).

    Returns:
        The floors' nodes, elevations and masses.
    """
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    tags = _Tags()
    heights = level_heights()
    grid = [
        [node_tag(level, column) for column in range(N_COLUMNS)] for level in range(len(heights))
    ]
    for level, y in enumerate(heights):
        for column, node in enumerate(grid[level]):
            ops.node(node, column * BAY_WIDTH, y)
    for node in grid[0]:
        ops.fix(node, 1, 1, 0)
    for node in grid[1]:
        ops.fix(node, 1, 0, 0)
    masses = np.asarray(FLOOR_MASSES) / FRAMES_SHARING_MASS
    floors = [grid[level][-1] for level in range(FIRST_FLOOR, len(heights))]
    for level in range(FIRST_FLOOR, len(heights)):
        master = grid[level][-1]
        ops.mass(master, masses[level - FIRST_FLOOR], 0.0, 0.0)
        for node in grid[level][:-1]:
            ops.equalDOF(master, node, 1)
    column_transform, beam_transform = tags.next("transform"), tags.next("transform")
    ops.geomTransf("PDelta" if config.p_delta else "Linear", column_transform)
    ops.geomTransf("Linear", beam_transform)
    builder = _MemberBuilder(ops, config, tags)
    frame = Frame(floors, np.asarray(heights[FIRST_FLOOR:]), masses, builder.members)
    for story in range(len(heights) - 1):
        for column in range(N_COLUMNS):
            _column(ops, builder, grid, story, column, column_transform)
    for level in range(1, len(heights)):
        shape = SHAPES[BEAMS[level - 1]]
        for bay in range(N_BAYS):
            left, right = grid[level][bay], grid[level][bay + 1]
            if config.pinned_bay and bay == N_BAYS - 1:
                right = _pin(ops, right, level)
            builder.member(left, right, shape, BEAM_YIELD_STRESS, beam_transform)
    if config.p_delta:
        _leaning_column(ops, tags, heights, floors, masses)
    return frame


def _pin(ops: Any, joint: int, level: int) -> int:
    """A node at ``joint`` that shares its translations and rotates freely: the end of a
    pinned beam. At the ground, whose horizontal DOF is fixed, the node is fixed itself
    rather than tied to a fixed DOF (a tie to a fixed DOF upsets the Transformation
    handler's dynamics)."""
    pin = node_tag(level, PIN_NODE)
    ops.node(pin, *ops.nodeCoord(joint))
    if level < FIRST_FLOOR:
        ops.fix(pin, 1, 0, 0)
        ops.equalDOF(joint, pin, 2)
    else:
        ops.equalDOF(joint, pin, 1, 2)
    return pin


def _column(
    ops: Any, builder: _MemberBuilder, grid, story: int, column: int, transform: int
) -> None:
    """The column on ``column`` line in ``story`` (0 basement ... 9): one element, two in a
    spliced story."""
    exterior = column in (0, N_COLUMNS - 1)
    bottom, top = grid[story][column], grid[story + 1][column]
    lower = SHAPES[column_shape(story, exterior, upper_part=False)]
    if story not in SPLICE_STORIES:
        builder.member(bottom, top, lower, COLUMN_YIELD_STRESS, transform)
        return
    x, y = ops.nodeCoord(bottom)
    splice = node_tag(story, SPLICE_NODE + column)
    ops.node(splice, x, y + SPLICE_HEIGHT)
    upper = SHAPES[column_shape(story, exterior, upper_part=True)]
    builder.member(bottom, splice, lower, COLUMN_YIELD_STRESS, transform)
    builder.member(splice, top, upper, COLUMN_YIELD_STRESS, transform)


def _leaning_column(ops: Any, tags: _Tags, heights, floors: list[int], masses) -> None:
    """The P-Delta effect of the floors' weight, which the gravity frames carry: story
    ``s`` of height ``h_s`` under the weight ``P_s`` of the floors above it gets a linear
    spring of stiffness ``-P_s / h_s`` between its floors, which is what a pin-ended
    leaning column with a linearised (P-Delta) transformation adds. Each spring joins two
    coincident nodes tied horizontally to the floors below and above.
    """
    weights = GRAVITY * np.cumsum(np.asarray(masses)[::-1])[::-1]
    below = None
    for index, (floor, weight) in enumerate(zip(floors, weights, strict=True)):
        level = FIRST_FLOOR + index
        bottom, top = node_tag(level - 1, LEANING_NODE), node_tag(level - 1, LEANING_NODE + 1)
        x, y = N_COLUMNS * BAY_WIDTH, heights[level - 1]
        ops.node(bottom, x, y)
        ops.node(top, x, y)
        if below is None:
            ops.fix(bottom, 1, 1, 1)
        else:
            ops.fix(bottom, 0, 1, 1)
            ops.equalDOF(below, bottom, 1)
        ops.fix(top, 0, 1, 1)
        ops.equalDOF(floor, top, 1)
        material = tags.next("material")
        ops.uniaxialMaterial("Elastic", material, -weight / (heights[level] - y))
        ops.element("zeroLength", tags.next("element"), bottom, top, "-mat", material, "-dir", 1)
        below = floor


class _MemberBuilder:
    """Defines one beam-column element per call, with the sections and integration of the
    configured model; sections are defined once per (shape, yield stress)."""

    def __init__(self, ops: Any, config: FrameConfig, tags: _Tags) -> None:
        self.ops, self.config, self.tags = ops, config, tags
        self.integrations: dict[tuple[str, float], int] = {}
        self.members: dict[int, Member] = {}

    def member(
        self, node_i: int, node_j: int, shape: WideFlange, yield_stress: float, transform: int
    ) -> None:
        key = (shape.name, yield_stress)
        if key not in self.integrations:
            self.integrations[key] = self._integration(shape, yield_stress)
        iterations, tolerance = self.config.element_iterations
        element = self.tags.next("element")
        self.members[element] = Member(shape, yield_stress)
        self.ops.element(
            "forceBeamColumn",
            element,
            node_i,
            node_j,
            transform,
            self.integrations[key],
            "-iter",
            iterations,
            tolerance,
        )

    def _integration(self, shape: WideFlange, yield_stress: float) -> int:
        ops, config = self.ops, self.config
        integration = self.tags.next("integration")
        if config.model == "fibre":
            section = self._fibre_section(shape, yield_stress)
            if not config.elastic_interior:
                ops.beamIntegration("Lobatto", integration, section, config.integration_points)
                return integration
            elastic = self.tags.next("section")
            ops.section("Elastic", elastic, STEEL_MODULUS, shape.area, shape.inertia)
            n = config.integration_points
            locations, weights = lobatto(n)
            sections = [section] + [elastic] * (n - 2) + [section]
            ops.beamIntegration(
                "UserDefined", integration, n, *sections, *locations.tolist(), *weights.tolist()
            )
            return integration
        hinge = self._hinge_section(shape, yield_stress)
        interior = self.tags.next("section")
        ops.section("Elastic", interior, STEEL_MODULUS, shape.area, shape.inertia)
        length = config.hinge_length * shape.depth
        ops.beamIntegration("HingeRadau", integration, hinge, length, hinge, length, interior)
        return integration

    def _steel(self, yield_stress: float) -> int:
        material = self.tags.next("material")
        self.ops.uniaxialMaterial("Steel01", material, yield_stress, STEEL_MODULUS, HARDENING_RATIO)
        return material

    def _fibre_section(self, shape: WideFlange, yield_stress: float) -> int:
        """The fibres of :func:`fibre_layout`, of bilinear steel."""
        material = self._steel(yield_stress)
        section = self.tags.next("section")
        self.ops.section("Fiber", section)
        for y, area in fibre_layout(shape, self.config):
            self.ops.fiber(y, 0.0, area, material)
        return section

    def _hinge_section(self, shape: WideFlange, yield_stress: float) -> int:
        """Bilinear moment-curvature (plastic moment, hardening ratio of the steel) with an
        elastic axial response."""
        ops = self.ops
        bending, axial = self.tags.next("material"), self.tags.next("material")
        ops.uniaxialMaterial(
            "Steel01",
            bending,
            shape.plastic_modulus * yield_stress,
            STEEL_MODULUS * shape.inertia,
            HARDENING_RATIO,
        )
        ops.uniaxialMaterial("Elastic", axial, STEEL_MODULUS * shape.area)
        section = self.tags.next("section")
        ops.section("Aggregator", section, axial, "P", bending, "Mz")
        return section


def eigenvalues(ops: Any, n: int) -> np.ndarray:
    """``[n]`` smallest eigenvalues omega^2 (rad^2/s^2) of the current stiffness and the
    mass, by a dense generalised solve (the rotations and verticals carry no mass), the
    rigid diaphragms' ties eliminated by the Transformation handler
    (:func:`cphysfno_opensees.matrices.eigenvalues`; OpenSees' messages are shown only if
    the solve fails)."""
    return matrices.eigenvalues(ops, ("Transformation",), n, system="BandGeneral")
