"""LinearRegressionRefiner against known generating weights and the normal equations."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_refiners import LinearRegressionRefiner, arrays

from cphysfno_core import ConfigError, InputError, NotFittedError
from cphysfno_core.plugin import Registry

TRUE_WEIGHTS = np.array([[0.002, 0.3, 0.8], [-0.001, 0.1, 0.95], [0.0, -0.2, 1.1]])
TRUE_SIGMA = np.array([0.004, 0.001, 0.01])


def synthetic(shape: tuple[int, int, int], sigma: np.ndarray, seed: int = 0):
    """``z``, ``u_hat`` and ``u = [1, z, u_hat] @ TRUE_WEIGHTS + sigma * noise`` (m)."""
    rng = np.random.default_rng(seed)
    z = 0.02 * rng.standard_normal(shape)
    u_hat = z + 0.01 * rng.standard_normal(shape)
    w = TRUE_WEIGHTS[: shape[2]]
    u = w[:, 0] + w[:, 1] * z + w[:, 2] * u_hat + sigma[: shape[2]] * rng.standard_normal(shape)
    return z, u_hat, u


def test_recovers_known_weights_and_noise_level() -> None:
    z, u_hat, u = synthetic((40, 2000, 3), TRUE_SIGMA)
    refiner = LinearRegressionRefiner(n_points=40_000).fit(z, u_hat, u, np.random.default_rng(1))
    assert refiner.weights_.shape == (3, 3)
    assert refiner.sigma_.shape == (3,)
    # Standard error of w_i2 and w_i3: sigma_i / (0.0089 sqrt(m)), 0.0089 m being the std of
    # z given u_hat; the intercept's is smaller. Allow five standard errors.
    tolerance = 5 * TRUE_SIGMA[:, None] / (0.0089 * np.sqrt(40_000))
    assert np.all(np.abs(refiner.weights_ - TRUE_WEIGHTS) < tolerance)
    np.testing.assert_allclose(refiner.sigma_, TRUE_SIGMA, rtol=0.05)


def test_uses_every_pair_when_fewer_than_n_points_and_matches_normal_equations() -> None:
    z, u_hat, u = synthetic((6, 50, 2), TRUE_SIGMA, seed=2)
    refiner = LinearRegressionRefiner(n_points=1000).fit(z, u_hat, u, np.random.default_rng(3))
    for i in range(2):
        a = np.column_stack([np.ones(300), z[..., i].ravel(), u_hat[..., i].ravel()])
        y = u[..., i].ravel()
        w = np.linalg.solve(a.T @ a, a.T @ y)
        rss = np.sum((y - a @ w) ** 2)
        np.testing.assert_allclose(refiner.weights_[i], w, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(refiner.sigma_[i], np.sqrt(rss / (300 - 3)), rtol=1e-9)


def test_exact_recovery_without_noise() -> None:
    z, u_hat, u = synthetic((5, 300, 3), np.zeros(3))
    refiner = LinearRegressionRefiner(n_points=50).fit(z, u_hat, u, np.random.default_rng(0))
    np.testing.assert_allclose(refiner.weights_, TRUE_WEIGHTS, rtol=0, atol=1e-10)
    np.testing.assert_allclose(refiner.sigma_, 0.0, atol=1e-12)
    mean, std = refiner.predict(z, u_hat)
    np.testing.assert_allclose(mean, u, rtol=0, atol=1e-12)
    np.testing.assert_allclose(std, 0.0, atol=1e-12)


def test_same_rng_seed_gives_the_same_fit() -> None:
    z, u_hat, u = synthetic((10, 500, 2), TRUE_SIGMA)
    fits = [
        LinearRegressionRefiner(n_points=200).fit(z, u_hat, u, np.random.default_rng(seed))
        for seed in (7, 7, 8)
    ]
    np.testing.assert_array_equal(fits[0].weights_, fits[1].weights_)
    np.testing.assert_array_equal(fits[0].sigma_, fits[1].sigma_)
    assert not np.array_equal(fits[0].weights_, fits[2].weights_)


def test_predict_applies_the_weights_per_dof() -> None:
    refiner = LinearRegressionRefiner()
    refiner.load_state_dict({"weights": TRUE_WEIGHTS[:2], "sigma": TRUE_SIGMA[:2]})
    rng = np.random.default_rng(4)
    z, u_hat = rng.standard_normal((2, 3, 7, 2))
    mean, std = refiner.predict(z, u_hat)
    assert mean.shape == std.shape == (3, 7, 2)
    for i in range(2):
        w1, w2, w3 = TRUE_WEIGHTS[i]
        np.testing.assert_allclose(mean[..., i], w1 + w2 * z[..., i] + w3 * u_hat[..., i])
        np.testing.assert_array_equal(std[..., i], TRUE_SIGMA[i])


def test_state_dict_round_trip() -> None:
    z, u_hat, u = synthetic((8, 200, 3), TRUE_SIGMA)
    fitted = LinearRegressionRefiner(n_points=500).fit(z, u_hat, u, np.random.default_rng(5))
    state = fitted.state_dict()
    assert set(state) == {"weights", "sigma"}
    assert all(isinstance(v, np.ndarray) and v.dtype.kind == "f" for v in state.values())
    restored = LinearRegressionRefiner(**fitted.get_params())
    restored.load_state_dict(state)
    for a, b in zip(fitted.predict(z, u_hat), restored.predict(z, u_hat), strict=True):
        np.testing.assert_array_equal(a, b)


def test_degenerate_design_gives_minimum_norm_weights() -> None:
    rng = np.random.default_rng(6)
    z = 0.01 * rng.standard_normal((4, 100, 1))
    u = 0.002 + 0.9 * z
    refiner = LinearRegressionRefiner(n_points=200).fit(z, z.copy(), u, rng)
    np.testing.assert_allclose(refiner.weights_, [[0.002, 0.45, 0.45]], atol=1e-10)
    mean, _ = refiner.predict(z, z)
    np.testing.assert_allclose(mean, u, atol=1e-12)


def test_not_fitted() -> None:
    refiner = LinearRegressionRefiner()
    with pytest.raises(NotFittedError):
        refiner.predict(np.zeros((1, 5, 2)), np.zeros((1, 5, 2)))
    with pytest.raises(NotFittedError):
        refiner.state_dict()


def test_shape_mismatch_names_the_shapes() -> None:
    a = np.zeros((2, 10, 3))
    with pytest.raises(InputError, match=r"u_hat \(2, 11, 3\)"):
        LinearRegressionRefiner().fit(a, np.zeros((2, 11, 3)), a, np.random.default_rng(0))
    with pytest.raises(InputError, match=r"z \(2, 10\)"):
        LinearRegressionRefiner().fit(a[..., 0], a[..., 0], a[..., 0], np.random.default_rng(0))


def test_predict_with_another_number_of_dofs() -> None:
    refiner = LinearRegressionRefiner()
    refiner.load_state_dict({"weights": TRUE_WEIGHTS, "sigma": TRUE_SIGMA})
    with pytest.raises(InputError, match=r"3 DOFs.*\(1, 4, 2\)"):
        refiner.predict(np.zeros((1, 4, 2)), np.zeros((1, 4, 2)))


def test_too_few_points() -> None:
    a = np.ones((1, 3, 2))
    with pytest.raises(InputError, match="at least 4"):
        LinearRegressionRefiner().fit(a, a, a, np.random.default_rng(0))


def test_non_finite_input() -> None:
    a = np.zeros((3, 10, 1))
    bad = a.copy()
    bad[2, 4, 0] = np.nan
    with pytest.raises(InputError, match="u_hat.*record 2"):
        LinearRegressionRefiner().fit(a, bad, a, np.random.default_rng(0))


def test_bad_state() -> None:
    with pytest.raises(InputError, match="sigma"):
        LinearRegressionRefiner().load_state_dict({"weights": TRUE_WEIGHTS})
    with pytest.raises(InputError, match=r"\(3, 2\)"):
        LinearRegressionRefiner().load_state_dict(
            {"weights": TRUE_WEIGHTS[:, :2], "sigma": TRUE_SIGMA}
        )


@pytest.mark.parametrize(("params", "field"), [({"n_points": 3}, "n_points"), ({"n": 9}, "n")])
def test_bad_params_name_the_field(params: dict, field: str) -> None:
    with pytest.raises(ConfigError, match=rf"linear-regression\.{field}:"):
        LinearRegressionRefiner(**params)


def test_registry_creates_it_by_name() -> None:
    registry = Registry(autoload=True)
    assert registry.get("refiner", "linear-regression") is LinearRegressionRefiner
    refiner = registry.create("refiner", "linear-regression", n_points=500)
    assert isinstance(refiner, LinearRegressionRefiner)
    assert refiner.get_params() == {"n_points": 500, "calibration_split": "training"}


def test_predict_in_record_blocks_equals_the_formula(monkeypatch) -> None:
    monkeypatch.setattr(arrays, "BLOCK_ELEMENTS", 40)
    refiner = LinearRegressionRefiner()
    refiner.load_state_dict({"weights": TRUE_WEIGHTS, "sigma": TRUE_SIGMA})
    rng = np.random.default_rng(9)
    z, u_hat = rng.standard_normal((2, 7, 5, 3))
    mean, std = refiner.predict(z, u_hat)
    w = TRUE_WEIGHTS
    np.testing.assert_array_equal(mean, w[:, 0] + w[:, 1] * z + w[:, 2] * u_hat)
    np.testing.assert_array_equal(std, np.broadcast_to(TRUE_SIGMA, z.shape))


def test_non_finite_value_in_a_later_block_names_its_record(monkeypatch) -> None:
    monkeypatch.setattr(arrays, "BLOCK_ELEMENTS", 20)
    refiner = LinearRegressionRefiner()
    refiner.load_state_dict({"weights": TRUE_WEIGHTS[:1], "sigma": TRUE_SIGMA[:1]})
    z = np.zeros((9, 10, 1))
    u_hat = z.copy()
    u_hat[6, 3, 0] = np.inf
    with pytest.raises(InputError, match="u_hat.*record 6"):
        refiner.predict(z, u_hat)
