"""A three-story, two-bay reinforced-concrete moment frame in OpenSeesPy (kN, m, tonne, s;
stresses in kPa).

Every member is a force-based beam-column element (five Gauss-Lobatto points) on a fibre
section: a confined core and an unconfined cover of ``Concrete02`` (fc' = 30 MPa, the core
confined to 39 MPa) around ``Steel02`` bars (fy = 420 MPa, E = 200 GPa, 1 % hardening).
Columns are 0.5 x 0.5 m with 8 bars of 25 mm (1.6 %), P-Delta transformation; beams are
0.4 x 0.6 m with 3 bars of 20 mm top and bottom, linear transformation. Bays of 6 m,
stories of 3.5 m. Each floor weighs 648 kN (a 6 m x 12 m tributary slab at 9 kPa), its
mass lumped at its three joints (a quarter at each outer joint, half at the inner one),
horizontally; the joints of a floor share their horizontal displacement (a rigid floor
diaphragm). ``gravity()`` puts the floors' weight on the joints; the columns' P-Delta
transformation feels it.

At the gravity state the first period is 0.45 s (uncracked sections). Pushed in its
first mode, the frame cracks early, its first story yields at a drift ratio of about
0.5-0.7 % and its base shear levels off at about 0.39 of its weight.

Used by examples/rc-frame.toml (``name = "opensees-model"``): cphysfno calls ``build()``
and ``gravity()`` and adds damping, the ground motion and the analysis.
"""

import openseespy.opensees as ops

G = 9.81  # m/s^2
BAY = 6.0  # m
STORY_HEIGHT = 3.5  # m
N_FLOORS = 3
N_LINES = 3  # column lines
FLOOR_WEIGHT = 648.0  # kN a floor
FC = 30.0e3  # kPa, unconfined concrete strength
FCC = 39.0e3  # kPa, confined core strength
FT = 0.1 * FC  # kPa, concrete tensile strength, lost linearly over a strain of 0.004
FY = 420.0e3  # kPa, bar yield stress
ES = 200.0e6  # kPa, bar modulus
COVER = 0.04  # m, from the face to the bars' centres
COLUMN = (0.5, 0.5, 8, 4.91e-4)  # width, depth (m), bars, bar area (m^2): 25 mm bars
BEAM = (0.4, 0.6, 6, 3.14e-4)  # 20 mm bars, half top, half bottom
COVER_CONCRETE, CORE_CONCRETE, STEEL = 1, 2, 3
COLUMN_SECTION, BEAM_SECTION = 1, 2


def _node(floor: int, line: int) -> int:
    """Node of column line ``line`` (1-3) at floor ``floor`` (0 the ground)."""
    return 10 * floor + line


def _fibre_section(tag: int, width: float, depth: float, bars: int, bar_area: float) -> None:
    """A rectangular section bending about its width: a confined core, cover on all four
    sides, the bars in two layers at the faces (eight bars: three at each face, two at
    mid-depth)."""
    y, z = depth / 2.0, width / 2.0
    yc, zc = y - COVER, z - COVER
    ops.section("Fiber", tag)
    ops.patch("rect", CORE_CONCRETE, 12, 1, -yc, -zc, yc, zc)
    ops.patch("rect", COVER_CONCRETE, 12, 1, -y, zc, y, z)
    ops.patch("rect", COVER_CONCRETE, 12, 1, -y, -z, y, -zc)
    ops.patch("rect", COVER_CONCRETE, 1, 1, -y, -zc, -yc, zc)
    ops.patch("rect", COVER_CONCRETE, 1, 1, yc, -zc, y, zc)
    face = 3 if bars == 8 else bars // 2
    ops.layer("straight", STEEL, face, bar_area, yc, zc, yc, -zc)
    ops.layer("straight", STEEL, face, bar_area, -yc, zc, -yc, -zc)
    if bars == 8:
        ops.layer("straight", STEEL, 2, bar_area, 0.0, zc, 0.0, -zc)


def build():
    """Nodes ``10 floor + line``: 1-3 at the ground (fixed), 11-13, 21-23, 31-33 at the
    floors, line 1 on the left. Elements 1xx columns, 2xx beams."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for floor in range(N_FLOORS + 1):
        for line in range(1, N_LINES + 1):
            ops.node(_node(floor, line), (line - 1) * BAY, floor * STORY_HEIGHT)
    for line in range(1, N_LINES + 1):
        ops.fix(_node(0, line), 1, 1, 1)
    # concrete: fpc, epsc0, fpcu, epsU (compression negative), lambda, ft, Ets
    ops.uniaxialMaterial("Concrete02", COVER_CONCRETE, -FC, -0.002, -0.2 * FC, -0.005,
                         0.1, FT, FT / 0.004)  # fmt: skip
    ops.uniaxialMaterial("Concrete02", CORE_CONCRETE, -FCC, -0.0026, -0.85 * FCC, -0.02,
                         0.1, FT, FT / 0.004)  # fmt: skip
    ops.uniaxialMaterial("Steel02", STEEL, FY, ES, 0.01, 18.0, 0.925, 0.15)
    _fibre_section(COLUMN_SECTION, *COLUMN)
    _fibre_section(BEAM_SECTION, *BEAM)
    ops.geomTransf("PDelta", 1)  # columns
    ops.geomTransf("Linear", 2)  # beams
    ops.beamIntegration("Lobatto", COLUMN_SECTION, COLUMN_SECTION, 5)
    ops.beamIntegration("Lobatto", BEAM_SECTION, BEAM_SECTION, 5)
    joint_mass = FLOOR_WEIGHT / G / (N_LINES - 1)  # t, inner joint; outer joints half
    for floor in range(1, N_FLOORS + 1):
        for line in range(1, N_LINES + 1):
            bottom, top = _node(floor - 1, line), _node(floor, line)
            ops.element("forceBeamColumn", 100 + top, bottom, top, 1, COLUMN_SECTION)
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
