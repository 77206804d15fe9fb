"""A five-story, three-bay reinforced-concrete moment frame in OpenSeesPy (kN, m, tonne, s;
stresses in kPa), a second RC frame beside examples/models/rc_frame.py.

Every member is a force-based beam-column element (five Gauss-Lobatto points) on a fibre
section: a confined core and an unconfined cover of ``Concrete01`` (no tensile strength;
fc' = 30 MPa, the core confined to 36 MPa) around ``Steel02`` bars (fy = 450 MPa,
E = 200 GPa, 0.8 % hardening). Columns of the first two stories are 0.65 x 0.65 m with 12
bars of 25 mm (1.4 %), those above 0.55 x 0.55 m with 8 bars of 25 mm (1.3 %), P-Delta
transformation; beams are 0.4 x 0.65 m with 4 bars of 25 mm on top and 3 at the bottom,
linear transformation. Bays of 7 m; a first story of 4.0 m, stories of 3.2 m above
(16.8 m in all). Each floor and the roof weigh 1323 kN (a 21 m x 7 m tributary slab at
9 kPa), its mass lumped at its four joints (a sixth at each outer joint, a third at each
inner one), horizontally; the joints of a floor share their horizontal displacement (a
rigid floor diaphragm). ``gravity()`` puts the floors' weight on the joints; the columns'
P-Delta transformation feels it.

At the gravity state the first three periods are 0.92, 0.28 and 0.14 s (the concrete
carries no tension, so the sections are cracked from the start). Pushed in its first mode,
the frame yields at a roof drift ratio of about 0.9 %, its base shear levelling off at
about 0.26 of its weight, then falling slowly (0.24 at 3 %) as P-Delta acts; the drift
gathers in the first three stories (about 4.5 % each at 3 % roof drift).

Used by examples/rc-frame-5story.toml (``name = "opensees-model"``): cphysfno calls
``build()`` and ``gravity()`` and adds damping, the ground motion and the analysis.
"""

import openseespy.opensees as ops

G = 9.81  # m/s^2
BAY = 7.0  # m
FIRST_STORY = 4.0  # m
STORY_HEIGHT = 3.2  # m, the stories above the first
N_FLOORS = 5
N_LINES = 4  # column lines
LOWER_FLOORS = 2  # stories with the larger columns
FLOOR_WEIGHT = 1323.0  # kN a floor (the roof too)
FC = 30.0e3  # kPa, unconfined concrete strength
FCC = 36.0e3  # kPa, confined core strength
FY = 450.0e3  # kPa, bar yield stress
ES = 200.0e6  # kPa, bar modulus
COVER = 0.05  # m, from the face to the bars' centres
# width, depth (m), bars at the top face, at the bottom face, rows of two bars between,
# bar area (m^2)
LOWER_COLUMN = (0.65, 0.65, 4, 4, 2, 4.91e-4)  # 25 mm bars
UPPER_COLUMN = (0.55, 0.55, 3, 3, 1, 4.91e-4)  # 25 mm bars
BEAM = (0.4, 0.65, 4, 3, 0, 4.91e-4)  # 25 mm bars
COVER_CONCRETE, CORE_CONCRETE, STEEL = 1, 2, 3
LOWER_COLUMN_SECTION, UPPER_COLUMN_SECTION, BEAM_SECTION = 1, 2, 3


def _node(floor: int, line: int) -> int:
    """Node of column line ``line`` (1-4) at floor ``floor`` (0 the ground)."""
    return 10 * floor + line


def _elevation(floor: int) -> float:
    """Height of floor ``floor`` above the ground (m)."""
    return 0.0 if floor == 0 else FIRST_STORY + (floor - 1) * STORY_HEIGHT


def _fibre_section(
    tag: int, width: float, depth: float, top: int, bottom: int, rows: int, bar_area: float
) -> None:
    """A rectangular section bending about its width: a confined core, cover on all four
    sides, ``top`` and ``bottom`` bars at the faces and ``rows`` rows of two bars (one at
    each side) evenly between them."""
    y, z = depth / 2.0, width / 2.0
    yc, zc = y - COVER, z - COVER
    ops.section("Fiber", tag)
    ops.patch("rect", CORE_CONCRETE, 12, 1, -yc, -zc, yc, zc)
    ops.patch("rect", COVER_CONCRETE, 12, 1, -y, zc, y, z)
    ops.patch("rect", COVER_CONCRETE, 12, 1, -y, -z, y, -zc)
    ops.patch("rect", COVER_CONCRETE, 1, 1, -y, -zc, -yc, zc)
    ops.patch("rect", COVER_CONCRETE, 1, 1, yc, -zc, y, zc)
    ops.layer("straight", STEEL, top, bar_area, yc, zc, yc, -zc)
    ops.layer("straight", STEEL, bottom, bar_area, -yc, zc, -yc, -zc)
    for row in range(1, rows + 1):
        level = -yc + 2.0 * yc * row / (rows + 1)
        ops.layer("straight", STEEL, 2, bar_area, level, zc, level, -zc)


def build():
    """Nodes ``10 floor + line``: 1-4 at the ground (fixed), 11-14, 21-24, ..., 51-54 at
    the floors, line 1 on the left. Elements 1xx columns, 2xx beams."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for floor in range(N_FLOORS + 1):
        for line in range(1, N_LINES + 1):
            ops.node(_node(floor, line), (line - 1) * BAY, _elevation(floor))
    for line in range(1, N_LINES + 1):
        ops.fix(_node(0, line), 1, 1, 1)
    # concrete: fpc, epsc0, fpcu, epsU (compression negative); no tension
    ops.uniaxialMaterial("Concrete01", COVER_CONCRETE, -FC, -0.002, -0.2 * FC, -0.006)
    ops.uniaxialMaterial("Concrete01", CORE_CONCRETE, -FCC, -0.0024, -0.85 * FCC, -0.02)
    ops.uniaxialMaterial("Steel02", STEEL, FY, ES, 0.008, 18.0, 0.925, 0.15)
    _fibre_section(LOWER_COLUMN_SECTION, *LOWER_COLUMN)
    _fibre_section(UPPER_COLUMN_SECTION, *UPPER_COLUMN)
    _fibre_section(BEAM_SECTION, *BEAM)
    ops.geomTransf("PDelta", 1)  # columns
    ops.geomTransf("Linear", 2)  # beams
    for section in (LOWER_COLUMN_SECTION, UPPER_COLUMN_SECTION, BEAM_SECTION):
        ops.beamIntegration("Lobatto", section, section, 5)
    joint_mass = FLOOR_WEIGHT / G / (N_LINES - 1)  # t, inner joint; outer joints half
    for floor in range(1, N_FLOORS + 1):
        column = LOWER_COLUMN_SECTION if floor <= LOWER_FLOORS else UPPER_COLUMN_SECTION
        for line in range(1, N_LINES + 1):
            bottom, top = _node(floor - 1, line), _node(floor, line)
            ops.element("forceBeamColumn", 100 + top, bottom, top, 1, column)
            share = 0.5 if line in (1, N_LINES) else 1.0
            ops.mass(top, share * joint_mass, 0.0, 0.0)
        for line in range(1, N_LINES):
            left, right = _node(floor, line), _node(floor, line + 1)
            ops.element("forceBeamColumn", 200 + left, left, right, 2, BEAM_SECTION)
        for line in range(2, N_LINES + 1):
            ops.equalDOF(_node(floor, 1), _node(floor, line), 1)


def gravity():
    """The floors' weight on their joints (kN), as a load pattern; cphysfno analyses it
    statically and holds it constant during every record."""
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    joint_weight = FLOOR_WEIGHT / (N_LINES - 1)
    for floor in range(1, N_FLOORS + 1):
        for line in range(1, N_LINES + 1):
            share = 0.5 if line in (1, N_LINES) else 1.0
            ops.load(_node(floor, line), 0.0, -share * joint_weight, 0.0)
