"""The two-story steel moment frame with concentrated plasticity of the OpenSees examples
(Laura Eads, Stanford University, 2010), in OpenSeesPy, in kip, inch and second (masses in
kip s^2/in).

Source: the OpenSees wiki examples "Pushover Analysis of 2-Story Moment Frame" and
"Dynamic Analysis of 2-Story Moment Frame" (concentrated-plasticity model),
https://opensees.berkeley.edu/wiki/index.php/Pushover_Analysis_of_2-Story_Moment_Frame
and https://opensees.berkeley.edu/wiki/index.php/Dynamic_Analysis_of_2-Story_Moment_Frame,
with their scripts (the concentrated-plasticity model, "pushover_concentrated.tcl" on the
pushover page, and its procedures rotSpring2DModIKModel and rotLeaningCol); the damping of
the dynamic analyses as in the script of the same frame in "Pushover and Dynamic Analyses
of 2-Story Moment Frame with Panel Zones and RBS" (MRF_2Story_Concentrated_PanelZone.tcl).
This script is written anew from the published facts listed here, not copied; they are
read from the concentrated-plasticity script of the pushover example (2010), whose frame
the dynamic example analyses too (the dynamic page's 2013 revision of its script was not
read here).

Published facts used:

- one bay of 30 ft (360 in); stories of 15 ft (180 in) and 12 ft (144 in); node numbers
  "xy" for pier x and floor y (11, 21, 31 at the ground; 12, 22, 32 at floor 2; 13, 23,
  33 at the roof), pier 3 being the leaning column, a bay further on;
- steel E = 29000 ksi; columns W24x131 in both stories (A = 38.5 in^2, I = 4020 in^4,
  yield moment My = 20350 kip in); beams W27x102 at both floors (A = 30.0 in^2,
  I = 3620 in^4, My = 10938 kip in); the base of the frame fixed, the leaning column
  pinned at its base;
- concentrated plasticity: each member an elastic beam-column element (P-Delta
  transformation) between zero-length rotational springs at both ends, at the joints (no
  offset), the spring's translations tied to the joint; the members' moment of inertia
  raised by (n + 1) / n and the springs' stiffness n times the modified member's 6 E I / L
  (so n + 1 times the member's), n = 10 (Ibarra and Krawinkler 2005), so that the
  spring-member-spring assembly has the member's elastic stiffness;
- the springs: OpenSees' uniaxialMaterial Bilin (modified Ibarra-Medina-Krawinkler
  model), cyclic deterioration off (Lambda = 1000 for basic strength, unloading
  stiffness, accelerated reloading stiffness and post-capping strength; exponents c = 1;
  D = 1), capping over yield moment Mc / My = 1.05, residual strength 0.4 My, ultimate
  rotation 0.4; plastic rotation to capping 0.025 (columns) and 0.02 (beams), post-capping
  rotation 0.3 (columns) and 0.16 (beams); the spring's strain-hardening ratio
  b = a / (1 + n (1 - a)) with the member's a = (n + 1) My (Mc / My - 1) / (Ks theta_p),
  the same for positive and negative bending;
- masses: floor weights 535 kip (floor 2) and 525 kip (roof), g = 386.2 in/s^2, each
  floor's mass lumped in halves on its two frame joints, horizontally;
- the floors' joints tied horizontally (equalDOF from the left joint to the right joint
  and to the leaning column's node); the leaning column: elastic beam-columns (P-Delta
  transformation) of A = 1000 in^2 and I = 100000 in^4 per story, joined at the floors
  by rotational springs of 1e-9 kip in/rad (their translations tied), linked to the
  frame's right-hand joints by truss elements of A = 1000 in^2 (elastic, E);
- gravity loads: 398.02 kip (floor 2) and 391.31 kip (roof) on the leaning column, the
  rest of each floor's weight in halves on its two frame joints, analysed statically in
  ten load steps and held constant;
- damping in the dynamic analyses: 2 % Rayleigh in modes 1 and 2 (mass- and
  stiffness-proportional), Newmark's average acceleration rule, Newton.

Differences from the published script, and assumptions:

- the leaning column's rotational springs are 1 kip in/rad here (``LEANING_SPRING``), not
  1e-9: with 1e-9 beside the leaning column's 1e8 kip in/rad, OpenSees' dense eigen
  solver, which the tests compare the periods against, returns NaN for the first mode
  (cphysfno's own condensation gives the same periods with 1e-9 as with 1 kip in/rad, to
  1e-7); from 1e-9 to 1 kip in/rad the spring adds nothing measurable;
- the published joints also carry masses of 1e-9 in their vertical and rotational DOFs
  (a numerical device for OpenSees' default eigen solver); here only the horizontal DOFs
  carry mass;
- the published gravity pattern has a constant time series; here it is linear, so that
  the ten load steps ramp the loads (the state they reach is the same);
- the published dynamic analyses assign their Rayleigh damping by regions (mass-proportional
  on the joints, stiffness-proportional on the frame members with the factor raised by
  (n + 1) / n, none on the springs); cphysfno applies ``rayleigh`` to the whole model
  (OpenSees itself leaves the zero-length springs and the trusses out of it), with the
  ratio the config gives (2 % in examples/opensees-model-imk.toml);
- OpenSeesPy 3.7 warns that ``Bilin`` has been replaced (by ``IMKBilin``); it is kept here
  because the published model uses it. Once the springs yield, Newton's iterations cycle
  on some steps of 0.01 s (cphysfno's fallbacks complete them); at 0.0025 s they converge.

``build(fy=55.0)`` takes the steel's yield stress in ksi: the springs' yield moments are
the published ones (those of an expected yield stress of 55 ksi: 20350 kip in is the
W24x131's plastic modulus, 370 in^3, times 55 ksi) scaled by ``fy / 55``, so that
``arguments.fy`` of the config can make the frame's strength uncertain
(examples/opensees-model-imk-family.toml).

``TIES`` (module constant) chooses how the spring nodes hang on the joints: ``"equalDOF"``
as published, or ``"rigidLink"``, where every spring's joint-side node is a node of its own
tied to the joint by ``rigidLink beam`` (a rigid joint, as one writes rigid end offsets),
the same frame mechanically.

Used by examples/opensees-model-imk.toml (``length_unit = "in"``, ``gravity = "gravity"``).
"""

import openseespy.opensees as ops

TIES = "equalDOF"  # or "rigidLink"

G = 386.2  # in/s^2
BAY = 360.0  # in
STORIES = (180.0, 144.0)  # in, story 1 and story 2
E = 29000.0  # ksi
COLUMN = {"area": 38.5, "inertia": 4020.0, "yield_moment": 20350.0}  # W24x131
BEAM = {"area": 30.0, "inertia": 3620.0, "yield_moment": 10938.0}  # W27x102
N = 10.0  # spring stiffness over the modified member's
FLOOR_WEIGHTS = (535.0, 525.0)  # kip, floor 2 and roof
LEANING_LOADS = (398.02, 391.31)  # kip, floor 2 and roof
RIGID_AREA, RIGID_INERTIA = 1000.0, 100000.0  # in^2, in^4: trusses and leaning column
LEANING_SPRING = 1.0  # kip in/rad (published: 1e-9; see the docstring)
PUBLISHED_FY = 55.0  # ksi, the expected yield stress behind the published yield moments
CAPPING = 1.05  # Mc / My
DETERIORATION = 1000.0  # Lambda: no cyclic deterioration
RESIDUAL, ULTIMATE = 0.4, 0.4
COLUMN_ROTATIONS = (0.025, 0.3)  # plastic rotation to capping, post-capping rotation
BEAM_ROTATIONS = (0.02, 0.16)


def _spring(tag, joint, node, stiffness, yield_moment, rotations):
    """A Bilin rotational spring (element and material ``tag``) from ``joint`` to the
    member's end ``node`` at the same place, its translations tied to the joint's."""
    theta_p, theta_pc = rotations
    member = (N + 1.0) * yield_moment * (CAPPING - 1.0) / (stiffness * theta_p)
    hardening = member / (1.0 + N * (1.0 - member))
    ops.uniaxialMaterial(
        "Bilin", tag, stiffness, hardening, hardening, yield_moment, -yield_moment,
        *(DETERIORATION,) * 4, *(1.0,) * 4, theta_p, theta_p, theta_pc, theta_pc,
        RESIDUAL, RESIDUAL, ULTIMATE, ULTIMATE, 1.0, 1.0,
    )  # fmt: skip
    if TIES == "rigidLink":
        # the joint's own node for this member end: rigidly part of the joint
        panel = node + 5000
        ops.node(panel, *ops.nodeCoord(joint))
        ops.rigidLink("beam", joint, panel)
        joint = panel
    ops.element("zeroLength", tag, joint, node, "-mat", tag, "-dir", 6)
    ops.equalDOF(joint, node, 1, 2)


def build(fy=PUBLISHED_FY):
    """The frame (piers 1 and 2), its springs, the leaning column (pier 3) and the ties;
    ``fy``: the steel's yield stress, ksi (the springs' yield moments scale with it)."""
    strength = fy / PUBLISHED_FY
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    x = (0.0, BAY, 2.0 * BAY)
    y = (0.0, STORIES[0], STORIES[0] + STORIES[1])
    for pier in (1, 2, 3):
        for floor in (1, 2, 3):
            ops.node(10 * pier + floor, x[pier - 1], y[floor - 1])
    ops.fix(11, 1, 1, 1)
    ops.fix(21, 1, 1, 1)
    ops.fix(31, 1, 1, 0)
    for floor, weight in zip((2, 3), FLOOR_WEIGHTS, strict=True):
        for pier in (1, 2):
            ops.mass(10 * pier + floor, weight / G / 2.0, 0.0, 0.0)
    ops.geomTransf("PDelta", 1)

    # columns: nodes "xy6" below and "xy7" above joint xy
    column_i = COLUMN["inertia"] * (N + 1.0) / N
    for story, height in enumerate(STORIES, start=1):
        stiffness = N * 6.0 * E * column_i / height
        for pier in (1, 2):
            bottom, top = 10 * pier + story, 10 * pier + story + 1
            below, above = 10 * top + 6, 10 * bottom + 7
            ops.node(above, *ops.nodeCoord(bottom))
            ops.node(below, *ops.nodeCoord(top))
            ops.element("elasticBeamColumn", 100 + 10 * pier + story, above, below,
                        COLUMN["area"], E, column_i, 1)  # fmt: skip
            for joint, node, end in ((bottom, above, 1), (top, below, 2)):
                _spring(3000 + 100 * pier + 10 * story + end, joint, node, stiffness,
                        strength * COLUMN["yield_moment"], COLUMN_ROTATIONS)  # fmt: skip

    # beams: nodes "1y2" right of joint 1y and "2y3" left of joint 2y
    beam_i = BEAM["inertia"] * (N + 1.0) / N
    stiffness = N * 6.0 * E * beam_i / BAY
    for floor in (2, 3):
        left, right = 10 + floor, 20 + floor
        start, end = 10 * left + 2, 10 * right + 3
        ops.node(start, *ops.nodeCoord(left))
        ops.node(end, *ops.nodeCoord(right))
        ops.element("elasticBeamColumn", 200 + 10 + floor, start, end, BEAM["area"], E,
                    beam_i, 1)  # fmt: skip
        for joint, node, side in ((left, start, 1), (right, end, 2)):
            _spring(4000 + 100 + 10 * floor + side, joint, node, stiffness,
                    strength * BEAM["yield_moment"], BEAM_ROTATIONS)  # fmt: skip

    # the leaning column: a beam-column per story between nodes 31, 326 and 327, 336,
    # pinned to the floor nodes 32 and 33 by springs of negligible stiffness
    ops.uniaxialMaterial("Elastic", 600, E)
    ops.uniaxialMaterial("Elastic", 500, LEANING_SPRING)
    ops.node(326, *ops.nodeCoord(32))
    ops.node(327, *ops.nodeCoord(32))
    ops.node(336, *ops.nodeCoord(33))
    ops.element("elasticBeamColumn", 731, 31, 326, RIGID_AREA, E, RIGID_INERTIA, 1)
    ops.element("elasticBeamColumn", 732, 327, 336, RIGID_AREA, E, RIGID_INERTIA, 1)
    for tag, floor_node, node in ((5312, 32, 326), (5321, 32, 327), (5322, 33, 336)):
        ops.element("zeroLength", tag, floor_node, node, "-mat", 500, "-dir", 6)
        ops.equalDOF(floor_node, node, 1, 2)
    for floor in (2, 3):
        ops.element("truss", 620 + floor, 20 + floor, 30 + floor, RIGID_AREA, 600)
        ops.equalDOF(10 + floor, 20 + floor, 1)
        ops.equalDOF(10 + floor, 30 + floor, 1)


def gravity():
    """The leaning column's loads and the rest of each floor's weight on its two joints
    (not analysed here: the caller analyses them)."""
    ops.timeSeries("Linear", 101)
    ops.pattern("Plain", 101, 101)
    for floor, weight, leaning in zip((2, 3), FLOOR_WEIGHTS, LEANING_LOADS, strict=True):
        ops.load(30 + floor, 0.0, -leaning, 0.0)
        for pier in (1, 2):
            ops.load(10 * pier + floor, 0.0, -0.5 * (weight - leaning), 0.0)
