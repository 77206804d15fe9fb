"""Published data of the SAC Los Angeles nine-story frame (Ohtori et al. 2004) and the
properties of its wide-flange sections.

Everything here is plain data and closed-form section properties, SI units (m, N, kg);
nothing touches OpenSees.
"""

from __future__ import annotations

from dataclasses import dataclass

FOOT = 0.3048
"""One foot in m: the published dimensions are whole feet."""

BAY_WIDTH = 30.0 * FOOT
N_BAYS = 5
BASEMENT_HEIGHT = 12.0 * FOOT
FIRST_STORY_HEIGHT = 18.0 * FOOT
TYPICAL_STORY_HEIGHT = 13.0 * FOOT
N_STORIES = 9
"""Stories above ground; story ``s`` (1..9) spans level ``s`` to level ``s + 1`` and the
basement spans the column bases to level 1 (the ground)."""

SPLICE_STORIES = (1, 3, 5, 7)
SPLICE_HEIGHT = 6.0 * FOOT
"""Column splices stand this high above the beam centre-line at the bottom of their story."""

STEEL_MODULUS = 200.0e9
COLUMN_YIELD_STRESS = 345.0e6
BEAM_YIELD_STRESS = 248.0e6
HARDENING_RATIO = 0.01
GRAVITY = 9.80665

FLOOR_MASSES = (1.01e6, 9.89e5, 9.89e5, 9.89e5, 9.89e5, 9.89e5, 9.89e5, 9.89e5, 1.07e6)
"""Seismic mass of the whole building at levels 2 ... roof, kg; one frame carries half."""
FRAMES_SHARING_MASS = 2


@dataclass(frozen=True)
class WideFlange:
    """A wide-flange (W) shape without fillets; dimensions in m.

    Attributes:
        name: AISC designation, e.g. ``"W14x500"``.
        depth: overall depth d.
        flange_width: b_f.
        flange_thickness: t_f.
        web_thickness: t_w.
    """

    name: str
    depth: float
    flange_width: float
    flange_thickness: float
    web_thickness: float

    @property
    def web_height(self) -> float:
        """Clear height of the web between the flanges, m."""
        return self.depth - 2.0 * self.flange_thickness

    @property
    def area(self) -> float:
        """Cross-section area, m^2."""
        return (
            2.0 * self.flange_width * self.flange_thickness + self.web_height * self.web_thickness
        )

    @property
    def inertia(self) -> float:
        """Second moment of area about the strong axis, m^4."""
        outer = self.flange_width * self.depth**3
        inner = (self.flange_width - self.web_thickness) * self.web_height**3
        return (outer - inner) / 12.0

    @property
    def plastic_modulus(self) -> float:
        """Plastic section modulus about the strong axis, m^3."""
        flanges = self.flange_width * self.flange_thickness * (self.depth - self.flange_thickness)
        return flanges + self.web_thickness * self.web_height**2 / 4.0


def _shape(name: str, d: float, bf: float, tf: float, tw: float) -> WideFlange:
    return WideFlange(name, d * 1e-3, bf * 1e-3, tf * 1e-3, tw * 1e-3)


SHAPES = {
    shape.name: shape
    for shape in (
        _shape("W14x500", 497.8, 431.8, 88.9, 55.6),
        _shape("W14x455", 482.6, 426.7, 81.5, 51.3),
        _shape("W14x370", 454.7, 419.1, 67.6, 42.2),
        _shape("W14x283", 424.2, 408.9, 52.6, 32.8),
        _shape("W14x257", 416.6, 406.4, 48.0, 30.0),
        _shape("W14x233", 406.4, 403.9, 43.7, 27.2),
        _shape("W36x160", 914.4, 304.8, 25.9, 16.5),
        _shape("W36x135", 904.2, 304.8, 20.1, 15.2),
        _shape("W30x99", 754.4, 266.7, 17.0, 13.2),
        _shape("W27x84", 678.2, 254.0, 16.3, 11.7),
        _shape("W24x68", 602.0, 227.8, 14.9, 10.5),
    )
}
"""The frame's W shapes (AISC nominal dimensions)."""

EXTERIOR_COLUMNS = ("W14x370",) * 4 + ("W14x283",) * 2 + ("W14x257",) * 2 + ("W14x233",) * 2
"""Exterior column shape of the basement and stories 1 ... 9."""
INTERIOR_COLUMNS = (
    ("W14x500",) * 2 + ("W14x455",) * 2 + ("W14x370",) * 2 + ("W14x283",) * 2 + ("W14x257",) * 2
)
"""Interior column shape of the basement and stories 1 ... 9."""
BEAMS = ("W36x160",) * 3 + ("W36x135",) * 4 + ("W30x99", "W27x84", "W24x68")
"""Beam shape of levels 1 (ground) ... 10 (roof)."""


def level_heights() -> tuple[float, ...]:
    """Elevations of the column bases and levels 1 (ground) ... 10 (roof), m, ground at 0."""
    heights = [-BASEMENT_HEIGHT, 0.0, FIRST_STORY_HEIGHT]
    for _ in range(N_STORIES - 1):
        heights.append(heights[-1] + TYPICAL_STORY_HEIGHT)
    return tuple(heights)


def column_shape(story: int, exterior: bool, upper_part: bool) -> str:
    """Shape of a column in ``story`` (0 basement, 1 ... 9).

    The published list gives one shape per story; the section changes at the splice, so
    the part of a spliced story above its splice already has the shape of the story above.
    """
    shapes = EXTERIOR_COLUMNS if exterior else INTERIOR_COLUMNS
    if upper_part and story in SPLICE_STORIES:
        return shapes[story + 1]
    return shapes[story]
