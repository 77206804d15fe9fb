"""OpenSees' uniaxial material ``Steel02`` in numba.

Giuffre-Menegotto-Pinto steel with the curvature parameters ``R0, cR1, cR2`` and Filippou's
isotropic hardening ``a1..a4``, written to give the stress and tangent OpenSees gives for any
strain history (no initial stress, ``sigInit = 0``).

A material's parameters are a :class:`Steel02Parameters`, which packs them into the flat
parameter vector ``p`` the compiled law reads (:meth:`Steel02Parameters.packed`, the one
place that knows its slots besides :func:`trial`). The material is a pure function of
``p``, a committed state vector (from :func:`initial_state`, then from earlier calls) and
the trial strain. :func:`trial` writes the trial state into a second vector; committing a step is
copying that vector over the committed one, reverting is not copying it. The state holds
every variable OpenSees' ``Steel02`` keeps between steps, in the slots named below.

Units: stresses and moduli in Pa, strains dimensionless.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numba
import numpy as np

from .material import UniaxialMaterial

# Slots of the parameter vector.
FY = 0  # yield stress [Pa]
E0 = 1  # initial elastic modulus [Pa]
B = 2  # strain-hardening ratio Esh / E0 [-]
R0 = 3  # transition curvature of the virgin curve [-]
CR1 = 4  # curvature degradation coefficient [-]
CR2 = 5  # curvature degradation coefficient [-]
A1 = 6  # isotropic hardening, compression: stress shift coefficient [-]
A2 = 7  # isotropic hardening, compression: strain range, in yield strains [-]
A3 = 8  # isotropic hardening, tension: stress shift coefficient [-]
A4 = 9  # isotropic hardening, tension: strain range, in yield strains [-]
ESH = 10  # hardening modulus b * E0 [Pa]
EPSY = 11  # yield strain Fy / E0 [-]
N_PARAMETERS = 12

# Slots of the state vector (OpenSees' names in brackets).
EPS = 0  # strain [-] (eps, committed: epsP)
SIG = 1  # stress [Pa] (sig, committed: sigP)
TANGENT = 2  # tangent modulus [Pa] (e, committed: eP)
EPS_MIN = 3  # largest compressive strain reached, at least the yield strain [-] (epsmin)
EPS_MAX = 4  # largest tensile strain reached, at least the yield strain [-] (epsmax)
EPS_PL = 5  # strain extreme of the previous excursion, for the curvature R [-] (epspl)
EPS_S0 = 6  # strain at the intersection of the branch's asymptotes [-] (epss0)
SIG_S0 = 7  # stress at the intersection of the branch's asymptotes [Pa] (sigs0)
EPS_R = 8  # strain at the last reversal [-] (epsr)
SIG_R = 9  # stress at the last reversal [Pa] (sigr)
KON = 10  # 0 virgin, 1 loading, 2 unloading, 3 virgin after a null first step (kon)
N_STATE = 11

# ln of a term surely too small to change 1.0 when added to it (below 2^-53, with a margin
# for the rounding of the logarithm): the Menegotto-Pinto powers are then exactly 1.
_NEGLIGIBLE_LOG = -53.0 * math.log(2.0) - 1e-6

# OpenSees treats a first strain increment below this (DBL_EPSILON * 10) as no increment.
_NULL_INCREMENT = 10.0 * np.finfo(np.float64).eps


@dataclass(frozen=True)
class Steel02Parameters(UniaxialMaterial):
    """The parameters of a Steel02 material: the arguments of OpenSees' ``uniaxialMaterial
    Steel02 tag Fy E0 b R0 cR1 cR2 a1 a2 a3 a4``, in that order, validated when made.

    Attributes:
        fy: yield stress [Pa], > 0.
        e0: initial elastic modulus [Pa], > 0.
        b: strain-hardening ratio Esh / E0 [-], 0 <= b < 1.
        r0: curvature of the elastic-to-hardening transition of the virgin curve [-], > 0.
        cr1: curvature degradation coefficient [-], 0 <= cr1 < 1 (so that R stays > 0).
        cr2: curvature degradation coefficient [-], > 0.
        a1: compressive isotropic hardening: stress shift per (range / (2 a2 Fy/E0))^0.8 [-].
        a2: compressive isotropic hardening: strain range scale, in yield strains [-], > 0.
        a3: tensile isotropic hardening: stress shift per (range / (2 a4 Fy/E0))^0.8 [-].
        a4: tensile isotropic hardening: strain range scale, in yield strains [-], > 0.

    Raises:
        ValueError: an argument is not a finite real number or is out of its range.
    """

    opensees_name: ClassVar[str] = "Steel02"

    fy: float
    e0: float
    b: float
    r0: float = 20.0
    cr1: float = 0.925
    cr2: float = 0.15
    a1: float = 0.0
    a2: float = 1.0
    a3: float = 0.0
    a4: float = 1.0

    def __post_init__(self) -> None:
        for name, value in vars(self).items():
            try:
                number = float(value)
            except (TypeError, ValueError):
                raise ValueError(f"Steel02 {name} must be a real number, got {value!r}") from None
            if not math.isfinite(number):
                raise ValueError(f"Steel02 {name} must be finite, got {value!r}")
            object.__setattr__(self, name, number)
        checks = (
            ("fy", self.fy > 0.0, "> 0"),
            ("e0", self.e0 > 0.0, "> 0"),
            ("b", 0.0 <= self.b < 1.0, "in [0, 1)"),
            ("r0", self.r0 > 0.0, "> 0"),
            ("cr1", 0.0 <= self.cr1 < 1.0, "in [0, 1)"),
            ("cr2", self.cr2 > 0.0, "> 0"),
            ("a2", self.a2 > 0.0, "> 0"),
            ("a4", self.a4 > 0.0, "> 0"),
        )
        for name, ok, requirement in checks:
            if not ok:
                value = getattr(self, name)
                raise ValueError(f"Steel02 {name} must be {requirement}, got {value!r}")

    def packed(self) -> np.ndarray:
        """The parameter vector :func:`trial` reads: float64 [N_PARAMETERS], the arguments
        in the slots ``FY`` to ``A4``, then Esh = b E0 [Pa] and the yield strain Fy / E0."""
        p = np.empty(N_PARAMETERS, dtype=np.float64)
        p[FY] = self.fy
        p[E0] = self.e0
        p[B] = self.b
        p[R0] = self.r0
        p[CR1] = self.cr1
        p[CR2] = self.cr2
        p[A1] = self.a1
        p[A2] = self.a2
        p[A3] = self.a3
        p[A4] = self.a4
        p[ESH] = p[B] * p[E0]  # as OpenSees: Esh = b * E0
        p[EPSY] = p[FY] / p[E0]  # as OpenSees: epsy = Fy / E0
        return p

    def initial_state(self) -> np.ndarray:
        """The committed state of a virgin fibre (see the function :func:`initial_state`)."""
        return initial_state(self.packed())


def initial_state(p: np.ndarray) -> np.ndarray:
    """Committed state of a virgin fibre (OpenSees' constructor, ``sigInit = 0``).

    Args:
        p: parameter vector from :meth:`Steel02Parameters.packed`.

    Returns:
        float64 array [N_STATE]: zero strain, stress and reversal point, tangent E0 [Pa],
        strain extremes at +-Fy/E0, ``KON`` 0.
    """
    state = np.zeros(N_STATE, dtype=np.float64)
    state[TANGENT] = p[E0]
    state[EPS_MAX] = p[FY] / p[E0]
    state[EPS_MIN] = -state[EPS_MAX]
    return state


# The material law works on scalars only, so that no array reference is held across its
# branches: numba then drops every reference count, which would otherwise cost more than
# the law itself. ``trial`` is straight-line code around it, inlined into its callers. The
# law is split in two so that LLVM inlines both parts: one function would be too large for
# its inliner, and a call left between ``trial``'s array accesses keeps their counts.
_SCALAR = {"cache": True, "error_model": "numpy"}


@numba.njit(**_SCALAR)
def _branch(
    eps,
    eps_p,
    sig_p,
    epsmin,
    epsmax,
    epspl,
    epss0,
    sigs0,
    epsr,
    sigr,
    kon,
    fy,
    e0,
    a1,
    a2,
    a3,
    a4,
    esh,
    epsy,
):
    """The branch of the hysteresis the strain is on: the strain, the committed state and
    the parameters in, the trial history variables (slot order from ``EPS_MIN``) out."""
    deps = eps - eps_p
    if kon == 0.0 or kon == 3.0:
        if abs(deps) < _NULL_INCREMENT:
            # Virgin fibre, null increment: kon = 3, the history variables kept as
            # committed (``_curve`` gives the initial stress, zero, and modulus).
            return epsmin, epsmax, epspl, epss0, sigs0, epsr, sigr, 3.0
        # Virgin fibre, first real increment: the virgin curve in its direction, from the
        # committed reversal point (the origin), asymptotes crossing at the yield point.
        # (Neither reversal below can follow: the direction taken is that of deps.)
        if deps < 0.0:
            return -epsy, epsy, -epsy, -epsy, -fy, epsr, sigr, 2.0
        return -epsy, epsy, epsy, epsy, fy, epsr, sigr, 1.0
    if kon == 2.0 and deps > 0.0:
        # Reversal from unloading to loading at the committed point: a new tensile branch,
        # its hardening asymptote shifted by the tensile isotropic hardening (a3, a4).
        if eps_p < epsmin:
            epsmin = eps_p
        if a3 == 0.0:
            shft = 1.0  # what the formula below gives, without the pow
        else:
            d1 = (epsmax - epsmin) / (2.0 * (a4 * epsy))
            shft = 1.0 + a3 * d1**0.8
        epss0 = (fy * shft - esh * epsy * shft - sig_p + e0 * eps_p) / (e0 - esh)
        sigs0 = fy * shft + esh * (epss0 - epsy * shft)
        return epsmin, epsmax, epsmax, epss0, sigs0, eps_p, sig_p, 1.0
    if kon == 1.0 and deps < 0.0:
        # Reversal from loading to unloading at the committed point: a new compressive
        # branch, its hardening asymptote shifted by the compressive hardening (a1, a2).
        if eps_p > epsmax:
            epsmax = eps_p
        if a1 == 0.0:
            shft = 1.0
        else:
            d1 = (epsmax - epsmin) / (2.0 * (a2 * epsy))
            shft = 1.0 + a1 * d1**0.8
        epss0 = (-fy * shft + esh * epsy * shft - sig_p + e0 * eps_p) / (e0 - esh)
        sigs0 = -fy * shft + esh * (epss0 + epsy * shft)
        return epsmin, epsmax, epsmin, epss0, sigs0, eps_p, sig_p, 2.0
    # Still on the committed branch.
    return epsmin, epsmax, epspl, epss0, sigs0, epsr, sigr, kon


@numba.njit(**_SCALAR)
def _curve(eps, epspl, epss0, sigs0, epsr, sigr, kon, e0, b, r0, cr1, cr2, epsy):
    """Stress and tangent at the strain on the branch ``_branch`` gave: the Menegotto-Pinto
    curve from (epsr, sigr) towards the asymptotes' intersection (epss0, sigs0), its
    curvature R reduced by the previous plastic excursion; after a null first increment
    (kon 3) the initial stress, zero, and modulus."""
    if kon == 3.0:
        return 0.0, e0
    xi = abs((epspl - epss0) / epsy)
    r = r0 * (1.0 - (cr1 * xi) / (cr2 + xi))
    epsrat = (eps - epsr) / (epss0 - epsr)
    if epsrat == 0.0 or r * math.log(abs(epsrat)) < _NEGLIGIBLE_LOG:
        # |epsrat|^r is below half an ulp of 1: both powers round to exactly 1
        dum1 = 1.0
        dum2 = 1.0
    else:
        dum1 = 1.0 + abs(epsrat) ** r
        dum2 = dum1 ** (1.0 / r)

    sig = b * epsrat + (1.0 - b) * epsrat / dum2
    sig = sig * (sigs0 - sigr) + sigr
    e = b + (1.0 - b) / (dum1 * dum2)
    e = e * (sigs0 - sigr) / (epss0 - epsr)
    return sig, e


@numba.njit(cache=True, error_model="numpy", inline="always")
def trial(p, committed, out, strain):
    """Trial state of a Steel02 fibre for a total strain (OpenSees ``setTrialStrain``).

    Works only from the parameters, the committed state and the strain, as OpenSees does, so
    any number of trials before a commit give what the last one alone gives. Every input is
    read before ``out`` is written, so ``out`` may be ``committed`` itself.

    Args:
        p: float64 [N_PARAMETERS], from :meth:`Steel02Parameters.packed`.
        committed: float64 [N_STATE], the committed state; not modified.
        out: float64 [N_STATE], receives the trial state.
        strain: total strain [-].

    Returns:
        (stress [Pa], tangent modulus [Pa]).
    """
    fy = p[FY]
    e0 = p[E0]
    b = p[B]
    r0 = p[R0]
    cr1 = p[CR1]
    cr2 = p[CR2]
    a1 = p[A1]
    a2 = p[A2]
    a3 = p[A3]
    a4 = p[A4]
    esh = p[ESH]
    epsy = p[EPSY]
    epsmin, epsmax, epspl, epss0, sigs0, epsr, sigr, kon = _branch(
        strain,
        committed[EPS],
        committed[SIG],
        committed[EPS_MIN],
        committed[EPS_MAX],
        committed[EPS_PL],
        committed[EPS_S0],
        committed[SIG_S0],
        committed[EPS_R],
        committed[SIG_R],
        committed[KON],
        fy,
        e0,
        a1,
        a2,
        a3,
        a4,
        esh,
        epsy,
    )
    # The history first, so that fewer values are kept across the curve's pow calls.
    out[EPS] = strain
    out[EPS_MIN] = epsmin
    out[EPS_MAX] = epsmax
    out[EPS_PL] = epspl
    out[EPS_S0] = epss0
    out[SIG_S0] = sigs0
    out[EPS_R] = epsr
    out[SIG_R] = sigr
    out[KON] = kon
    sig, e = _curve(strain, epspl, epss0, sigs0, epsr, sigr, kon, e0, b, r0, cr1, cr2, epsy)
    out[SIG] = sig
    out[TANGENT] = e
    return sig, e
