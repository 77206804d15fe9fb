"""Small components registered by the core's tests, so the core is tested without plugins."""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import numpy as np
import torch
from pydantic import Field

import cphysfno_core as cp
from cphysfno_core import plugin
from cphysfno_core.plugin import (
    GroundMotionSource,
    NeuralOperator,
    PhysicsPreprocessor,
    Refiner,
    Registry,
    Stories,
    Structure,
    hookimpl,
)


class ToyStructure(Structure):
    """Two independent damped oscillators with a cubic spring, integrated by RK4."""

    name = "toy-structure"

    class Params(plugin.Params):
        frequencies_hz: tuple[float, float] = (1.0, 3.0)
        cubic: float = 0.0
        delay_s: float = 0.0

    @property
    def output_names(self):
        return ("dof-1", "dof-2")

    def periods(self, n=None):
        return (1.0 / np.asarray(self.params.frequencies_hz))[:n]

    def simulate(self, motions, *, dt=None):
        time.sleep(self.params.delay_s)
        w = 2 * np.pi * np.asarray(self.params.frequencies_hz)
        ag = motions.acceleration
        n, steps = ag.shape
        u = np.zeros((n, 2))
        v = np.zeros((n, 2))
        out = np.zeros((n, steps, 2))

        def accel(u, v, a):
            return -a[:, None] - 2 * 0.05 * w * v - w**2 * (u + self.params.cubic * u**3)

        h = motions.dt
        for k in range(steps - 1):
            a0, a1 = ag[:, k], ag[:, k + 1]
            am = 0.5 * (a0 + a1)
            k1u, k1v = v, accel(u, v, a0)
            k2u, k2v = v + 0.5 * h * k1v, accel(u + 0.5 * h * k1u, v + 0.5 * h * k1v, am)
            k3u, k3v = v + 0.5 * h * k2v, accel(u + 0.5 * h * k2u, v + 0.5 * h * k2v, am)
            k4u, k4v = v + h * k3v, accel(u + h * k3u, v + h * k3v, a1)
            u = u + h / 6 * (k1u + 2 * k2u + 2 * k3u + k4u)
            v = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
            out[:, k + 1] = u
        return cp.Responses(out, motions.dt)


class StoriedToyStructure(ToyStructure):
    """The toy structure read as a two-story building: output 0 is the first floor, output
    1 the second, stories of ``heights_m`` (m)."""

    name = "toy-storied"
    capabilities = frozenset({"stories"})

    class Params(ToyStructure.Params):
        heights_m: tuple[float, float] = (3.0, 2.5)

    def stories(self):
        return Stories.stacked(self.params.heights_m)


class AcceleratingToyStructure(StoriedToyStructure):
    """The storied toy structure that also returns the absolute acceleration of each output
    (the extra ``absolute_acceleration``, m/s^2): by its equations, minus the damping and
    spring forces per unit mass (velocities by central differences)."""

    name = "toy-accelerating"

    def simulate(self, motions, *, dt=None):
        u = super().simulate(motions, dt=dt).displacement
        v = np.gradient(u, motions.dt, axis=1)
        w = 2 * np.pi * np.asarray(self.params.frequencies_hz)
        absolute = -2 * 0.05 * w * v - w**2 * (u + self.params.cubic * u**3)
        return cp.Responses(u, motions.dt, extras={"absolute_acceleration": absolute})


class ReactingToyStructure(AcceleratingToyStructure):
    """The accelerating toy structure that also records a named response: ``base_shear``
    (kN), minus the floors' inertia forces with a mass of 1 t each, minus the sum of their
    absolute accelerations."""

    name = "toy-reacting"
    BASE_SHEAR = plugin.ResponseChannel(
        "base_shear", "kN", "minus the inertia forces", pelicun_type="VB", pelicun_location=0
    )

    def response_channels(self):
        return (self.BASE_SHEAR,)

    def simulate(self, motions, *, dt=None):
        responses = super().simulate(motions, dt=dt)
        absolute = responses.extras["absolute_acceleration"]
        shear = -absolute.sum(axis=2, keepdims=True)
        extras = {**responses.extras, "base_shear": shear}
        return cp.Responses(responses.displacement, motions.dt, extras=extras)


class FragileStructure(ToyStructure):
    """The toy structure, failing on records whose peak |a_g| exceeds ``limit``: with NaN
    output (``mode = "nan"``), an exception (``mode = "raise"``) or NaN rows named in
    ``Responses.failures`` (``mode = "report"``). ``calls`` counts simulations."""

    name = "toy-fragile"

    class Params(ToyStructure.Params):
        limit: float = 1.0
        mode: str = "nan"

    calls = 0

    def simulate(self, motions, *, dt=None):
        FragileStructure.calls += 1
        responses = super().simulate(motions, dt=dt)
        broken = np.max(np.abs(motions.acceleration), axis=1) > self.params.limit
        if broken.any() and self.params.mode == "raise":
            raise cp.CphysfnoError("Newton did not converge")
        displacement = responses.displacement.copy()
        displacement[broken] = np.nan
        failures = {}
        if self.params.mode == "report":
            failures = {
                int(i): "Newton did not converge at t = 1.5 s" for i in np.flatnonzero(broken)
            }
        return cp.Responses(displacement, responses.dt, failures=failures)


class WrongShapeStructure(ToyStructure):
    """Returns one output too few: a broken plugin."""

    name = "toy-wrong-shape"

    def simulate(self, motions, *, dt=None):
        responses = super().simulate(motions, dt=dt)
        return cp.Responses(responses.displacement[:, :, :1], responses.dt)


class DyingOnceStructure(ToyStructure):
    """The toy structure, except that the first simulation anywhere kills its process
    (it leaves ``marker`` behind so that the next attempt lives)."""

    name = "toy-dying-once"

    class Params(ToyStructure.Params):
        marker: str

    def simulate(self, motions, *, dt=None):
        marker = Path(self.params.marker)
        if not marker.exists():
            marker.write_text(str(os.getpid()))
            os._exit(1)
        return super().simulate(motions, dt=dt)


class ToySource(GroundMotionSource):
    """Band-limited random accelerations."""

    name = "toy-source"
    independent_draws = True

    class Params(plugin.Params):
        n_steps: int = Field(200, gt=1)
        dt: float = Field(0.02, gt=0)
        scale: float = 1.0

    def sample(self, n, rng):
        return _smooth_noise(n, rng, self.params)


def _smooth_noise(n, rng, params):
    raw = rng.standard_normal((n, params.n_steps))
    smooth = np.cumsum(raw, axis=1)
    smooth -= np.linspace(0, 1, params.n_steps) * smooth[:, -1:]
    return cp.GroundMotions(params.scale * smooth, params.dt)


class ToyRecordSet(ToySource):
    """A finite set of ``size`` toy records, drawn without replacement (so not independent
    draws); asked for more, it returns all it has."""

    name = "toy-record-set"
    independent_draws = False

    class Params(ToySource.Params):
        size: int = 12

    def sample(self, n, rng):
        pool = _smooth_noise(self.params.size, np.random.default_rng(0), self.params)
        return pool[rng.permutation(self.params.size)[: min(n, self.params.size)]]


class ToyPreprocessor(PhysicsPreprocessor):
    """The linear part of the toy structure (cubic term dropped)."""

    name = "toy-linear"

    def fit(self, structure):
        self.structure_ = ToyStructure(frequencies_hz=structure.params.frequencies_hz)
        return self

    def transform(self, motions):
        if not hasattr(self, "structure_"):
            raise cp.NotFittedError("fit first")
        return self.structure_.simulate(motions).displacement

    def write_artifacts(self, directory):
        directory.mkdir(parents=True, exist_ok=True)
        summary = directory / "summary.md"
        frequencies = self.structure_.params.frequencies_hz
        summary.write_text(f"Toy linear oscillators at {frequencies} Hz.\n")
        return [summary]

    def restore(self, structure, directory):
        self.restored_from_ = directory if (directory / "summary.md").exists() else None
        return self.fit(structure)


class FragilePreprocessor(ToyPreprocessor):
    """The toy linear part, NaN for the records whose peak ground acceleration exceeds
    ``limit``: a physics simulation that fails on them. ``calls`` counts transforms."""

    name = "toy-fragile-linear"

    class Params(plugin.Params):
        limit: float = 1e9

    calls = 0

    def transform(self, motions):
        FragilePreprocessor.calls += 1
        z = super().transform(motions)
        z[np.max(np.abs(motions.acceleration), axis=1) > self.params.limit] = np.nan
        return z


class NeedsLinearSystem(PhysicsPreprocessor):
    """A preprocessor that needs a capability the toy structure lacks."""

    name = "needs-linear-system"
    requires = frozenset({"linear_system"})

    def fit(self, structure):
        self.check(structure)
        return self

    def transform(self, motions):
        raise AssertionError("never reached")


class ToyOperator(NeuralOperator):
    """A pointwise two-layer network (no coupling in time)."""

    name = "toy-operator"

    class Params(plugin.Params):
        width: int = Field(8, gt=0)

    def __init__(self, in_channels, out_channels, **hyper):
        super().__init__(in_channels, out_channels, **hyper)
        self.net = torch.nn.Sequential(
            torch.nn.Linear(in_channels, self.params.width),
            torch.nn.Tanh(),
            torch.nn.Linear(self.params.width, out_channels),
        )

    def forward(self, x):
        return self.net(x)


class OtherToyOperator(ToyOperator):
    """The toy operator under another name, for configs with several operators."""

    name = "other-toy-operator"


class ToyRefiner(Refiner):
    """Mean = operator output + a constant offset per DOF; std = residual std."""

    name = "toy-refiner"

    def fit(self, z, u_hat, u, rng):
        self.offset_ = np.mean(u - u_hat, axis=(0, 1))
        self.sigma_ = np.std(u - u_hat - self.offset_, axis=(0, 1))
        return self

    def predict(self, z, u_hat):
        if not hasattr(self, "offset_"):
            raise cp.NotFittedError("fit first")
        return u_hat + self.offset_, np.broadcast_to(self.sigma_, u_hat.shape)

    def state_dict(self):
        return {"offset": self.offset_, "sigma": self.sigma_}

    def load_state_dict(self, state):
        self.offset_, self.sigma_ = state["offset"], state["sigma"]


class CalibratedToyRefiner(ToyRefiner):
    """The toy refiner, calibrated on the validation split; ``fitted_on`` keeps the number
    of records it was fitted on."""

    name = "toy-calibrated-refiner"
    calibration_split = "validation"

    def fit(self, z, u_hat, u, rng):
        self.fitted_on = z.shape[0]
        return super().fit(z, u_hat, u, rng)


@hookimpl
def cphysfno_structures():
    return [
        ToyStructure,
        StoriedToyStructure,
        AcceleratingToyStructure,
        ReactingToyStructure,
        DyingOnceStructure,
        FragileStructure,
        WrongShapeStructure,
    ]


@hookimpl
def cphysfno_ground_motions():
    return [ToySource, ToyRecordSet]


@hookimpl
def cphysfno_preprocessors():
    return [ToyPreprocessor, FragilePreprocessor, NeedsLinearSystem]


@hookimpl
def cphysfno_operators():
    return [ToyOperator, OtherToyOperator]


@hookimpl
def cphysfno_refiners():
    return [ToyRefiner, CalibratedToyRefiner]


@contextlib.contextmanager
def registered(*plugins: ModuleType) -> Iterator[Registry]:
    """The global registry, while the block runs, of the toy components and ``plugins``
    (modules with hook implementations) alone, no installed plugin loaded."""
    from cphysfno_core.api.registry import set_registry

    registry = Registry(autoload=False, plugins=(sys.modules[__name__], *plugins))
    set_registry(registry)
    try:
        yield registry
    finally:
        set_registry(None)
