"""A three-story building on bilinear (lead-rubber-like) isolators in OpenSeesPy (kN, m,
tonne, s).

Two bays of 6 m, stories of 3.5 m. The superstructure is elastic and stiff: concrete
columns of 0.5 x 0.5 m and beams of 0.4 x 0.7 m (E = 30 GPa, gross sections), P-Delta on
the columns, a fixed-base first period of 0.41 s. It stands on a base level of beams of
0.6 x 1.0 m, and under each of its three column lines one isolator: a ``zeroLength``
element from a fixed ground node to the base node at the same place, horizontally
``Steel01`` (a bilinear hysteresis), vertically an elastic spring of 1.5e6 kN/m; the base
nodes' rotation is fixed (a stiff pedestal). The isolators together yield at 6 % of the
weight above them (138 kN), their initial stiffness ten times their post-yield one, which
gives the isolated mass an isolation period of 2.75 s (2.77 s with the superstructure's
flexibility) and a yield displacement of 11 mm. The first period at the initial stiffness
is 0.93 s. The base and each floor weigh 576 kN (a 6 m x 12 m tributary slab at
8 kPa), mass lumped at the three joints (a quarter at each outer joint, half at the inner
one), horizontally; the joints of each level share their horizontal displacement.

Damping: the isolators are given no Rayleigh damping (``zeroLength`` elements take none
unless given ``-doRayleigh``): theirs is their hysteresis. The Rayleigh damping that
cphysfno adds (the config's ``damping_ratio`` in its ``rayleigh_modes``) therefore acts
through the masses and the superstructure's initial stiffness only.

The isolator has no height: a config gives the isolator story a nominal height with
``story_heights`` (examples/isolated-building.toml: 0.3 m), so that its "drift ratio" is
its displacement over 0.3 m.

Used by examples/isolated-building.toml (``name = "opensees-model"``): cphysfno calls
``build()`` and ``gravity()`` and adds damping, the ground motion and the analysis.
"""

import math

import openseespy.opensees as ops

G = 9.81  # m/s^2
BAY = 6.0  # m
STORY_HEIGHT = 3.5  # m
N_LEVELS = 4  # the base and three floors
N_LINES = 3  # column lines
LEVEL_WEIGHT = 576.0  # kN a level
E = 30.0e6  # kPa
COLUMN = (0.5, 0.5)  # width, depth, m
BEAM = (0.4, 0.7)
BASE_BEAM = (0.6, 1.0)
ISOLATION_PERIOD = 2.75  # s, of the whole mass on the isolators' post-yield stiffness
YIELD_SHARE = 0.06  # isolators' yield force over the weight above them
STIFFNESS_RATIO = 10.0  # initial over post-yield stiffness
VERTICAL_STIFFNESS = 1.5e6  # kN/m, an isolator
ISOLATOR, VERTICAL = 1, 2


def _node(level: int, line: int) -> int:
    """Node of column line ``line`` (1-3) at ``level``: 0 the ground, 1 the base, 2-4 the
    floors."""
    return 10 * level + line


def _elastic(tag: int, i: int, j: int, section: tuple[float, float], transformation: int):
    width, depth = section
    area, inertia = width * depth, width * depth**3 / 12.0
    ops.element("elasticBeamColumn", tag, i, j, area, E, inertia, transformation)


def build():
    """Nodes ``10 level + line``: 1-3 at the ground (fixed), 11-13 at the base (on the
    isolators, elements 1-3), 21-23, 31-33, 41-43 at the floors, line 1 on the left.
    Elements 1xx columns, 2xx beams."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for line in range(1, N_LINES + 1):
        ops.node(_node(0, line), (line - 1) * BAY, 0.0)
        ops.fix(_node(0, line), 1, 1, 1)
        for level in range(1, N_LEVELS + 1):
            ops.node(_node(level, line), (line - 1) * BAY, (level - 1) * STORY_HEIGHT)
        ops.fix(_node(1, line), 0, 0, 1)
    mass = N_LEVELS * LEVEL_WEIGHT / G  # t on the isolators
    post_yield = mass * (2.0 * math.pi / ISOLATION_PERIOD) ** 2 / N_LINES  # kN/m an isolator
    yield_force = YIELD_SHARE * N_LEVELS * LEVEL_WEIGHT / N_LINES  # kN an isolator
    ops.uniaxialMaterial("Steel01", ISOLATOR, yield_force, STIFFNESS_RATIO * post_yield,
                         1.0 / STIFFNESS_RATIO)  # fmt: skip
    ops.uniaxialMaterial("Elastic", VERTICAL, VERTICAL_STIFFNESS)
    for line in range(1, N_LINES + 1):
        ops.element("zeroLength", line, _node(0, line), _node(1, line),
                    "-mat", ISOLATOR, VERTICAL, "-dir", 1, 2)  # fmt: skip
    ops.geomTransf("PDelta", 1)  # columns
    ops.geomTransf("Linear", 2)  # beams
    joint_mass = LEVEL_WEIGHT / G / (N_LINES - 1)  # t, inner joint; outer joints half
    for level in range(1, N_LEVELS + 1):
        for line in range(1, N_LINES + 1):
            node = _node(level, line)
            if level > 1:
                _elastic(100 + node, _node(level - 1, line), node, COLUMN, 1)
            share = 0.5 if line in (1, N_LINES) else 1.0
            ops.mass(node, share * joint_mass, 0.0, 0.0)
        section = BASE_BEAM if level == 1 else BEAM
        for line in range(1, N_LINES):
            left = _node(level, line)
            _elastic(200 + left, left, left + 1, section, 2)
        for line in range(2, N_LINES + 1):
            ops.equalDOF(_node(level, 1), _node(level, line), 1)


def gravity():
    """The levels' weight on their joints (kN), as a load pattern; cphysfno analyses it
    statically and holds it constant during every record."""
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    joint_weight = LEVEL_WEIGHT / (N_LINES - 1)
    for level in range(1, N_LEVELS + 1):
        for line in range(1, N_LINES + 1):
            share = 0.5 if line in (1, N_LINES) else 1.0
            ops.load(_node(level, line), 0.0, -share * joint_weight, 0.0)
