"""A five-story building on smooth-hysteresis (Bouc-Wen) lead-rubber bearings in OpenSeesPy
(kN, m, tonne, s).

Three bays of 8 m, stories of 3.4 m. The superstructure is elastic and flexible: concrete
columns of 0.8 x 0.8 m and beams of 0.5 x 0.9 m (E = 30 GPa; cracked sections, 0.7 of the
columns' gross moment of inertia and 0.35 of the beams'), P-Delta on the columns, a
fixed-base first period of 0.74 s under gravity (0.73 s without it). It stands on a base
level of beams of 0.6 x 1.0 m (gross sections), and under each of its four column lines
one lead-rubber bearing: an
``elastomericBearingBoucWen`` element of no length from a fixed ground node to the base
node at the same place (local x vertical, local y along -X, as for a vertical element),
horizontally a Bouc-Wen hysteresis (smooth: eta = 1, beta = gamma = 0.5), vertically an
elastic spring of 2.0e6 kN/m, in rotation an elastic one; the base nodes' rotation is
fixed (a stiff pedestal). The bearings together have a characteristic strength of 5 % of
the weight above them (490 kN), their initial stiffness twelve times their post-yield one,
which gives the isolated mass an isolation period of 3.00 s on the post-yield stiffness
(3.06 s with the superstructure's flexibility) and a yield displacement (characteristic
strength over initial minus post-yield stiffness) of 10 mm. The first period at the
initial stiffness is 1.09 s. The base and each floor weigh 1632 kN (an 8 m x 24 m
tributary slab at 8.5 kPa), mass lumped at the four joints (a sixth at each outer joint, a
third at each inner one), horizontally; the joints of each level share their horizontal
displacement.

Damping: the bearings are given no Rayleigh damping (``elastomericBearingBoucWen`` takes
none unless given ``-doRayleigh``): theirs is their hysteresis. The Rayleigh damping that
cphysfno adds (the config's ``damping_ratio`` in its ``rayleigh_modes``) therefore acts
through the masses and the superstructure's initial stiffness only.

The bearing has no height: a config gives the isolator story a nominal height with
``story_heights`` (examples/isolated-building-bouc-wen.toml: 0.3 m), so that its "drift
ratio" is its displacement over 0.3 m. Its ``basicForce`` (shear, component 2) is along
local y, -X: minus the force on the base in X.

A second isolated building beside examples/models/isolated_building.py (three stories on
bilinear ``Steel01`` isolators), to check on an isolated building it was not developed on
what was developed on that one. Used by examples/isolated-building-bouc-wen.toml
(``name = "opensees-model"``): cphysfno calls ``build()`` and ``gravity()`` and adds
damping, the ground motion and the analysis.
"""

import math

import openseespy.opensees as ops

G = 9.81  # m/s^2
BAY = 8.0  # m
STORY_HEIGHT = 3.4  # m
N_LEVELS = 6  # the base and five floors
N_LINES = 4  # column lines
LEVEL_WEIGHT = 8.5 * 8.0 * (N_LINES - 1) * BAY  # kN a level: 8.5 kPa on 8 m x 24 m, 1632
E = 30.0e6  # kPa
COLUMN = (0.8, 0.8)  # width, depth, m
BEAM = (0.5, 0.9)
BASE_BEAM = (0.6, 1.0)
COLUMN_CRACKED = 0.7  # effective over gross moment of inertia
BEAM_CRACKED = 0.35
ISOLATION_PERIOD = 3.0  # s, of the whole mass on the bearings' post-yield stiffness
STRENGTH_SHARE = 0.05  # bearings' characteristic strength over the weight above them
STIFFNESS_RATIO = 12.0  # initial over post-yield stiffness
ETA, BETA, GAMMA = 1.0, 0.5, 0.5  # Bouc-Wen: sharpness of the loop, shape
VERTICAL_STIFFNESS = 2.0e6  # kN/m, a bearing
ROTATIONAL_STIFFNESS = 1.0e6  # kN m/rad, a bearing (its rotation is fixed)
VERTICAL, ROTATIONAL = 1, 2


def _node(level: int, line: int) -> int:
    """Node of column line ``line`` (1-4) at ``level``: 0 the ground, 1 the base, 2-6 the
    floors."""
    return 10 * level + line


def _elastic(
    tag: int, i: int, j: int, section: tuple[float, float], cracked: float, transformation: int
):
    width, depth = section
    area, inertia = width * depth, cracked * width * depth**3 / 12.0
    ops.element("elasticBeamColumn", tag, i, j, area, E, inertia, transformation)


def build():
    """Nodes ``10 level + line``: 1-4 at the ground (fixed), 11-14 at the base (on the
    bearings, elements 1-4), 21-24, ..., 61-64 at the floors, line 1 on the left.
    Elements 1xx columns, 2xx beams."""
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for line in range(1, N_LINES + 1):
        ops.node(_node(0, line), (line - 1) * BAY, 0.0)
        ops.fix(_node(0, line), 1, 1, 1)
        for level in range(1, N_LEVELS + 1):
            ops.node(_node(level, line), (line - 1) * BAY, (level - 1) * STORY_HEIGHT)
        ops.fix(_node(1, line), 0, 0, 1)
    mass = N_LEVELS * LEVEL_WEIGHT / G  # t on the bearings
    post_yield = mass * (2.0 * math.pi / ISOLATION_PERIOD) ** 2 / N_LINES  # kN/m a bearing
    strength = STRENGTH_SHARE * N_LEVELS * LEVEL_WEIGHT / N_LINES  # kN a bearing
    ops.uniaxialMaterial("Elastic", VERTICAL, VERTICAL_STIFFNESS)
    ops.uniaxialMaterial("Elastic", ROTATIONAL, ROTATIONAL_STIFFNESS)
    for line in range(1, N_LINES + 1):
        ops.element("elastomericBearingBoucWen", line, _node(0, line), _node(1, line),
                    STIFFNESS_RATIO * post_yield, strength, 1.0 / STIFFNESS_RATIO, 0.0, 2.0,
                    ETA, BETA, GAMMA, "-P", VERTICAL, "-Mz", ROTATIONAL,
                    "-orient", 0.0, 1.0, 0.0, -1.0, 0.0, 0.0)  # fmt: skip
    ops.geomTransf("PDelta", 1)  # columns
    ops.geomTransf("Linear", 2)  # beams
    joint_mass = LEVEL_WEIGHT / G / (N_LINES - 1)  # t, inner joint; outer joints half
    for level in range(1, N_LEVELS + 1):
        for line in range(1, N_LINES + 1):
            node = _node(level, line)
            if level > 1:
                _elastic(100 + node, _node(level - 1, line), node, COLUMN, COLUMN_CRACKED, 1)
            share = 0.5 if line in (1, N_LINES) else 1.0
            ops.mass(node, share * joint_mass, 0.0, 0.0)
        section, cracked = (BASE_BEAM, 1.0) if level == 1 else (BEAM, BEAM_CRACKED)
        for line in range(1, N_LINES):
            left = _node(level, line)
            _elastic(200 + left, left, left + 1, section, cracked, 2)
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
