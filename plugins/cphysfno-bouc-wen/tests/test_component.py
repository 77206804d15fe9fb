"""Registration, parameters, outputs and input checks of the structure."""

from __future__ import annotations

import cphysfno_core
import numpy as np
import pytest
from cphysfno_core import ConfigError, CphysfnoError, GroundMotions, InputError
from cphysfno_core.plugin import get_registry

from cphysfno_bouc_wen import BoucWenShearBuilding, explicit


def test_registry_builds_it_by_name() -> None:
    building = cphysfno_core.create("structure", "bouc-wen-shear-building", damping_ratio=0.02)
    assert isinstance(building, BoucWenShearBuilding)
    assert building.params.damping_ratio == 0.02
    entry = get_registry().entry("structure", "bouc-wen-shear-building")
    assert entry.distribution.startswith("cphysfno-bouc-wen")
    assert building.capabilities == {
        "linear_system",
        "equivalent_linear_system",
        "restoring_force",
        "coarse_simulation",
        "stories",
        "projected_simulation",
        "pushover",
    }


def test_defaults_follow_the_design() -> None:
    building = BoucWenShearBuilding()
    assert building.output_names == ("story-1", "story-2", "story-3", "story-4", "story-5")
    assert building.delta == pytest.approx(0.5 / 0.01**3)
    assert building.zeta == pytest.approx(0.5 / 0.01**3)
    assert BoucWenShearBuilding(delta=1e5).delta == 1e5


def test_other_story_counts_work(white_noise) -> None:
    building = BoucWenShearBuilding(masses=[2e4, 2e4], stiffnesses=[4e7, 2e7])
    assert building.output_names == ("story-1", "story-2")
    assert building.periods().shape == (2,)
    motion = GroundMotions(white_noise(1, seed=0, duration=2.0), 0.01)
    responses = building.simulate(motion)
    assert responses.displacement.shape == (1, 201, 2)


def test_extras_are_drifts_and_shears(white_noise) -> None:
    building = BoucWenShearBuilding()
    responses = building.simulate(GroundMotions(white_noise(2, seed=3, duration=5.0), 0.01))
    u = responses.displacement
    drift, shear = responses.extras["story_drift"], responses.extras["story_shear"]
    assert drift.shape == shear.shape == u.shape
    np.testing.assert_allclose(drift, np.diff(u, axis=2, prepend=0.0), atol=1e-15)
    stiffness = np.array([7.5e7, 7.0e7, 6.0e7, 4.5e7, 2.5e7])
    hysteretic = (shear / stiffness - 0.1 * drift) / 0.9
    assert np.abs(hysteretic).max() <= 0.01 * (1 + 1e-6)


def test_every_length_and_record_count_is_written_in_place(white_noise) -> None:
    """Outputs leave the integrator in windows of samples and blocks of records: a record
    cut short, or simulated among other records, gives the start of the same response."""
    window, lanes = explicit.WINDOW, explicit.LANES
    ag = white_noise(lanes + 3, seed=11, duration=(2 * window + 1) * 0.01)
    building = BoucWenShearBuilding()
    whole = building.simulate(GroundMotions(ag, 0.01))
    assert np.abs(whole.displacement[:, -1]).min() > 0.0
    for length in (2, window - 1, window, window + 1, 2 * window + 2):
        for records in (slice(lanes + 2, lanes + 3), slice(0, lanes + 3)):
            part = building.simulate(GroundMotions(ag[records, :length], 0.01))
            for name in ("story_drift", "story_shear"):
                np.testing.assert_array_equal(
                    part.extras[name], whole.extras[name][records, :length], err_msg=name
                )
            np.testing.assert_array_equal(part.displacement, whole.displacement[records, :length])


@pytest.mark.parametrize(
    ("params", "field"),
    [
        ({"masses": [3e4, 3e4], "stiffnesses": [1e7]}, "stiffnesses"),
        ({"masses": [3e4, -1.0, 3e4, 3e4, 3e4]}, "masses.1"),
        ({"masses": []}, "masses"),
        ({"stiffnesses": [1e7, 1e7, 0.0, 1e7, 1e7]}, "stiffnesses.2"),
        ({"alpha": 1.5}, "alpha"),
        ({"exponent": 0.5}, "exponent"),
        ({"A": 0.0}, "A"),
        ({"yield_displacement": -0.01}, "yield_displacement"),
        ({"delta": float("inf")}, "delta"),
        ({"zeta": -1.0}, "zeta"),
        ({"damping_ratio": 1.0}, "damping_ratio"),
        ({"substeps": 0}, "substeps"),
        ({"precision": "float16"}, "precision"),
        ({"mass": 3e4}, "mass"),
    ],
)
def test_bad_params_name_the_field(params: dict, field: str) -> None:
    with pytest.raises(ConfigError, match=rf"bouc-wen-shear-building\.{field}:"):
        cphysfno_core.create("structure", "bouc-wen-shear-building", **params)


@pytest.mark.parametrize("n", [0, 6, 2.5, True])
def test_bad_period_counts(n) -> None:
    with pytest.raises(ConfigError, match="n must be"):
        BoucWenShearBuilding().periods(n)


def test_motions_must_be_ground_motions() -> None:
    with pytest.raises(InputError, match="GroundMotions"):
        BoucWenShearBuilding().simulate(np.zeros((1, 10)))


def test_an_unstable_explicit_step_is_reported(white_noise) -> None:
    motion = GroundMotions(white_noise(2, seed=4, dt=0.05, duration=10.0), 0.05)
    with pytest.raises(CphysfnoError, match="diverged for record 0.*raise substeps"):
        BoucWenShearBuilding(substeps=1).simulate(motion)
