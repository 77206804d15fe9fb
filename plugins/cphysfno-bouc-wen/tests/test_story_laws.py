"""The built-in story laws against OpenSees' materials, and the law checks against wrong
laws."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from cphysfno_core import ConfigError, create
from cphysfno_core.plugin import LawFunctions, Params, StoryLaw
from cphysfno_core.testing import check_story_law
from cphysfno_core.testing.story_law import cyclic_drift, drive
from cphysfno_opensees.uniaxial import uniaxial_stress

from cphysfno_bouc_wen.laws import BUILT_IN_LAWS, BilinearLaw, PeakOrientedLaw
from cphysfno_bouc_wen.laws.bilinear import bilinear_force, bilinear_rate, bilinear_settle

STIFFNESS, YIELD, ALPHA = 1.0e7, 0.01, 0.05

LAWS = {
    "linear": {},
    "bilinear": {"yield_displacement": YIELD},
    "bouc-wen": {},
    "peak-oriented": {"yield_displacement": YIELD},
    "pinching": {"yield_displacement": YIELD},
    "cracked-pinching": {"yield_displacement": YIELD, "crack_displacement": 0.2 * YIELD},
}


@pytest.mark.parametrize("name", sorted(LAWS))
def test_every_built_in_law_passes_the_law_checks(name) -> None:
    check_story_law(create("story_law", name, **LAWS[name]))


def test_every_built_in_law_is_registered() -> None:
    assert sorted(law.name for law in BUILT_IN_LAWS) == sorted(LAWS)


def _path() -> np.ndarray:
    """Cycles growing to 4 u_y, a half-size excursion off-centre, then a random walk to
    about 8 u_y with many small reversals on every branch."""
    path = cyclic_drift(4.0 * YIELD)
    path = np.concatenate([path, 0.5 * path[:800] + path[-1]])
    walk = np.cumsum(np.random.default_rng(0).standard_normal(4000))
    walk = np.convolve(walk, np.ones(50) / 50, "same")
    return np.concatenate([path, path[-1] + 8.0 * YIELD * (walk - walk[0]) / np.abs(walk).max()])


def _law_loop(law: StoryLaw, path: np.ndarray) -> np.ndarray:
    coefficients = law.coefficients(np.array([STIFFNESS]))[0]
    return drive(law.functions(), law.n_states, coefficients, path)


def test_bilinear_follows_opensees_steel01() -> None:
    path = _path()
    reference = uniaxial_stress(["Steel01", 1, STIFFNESS * YIELD, STIFFNESS, ALPHA], path)
    loop = _law_loop(BilinearLaw(alpha=ALPHA, yield_displacement=YIELD), path)
    assert np.max(np.abs(loop - reference)) < 1e-3 * np.max(np.abs(reference))


def test_peak_oriented_follows_opensees_hysteretic_without_pinching_or_damage() -> None:
    path = _path()
    fy, far = STIFFNESS * YIELD, 11.0 * YIELD
    strength = fy + ALPHA * STIFFNESS * (far - YIELD)
    material = ["Hysteretic", 1, fy, YIELD, strength, far, -fy, -YIELD, -strength, -far]
    reference = uniaxial_stress([*material, 1.0, 1.0, 0.0, 0.0, 0.0], path)
    loop = _law_loop(PeakOrientedLaw(alpha=ALPHA, yield_displacement=YIELD), path)
    assert np.max(np.abs(loop - reference)) < 1e-3 * np.max(np.abs(reference))
    # the reloading stiffness after the largest cycle is well below the initial one
    assert np.max(np.abs(loop)) > 1.1 * STIFFNESS * YIELD


def test_a_per_story_value_of_the_wrong_length_names_its_field() -> None:
    law = BilinearLaw(yield_displacement=(0.01, 0.02))
    with pytest.raises(ConfigError, match=r"story_law\.yield_displacement.*2 values for 3"):
        law.coefficients(np.full(3, STIFFNESS))


@numba.njit(inline="always")
def _stiff_force(c, v, s):
    return 2.0 * bilinear_force(c, v, s)


@numba.njit(inline="always")
def _viscous_force(c, v, s):
    return c[0] * v + s[0]


@numba.njit(inline="always")
def _viscous_rate(c, v, v_dot, s, out):
    """A Maxwell damper beside the spring: 1e-4 k (s) of viscosity relaxing at 5 1/s."""
    out[0] = 5.0 * (1e-4 * c[0] * v_dot - s[0])


@numba.njit(inline="always")
def _creating_force(c, v, s):
    """(k + k_d) v - k_d w: the right tangent at rest, but its loops turn the wrong way."""
    return 1.5 * c[0] * v - 0.5 * c[0] * s[0]


@numba.njit(inline="always")
def _friction_rate(c, v, v_dot, s, out):
    out[0] = v_dot - abs(v_dot) * s[0] / c[2]


@numba.njit(inline="always")
def _nothing(c, v, s):
    pass


class _WrongLawParams(Params):
    pass


def _wrong_law(functions: LawFunctions) -> StoryLaw:
    class WrongLaw(StoryLaw):
        name = "wrong"
        Params = _WrongLawParams
        n_states = 1
        state_names = ("s",)

        def coefficients(self, stiffness):
            return np.column_stack(
                [stiffness, np.full(len(stiffness), ALPHA), np.full(len(stiffness), YIELD)]
            )

        def functions(self):
            return functions

        def yield_drift(self, n_stories):
            return np.full(n_stories, YIELD)

    return WrongLaw()


@pytest.mark.parametrize(
    ("functions", "complaint"),
    [
        (LawFunctions(_stiff_force, bilinear_rate, bilinear_settle), "tangent at rest"),
        (LawFunctions(_viscous_force, _viscous_rate, _nothing), "rate-dependent"),
        (LawFunctions(_creating_force, _friction_rate, _nothing), "creates energy"),
    ],
    ids=["twice-too-stiff", "viscous", "energy-creating"],
)
def test_the_law_checks_catch_a_wrong_law(functions, complaint) -> None:
    with pytest.raises(AssertionError, match=complaint):
        check_story_law(_wrong_law(functions))
