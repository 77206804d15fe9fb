"""Story laws that soften past yield (a negative ``alpha``) against references written here:
a story with P-Delta (geometric stiffness ``k_g = P / H``) integrated by ``solve_ivp`` from
its own equations, OpenSees' ``Steel01`` with a negative hardening ratio, and the closed-form
backbone of the pushover."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.integrate
from cphysfno_core import ConfigError, GroundMotions, create
from cphysfno_core.signals import monotonic_protocol
from cphysfno_core.testing import check_story_law
from cphysfno_core.testing.story_law import drive
from cphysfno_opensees.uniaxial import uniaxial_stress

from cphysfno_bouc_wen.laws import BilinearLaw

from .conftest import paper_white_noise

MASS, STIFFNESS, YIELD, HEIGHT = 2.0e4, 3.0e7, 0.01, 3.0
GEOMETRIC = 0.05 * STIFFNESS
"""``P / H`` of the story (N/m): a stability coefficient of 0.05."""
HARDENING = 0.03
"""``alpha`` of the story without its P-Delta."""
FOLDED_STIFFNESS = STIFFNESS - GEOMETRIC
FOLDED_ALPHA = (HARDENING * STIFFNESS - GEOMETRIC) / (STIFFNESS - GEOMETRIC)
"""The law of the story with its P-Delta: ``alpha`` about -0.021, no strength left past
48 yield drifts."""
DAMPING_RATIO = 0.05
DT = 0.01


def story(law: dict, **extra):
    return create(
        "structure",
        "shear-building",
        masses=(MASS,),
        stiffnesses=(FOLDED_STIFFNESS,),
        story_heights=(HEIGHT,),
        story_law=law,
        damping_ratio=DAMPING_RATIO,
        **extra,
    )


@pytest.fixture(scope="module")
def strong() -> GroundMotions:
    """Two 8-s records of the paper's white noise, three times as strong: the story yields
    both ways and drifts 2 to 8 yield drifts."""
    return GroundMotions(3.0 * paper_white_noise(2, seed=3, duration=8.0), DT)


def with_p_delta(
    ag: np.ndarray, hysteretic_rate, geometric: float = GEOMETRIC, dt: float = DT
) -> tuple[np.ndarray, np.ndarray]:
    """Drift (m) and shear of the law without P-Delta (N) of the story ``m u'' + c u' +
    k [alpha_0 u + (1 - alpha_0) z] - k_g u = -m a_g`` with ``alpha_0 = HARDENING``,
    ``k_g = geometric`` (N/m), ``c`` the damping ratio at the period of ``k - k_g``,
    ``z' = hysteretic_rate(u', z)`` and ``a_g`` linear between samples ``dt`` (s) apart, by
    DOP853 at rtol 1e-11, ``[T]`` each."""
    t = np.arange(ag.shape[0]) * dt
    damping = 2.0 * DAMPING_RATIO * np.sqrt((STIFFNESS - geometric) * MASS)

    def spring(u, z):
        return STIFFNESS * (HARDENING * u + (1.0 - HARDENING) * z)

    def rhs(time, y):
        u, w, z = y
        ground = np.interp(time, t, ag)
        acceleration = -(spring(u, z) - geometric * u + damping * w) / MASS - ground
        return [w, acceleration, hysteretic_rate(w, z)]

    solution = scipy.integrate.solve_ivp(
        rhs,
        (0.0, t[-1]),
        [0.0, 0.0, 0.0],
        method="DOP853",
        t_eval=t,
        rtol=1e-11,
        atol=1e-14,
        max_step=dt / 4,
    )
    u, _, z = solution.y
    return u, spring(u, z)


def perfectly_plastic_rate(w: float, z: float) -> float:
    """``z' = u'`` inside the yield range or moving back into it, else 0."""
    return 0.0 if abs(z) >= YIELD and z * w > 0.0 else w


def bouc_wen_rate(w: float, z: float, n: float = 2.0) -> float:
    """Bouc-Wen with ``A = 1`` and ``beta = gamma = 1 / (2 u_y^n)``."""
    shape = 0.5 / YIELD**n
    power = abs(z) ** (n - 1.0)
    return w * (1.0 - shape * power * abs(z)) - shape * abs(w) * power * z


def relative(value: np.ndarray, reference: np.ndarray) -> float:
    return float(np.linalg.norm(value - reference) / np.linalg.norm(reference))


@pytest.mark.parametrize(
    ("law", "rate", "tolerance"),
    [
        ({"name": "bilinear", "yield_displacement": YIELD}, perfectly_plastic_rate, 1e-3),
        ({"name": "bouc-wen", "exponent": 2.0, "yield_displacement": YIELD}, bouc_wen_rate, 1e-4),
    ],
    ids=["bilinear", "bouc-wen"],
)
def test_a_negative_alpha_is_the_story_with_its_p_delta(strong, law, rate, tolerance) -> None:
    building = story({**law, "alpha": FOLDED_ALPHA}, substeps=20)
    response = building.simulate(strong)
    for record, ag in enumerate(strong.acceleration):
        drift, shear = with_p_delta(ag, rate)
        assert relative(response.displacement[record, :, 0], drift) < tolerance
        # the law's shear is the spring's less the P-Delta force
        folded = shear - GEOMETRIC * drift
        assert relative(response.extras["story_shear"][record, :, 0], folded) < tolerance
    # far past yield, short of the drift u_y (1 - 1 / alpha) where the story has no
    # strength left; there its shear has fallen below the yield force
    drift = np.abs(response.extras["story_drift"]).ravel()
    assert 3.0 * YIELD < drift.max() < 0.5 * YIELD * (1.0 - 1.0 / FOLDED_ALPHA)
    at_peak = abs(response.extras["story_shear"].ravel()[drift.argmax()])
    assert at_peak < FOLDED_STIFFNESS * YIELD


@pytest.mark.parametrize("geometric", [GEOMETRIC, 0.0], ids=["p-delta", "without"])
def test_the_coarse_bouc_wen_integration_follows_the_story(strong, geometric) -> None:
    """The dedicated kernel's Gauss-Legendre steps on a grid of 0.02 s against the
    reference driven by the same resampled motion, with and without P-Delta (``alpha``
    about -0.021 and 0.03): as close to it either way (relative L2 measured 0.013 and 0.004
    with P-Delta, 0.008 and 0.010 without: the law's corner where the drift turns,
    ``|v'|``, limits the sixth order)."""
    stiffness = STIFFNESS - geometric
    alpha = (HARDENING * STIFFNESS - geometric) / stiffness
    law = {"name": "bouc-wen", "exponent": 2.0, "yield_displacement": YIELD, "alpha": alpha}
    building = create(
        "structure",
        "shear-building",
        masses=(MASS,),
        stiffnesses=(stiffness,),
        story_law=law,
        damping_ratio=DAMPING_RATIO,
    )
    coarse = strong.resample(2.0 * DT)
    response = building.simulate(strong, dt=2.0 * DT)
    for record, ag in enumerate(coarse.acceleration):
        drift, _ = with_p_delta(ag, bouc_wen_rate, geometric, 2.0 * DT)
        assert relative(response.displacement[record, :, 0], drift) < 2.5e-2


def test_the_monotonic_pushover_falls_past_yield_by_alpha_k() -> None:
    alpha = -0.2  # the backbone's shear changes sign at 6 u_y
    protocol = monotonic_protocol(8.0 * YIELD / HEIGHT, 81)
    curves = story({"name": "bilinear", "alpha": alpha, "yield_displacement": YIELD})
    curves = curves.story_pushover(protocol)
    drift = curves.story_drift[:, 0]
    expected = np.where(
        drift <= YIELD,
        FOLDED_STIFFNESS * drift,
        FOLDED_STIFFNESS * (YIELD + alpha * (drift - YIELD)),
    )
    np.testing.assert_allclose(curves.story_shear[:, 0], expected, rtol=1e-12, atol=1e-6)
    past = drift > 1.01 * YIELD
    slopes = np.diff(curves.story_shear[past, 0]) / np.diff(drift[past])
    np.testing.assert_allclose(slopes, alpha * FOLDED_STIFFNESS, rtol=1e-9)
    assert curves.story_shear[-1, 0] < 0.0


def _cycles() -> np.ndarray:
    """Cycles growing to 5 u_y, then one and a half cycles of 2 u_y inside the last loop."""
    t = np.linspace(0.0, 3.0, 1201)
    path = 5.0 * YIELD * (t / 3.0) * np.sin(2.0 * np.pi * t)
    return np.concatenate([path, path[-1] + 2.0 * YIELD * np.sin(np.linspace(0, 3 * np.pi, 301))])


def test_bilinear_softening_follows_opensees_steel01() -> None:
    alpha = -0.05
    path = _cycles()
    reference = uniaxial_stress(["Steel01", 1, STIFFNESS * YIELD, STIFFNESS, alpha], path)
    law = BilinearLaw(alpha=alpha, yield_displacement=YIELD)
    # 40 Runge-Kutta steps a sample: a yield corner inside a step is off by half a step
    loop = drive(law.functions(), 1, law.coefficients(np.array([STIFFNESS]))[0], path, 1.0, 40)
    assert np.max(np.abs(loop - reference)) < 1e-3 * np.max(np.abs(reference))
    assert loop[np.argmax(path)] < STIFFNESS * YIELD  # it has fallen from the yield force


@pytest.mark.parametrize("name", ["bilinear", "bouc-wen"])
def test_the_story_test_folds_p_delta_exactly(name) -> None:
    """The law at (k - k_g, FOLDED_ALPHA) against the same law at (k, HARDENING) less
    ``k_g v``, along the same drifts."""
    path = _cycles()
    law = {"name": name, "yield_displacement": YIELD}
    folded = story({**law, "alpha": FOLDED_ALPHA}).story_shears(path[:, None])[:, 0]
    plain = create(
        "structure",
        "shear-building",
        masses=(MASS,),
        stiffnesses=(STIFFNESS,),
        story_law={**law, "alpha": HARDENING},
    )
    expected = plain.story_shears(path[:, None])[:, 0] - GEOMETRIC * path
    assert np.max(np.abs(folded - expected)) < 1e-9 * STIFFNESS * YIELD


@pytest.mark.parametrize("name", ["bilinear", "bouc-wen"])
@pytest.mark.parametrize("alpha", [-0.05, -0.5])
def test_softening_laws_pass_the_law_checks(name, alpha) -> None:
    check_story_law(create("story_law", name, alpha=alpha, yield_displacement=YIELD))


@pytest.mark.parametrize(
    ("name", "alpha"),
    [
        ("bilinear", -0.51),
        ("bouc-wen", (0.05, -0.6)),
        ("peak-oriented", -0.01),
        ("pinching", -0.01),
    ],
)
def test_an_alpha_below_its_bound_is_refused(name, alpha) -> None:
    with pytest.raises(ConfigError, match="alpha"):
        create("story_law", name, alpha=alpha, yield_displacement=YIELD)
    with pytest.raises(ConfigError, match="alpha"):
        story({"name": name, "alpha": alpha, "yield_displacement": YIELD})


@pytest.mark.parametrize("name", ["bilinear", "bouc-wen"])
def test_the_restoring_force_of_a_softening_story(name) -> None:
    """At a drift of 4 u_y and a hysteretic displacement of u_y the story force is
    ``k [alpha v + (1 - alpha) z]``, and the linear system keeps the initial ``k``."""
    law = {"name": name, "alpha": FOLDED_ALPHA, "yield_displacement": YIELD}
    building = story(law)
    force = building.restoring_force().force(np.array([[4.0 * YIELD]]), np.array([[YIELD]]))
    expected = FOLDED_STIFFNESS * (FOLDED_ALPHA * 4.0 + 1.0 - FOLDED_ALPHA) * YIELD
    np.testing.assert_allclose(force, [[expected]], rtol=1e-12)
    np.testing.assert_allclose(building.linear_system().stiffness, [[FOLDED_STIFFNESS]])


@pytest.mark.parametrize(
    "law",
    [
        {"name": "bilinear", "alpha": -0.5, "yield_displacement": YIELD},
        {"name": "bouc-wen", "alpha": -0.5},
    ],
)
def test_a_story_driven_past_its_zero_strength_collapses_instead_of_failing(law):
    """With alpha = -0.5 the story has no strength left past 3 yield drifts: a resonant
    sine drives it there and it runs away. The record is a collapse (NaN from where it
    overflowed), a weak record beside it is not."""
    building = story(law)
    period = float(building.periods()[0])
    t = np.arange(0.0, 20.0, DT)
    resonant = 20.0 * np.sin(2.0 * np.pi * t / period)
    responses = building.simulate(GroundMotions(np.stack([resonant, 0.01 * resonant]), DT))
    assert responses.collapsed.tolist() == [True, False]
    drift = responses.displacement[0, :, 0]
    assert np.isnan(drift[-1]) and np.isfinite(drift[0])
    assert np.isfinite(responses.displacement[1]).all()


def test_a_story_that_cannot_soften_still_blames_the_step_when_it_diverges():
    building = story({"name": "bilinear", "alpha": 0.02, "yield_displacement": YIELD},
                     substeps=1)  # fmt: skip
    stiff = create("structure", "shear-building", masses=(MASS,), stiffnesses=(1e12,),
                   story_law={"name": "bilinear", "alpha": 0.02, "yield_displacement": 1.0},
                   substeps=1)  # fmt: skip
    assert not building.softens
    t = np.arange(0.0, 2.0, DT)
    with pytest.raises(Exception, match="raise substeps"):
        stiff.simulate(GroundMotions(np.sin(t)[None], DT))
