"""Shared test material: a small hysteretic building with a tight-tolerance reference
simulator, variants of it that lack capabilities, references for linear systems, and the
registry's Example 1 components (the Bouc-Wen and ground-motion plugins are test
dependencies of this one)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.signal import lsim

from cphysfno_core import GroundMotions, Responses, create
from cphysfno_core.plugin import LinearSystem, Structure

RTOL = 1e-10


def _relative_l2(z: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``[n_outputs]`` sqrt(sum (z - u)^2 / sum u^2) over records and time."""
    return np.sqrt(np.sum((z - u) ** 2, axis=(0, 1)) / np.sum(u**2, axis=(0, 1)))


def _lsim_response(system: LinearSystem, motions: GroundMotions) -> np.ndarray:
    """``[n, T, n_outputs]`` linear response from scipy.signal.lsim (linear input hold)."""
    n = system.n_dof
    a = np.block(
        [
            [np.zeros((n, n)), np.eye(n)],
            [
                -np.linalg.solve(system.mass, system.stiffness),
                -np.linalg.solve(system.mass, system.damping),
            ],
        ]
    )
    b = np.concatenate([np.zeros(n), -system.influence])[:, None]
    c = np.hstack([system.output_map, np.zeros_like(system.output_map)])
    d = np.zeros((c.shape[0], 1))
    out = [lsim((a, b, c, d), record, motions.time)[1] for record in motions.acceleration]
    return np.stack([np.reshape(y, (motions.n_steps, -1)) for y in out])


def _band_limited_motions(
    n: int, duration: float, dt: float, peak: float, rng: np.random.Generator
) -> GroundMotions:
    """``n`` records of random sinusoids (1-15 Hz) under a smooth envelope, peak ``peak`` m/s^2."""
    t = np.arange(round(duration / dt) + 1) * dt
    frequency = rng.uniform(1.0, 15.0, size=(n, 12, 1))
    phase = rng.uniform(0.0, 2 * np.pi, size=(n, 12, 1))
    ag = np.sin(2 * np.pi * frequency * t + phase).sum(axis=1)
    ag *= np.sin(np.pi * t / t[-1]) ** 2 + 0.2
    ag *= peak / np.abs(ag).max(axis=1, keepdims=True)
    return GroundMotions(ag, dt)


class StoryHysteresis:
    """Smooth Bouc-Wen story shears of a shear building (RestoringForce protocol).

    Story ``i`` drift ``v_i = u_i - u_{i-1}``; shear ``k_i (alpha v_i + (1 - alpha) h_i)`` with
    ``h_i' = v_i' - (|v_i'|_e h_i^3 + v_i' |h_i|^3) / (2 u_y^3)`` (h in m), where
    ``|x|_e = sqrt(x^2 + e^2)`` rounds the kink of ``|v_i'|`` so that tight references are cheap.
    """

    velocity_rounding = 5e-3

    def __init__(self, stiffness: np.ndarray, alpha: float, yield_drift: float) -> None:
        self.stiffness = stiffness
        self.alpha = alpha
        self.yield_drift = yield_drift
        self.n_states = stiffness.size

    def initial_state(self, n_records: int) -> np.ndarray:
        return np.zeros((n_records, self.n_states))

    def force(self, u: np.ndarray, state: np.ndarray) -> np.ndarray:
        drift = np.diff(u, axis=1, prepend=0.0)
        shear = self.stiffness * (self.alpha * drift + (1 - self.alpha) * state)
        return shear - np.concatenate([shear[:, 1:], np.zeros_like(shear[:, :1])], axis=1)

    def state_rate(self, u: np.ndarray, velocity: np.ndarray, state: np.ndarray) -> np.ndarray:
        rate = np.diff(velocity, axis=1, prepend=0.0)
        speed = np.sqrt(rate**2 + self.velocity_rounding**2)
        ratio = state / self.yield_drift
        return rate - 0.5 * (speed * ratio**3 + rate * np.abs(ratio) ** 3)


class ToyBuilding(Structure):
    """Three-story hysteretic shear building; outputs floor 1, floor 3 and the top drift.

    :meth:`simulate` integrates the motion (linear between its samples, or between the
    samples of its resampling at a coarser ``dt``) with DOP853 at rtol 1e-10.
    """

    name = "toy-building"
    capabilities = frozenset({"linear_system", "restoring_force", "coarse_simulation"})
    masses = np.array([2.0e3, 2.0e3, 1.5e3])
    story_stiffness = np.array([4.0e6, 3.0e6, 2.0e6])
    influence = np.ones(3)
    output_map = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 1.0]])

    @property
    def output_names(self) -> tuple[str, ...]:
        return ("floor-1", "floor-3", "drift-3")

    def stiffness_matrix(self) -> np.ndarray:
        k = self.story_stiffness
        upper = np.append(k[1:], 0.0)
        return np.diag(k + upper) - np.diag(k[1:], 1) - np.diag(k[1:], -1)

    def elastic_model(self) -> LinearSystem:
        mass, stiffness = np.diag(self.masses), self.stiffness_matrix()
        damping = 0.3 * mass + 1.5e-3 * stiffness
        return LinearSystem(mass, damping, stiffness, self.influence, self.output_map)

    def hysteresis(self) -> StoryHysteresis:
        return StoryHysteresis(self.story_stiffness, alpha=0.2, yield_drift=2e-3)

    def linear_system(self) -> LinearSystem:
        return self.elastic_model()

    def restoring_force(self) -> StoryHysteresis:
        return self.hysteresis()

    def periods(self, n: int | None = None) -> np.ndarray:
        omega2 = np.sort(
            np.linalg.eigvals(np.linalg.solve(np.diag(self.masses), self.stiffness_matrix())).real
        )
        return (2 * np.pi / np.sqrt(omega2))[:n]

    def simulate(self, motions: GroundMotions, *, dt: float | None = None) -> Responses:
        if dt is not None:
            motions = motions.resample(dt)
        system, hysteresis = self.elastic_model(), self.hysteresis()
        n, n_dof = motions.n_records, system.n_dof
        ag, step = motions.acceleration, motions.dt
        damping = np.linalg.solve(system.mass, system.damping)

        def rate(t: float, y: np.ndarray, k: int) -> np.ndarray:
            u, v, h = np.split(y.reshape(n, 3 * n_dof), 3, axis=1)
            a = ag[:, k] + (ag[:, k + 1] - ag[:, k]) * (t / step - k)
            accel = -v @ damping.T - hysteresis.force(u, h) / self.masses - a[:, None]
            return np.concatenate([v, accel, hysteresis.state_rate(u, v, h)], axis=1).ravel()

        states = np.zeros((motions.n_steps, n * 3 * n_dof))
        for k in range(motions.n_steps - 1):
            interval = solve_ivp(
                rate,
                (k * step, (k + 1) * step),
                states[k],
                method="DOP853",
                args=(k,),
                rtol=RTOL,
                atol=1e-14,
            )
            states[k + 1] = interval.y[:, -1]
        u = states.reshape(-1, n, 3 * n_dof)[:, :, :n_dof].transpose(1, 0, 2)
        return Responses(u @ self.output_map.T, motions.dt)


class ToyWithoutRestoringForce(ToyBuilding):
    """The toy building with only a linear system and fine-grid simulation."""

    name = "toy-without-restoring-force"
    capabilities = frozenset({"linear_system"})
    restoring_force = Structure.restoring_force


class ToyWithoutLinearSystem(ToyBuilding):
    """The toy building that exposes no linear system."""

    name = "toy-without-linear-system"
    capabilities = frozenset({"restoring_force", "coarse_simulation"})
    linear_system = Structure.linear_system


@pytest.fixture(scope="session")
def relative_l2():
    """sqrt(sum (z - u)^2 / sum u^2) per output, over records and time."""
    return _relative_l2


@pytest.fixture(scope="session")
def lsim_response():
    """The response of a LinearSystem to GroundMotions from scipy.signal.lsim."""
    return _lsim_response


@pytest.fixture(scope="session")
def toy() -> ToyBuilding:
    return ToyBuilding()


@pytest.fixture(scope="session")
def toy_motions() -> GroundMotions:
    """Three 4-s records at dt = 0.01 s that yield the toy building (ELS rel. L2 about 0.5)."""
    return _band_limited_motions(3, 4.0, 0.01, 1.0, np.random.default_rng(7))


@pytest.fixture(scope="session")
def toy_truth(toy: ToyBuilding, toy_motions: GroundMotions) -> np.ndarray:
    return toy.simulate(toy_motions).displacement


def _registered(kind: str, name: str, **params):
    """A registry component; a missing plugin fails the test with the registry's message."""
    return create(kind, name, **params)


@pytest.fixture(scope="session")
def building() -> Structure:
    """The Example 1 Bouc-Wen building from its plugin."""
    return _registered("structure", "bouc-wen-shear-building")


@pytest.fixture(scope="session")
def paper_motions() -> GroundMotions:
    """Twelve §5.1 white-noise records (30 s at 0.01 s) from the ground-motion plugin."""
    return _registered("ground_motion", "white-noise").sample(12, np.random.default_rng(2024))


@pytest.fixture(scope="session")
def paper_truth(building: Structure, paper_motions: GroundMotions) -> np.ndarray:
    return building.simulate(paper_motions).displacement


@pytest.fixture(scope="session")
def toy_without_restoring_force() -> ToyWithoutRestoringForce:
    return ToyWithoutRestoringForce()


@pytest.fixture(scope="session")
def toy_without_linear_system() -> ToyWithoutLinearSystem:
    return ToyWithoutLinearSystem()
