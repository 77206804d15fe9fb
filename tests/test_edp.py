"""Engineering demand parameters against hand computation and an exact linear response."""

import numpy as np
import pytest
import scipy.signal
import toy_components

import cphysfno_core as cp
from cphysfno_core import edp
from cphysfno_core.plugin import LinearSystem, Rayleigh, Stories
from cphysfno_core.signals import ResponseChannel
from cphysfno_core.testing import small_motions

MASS, K1, K2 = 2.0e5, 4.0e7, 2.5e7  # kg, N/m: 1.3 and 3.1 Hz
H1, H2 = 4.0, 3.0  # m
TWO_STORIES = Stories.stacked([H1, H2])


def _two_story_system(damping_ratio: float = 0.0) -> LinearSystem:
    m = np.diag([MASS, MASS])
    k = np.array([[K1 + K2, -K2], [-K2, K2]])
    omega = np.sqrt(np.linalg.eigvalsh(np.linalg.solve(m, k)))
    rayleigh = Rayleigh.matching(omega[0], omega[1], damping_ratio)
    return LinearSystem(m, rayleigh.matrix(m, k), k, np.ones(2), np.eye(2))


def _harmonic_case(seconds: float = 2.0, dt: float = 0.01):
    """Steady state of the undamped two-story building under a_g = a0 sin(w t): u = U sin(w t)
    with (K - w^2 M) U = -M r a0."""
    a0, frequency = 1.5, 1.0  # m/s^2, Hz
    w = 2 * np.pi * frequency
    system = _two_story_system()
    amplitude = np.linalg.solve(
        system.stiffness - w**2 * system.mass, -system.mass @ np.ones(2) * a0
    )
    t = np.arange(int(round(seconds / dt)) + 1) * dt
    motions = cp.GroundMotions(a0 * np.sin(w * t), dt)
    u = amplitude[None, None, :] * np.sin(w * t)[None, :, None]
    return motions, u, amplitude, a0, w


def test_drift_ratios_and_floor_accelerations_match_the_hand_computation():
    motions, u, (u1, u2), a0, w = _harmonic_case()
    found = edp.compute(u, TWO_STORIES, motions)
    # sin(w t) reaches +-1 at t = 0.25 s, a sample: the peaks are the amplitudes.
    assert found.pid.shape == (1, 2) and found.rid.shape == (1, 2)
    np.testing.assert_allclose(found.pid[0], [abs(u1) / H1, abs(u2 - u1) / H2], rtol=1e-12)
    # Two whole cycles: the record ends at rest position, no residual drift.
    np.testing.assert_allclose(found.rid[0], 0.0, atol=1e-15)
    # Absolute floor acceleration (a0 - w^2 U_j) sin(w t), averaged over t +- dt with a
    # triangle: the second difference of u carries w^2 -> (2 - 2 cos(w dt)) / dt^2, the
    # ground's (a[k-1] + 4 a[k] + a[k+1]) / 6 carries a0 -> a0 (4 + 2 cos(w dt)) / 6 (the
    # average of the sine's linear interpolant): within (w dt)^2 / 12 and / 6 of the exact.
    dt = motions.dt
    discrete = (2 - 2 * np.cos(w * dt)) / dt**2
    ground = a0 * (4 + 2 * np.cos(w * dt)) / 6
    assert found.pfa.shape == (1, 3)
    np.testing.assert_allclose(
        found.pfa[0], [a0, abs(ground - discrete * u1), abs(ground - discrete * u2)], rtol=1e-9
    )
    exact = np.array([a0, abs(a0 - w**2 * u1), abs(a0 - w**2 * u2)])
    bound = (w * dt) ** 2 * (a0 / 6 + w**2 * np.abs([0.0, u1, u2]) / 12)
    assert np.all(np.abs(found.pfa[0] - exact) <= bound)
    named = edp.compute(u, TWO_STORIES, motions, output_names=("first", "second"))
    assert named.columns["PFA"] == ("ground", "first", "second")
    assert named.units["PFA"] == ("m/s^2",) * 3 and named.units["PID"] == ("m/m",) * 2


def test_the_same_function_takes_responses_a_structure_or_an_array():
    motions, u, *_ = _harmonic_case()
    structure = toy_components.StoriedToyStructure(heights_m=(H1, H2))
    from_array = edp.compute(u, TWO_STORIES, motions)
    from_responses = edp.compute(cp.Responses(u, motions.dt), structure, motions)
    for key, values in from_array.values.items():
        np.testing.assert_array_equal(values, from_responses.values[key])


def test_residual_drift_is_the_mean_over_the_free_vibration():
    dt, strong, tail = 0.01, 1.0, 2.0
    n_strong, n_tail = int(strong / dt), int(tail / dt)
    t = np.arange(n_strong + n_tail + 1) * dt
    ag = np.where(t <= strong, np.sin(2 * np.pi * t), 0.0)
    motions = cp.GroundMotions(ag, dt)
    # Floor 1 settles at 10 mm, floor 2 at 4 mm, both oscillating at 2 Hz about it: the
    # second half of the tail (1 s) holds two whole periods, whose mean is the set.
    wobble = 0.003 * np.sin(2 * np.pi * 2.0 * t)
    u = np.stack([0.010 + wobble, 0.004 + 2 * wobble], axis=-1)[None]
    found = edp.compute(u, TWO_STORIES, motions, free_vibration_s=tail)
    np.testing.assert_allclose(found.rid[0], [0.010 / H1, 0.006 / H2], rtol=1e-9)
    last_sample = edp.compute(u, TWO_STORIES, motions)
    np.testing.assert_allclose(last_sample.rid[0], np.abs(u[0, -1] - [0, u[0, -1, 0]]) / [H1, H2])
    with pytest.raises(cp.InputError, match="ground still moves in the last 1.5 s"):
        edp.compute(u, TWO_STORIES, cp.GroundMotions(np.sin(t), dt), free_vibration_s=1.5)
    with pytest.raises(cp.InputError, match="not shorter than the records"):
        edp.compute(u, TWO_STORIES, motions, free_vibration_s=5.0)


def test_padding_with_free_vibration_appends_zero_ground_motion():
    motions = small_motions(n_records=2, n_steps=50, dt=0.02)
    padded = edp.pad_free_vibration(motions, 1.0)
    assert padded.n_steps == 100 and padded.dt == motions.dt
    np.testing.assert_array_equal(padded.acceleration[:, :50], motions.acceleration)
    assert not padded.acceleration[:, 50:].any()
    structure = toy_components.StoriedToyStructure()
    responses = structure.simulate(padded)
    found = edp.compute(responses, structure, padded, free_vibration_s=1.0)
    assert found.rid.shape == (2, 2) and np.all(found.rid <= found.pid)


def test_floor_acceleration_from_displacement_agrees_with_the_exact_linear_response():
    """A damped linear two-story building: lsim gives the displacement and, independently,
    the exact absolute acceleration -M^-1 (C u' + K u). The second difference of the
    displacement with the ground acceleration averaged alike gives the peaks within 0.5 %
    (the building at 1.3 and 3.1 Hz, dt = 0.01 s: sinc^2(3.1 * 0.01) is 0.3 % short of
    1)."""
    system = _two_story_system(damping_ratio=0.05)
    motions = small_motions(n_records=3, n_steps=801, dt=0.01, peak=2.0, seed=3)
    a, b = system.state_space()
    n = system.n_dof
    minv = np.linalg.inv(system.mass)
    c = np.vstack(
        [
            np.hstack([np.eye(n), np.zeros((n, n))]),
            -minv @ np.hstack([system.stiffness, system.damping]),
        ]
    )
    lti = scipy.signal.StateSpace(a, b[:, None], c, np.zeros((2 * n, 1)))
    displacement, acceleration = [], []
    for ag in motions.acceleration:
        _, y, _ = scipy.signal.lsim(lti, ag, motions.time)
        displacement.append(y[:, :n])
        acceleration.append(y[:, n:])
    u, exact = np.array(displacement), np.array(acceleration)
    found = edp.compute(u, TWO_STORIES, motions)
    peaks = np.max(np.abs(exact), axis=1)
    np.testing.assert_allclose(found.pfa[:, 1:], peaks, rtol=0.005)
    # With the exact acceleration as an extra channel, PFA is its peak.
    responses = cp.Responses(u, motions.dt, extras={edp.ACCELERATION_EXTRA: exact})
    np.testing.assert_allclose(edp.compute(responses, TWO_STORIES, motions).pfa[:, 1:], peaks)
    np.testing.assert_allclose(found.pfa[:, 0], np.max(np.abs(motions.acceleration), axis=1))


def test_a_bridge_like_structure_has_one_story_per_pier_top():
    motions, u, (u1, u2), *_ = _harmonic_case()
    piers = Stories((None, None), (0, 1), (6.3, 8.1))
    found = edp.compute(u, piers, motions)
    np.testing.assert_allclose(found.pid[0], [abs(u1) / 6.3, abs(u2) / 8.1], rtol=1e-12)


def test_the_interval_holds_every_history_that_stays_in_the_band():
    rng = np.random.default_rng(0)
    motions, u, *_ = _harmonic_case()
    motions = cp.GroundMotions(np.repeat(motions.acceleration, 20, axis=0), motions.dt)
    mean = np.repeat(u, 20, axis=0) * rng.uniform(0.5, 1.5, (20, 1, 2))
    std = 0.2 * np.abs(mean).max() * rng.uniform(0.2, 1.0, (20, 1, 2))
    inside = mean + std * rng.uniform(-1.0, 1.0, mean.shape)
    bounds = edp.interval(mean, std, TWO_STORIES, motions, k=1.0)
    truth = edp.compute(inside, TWO_STORIES, motions)
    assert bounds.coverage(truth) == {"PID": [1.0, 1.0], "RID": [1.0, 1.0]}
    assert np.all(bounds.pid_lower <= bounds.pid_upper)
    point = edp.interval(mean, std, TWO_STORIES, motions, k=0.0)
    centre = edp.compute(mean, TWO_STORIES, motions)
    np.testing.assert_allclose(point.pid_lower, centre.pid)
    np.testing.assert_allclose(point.pid_upper, centre.pid)
    np.testing.assert_allclose(point.rid_upper, centre.rid)
    outside = mean + 3 * std
    assert min(bounds.coverage(edp.compute(outside, TWO_STORIES, motions))["PID"]) < 1.0


def test_log_errors_are_quantiles_of_the_log_ratio():
    truth = edp.EDPs.from_tables(
        {
            "PID": np.array([[0.01, 0.02], [0.02, 0.04], [0.03, 0.0]]),
            "RID": np.zeros((3, 2)),
            "PFA": np.array([[1.0, 2.0, 3.0]] * 3),
        },
        TWO_STORIES,
    )
    predicted = truth.with_values(
        {
            "PID": truth.pid * np.array([[1.1], [1 / 1.2], [1.0]]),
            "RID": truth.rid,
            "PFA": truth.pfa * 2.0,
        }
    )
    errors = edp.log_errors(predicted, truth)
    np.testing.assert_allclose(errors["PID"]["median"], [np.log(1.1), np.log(1.1 * 1.2) / 2])
    np.testing.assert_allclose(errors["PID"]["p90"][1], np.log(1.2) - 0.1 * np.log(1.2 / 1.1))
    np.testing.assert_allclose(errors["PFA"]["median"], [np.log(2.0)] * 2)
    assert len(errors["PFA"]["p90"]) == 2  # floors above the ground only
    assert set(errors) == {"PID", "PFA"}  # RID is not scored


def test_wrong_inputs_are_refused_with_what_to_change():
    motions, u, *_ = _harmonic_case()
    with pytest.raises(cp.InputError, match="do not match motions"):
        edp.compute(u[:, :-1], TWO_STORIES, motions)
    with pytest.raises(cp.InputError, match="there are 1 outputs"):
        edp.compute(u[:, :, :1], TWO_STORIES, motions)
    with pytest.raises(cp.InputError, match="compute EDPs on the motions' own grid"):
        edp.compute(cp.Responses(u, 0.02), TWO_STORIES, motions)
    with pytest.raises(cp.CapabilityError, match="to provide stories"):
        edp.compute(u, toy_components.ToyStructure(), motions)
    with pytest.raises(cp.InputError, match="k must be"):
        edp.interval(u, np.ones_like(u), TWO_STORIES, motions, k=-1.0)
    nan = u.copy()
    nan[0, 50:] = np.nan
    assert np.isnan(edp.compute(nan, TWO_STORIES, motions).pid).all()


def test_a_composite_models_prediction_gets_edps_and_drift_bounds(trained_toy):
    model, motions = trained_toy
    mean, std = model.predict(motions)
    predicted = edp.compute(mean, TWO_STORIES, motions)
    assert predicted.pid.shape == (12, 2) and predicted.pfa.shape == (12, 3)
    bounds = edp.interval(mean, std, TWO_STORIES, motions, k=1.0)
    assert np.all(bounds.pid_lower <= predicted.pid) and np.all(predicted.pid <= bounds.pid_upper)
    assert np.all(bounds.rid_lower <= predicted.rid) and np.all(predicted.rid <= bounds.rid_upper)


def test_floor_velocities_and_output_displacements_match_the_hand_computation():
    motions, u, (u1, u2), a0, w = _harmonic_case()
    found = edp.compute(u, TWO_STORIES, motions)
    # Absolute velocity U w cos(w t) + v_g(t), v_g = a0 / w (1 - cos(w t)) from rest; the
    # centred difference and the trapezoidal v_g are within (w dt)^2 / 6 of it.
    t = motions.time[1:-1]
    ground = a0 / w * (1 - np.cos(w * motions.time))
    exact = [np.max(np.abs(amplitude * w * np.cos(w * t) + ground[1:-1])) for amplitude in (u1, u2)]
    assert found["PFV"].shape == (1, 3) and found.units["PFV"] == ("m/s",) * 3
    np.testing.assert_allclose(
        found["PFV"][0], [2 * a0 / w, *exact], rtol=(w * motions.dt) ** 2 / 6
    )
    np.testing.assert_allclose(found["pd"][0], [abs(u1), abs(u2)], rtol=1e-12)
    assert found.columns["PD"] == ("output-1", "output-2")
    assert "PR" not in found.values  # no named responses recorded


def test_a_named_responses_peak_is_its_largest_magnitude_in_its_unit():
    motions, u, *_ = _harmonic_case()
    shear = -3.0 * np.sin(2 * np.pi * motions.time)[None, :, None]
    channel = ResponseChannel("base_shear", "kN", pelicun_type="VB")
    responses = cp.Responses(u, motions.dt, extras={"base_shear": shear})
    found = edp.compute(responses, TWO_STORIES, motions, channels=[channel])
    np.testing.assert_allclose(found["PR"], [[3.0]], rtol=1e-12)
    assert found.columns["PR"] == ("base_shear",) and found.units["PR"] == ("kN",)
    with pytest.raises(cp.InputError, match="no named response 'isolator'"):
        edp.compute(responses, TWO_STORIES, motions, channels=[ResponseChannel("isolator", "m")])


def test_an_unknown_edp_is_an_error_that_lists_the_known_ones():
    with pytest.raises(cp.ConfigError, match="unknown EDP 'PGX'.*PID .*PFV "):
        edp.definition("PGX")
    motions, u, *_ = _harmonic_case()
    found = edp.compute(u, TWO_STORIES, motions)
    with pytest.raises(cp.ConfigError, match="unknown EDP"):
        found["drift"]
    with pytest.raises(cp.ConfigError, match="PR .* was not computed"):
        found["pr"]
    assert list(edp.EDP_TABLE) == ["PID", "RID", "PFA", "PFV", "PD", "PR"]
