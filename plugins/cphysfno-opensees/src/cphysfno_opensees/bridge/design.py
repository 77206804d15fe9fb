"""The calibrated quantities of the Auburn Ravine type bridge, in SI units.

Every number here is either given by the paper (Table 2 and §5.2) or chosen by this project
and stated in the plugin's README (section "auburn-ravine-bridge"); the README says which
is which and why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

GRAVITY = 9.81
"""Acceleration of gravity, m/s^2."""


@dataclass(frozen=True)
class ConfinedConcrete:
    """Mander, Priestley and Park (1988) confined concrete of a circular spiral column.

    Attributes:
        strength: confined peak stress f'cc, Pa.
        peak_strain: strain at f'cc.
        ultimate_strain: crushing strain of the core (energy balance, Priestley et al.).
    """

    strength: float
    peak_strain: float
    ultimate_strain: float


@dataclass(frozen=True)
class BridgeDesign:
    """Geometry, materials, masses and damping of the bridge (SI units).

    The deck runs along global X, the two columns of a bent stand at ``y = +-spacing/2``
    and the excitation is transverse (global Y).
    """

    spans: tuple[float, ...] = (22.4, 30.4, 30.4, 30.4, 30.4, 22.4)
    """Span lengths from abutment to abutment, m (total 166.4 m)."""
    pier_heights: tuple[float, ...] = (6.3, 8.1, 9.3, 9.1, 7.4)
    """Clear column height of each bent from west to east, m."""
    column_spacing: float = 6.0
    """Transverse distance between the two columns of a bent, m."""
    deck_elements_per_span: int = 4
    """Elastic girder elements per span."""

    deck_area: float = 6.43
    """Girder cross-section area, m^2 (paper)."""
    deck_modulus: float = 28.3e9
    """Girder Young's modulus, Pa (paper)."""
    deck_poisson: float = 0.2
    """Girder Poisson ratio (G = E / (2 (1 + nu)))."""
    deck_vertical_inertia: float = 3.3
    """Girder second moment of area for vertical bending, m^4."""
    deck_lateral_inertia: float = 43.0
    """Girder second moment of area for lateral (transverse) bending, m^4."""
    deck_torsion_constant: float = 6.4
    """Girder Saint-Venant torsion constant, m^4 (closed box, Bredt)."""
    deck_mass_per_length: float = 19.1e3
    """Girder self weight (6.43 m^2 x 2500 kg/m^3) plus 3.0 t/m superimposed dead load, kg/m."""
    diaphragm_mass: float = 60.0e3
    """Bent cap / diaphragm mass lumped at the girder node of each bent, kg."""

    cap_area: float = 3.6
    """Bent cap (2.0 m x 1.8 m) area, m^2."""
    cap_inertia: float = 1.0
    """Bent cap second moment of area about both axes, m^4."""
    cap_torsion_constant: float = 1.5
    """Bent cap torsion constant, m^4."""

    column_diameter: float = 1.38
    """Column diameter, m (paper)."""
    cover: float = 0.05
    """Concrete cover to the spiral, m (paper)."""
    concrete_modulus: float = 27.6e9
    """Concrete Young's modulus E_c, Pa (paper)."""
    concrete_strength: float = 34.5e6
    """Unconfined concrete strength f'c, Pa (paper)."""
    concrete_peak_strain: float = 0.002
    """Strain at f'c (paper)."""
    cover_spalling_strain: float = 0.005
    """Strain at which unconfined cover concrete has no strength left."""
    concrete_density: float = 2500.0
    """Reinforced concrete density, kg/m^3."""
    steel_modulus: float = 200.0e9
    """Reinforcing steel Young's modulus, Pa (paper)."""
    steel_yield: float = 475.0e6
    """Reinforcing steel yield strength f_y, Pa (paper)."""
    steel_ultimate: float = 655.0e6
    """Reinforcing steel tensile strength f_u, Pa (paper)."""
    steel_hardening_strain: float = 0.0115
    """Strain at the onset of strain hardening (paper)."""
    steel_ultimate_strain: float = 0.09
    """Strain at f_u (Caltrans SDC, A706 bars)."""
    longitudinal_bars: int = 22
    """Longitudinal bars per column."""
    bar_area: float = 1006e-6
    """Area of one longitudinal bar (#11), m^2."""
    spiral_area: float = 284e-6
    """Area of the spiral bar (#6), m^2."""
    spiral_pitch: float = 0.1
    """Spiral pitch, m."""
    shear_area_factor: float = 0.9
    """Shear area of a column over its gross area."""
    column_torsion_factor: float = 0.2
    """Cracked over gross torsional stiffness of a column (Caltrans SDC)."""

    abutment_longitudinal: float = 1.0e9
    """Longitudinal abutment spring at each girder end, N/m."""
    abutment_transverse: float = 1.0e9
    """Transverse abutment spring at each girder end, N/m."""

    damping_ratio: float = 0.05
    """Rayleigh damping ratio at the first elastic period and at ``damping_period``."""
    damping_period: float = 0.1
    """Second period at which Rayleigh damping equals ``damping_ratio``, s."""

    @property
    def length(self) -> float:
        """Total girder length, m."""
        return float(sum(self.spans))

    @property
    def gross_area(self) -> float:
        """Column gross area, m^2."""
        return math.pi * self.column_diameter**2 / 4.0

    @property
    def longitudinal_ratio(self) -> float:
        """Longitudinal reinforcement over gross area."""
        return self.longitudinal_bars * self.bar_area / self.gross_area

    @property
    def core_diameter(self) -> float:
        """Diameter of the confined core, to the spiral's centreline, m."""
        return self.column_diameter - 2.0 * self.cover

    @property
    def spiral_ratio(self) -> float:
        """Volumetric ratio of the spiral, ``4 A_sp / (d_s s)``."""
        return 4.0 * self.spiral_area / (self.core_diameter * self.spiral_pitch)

    @property
    def bar_radius(self) -> float:
        """Radius of the circle through the longitudinal bars' centres, m (inside the
        spiral by its own and half a bar's diameter)."""
        spiral_diameter = math.sqrt(4.0 * self.spiral_area / math.pi)
        bar_diameter = math.sqrt(4.0 * self.bar_area / math.pi)
        return self.core_diameter / 2.0 - spiral_diameter / 2.0 - bar_diameter / 2.0

    def confined_concrete(self) -> ConfinedConcrete:
        """Mander's model for the core: lateral pressure ``f_l = k_e rho_s f_yh / 2``
        with ``k_e = (1 - s' / (2 d_s)) / (1 - rho_cc)`` for spirals,
        ``f'cc = f'c (2.254 sqrt(1 + 7.94 f_l / f'c) - 2 f_l / f'c - 1.254)``,
        ``eps_cc = eps_c0 (1 + 5 (f'cc / f'c - 1))`` and
        ``eps_cu = 0.004 + 1.4 rho_s f_yh eps_su / f'cc``."""
        spiral_diameter = math.sqrt(4.0 * self.spiral_area / math.pi)
        clear_pitch = self.spiral_pitch - spiral_diameter
        core_area = math.pi * self.core_diameter**2 / 4.0
        core_steel = self.longitudinal_bars * self.bar_area / core_area
        effectiveness = (1.0 - clear_pitch / (2.0 * self.core_diameter)) / (1.0 - core_steel)
        pressure = 0.5 * effectiveness * self.spiral_ratio * self.steel_yield
        ratio = pressure / self.concrete_strength
        strength = self.concrete_strength * (
            2.254 * math.sqrt(1.0 + 7.94 * ratio) - 2.0 * ratio - 1.254
        )
        peak = self.concrete_peak_strain * (1.0 + 5.0 * (strength / self.concrete_strength - 1.0))
        ultimate = 0.004 + (
            1.4 * self.spiral_ratio * self.steel_yield * self.steel_ultimate_strain / strength
        )
        return ConfinedConcrete(strength, peak, ultimate)

    @property
    def concrete_tensile_strength(self) -> float:
        """Tensile strength of the column concrete, ``0.33 sqrt(f'c [MPa])`` MPa, in Pa."""
        return 0.33 * math.sqrt(self.concrete_strength / 1e6) * 1e6
