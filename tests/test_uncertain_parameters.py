"""Random structural parameters in the config: distributions parse and validate, bad ones
are named, and the draws follow their distributions and correlations, reproducibly."""

import math
import tomllib

import numpy as np
import pytest
from scipy import stats
from tiny_family_run import tiny_config

import cphysfno_core as cp
from cphysfno_core.config import ExperimentConfig
from cphysfno_core.config.uncertainty import (
    UncertainParameters,
    distinct_draws,
    value_at,
    with_values,
)

STRUCTURE = """
[structure]
name = "shear-building"
masses = [4.0e4, 3.0e4, 3.0e4]
stiffnesses = [{{ dist = "normal", mean = 4e7, std = 4e6, unit = "N/m" }}, 3e7, 2e7]
damping_ratio = {{ dist = "uniform", low = 0.03, high = 0.07 }}
story_law = {{ name = "bilinear", alpha = 0.05, yield_displacement = {law} }}
"""

LAW = '{ dist = "lognormal", median = 0.02, beta = 0.2, unit = "m" }'


def _config(law: str = LAW, extra: str = "") -> ExperimentConfig:
    return tiny_config(STRUCTURE.format(law=law) + extra)


def test_a_structure_with_distributions_parses_and_its_nominal_structure_is_the_medians():
    config = _config()
    space = config.uncertain_parameters()
    assert space.names == ("damping_ratio", "stiffnesses.0", "story_law.yield_displacement")
    assert space.units == ("", "N/m", "m")
    nominal = config.structure.params
    assert nominal["stiffnesses"] == [4e7, 3e7, 2e7]
    assert nominal["damping_ratio"] == pytest.approx(0.05, rel=1e-15)
    assert nominal["story_law"] == {"name": "bilinear", "alpha": 0.05, "yield_displacement": 0.02}
    assert cp.create("structure", "shear-building", **nominal).n_stories == 3


def test_the_config_keeps_its_distributions_through_toml():
    config = _config(
        extra='[uncertainty]\ncorrelations = [["stiffnesses.0", "damping_ratio", 0.3]]'
    )
    again = cp.parse_config(tomllib.loads(config.to_toml()))
    assert again.to_dict() == config.to_dict()
    assert again.to_dict()["structure"]["stiffnesses"][0]["dist"] == "normal"
    np.testing.assert_array_equal(
        again.uncertain_parameters().correlation, config.uncertain_parameters().correlation
    )


def test_the_median_of_a_truncated_distribution_is_its_own():
    truncated_normal = '{ dist = "normal", mean = 0.02, std = 0.01, lower = 0.02 }'
    truncated_lognormal = '{ dist = "lognormal", median = 0.02, beta = 0.3, upper = 0.02 }'
    expected_normal = 0.02 + 0.01 * stats.norm.ppf(0.75)
    expected_lognormal = 0.02 * math.exp(0.3 * stats.norm.ppf(0.25))
    for law, expected in (
        (truncated_normal, expected_normal),
        (truncated_lognormal, expected_lognormal),
    ):
        law_params = _config(law).structure.params["story_law"]
        assert law_params["yield_displacement"] == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    ("law", "message"),
    [
        ('{ dist = "gamma", k = 2 }', r"\.dist: unknown distribution 'gamma': use one of normal"),
        ('{ dist = "normal", mean = 0.02 }', r"\.std: Field required"),
        ('{ dist = "lognormal", median = 0.02, beta = 0 }', r"\.beta: .*greater than 0"),
        ('{ dist = "lognormal", median = 0.02, beta = -0.1 }', r"\.beta: .*greater than 0"),
        (
            '{ dist = "normal", mean = 0.02, std = 0.001, lower = 0.1, upper = 0.2 }',
            r": .*truncation lower = 0.1 and upper = 0.2 leaves the distribution no probability",
        ),
        ('{ dist = "lognormal", median = 0.02, beta = 0.1, upper = -1 }', r": .*no probability"),
        ('{ dist = "uniform", low = 0.02, high = 0.03, upper = 0.01 }', r": .*no probability"),
        ('{ dist = "uniform", low = 0.03, high = 0.02 }', r": .*low = 0.03 exceeds high = 0.02"),
        ('{ dist = "normal", mean = 0.02, std = 0.01, scale = 2 }', r"\.scale: unknown field"),
    ],
)
def test_a_bad_distribution_is_named(law, message):
    with pytest.raises(cp.ConfigError, match=r"structure\.story_law\.yield_displacement" + message):
        _config(law)


def test_a_distribution_whose_median_is_not_a_valid_value_fails_as_that_value_would():
    text = STRUCTURE.format(law=LAW).replace(
        'mean = 4e7, std = 4e6, unit = "N/m"', "mean = -4e7, std = 4e6"
    )
    with pytest.raises(cp.ConfigError, match=r"structure\.stiffnesses.*greater than 0"):
        tiny_config(text)


@pytest.mark.parametrize(
    ("correlations", "message"),
    [
        ('[["stiffnesses.1", "damping_ratio", 0.3]]', r"'stiffnesses.1' is not a random"),
        ('[["stiffnesses.0", "stiffnesses.0", 0.3]]', r"with itself"),
        ('[["stiffnesses.0", "damping_ratio", 1.0]]', r"\.0\.2: .*less than 1"),
        (
            '[["stiffnesses.0", "damping_ratio", 0.3], ["damping_ratio", "stiffnesses.0", 0.3]]',
            r"correlated twice",
        ),
        (
            '[["stiffnesses.0", "damping_ratio", 0.9], ["stiffnesses.0", '
            '"story_law.yield_displacement", 0.9], ["damping_ratio", '
            '"story_law.yield_displacement", -0.9]]',
            r"not form a positive-definite matrix",
        ),
    ],
)
def test_bad_correlations_are_named(correlations, message):
    with pytest.raises(cp.ConfigError, match=r"uncertainty\.correlations.*" + message):
        _config(extra=f"[uncertainty]\ncorrelations = {correlations}\n")


def test_a_bad_fixed_parameter_beside_distributions_is_still_reported():
    text = STRUCTURE.format(law=LAW).replace("masses = [4.0e4, 3.0e4, 3.0e4]", "masses = [4.0e4]")
    with pytest.raises(cp.ConfigError, match="number of stories differs"):
        tiny_config(text)


def _space(correlations=()) -> UncertainParameters:
    return UncertainParameters.of(
        {
            "k": [{"dist": "normal", "mean": 4e7, "std": 4e6}, 3e7],
            "law": {"uy": {"dist": "lognormal", "median": 0.02, "beta": 0.3}},
            "zeta": {"dist": "uniform", "low": 0.02, "high": 0.06, "lower": 0.03},
            "fixed": {"dist": "uniform", "low": 2.5, "high": 2.5},
        },
        correlations,
    )


def test_draws_are_reproducible_by_seed_and_a_record_keeps_its_draw_for_any_count():
    space = _space([("k.0", "law.uy", 0.5)])
    assert space.names == ("fixed", "k.0", "law.uy", "zeta")
    many = space.draw(50, seed=3)
    assert many.shape == (50, 4) and many.dtype == np.float64
    np.testing.assert_array_equal(space.draw(50, seed=3), many)
    np.testing.assert_array_equal(space.draw(7, seed=3), many[:7])
    assert not np.array_equal(space.draw(50, seed=4), many)
    assert (many[:, 0] == 2.5).all()  # no spread: the one value, exactly
    assert many[:, 3].min() >= 0.03 and many[:, 3].max() <= 0.06


def test_draws_follow_their_distributions_and_correlations():
    n = 40_000
    space = _space([("k.0", "law.uy", 0.6), ("k.0", "zeta", -0.4)])
    draws = space.draw(n, seed=11)
    k, uy, zeta = draws[:, 1], draws[:, 2], draws[:, 3]
    assert k.mean() == pytest.approx(4e7, rel=2e-3)
    assert k.std() == pytest.approx(4e6, rel=2e-2)
    assert np.median(uy) == pytest.approx(0.02, rel=1e-2)
    assert np.log(uy).std() == pytest.approx(0.3, rel=2e-2)
    # the truncated uniform is uniform on [0.03, 0.06]
    assert stats.kstest(zeta, stats.uniform(0.03, 0.03).cdf).statistic < 0.01
    # the copula's correlation is that of the standard normal numbers behind the draws
    normal_scores = np.column_stack(
        [(k - 4e7) / 4e6, np.log(uy / 0.02) / 0.3, stats.norm.ppf((zeta - 0.03) / 0.03)]
    )
    correlation = np.corrcoef(normal_scores, rowvar=False)
    assert correlation[0, 1] == pytest.approx(0.6, abs=0.02)
    assert correlation[0, 2] == pytest.approx(-0.4, abs=0.02)
    assert correlation[1, 2] == pytest.approx(0.0, abs=0.02)
    assert np.corrcoef(k, uy)[0, 1] > 0.5


def test_a_truncated_normal_draws_from_its_truncated_distribution():
    space = UncertainParameters.of(
        {"x": {"dist": "normal", "mean": 1.0, "std": 2.0, "lower": 0.5, "upper": 6.0}}
    )
    x = space.draw(20_000, seed=0)[:, 0]
    assert x.min() >= 0.5 and x.max() <= 6.0
    expected = stats.truncnorm((0.5 - 1.0) / 2.0, (6.0 - 1.0) / 2.0, loc=1.0, scale=2.0)
    assert stats.kstest(x, expected.cdf).statistic < 0.012


def test_values_replace_numbers_or_distributions_at_their_paths_only():
    table = {
        "stiffnesses": [{"dist": "lognormal", "median": 4e7, "beta": 0.3}, 3e7],
        "story_law": {"name": "bilinear", "yield_displacement": 0.01},
    }
    replaced = with_values(table, {"stiffnesses.0": 5e7, "story_law.yield_displacement": 0.02})
    assert replaced == {
        "stiffnesses": [5e7, 3e7],
        "story_law": {"name": "bilinear", "yield_displacement": 0.02},
    }
    assert value_at(replaced, "stiffnesses.1") == 3e7
    with pytest.raises(cp.ConfigError, match="no number at stiffnesses.2, story_law.fy"):
        with_values(replaced, {"story_law.fy": 1.0, "stiffnesses.2": 1.0})
    with pytest.raises(cp.ConfigError, match="stiffnesses.0: a distribution was given no value"):
        with_values(table, {"stiffnesses.1": 1.0})
    with pytest.raises(cp.ConfigError, match="no number at story_law.name"):
        value_at(table, "story_law.name")


def test_distinct_draws_group_records_in_order_of_their_first():
    draws = np.array([[2.0, 1.0], [1.0, 1.0], [2.0, 1.0], [3.0, 0.0]])
    groups = distinct_draws(draws)
    assert [row.tolist() for row, _ in groups] == [[2.0, 1.0], [1.0, 1.0], [3.0, 0.0]]
    assert [rows.tolist() for _, rows in groups] == [[0, 2], [1], [3]]


@pytest.mark.parametrize(
    "table, words",
    [
        ({"dist": "lognormal", "median": 4e7, "beta": 0.3}, "lognormal, median 4e+07, β 0.3"),
        (
            {"dist": "normal", "mean": 0.05, "std": 0.01, "lower": 0.02},
            "normal, mean 0.05, σ 0.01, truncated ≥ 0.02",
        ),
        (
            {"dist": "uniform", "low": 1, "high": 2, "upper": 1.5},
            "uniform, 1 to 2, truncated ≤ 1.5",
        ),
    ],
)
def test_a_distribution_describes_itself(table, words):
    (parameter,) = UncertainParameters.of({"x": table}).parameters
    assert parameter.distribution.describe() == words


def test_test_tails_put_training_draws_in_the_centre_and_test_draws_beyond_it():
    space = UncertainParameters.of(
        {
            "a": {"dist": "normal", "mean": 0.0, "std": 1.0},
            "b": {"dist": "normal", "mean": 0.0, "std": 2.0},
        },
        test_tails=1.0,
    )
    draws = space.draw(4000, seed=3, n_central=3000)
    central, tails = draws[:3000] / [1.0, 2.0], draws[3000:] / [1.0, 2.0]
    assert np.abs(central).max() <= 1.0 and np.abs(tails).min() >= 1.0
    assert (tails < 0).mean() == pytest.approx(0.5, abs=0.05)
    # within each region, the draws follow the distribution restricted to it
    within = stats.truncnorm(-1.0, 1.0)
    assert stats.kstest(central[:, 0], within.cdf).pvalue > 0.01
    beyond = np.abs(tails[:, 1])
    assert stats.kstest(beyond, stats.truncnorm(1.0, np.inf).cdf).pvalue > 0.01
    # a record keeps its draw for any number of records, and a far edge changes nothing
    np.testing.assert_array_equal(space.draw(3100, seed=3, n_central=3000), draws[:3100])
    plain = UncertainParameters.of({"a": {"dist": "normal", "mean": 0.0, "std": 1.0}})
    far = UncertainParameters.of({"a": {"dist": "normal", "mean": 0.0, "std": 1.0}}, test_tails=9)
    np.testing.assert_allclose(far.draw(50, 1, n_central=50), plain.draw(50, 1), atol=1e-9)


def test_test_tails_reach_the_dataset_splits(tmp_path):
    text = """
[structure]
name = "shear-building"
masses = [4.0e4, 3.0e4]
stiffnesses = [{ dist = "lognormal", median = 4e7, beta = 0.3 }, 3e7]

[uncertainty]
test_tails = 1.0

[ground_motion]
name = "white-noise"
duration = 1.0

[[preprocessor]]
name = "els"

[operator]
name = "fno"

[data]
n_train = 4
n_val = 2
n_test = 4
executor = "serial"
"""
    config = cp.parse_config(tomllib.loads(text))
    cp.generate_dataset(config, tmp_path / "d.h5", progress=False)
    z = np.log(cp.load_dataset(tmp_path / "d.h5").params[:, 0] / 4e7) / 0.3
    assert np.abs(z[:6]).max() <= 1.0 + 1e-12 and np.abs(z[6:]).min() >= 1.0 - 1e-12
