"""A two-story, one-bay steel moment frame with a leaning column, in OpenSeesPy, in US
units (kip, inch, second; masses in kip s^2/in).

The frame carries its own floors' weight; the gravity frames beside it, represented by a
leaning column (pinned trusses whose P-Delta transformation is corotational), carry the
rest of the building's. The leaning column is tied to the frame at each floor through the
right-hand joint, which is tied to the left-hand one itself: a chain of equalDOF
constraints, as such models are often written. OpenSees' Transformation handler does not
follow chains (it ties the wrong DOFs); cphysfno's ``constraints = "auto"`` finds that out
and analyses the model with the Penalty handler.

Used by examples/opensees-model-us.toml (``length_unit = "in"``): records are converted
into in/s^2 before they are applied, and the displacements come back in m.
"""

import openseespy.opensees as ops

G = 386.09  # in/s^2
STORY_HEIGHT = 144.0  # in (12 ft)
BAY = 240.0  # in (20 ft)
E = 29000.0  # ksi
COLUMN_AREA, COLUMN_I = 14.4, 272.0  # in^2, in^4 (W10x49)
BEAM_AREA, BEAM_I = 14.7, 800.0  # in^2, in^4 (W18x50)
PLASTIC_MOMENT = 2000.0  # kip in, the columns' bending at yield
HARDENING = 0.02
FRAME_WEIGHT = 50.0  # kip at each joint of the frame
LEANING_WEIGHT = 150.0  # kip per floor on the leaning column


def build():
    """Nodes 1, 2 at the ground, 11, 12 at the first floor, 21, 22 at the roof; the
    leaning column on nodes 3, 13 and 23."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for floor in range(3):
        for line, x in ((1, 0.0), (2, BAY), (3, 2.0 * BAY)):
            ops.node(10 * floor + line, x, floor * STORY_HEIGHT)
    ops.fix(1, 1, 1, 1)
    ops.fix(2, 1, 1, 1)
    ops.fix(3, 1, 1, 1)
    ops.geomTransf("PDelta", 1)
    ops.geomTransf("Linear", 2)
    ops.uniaxialMaterial("Elastic", 1, E * COLUMN_AREA)
    ops.uniaxialMaterial("Steel01", 2, PLASTIC_MOMENT, E * COLUMN_I, HARDENING)
    ops.section("Aggregator", 1, 1, "P", 2, "Mz")
    ops.beamIntegration("Lobatto", 1, 1, 3)
    ops.uniaxialMaterial("Elastic", 3, 100.0 * E)  # the leaning column: axially rigid
    for floor in (1, 2):
        left, right, leaning = 10 * floor + 1, 10 * floor + 2, 10 * floor + 3
        for line in (1, 2):
            ops.element(
                "forceBeamColumn",
                100 + 10 * floor + line,
                left - 10 + line - 1,
                left + line - 1,
                1,
                1,
            )
        ops.element("elasticBeamColumn", 200 + floor, left, right, BEAM_AREA, E, BEAM_I, 2)
        ops.element("corotTruss", 300 + floor, leaning - 10, leaning, 100.0, 3)
        ops.fix(leaning, 0, 0, 1)  # a truss node's rotation has no stiffness: fix it
        mass = FRAME_WEIGHT / G
        ops.mass(left, mass, 0.0, 0.0)
        ops.mass(right, mass, 0.0, 0.0)
        ops.equalDOF(left, right, 1)
        ops.equalDOF(right, leaning, 1)  # tied to a tied joint: a chain


def gravity():
    """The frame's weight on its joints and the gravity frames' on the leaning column."""
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    for floor in (1, 2):
        ops.load(10 * floor + 1, 0.0, -FRAME_WEIGHT, 0.0)
        ops.load(10 * floor + 2, 0.0, -FRAME_WEIGHT, 0.0)
        ops.load(10 * floor + 3, 0.0, -LEANING_WEIGHT, 0.0)
