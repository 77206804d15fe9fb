"""The columns' section as data: its fibres, their materials, and its elastic shear and
torsion. The OpenSees model (:mod:`.model`) and the compiled engine (:mod:`.compiled`)
both build their columns from these."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..fibre.concrete04 import Concrete04Parameters
from ..fibre.steel02 import Steel02Parameters
from .design import BridgeDesign
from .numerics import Numerics


def shear_and_torsion_stiffness(design: BridgeDesign) -> tuple[float, float]:
    """The elastic shear stiffness GA (N, each of Vy and Vz) and torsional stiffness GJ
    (N m^2) of a column."""
    shear_modulus = design.concrete_modulus / 2.4
    polar = np.pi * design.column_diameter**4 / 32.0
    return (
        shear_modulus * design.shear_area_factor * design.gross_area,
        design.column_torsion_factor * shear_modulus * polar,
    )


def section_fibres(
    design: BridgeDesign, numerics: Numerics
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(core, cover, bars)``: ``[n, 3]`` fibres ``(y, z, area)`` (m, m, m^2) of the column
    section, each group of one material."""
    core_radius = design.core_diameter / 2.0
    outer = design.column_diameter / 2.0
    core = polar_gauss(0.0, core_radius, numerics.core_rings, numerics.sectors)
    cover = polar_gauss(core_radius, outer, numerics.cover_rings, numerics.sectors)
    angles = 2.0 * np.pi * np.arange(design.longitudinal_bars) / design.longitudinal_bars
    bars = np.stack(
        [
            design.bar_radius * np.cos(angles),
            design.bar_radius * np.sin(angles),
            np.full(angles.size, design.bar_area),
        ],
        axis=1,
    )
    return np.array(core), np.array(cover), bars


def polar_gauss(
    inner: float, outer: float, rings: int, sectors: int
) -> list[tuple[float, float, float]]:
    """Fibres ``(y, z, area)`` (m, m, m^2) of the annulus ``inner <= r <= outer``.

    Gauss-Legendre points in the radius (weight ``r dr``) times ``sectors`` equal angles
    (the midpoint rule, exact for trigonometric polynomials of degree below ``sectors``):
    the areas sum to the annulus's, and the second moments are exact from 2 rings and 3
    sectors up, so the elastic stiffness does not depend on the mesh. Angles sit at the
    middle of the sectors, symmetric about both axes when ``sectors`` is even.
    """
    nodes, weights = np.polynomial.legendre.leggauss(rings)
    half = 0.5 * (outer - inner)
    radii = inner + half * (nodes + 1.0)
    widths = 2.0 * np.pi / sectors
    fibres = []
    for radius, weight in zip(radii, weights * half, strict=True):
        for j in range(sectors):
            angle = (j + 0.5) * widths
            area = weight * radius * widths
            fibres.append((float(radius * np.cos(angle)), float(radius * np.sin(angle)), area))
    return fibres


@dataclass(frozen=True)
class ColumnMaterials:
    """The uniaxial materials of the column section's three fibre groups.

    Attributes:
        core: Mander's confined concrete of the core.
        cover: the unconfined cover concrete, spalled at ``cover_spalling_strain``.
        bars: the longitudinal bars, their hardening slope the secant from first yield to
            ``(steel_ultimate_strain, steel_ultimate)``.
    """

    core: Concrete04Parameters
    cover: Concrete04Parameters
    bars: Steel02Parameters


def column_materials(design: BridgeDesign) -> ColumnMaterials:
    """The core and cover ``Concrete04`` (tension up to ``concrete_tensile_strength``, zero
    right after cracking) and the bars' ``Steel02`` of the design (see the README)."""
    core = design.confined_concrete()
    tension = design.concrete_tensile_strength
    cracking = tension / design.concrete_modulus
    hardening = (design.steel_ultimate - design.steel_yield) / (
        design.steel_modulus
        * (design.steel_ultimate_strain - design.steel_yield / design.steel_modulus)
    )
    confined = Concrete04Parameters(
        fc=-core.strength,
        epsc=-core.peak_strain,
        epscu=-core.ultimate_strain,
        ec=design.concrete_modulus,
        ft=tension,
        et=cracking,
    )
    return ColumnMaterials(
        core=confined,
        cover=dataclasses.replace(  # the same concrete, unconfined
            confined,
            fc=-design.concrete_strength,
            epsc=-design.concrete_peak_strain,
            epscu=-design.cover_spalling_strain,
        ),
        bars=Steel02Parameters(
            fy=design.steel_yield,
            e0=design.steel_modulus,
            b=hardening,
            r0=20.0,
            cr1=0.925,
            cr2=0.15,
        ),
    )
