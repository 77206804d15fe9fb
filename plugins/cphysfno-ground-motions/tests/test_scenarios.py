"""Recorded shapes scaled to intensities drawn from BSSA14 for scenarios in a window."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.stats
from cphysfno_core import ConfigError, create
from cphysfno_core.signals.intensity import response_spectrum

from cphysfno_ground_motions.target import bssa14_target

WINDOW = {"magnitude": [5.0, 7.0], "rjb_km": [15.0, 50.0], "vs30": [180.0, 1800.0]}


@pytest.fixture(scope="module")
def motions():
    source = create(
        "ground_motion",
        "recorded",
        dt=0.02,
        duration=20.0,
        copies=6,
        intensity_scenarios={**WINDOW, "period": 1.0},
    )
    return source.sample(120, np.random.default_rng(4))


def test_each_record_has_the_psa_of_its_drawn_scenario(motions):
    psa = response_spectrum(motions.acceleration, motions.dt, [1.0]).pseudo_acceleration[:, 0]
    target = np.array([m["target_psa"] for m in motions.metadata])
    np.testing.assert_allclose(psa, target, rtol=1e-9)
    for meta in motions.metadata[:5]:
        site = min(meta["scenario_vs30"], 1500.0)
        model = bssa14_target(meta["scenario_magnitude"], meta["scenario_rjb_km"],
                              site, "U", "global", np.array([1.0]))  # fmt: skip
        expected = model.median[0] * np.exp(meta["epsilon"] * model.ln_std[0])
        assert meta["target_psa"] == pytest.approx(expected, rel=1e-12)
        assert 5.0 <= meta["scenario_magnitude"] <= 7.0
        assert 15.0 <= meta["scenario_rjb_km"] <= 50.0
        assert 180.0 <= meta["scenario_vs30"] <= 1800.0


def test_the_draws_fill_the_window_and_epsilon_is_standard_normal(motions):
    epsilon = np.array([m["epsilon"] for m in motions.metadata])
    magnitude = np.array([m["scenario_magnitude"] for m in motions.metadata])
    assert scipy.stats.kstest(epsilon, "norm").pvalue > 0.01
    assert magnitude.min() < 5.3 and magnitude.max() > 6.7
    assert len({m["rsn"] for m in motions.metadata}) > 20  # many recordings, not one


def test_scenarios_and_a_scale_range_exclude_each_other():
    with pytest.raises(ConfigError, match="scale_range or intensity_scenarios, not both"):
        create("ground_motion", "recorded", scale_range=[0.5, 1.0],
               intensity_scenarios={**WINDOW, "period": 1.0})  # fmt: skip
