"""A two-story, one-bay steel moment frame in OpenSeesPy (SI units: m, N, kg, s).

The columns are force-based elements whose bending follows a bilinear moment-curvature
law (they yield), the beams are elastic, the two joints of a floor share their horizontal
displacement, and each floor's mass is lumped at its joints. ``gravity()`` puts the
floors' weight on the joints; the columns' P-Delta transformation feels it.

Used by examples/opensees-model.toml (``name = "opensees-model"``): cphysfno calls
``build()`` and ``gravity()`` and adds damping, the ground motion and the analysis.
"""

import openseespy.opensees as ops

STORY_HEIGHT = 3.0  # m
BAY = 5.0  # m
E = 2.0e11  # Pa
AREA = 0.01  # m^2
COLUMN_I = 1.0e-4  # m^4
BEAM_I = 2.0e-4  # m^4
YIELD_MOMENT = 6.0e4  # N m, the columns' plastic moment
HARDENING = 0.02  # post-yield over elastic bending stiffness
JOINT_MASS = 1.0e4  # kg at each joint
JOINT_WEIGHT = 2.0e5  # N at each joint


def build():
    """Nodes 1, 2 at the ground; 11, 12 at the first floor; 21, 22 at the roof."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for floor in range(3):
        ops.node(10 * floor + 1, 0.0, floor * STORY_HEIGHT)
        ops.node(10 * floor + 2, BAY, floor * STORY_HEIGHT)
    ops.fix(1, 1, 1, 1)
    ops.fix(2, 1, 1, 1)
    ops.geomTransf("PDelta", 1)  # columns
    ops.geomTransf("Linear", 2)  # beams
    ops.uniaxialMaterial("Elastic", 1, E * AREA)
    ops.uniaxialMaterial("Steel01", 2, YIELD_MOMENT, E * COLUMN_I, HARDENING)
    ops.section("Aggregator", 1, 1, "P", 2, "Mz")
    ops.beamIntegration("Lobatto", 1, 1, 3)
    for floor in (1, 2):
        for line in (1, 2):
            bottom, top = 10 * (floor - 1) + line, 10 * floor + line
            ops.element("forceBeamColumn", 100 + top, bottom, top, 1, 1)
        left, right = 10 * floor + 1, 10 * floor + 2
        ops.element("elasticBeamColumn", 200 + floor, left, right, AREA, E, BEAM_I, 2)
        ops.mass(left, JOINT_MASS, 0.0, 0.0)
        ops.mass(right, JOINT_MASS, 0.0, 0.0)
        ops.equalDOF(left, right, 1)


def gravity():
    """The joints' weight, applied as a load pattern; cphysfno analyses it statically and
    holds it constant during every record."""
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    for floor in (1, 2):
        for line in (1, 2):
            ops.load(10 * floor + line, 0.0, -JOINT_WEIGHT, 0.0)
