"""OpenSees' uniaxial material ``Concrete04`` in numba, state held in flat float64 arrays.

The compression envelope is Popovics' curve up to the crushing strain ``epscu`` and zero
beyond it; unloading from the envelope follows Karsan and Jirsa's rule for the plastic
strain; in tension the stress rises linearly with the initial modulus to ``ft`` at
``ft / Ec``, then decays exponentially, reaching ``beta * ft`` at ``et``, and is zero beyond
``et``; tension unloads and reloads along the secant to the origin from the largest tensile
strain reached.

Every rule, tolerance and tangent follows ``Concrete04::setTrialStrain`` of OpenSees, in the
same floating-point order, so stress and tangent are those of OpenSees for any strain
history. A fibre's committed state is one row of ``N_STATE`` numbers; ``trial`` reads it,
never writes it, and writes the trial state into a second row, which the caller copies onto
the committed one to commit the step (or leaves alone to revert it). Signs are those of
OpenSees: compression negative. A material's parameters are a :class:`Concrete04Parameters`,
which packs them, with the constants the law derives from them, into the flat vector ``p``
that ``trial`` reads (:meth:`Concrete04Parameters.packed`, the one place that knows its
slots besides ``trial``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numba
import numpy as np

from .material import UniaxialMaterial

# Parameter slots of the array returned by ``Concrete04Parameters.packed``.
FC = 0  # peak compressive stress f'c, Pa (negative)
EPSC = 1  # strain at f'c (negative)
EPSCU = 2  # crushing strain, beyond which the compressive stress is zero (negative)
EC = 3  # initial modulus, Pa
FT = 4  # tensile strength, Pa (zero: no tension)
ET = 5  # tensile strain at which the stress has decayed to beta * ft
BETA = 6  # ratio of the stress at ET to ft
R = 7  # Popovics exponent, Ec / (Ec - f'c / epsc), or 400 when the secant is the steeper
R_MINUS_ONE = 8  # R - 1
POPOVICS_SLOPE = 9  # f'c * R * (R - 1), Pa: numerator factor of the envelope tangent
CRACKING_STRAIN = 10  # ft / Ec, the end of the linear tensile branch
LOG_BETA = 11  # ln(beta)
SOFTENING_SPAN = 12  # ET - ft / Ec, strain length of the exponential decay
N_PARAMETERS = 13

# State slots of one fibre (OpenSees' committed variables of the same meaning).
STRAIN = 0  # strain (Cstrain)
STRESS = 1  # stress, Pa (Cstress)
TANGENT = 2  # tangent modulus, Pa (Ctangent)
MIN_STRAIN = 3  # most compressive strain reached on the envelope (CminStrain)
MAX_STRAIN = 4  # largest tensile strain reached on the envelope (CmaxStrain)
END_STRAIN = 5  # strain where compressive unloading reaches zero stress (CendStrain)
UNLOAD_SLOPE = 6  # slope of compressive unloading and reloading, Pa (CunloadSlope)
TENSION_SLOPE = 7  # secant slope of tensile unloading and reloading, Pa (CUtenSlope)
N_STATE = 8

# OpenSees' DBL_EPSILON: strain changes smaller than this leave the committed state as is.
_DBL_EPSILON = float(np.finfo(np.float64).eps)


@dataclass(frozen=True)
class Concrete04Parameters(UniaxialMaterial):
    """The parameters of a Concrete04 material: the arguments of OpenSees' ``uniaxialMaterial
    Concrete04 tag fc epsc epscu Ec fct et beta``, in that order and with its signs
    (compression negative), validated when made.

    Attributes:
        fc: peak compressive stress f'c, Pa, negative.
        epsc: strain at f'c, negative.
        epscu: crushing strain, negative; the compressive stress is zero beyond it.
        ec: initial modulus, Pa, positive.
        ft: tensile strength, Pa, zero or positive; zero leaves the material without tension
            (OpenSees' four-argument form).
        et: tensile strain at which the stress has decayed to ``beta * ft``, zero or positive;
            at or below ``ft / ec`` the tensile stress drops to zero right after cracking.
        beta: ratio of the stress at ``et`` to ``ft``, positive.

    Raises:
        ValueError: a value is not finite or has the wrong sign.
    """

    opensees_name: ClassVar[str] = "Concrete04"

    fc: float
    epsc: float
    epscu: float
    ec: float
    ft: float = 0.0
    et: float = 0.0
    beta: float = 0.1

    def __post_init__(self) -> None:
        for name, value in vars(self).items():
            if not math.isfinite(value):
                raise ValueError(f"Concrete04: {name} must be finite, got {value!r}")
            object.__setattr__(self, name, float(value))
        for name in ("fc", "epsc", "epscu"):
            value = getattr(self, name)
            if value >= 0.0:
                raise ValueError(
                    f"Concrete04: {name} must be negative (compression), got {value!r}"
                )
        if self.ec <= 0.0:
            raise ValueError(f"Concrete04: ec must be positive, got {self.ec!r}")
        if self.ft < 0.0:
            raise ValueError(
                f"Concrete04: ft must be zero (no tension) or positive, got {self.ft!r}"
            )
        if self.et < 0.0:
            raise ValueError(f"Concrete04: et must be zero or positive, got {self.et!r}")
        if self.beta <= 0.0:
            raise ValueError(f"Concrete04: beta must be positive, got {self.beta!r}")

    def packed(self) -> np.ndarray:
        """The parameter vector :func:`trial` reads, with the constants it derives from the
        arguments: float64 [N_PARAMETERS] (slots ``FC`` to ``SOFTENING_SPAN``)."""
        fc, epsc, ec, ft, et, beta = self.fc, self.epsc, self.ec, self.ft, self.et, self.beta
        # Popovics exponent, as OpenSees: 400 when the secant to the peak is not below Ec.
        secant = fc / epsc
        r = 400.0 if secant >= ec else ec / (ec - secant)
        p = np.empty(N_PARAMETERS)
        p[FC] = fc
        p[EPSC] = epsc
        p[EPSCU] = self.epscu
        p[EC] = ec
        p[FT] = ft
        p[ET] = et
        p[BETA] = beta
        p[R] = r
        p[R_MINUS_ONE] = r - 1.0
        p[POPOVICS_SLOPE] = fc * r * (r - 1.0)
        p[CRACKING_STRAIN] = ft / ec
        p[LOG_BETA] = math.log(beta)
        p[SOFTENING_SPAN] = et - ft / ec
        return p

    def initial_state(self) -> np.ndarray:
        """The committed state of a virgin fibre (see the function :func:`initial_state`)."""
        return initial_state(self.packed())


def initial_state(p: np.ndarray) -> np.ndarray:
    """Committed state of a virgin fibre.

    Args:
        p: parameters from :meth:`Concrete04Parameters.packed`.

    Returns:
        float64 array of length ``N_STATE``: zero strain, stress and history, tangent and
        unloading slope ``Ec`` (Pa), tensile secant slope ``Ec`` (zero without tension).
    """
    state = np.zeros(N_STATE)
    state[TANGENT] = p[EC]
    state[UNLOAD_SLOPE] = p[EC]
    state[TENSION_SLOPE] = p[EC] if p[FT] > 0.0 else 0.0
    return state


# The material law works on scalars only, so that no array reference is held across its
# branches: numba then drops every reference count, which would otherwise cost more than
# the law itself. ``trial`` is straight-line code around it, inlined into its callers.
_SCALAR = {"cache": True, "error_model": "numpy"}


@numba.njit(**_SCALAR)
def _compression_envelope(strain, fc, epsc, epscu, r, r_minus_one, popovics_slope):
    """Stress and tangent (Pa) on the compression envelope at ``strain`` (<= 0)."""
    if strain >= epscu:
        # Popovics' curve.
        eta = strain / epsc
        power = eta**r
        denominator = r_minus_one + power
        stress = fc * eta * r / denominator
        tangent = popovics_slope * (1.0 - power) / (denominator * denominator * epsc)
    else:
        # Crushed: beyond epscu the envelope carries nothing, with zero tangent.
        stress = 0.0
        tangent = 0.0
    return stress, tangent


@numba.njit(**_SCALAR)
def _compression_unloading(min_strain, stress, epsc, epscu, ec):
    """End strain and slope (Pa) of the unloading line from the envelope point
    (``min_strain``, ``stress``), by Karsan and Jirsa's plastic-strain rule."""
    eta = (min_strain if min_strain >= epscu else epscu) / epsc
    if eta < 2.0:
        ratio = 0.145 * eta * eta + 0.13 * eta
    else:
        ratio = 0.707 * (eta - 2.0) + 0.834
    end_strain = ratio * epsc
    span = min_strain - end_strain  # the strain the unloading line covers, <= 0
    elastic_span = stress / ec  # the same with the initial modulus
    slope = ec
    if span > -_DBL_EPSILON:
        # Next to the origin: keep the Karsan-Jirsa end strain, unload with Ec.
        pass
    elif span <= elastic_span:
        # The Karsan-Jirsa line is no steeper than Ec: unload along it.
        end_strain = min_strain - span
        slope = stress / span
    else:
        # It would be steeper than Ec: unload with Ec instead.
        end_strain = min_strain - elastic_span
    return end_strain, slope


@numba.njit(**_SCALAR)
def _tension_envelope(strain, ec, ft, et, beta, cracking_strain, log_beta, softening_span):
    """Stress and tangent (Pa) on the tension envelope at ``strain`` (>= 0)."""
    if strain <= cracking_strain:
        # Uncracked: linear with Ec.
        stress = strain * ec
        tangent = ec
    elif strain > et:
        # Fully cracked.
        stress = 0.0
        tangent = 0.0
    else:
        # Exponential softening from ft down to beta * ft at et.
        stress = ft * beta ** ((strain - cracking_strain) / softening_span)
        tangent = stress * log_beta / softening_span
    return stress, tangent


@numba.njit(**_SCALAR)
def _law(
    strain,
    c_strain,
    stress,
    tangent,
    min_strain,
    max_strain,
    end_strain,
    unload_slope,
    tension_slope,
    fc,
    epsc,
    epscu,
    ec,
    ft,
    et,
    beta,
    r,
    r_minus_one,
    popovics_slope,
    cracking_strain,
    log_beta,
    softening_span,
):
    """Concrete04::setTrialStrain on scalars: the committed state (slot order) and the
    parameters in, the trial state out, in slot order."""
    new_strain = c_strain
    if ft == 0.0 and strain > 0.0:
        # No tension: zero stress and tangent, history untouched.
        new_strain = strain
        stress = 0.0
        tangent = 0.0
        tension_slope = 0.0
    elif abs(strain - c_strain) >= _DBL_EPSILON:
        # (A smaller change keeps the committed state, strain included.)
        new_strain = strain
        if strain - c_strain <= 0.0:
            if strain > 0.0:
                # Tension unloading, along the secant to the origin.
                tangent = tension_slope
                stress = strain * tension_slope
            elif strain <= min_strain:
                # Compression envelope, a new most compressive strain.
                min_strain = strain
                stress, tangent = _compression_envelope(
                    strain, fc, epsc, epscu, r, r_minus_one, popovics_slope
                )
                end_strain, unload_slope = _compression_unloading(
                    min_strain, stress, epsc, epscu, ec
                )
            elif strain < end_strain:
                # Compression reloading, along the unloading line.
                tangent = unload_slope
                stress = unload_slope * (strain - end_strain)
            else:
                # Compression reloading, gap not yet closed.
                stress = 0.0
                tangent = 0.0
        elif strain >= 0.0:
            if strain < max_strain:
                # Tension reloading, along the secant to the origin.
                stress = strain * tension_slope
                tangent = tension_slope
            else:
                # Tension envelope, a new largest tensile strain.
                max_strain = strain
                stress, tangent = _tension_envelope(
                    strain, ec, ft, et, beta, cracking_strain, log_beta, softening_span
                )
                # Secant slope for later unloading. At strain 0 exactly (OpenSees divides
                # 0 by 0 here) the limit Ec is kept instead; the slot is never read before
                # the envelope is visited again at a positive strain.
                tension_slope = stress / strain if strain > 0.0 else ec
        elif strain <= end_strain:
            # Compression unloading, along the unloading line.
            tangent = unload_slope
            stress = unload_slope * (strain - end_strain)
        else:
            # Compression unloading, past the end strain: gap open.
            stress = 0.0
            tangent = 0.0
    return (
        new_strain,
        stress,
        tangent,
        min_strain,
        max_strain,
        end_strain,
        unload_slope,
        tension_slope,
    )


@numba.njit(cache=True, error_model="numpy", inline="always")
def trial(p, committed, out, strain):
    """Trial state of one fibre at total strain ``strain``.

    Works only from the committed state, as OpenSees does, so calling it several times
    before a commit is the same as calling it once with the last strain. Allocates nothing
    and raises nothing; ``committed`` and ``out`` may be the same array.

    Args:
        p: parameters from :meth:`Concrete04Parameters.packed` (float64 [N_PARAMETERS]).
        committed: committed state (float64 [N_STATE]); read only.
        out: receives the trial state (float64 [N_STATE]).
        strain: total strain, compression negative.

    Returns:
        (stress, tangent), both Pa.
    """
    state = _law(
        strain,
        committed[STRAIN],
        committed[STRESS],
        committed[TANGENT],
        committed[MIN_STRAIN],
        committed[MAX_STRAIN],
        committed[END_STRAIN],
        committed[UNLOAD_SLOPE],
        committed[TENSION_SLOPE],
        p[FC],
        p[EPSC],
        p[EPSCU],
        p[EC],
        p[FT],
        p[ET],
        p[BETA],
        p[R],
        p[R_MINUS_ONE],
        p[POPOVICS_SLOPE],
        p[CRACKING_STRAIN],
        p[LOG_BETA],
        p[SOFTENING_SPAN],
    )
    out[STRAIN] = state[0]
    out[STRESS] = state[1]
    out[TANGENT] = state[2]
    out[MIN_STRAIN] = state[3]
    out[MAX_STRAIN] = state[4]
    out[END_STRAIN] = state[5]
    out[UNLOAD_SLOPE] = state[6]
    out[TENSION_SLOPE] = state[7]
    return state[1], state[2]
