import os

import numpy as np
import pytest

import cphysfno_core as cp
from cphysfno_core.plugin import LinearSystem, Rayleigh
from cphysfno_core.signals import record_slices, run_in_slices, usable_cpus


def test_ground_motions_carry_their_time_step():
    gm = cp.GroundMotions(np.zeros((3, 11)), dt=0.5)
    assert gm.n_records == 3 and gm.n_steps == 11
    np.testing.assert_allclose(gm.time, np.arange(11) * 0.5)
    assert gm.duration == 5.0
    assert cp.GroundMotions(np.zeros(11), 0.1).acceleration.shape == (1, 11)


@pytest.mark.parametrize(
    "ag, dt, message",
    [
        (np.zeros((2, 3, 4)), 0.01, r"shape \[n_records, n_steps\], got shape \(2, 3, 4\)"),
        (np.array([[0.0, np.nan, 1.0]]), 0.01, "NaN or Inf \\(first in record 0\\)"),
        (np.array([[0.0, 1.0], [np.inf, 0.0]]), 0.01, "first in record 1"),
        (np.zeros((2, 5)), 0.0, "dt must be a finite time step > 0 s"),
        (np.zeros((2, 5)), -0.01, "dt must be a finite time step > 0 s"),
        (np.zeros((2, 5)), "fast", "dt must be a number of seconds"),
        (np.zeros((2, 1)), 0.01, "at least 2 time steps"),
        ([["a", "b"]], 0.01, "numeric array"),
        (np.ones((1, 3), dtype=complex), 0.01, "must be real"),
    ],
)
def test_bad_ground_motions_say_what_to_change(ag, dt, message):
    with pytest.raises(cp.InputError, match=message):
        cp.GroundMotions(ag, dt)


def test_metadata_must_match_the_records():
    with pytest.raises(cp.InputError, match="metadata has 1 entries for 2 records"):
        cp.GroundMotions(np.zeros((2, 4)), 0.1, metadata=[{"a": 1}])


def test_indexing_keeps_metadata_and_batch():
    gm = cp.GroundMotions(np.arange(12.0).reshape(3, 4), 0.1, [{"i": i} for i in range(3)])
    one = gm[1]
    assert one.acceleration.shape == (1, 4)
    assert one.metadata == ({"i": 1},)
    assert [m["i"] for m in gm[np.array([2, 0])].metadata] == [2, 0]


def test_resample_is_linear_between_samples_and_holds_the_end():
    gm = cp.GroundMotions(np.array([[0.0, 1.0, 0.0, 2.0]]), dt=1.0)
    coarse = gm.resample(2.0)  # grid 0, 2, 4 covers the 3 s record; 4 s holds the end
    np.testing.assert_allclose(coarse.acceleration, [[0.0, 0.0, 2.0]])
    fine = gm.resample(0.5)
    np.testing.assert_allclose(fine.acceleration, [[0, 0.5, 1, 0.5, 0, 1, 2]])
    longer = gm.resample(2.5)  # grid 0, 2.5, 5
    np.testing.assert_allclose(longer.acceleration, [[0.0, 1.0, 2.0]])


def test_linear_system_checks_shapes():
    eye = np.eye(2)
    system = LinearSystem(eye, eye, eye, np.ones(2), eye)
    assert system.n_dof == 2
    with pytest.raises(cp.InputError, match=r"stiffness must be \[2, 2\]"):
        LinearSystem(eye, eye, np.eye(3), np.ones(2), eye)


def test_state_space_of_a_single_oscillator_is_the_textbook_one():
    m, c, k = 2.0, 0.3, 50.0
    system = LinearSystem([[m]], [[c]], [[k]], [1.0], [[1.0]])
    a, b = system.state_space()
    np.testing.assert_allclose(a, [[0.0, 1.0], [-k / m, -c / m]])
    np.testing.assert_allclose(b, [0.0, -1.0])


def test_rayleigh_damping_matches_its_ratio_at_both_frequencies():
    damping = Rayleigh.matching(2.0, 12.0, 0.05)
    # a0 = 2 zeta w_a w_b / (w_a + w_b), a1 = 2 zeta / (w_a + w_b)
    assert damping.mass_factor == pytest.approx(2 * 0.05 * 24.0 / 14.0)
    assert damping.stiffness_factor == pytest.approx(0.1 / 14.0)
    np.testing.assert_allclose(damping.ratio(np.array([2.0, 12.0])), 0.05)
    assert damping.ratio(np.sqrt(24.0)) < 0.05  # least damped between the two
    mass, stiffness = np.diag([2.0, 1.0]), np.array([[3.0, -1.0], [-1.0, 1.0]])
    np.testing.assert_allclose(
        damping.matrix(mass, stiffness),
        damping.mass_factor * mass + damping.stiffness_factor * stiffness,
    )
    with pytest.raises(cp.InputError, match="Rayleigh frequencies"):
        Rayleigh.matching(0.0, 12.0, 0.05)


def test_usable_cpus_are_those_the_process_may_run_on(monkeypatch):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {3}, raising=False)
    assert usable_cpus() == 1  # a container or taskset limited to one CPU
    monkeypatch.delattr(os, "sched_getaffinity")  # a platform without affinity sets
    monkeypatch.setattr(os, "cpu_count", lambda: 6)
    assert usable_cpus() == 6
    monkeypatch.setattr(os, "cpu_count", lambda: None)
    assert usable_cpus() == 1


@pytest.mark.parametrize(
    "n_records, granule, workers, expected",
    [
        (100, 8, 2, [(0, 48), (48, 100)]),  # 13 granules: 6 and 7, cut on a granule
        (5, 8, 4, [(0, 5)]),  # fewer granules than workers: one slice
        (10, 1, 3, [(0, 3), (3, 6), (6, 10)]),
        (16, 8, 4, [(0, 8), (8, 16)]),
        (0, 8, 2, []),
    ],
)
def test_record_slices_cover_the_records_on_granule_bounds(n_records, granule, workers, expected):
    slices = record_slices(n_records, granule, workers)
    assert [(s.start, s.stop) for s in slices] == expected


def test_run_in_slices_calls_the_kernel_on_every_record_once(monkeypatch):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1, 2}, raising=False)
    seen = np.zeros(37, dtype=int)

    def kernel(rows: slice) -> None:
        assert rows.start % 4 == 0
        seen[rows] += 1

    run_in_slices(kernel, 37, 4)
    np.testing.assert_array_equal(seen, 1)
    run_in_slices(kernel, 0, 4)  # no records: the kernel is not called
    np.testing.assert_array_equal(seen, 1)
