"""Conformance checks every component of a kind must pass, for plugin authors' tests.

Each ``check_*`` function raises ``AssertionError`` with a message naming the component and
the broken promise, and returns nothing when the component conforms::

    from cphysfno_core.testing import check_structure
    check_structure(MyBuilding())

The checks use small inputs (a few records, a few hundred samples) so that they run in
seconds.
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import torch

from ..api.interfaces import (
    GroundMotionSource,
    NeuralOperator,
    PhysicsPreprocessor,
    Refiner,
    Structure,
)
from ..signals import GroundMotions, LinearSystem, Responses, Stories, StoryPushover
from ..signals.errors import CapabilityError, CphysfnoError, InputError, NotFittedError
from ..signals.pushover import cyclic_protocol
from .physics import check_linear_physics, smooth_random_motions


def _fail(component: Any, message: str) -> AssertionError:
    return AssertionError(f"{getattr(component, 'name', type(component).__name__)}: {message}")


def small_motions(
    n_records: int = 2, n_steps: int = 301, dt: float = 0.01, peak: float = 0.5, seed: int = 0
) -> GroundMotions:
    """Smooth random accelerations (m/s^2) of moderate amplitude for quick checks."""
    return smooth_random_motions(n_records, n_steps, dt, peak, seed, window=9)


def _check_response(component: Any, values: np.ndarray, shape: tuple, what: str) -> None:
    values = np.asarray(values)
    if values.shape != shape:
        raise _fail(component, f"{what} has shape {values.shape}, expected {shape}")
    if values.dtype != np.float64:
        raise _fail(component, f"{what} must be float64, got {values.dtype}")
    if not np.isfinite(values).all():
        raise _fail(component, f"{what} holds NaN or Inf for moderate input")


def check_structure(structure: Structure) -> None:
    """Shapes and units of ``simulate``, any T, at rest stays at rest, determinism,
    elastic periods, declared stories (indices in range, heights > 0), and each capability
    it claims, including that the capabilities describe the physics of ``simulate``
    (:func:`~.physics.check_linear_physics`)."""
    names = structure.output_names
    if not names or len(names) != structure.n_outputs:
        raise _fail(structure, "output_names must name every output")
    for n_steps in (201, 333):
        motions = small_motions(n_steps=n_steps)
        responses = structure.simulate(motions)
        if not isinstance(responses, Responses):
            raise _fail(structure, "simulate must return cphysfno_core.Responses")
        if responses.dt != motions.dt:
            raise _fail(structure, f"response dt {responses.dt} s != motion dt {motions.dt} s")
        shape = (motions.n_records, n_steps, structure.n_outputs)
        _check_response(structure, responses.displacement, shape, "displacement")
    again = structure.simulate(motions).displacement
    if not np.array_equal(again, responses.displacement):
        raise _fail(structure, "simulate is not deterministic")
    rest = structure.simulate(GroundMotions(np.zeros((1, 101)), 0.01)).displacement
    if np.max(np.abs(rest)) != 0.0:
        raise _fail(structure, "a structure at rest under zero ground motion must stay at rest")
    periods = np.asarray(structure.periods(2))
    if periods.shape != (min(2, len(structure.periods())),) or not (periods > 0).all():
        raise _fail(structure, f"periods(2) must be positive seconds, got {periods}")
    if (np.diff(structure.periods()) > 0).any():
        raise _fail(structure, "periods() must list the longest period first")
    _check_declared_capabilities(structure)
    capabilities = structure.capabilities
    if "linear_system" in capabilities:
        system = structure.linear_system()
        if not isinstance(system, LinearSystem):
            raise _fail(structure, "linear_system() must return cphysfno_core.LinearSystem")
        if system.output_map.shape[0] != structure.n_outputs:
            raise _fail(structure, "linear_system().output_map must have one row per output")
    else:
        _expect(structure, CapabilityError, structure.linear_system)
    if "stories" in capabilities:
        _check_stories(structure)
    else:
        _expect(structure, CapabilityError, structure.stories)
    if "pushover" in capabilities:
        if structure.stories().has_heights:  # a pushover by drift ratio needs heights
            _check_pushover(structure)
    else:
        _expect(structure, CapabilityError, structure.story_pushover, np.zeros(2))
    if "coarse_simulation" in capabilities:
        coarse = structure.simulate(motions, dt=3 * motions.dt)
        n_coarse = int(np.ceil(motions.duration / (3 * motions.dt) - 1e-9)) + 1
        shape = (motions.n_records, n_coarse, structure.n_outputs)
        _check_response(structure, coarse.displacement, shape, "coarse displacement")
    check_linear_physics(structure)


CAPABILITY_METHODS = {
    "linear_system": "linear_system",
    "restoring_force": "restoring_force",
    "projected_simulation": "simulate_projected",
    "stories": "stories",
    "pushover": "story_pushover",
}
"""Capabilities provided by overriding one method of :class:`Structure`."""


def _check_declared_capabilities(structure: Structure) -> None:
    """A capability is declared in ``capabilities`` exactly where its method is defined."""
    declared = structure.capabilities
    for capability, method in CAPABILITY_METHODS.items():
        defined = getattr(type(structure), method) is not getattr(Structure, method)
        if defined and capability not in declared:
            raise _fail(
                structure,
                f"defines {method}() but does not declare '{capability}' in its capabilities",
            )
        if capability in declared and not defined:
            raise _fail(structure, f"declares '{capability}' but does not define {method}()")
    own = type(structure).equivalent_linear_system is not Structure.equivalent_linear_system
    if "equivalent_linear_system" in declared and "linear_system" not in declared and not own:
        raise _fail(
            structure,
            "declares 'equivalent_linear_system' but defines neither linear_system() nor "
            "equivalent_linear_system()",
        )


def _check_stories(structure: Structure) -> None:
    """``stories()`` returns :class:`~cphysfno_core.signals.Stories` whose indices name the
    structure's outputs and whose heights are finite and > 0 m (or ``nan``, a story without
    height), the same on every call."""
    stories = structure.stories()
    if not isinstance(stories, Stories):
        raise _fail(structure, "stories() must return cphysfno_core.Stories")
    try:  # a Stories built by hand past its constructor's checks is checked again here
        Stories(stories.lower, stories.upper, stories.heights_m)
        stories.check_outputs(structure.n_outputs)
    except InputError as error:
        raise _fail(structure, f"stories(): {error}") from None
    again = structure.stories()
    same_heights = np.array_equal(again.heights_m, stories.heights_m, equal_nan=True)
    if (again.lower, again.upper) != (stories.lower, stories.upper) or not same_heights:
        raise _fail(structure, "stories() must return the same stories on every call")


def _check_pushover(structure: Structure) -> None:
    """``story_pushover`` over a small cyclic protocol returns a
    :class:`~cphysfno_core.signals.StoryPushover` of one curve per story, the stories' heights,
    positive masses and a pattern summing to 1; it starts at zero shear and drift, its story
    drifts add up to the roof's displacement, and every story's initial slope is positive."""
    protocol = cyclic_protocol([1e-4, 2e-4], points_per_cycle=8)
    curves = structure.story_pushover(protocol)
    if not isinstance(curves, StoryPushover):
        raise _fail(structure, "story_pushover must return cphysfno_core.StoryPushover")
    heights = np.asarray(structure.stories().heights_m)
    if curves.n_stories != heights.size or not np.allclose(curves.heights, heights):
        raise _fail(structure, "story_pushover must give every story of stories() its height")
    if curves.stopped or curves.roof_drift_ratio.shape != protocol.shape:
        raise _fail(structure, f"story_pushover stopped at small drifts: {curves.stopped}")
    if not (np.all(curves.masses > 0) and np.isclose(curves.pattern.sum(), 1.0)):
        raise _fail(structure, "story_pushover: masses must be > 0 kg and the pattern sum to 1")
    for what, values in (("story_drift", curves.story_drift), ("story_shear", curves.story_shear)):
        if not np.all(np.isfinite(values)) or np.any(values[0] != 0.0):
            raise _fail(structure, f"story_pushover: {what} must be finite and start at 0")
    roof = curves.story_drift.sum(axis=1)
    if not np.allclose(roof, protocol * heights.sum(), rtol=1e-6, atol=1e-9 * heights.sum()):
        raise _fail(structure, "story_pushover: the story drifts do not add up to the roof's")
    if not np.all(curves.initial_stiffness > 0):
        raise _fail(structure, "story_pushover: every story's initial slope must be > 0 N/m")


def _expect(component: Any, error: type[BaseException], call, *args: Any) -> None:
    try:
        call(*args)
    except error:
        return
    except Exception as other:
        message = f"expected {error.__name__}, got {type(other).__name__}: {other}"
        raise _fail(component, message) from other
    raise _fail(component, f"expected {error.__name__}, nothing was raised")


def check_ground_motion_source(source: GroundMotionSource, n: int = 3) -> None:
    """``sample`` returns GroundMotions of at most ``n`` finite records, deterministic under
    a seed."""
    first = source.sample(n, np.random.default_rng(123))
    if not isinstance(first, GroundMotions):
        raise _fail(source, "sample must return cphysfno_core.GroundMotions")
    if not 1 <= first.n_records <= n:
        raise _fail(source, f"sample({n}) returned {first.n_records} records")
    second = source.sample(n, np.random.default_rng(123))
    if not np.array_equal(first.acceleration, second.acceleration) or first.dt != second.dt:
        raise _fail(source, "sample is not deterministic under the same seed")


def check_preprocessor(preprocessor: PhysicsPreprocessor, structure: Structure) -> None:
    """Not usable before ``fit``; ``z`` of shape ``[n, T, n_outputs]`` in float64 on the
    motion's own grid at any T; zero motion gives zero z; deterministic."""
    fresh = copy.deepcopy(preprocessor)
    _expect(preprocessor, NotFittedError, fresh.transform, small_motions())
    if fresh.fit(structure) is not fresh:
        raise _fail(preprocessor, "fit must return the preprocessor itself")
    for n_steps in (201, 334):
        motions = small_motions(n_steps=n_steps)
        z = fresh.transform(motions)
        shape = (motions.n_records, n_steps, structure.n_outputs)
        _check_response(preprocessor, z, shape, "z")
    if not np.array_equal(fresh.transform(motions), z):
        raise _fail(preprocessor, "transform is not deterministic")
    rest = fresh.transform(GroundMotions(np.zeros((1, 101)), 0.01))
    if np.max(np.abs(rest)) != 0.0:
        raise _fail(preprocessor, "zero ground motion must give zero z")


def check_operator(cls: type[NeuralOperator], **hyper: Any) -> None:
    """Build with ``(in_channels=3, out_channels=2, **hyper)``: output ``[b, T, 2]`` at any
    T, gradients reach every parameter, a state-dict round trip reproduces the output, the
    state dict holds tensors only, under bfloat16 autocast (``precision="bfloat16"`` in
    prediction and training) the output stays within 5 % of float32's and the gradients
    within 25 %, ``zero_output_()`` zeroes the output without stopping it from learning,
    and a wrong input raises the package's own error."""
    torch.manual_seed(0)
    operator = cls(3, 2, **hyper)
    for steps in (64, 101):
        x = torch.randn(2, steps, 3)
        y = operator(x)
        if tuple(y.shape) != (2, steps, 2):
            raise _fail(operator, f"output shape {tuple(y.shape)} for input {tuple(x.shape)}")
    y.square().mean().backward()
    missing = [n for n, p in operator.named_parameters() if p.grad is None or not p.grad.any()]
    if missing:
        raise _fail(operator, f"no gradient reaches {', '.join(missing)}")
    state = operator.state_dict()
    if not all(isinstance(v, torch.Tensor) for v in state.values()):
        raise _fail(operator, "state_dict must hold tensors only")
    torch.manual_seed(1)
    rebuilt = cls(3, 2, **hyper)
    rebuilt.load_state_dict(state)
    operator.eval()
    rebuilt.eval()
    with torch.no_grad():
        if not torch.equal(operator(x), rebuilt(x)):
            raise _fail(operator, "a state_dict round trip changes the output")
    _check_bfloat16(operator, x)
    _check_zero_start(cls, hyper, x)
    _expect(operator, CphysfnoError, operator, torch.randn(2, 50, 4))


def _check_zero_start(cls: type[NeuralOperator], hyper: dict[str, Any], x: torch.Tensor) -> None:
    """After ``zero_output_()`` the output is zero, and one optimiser step towards a
    non-zero target moves it (the residual formulation starts from the physics response)."""
    torch.manual_seed(2)
    operator = cls(3, 2, **hyper)
    operator.zero_output_()
    with torch.no_grad():
        if operator(x).abs().max() != 0:
            raise _fail(operator, "after zero_output_() the output is not zero")
    optimiser = torch.optim.Adam(operator.parameters(), lr=1e-2)
    (operator(x) - 1.0).square().mean().backward()
    optimiser.step()
    with torch.no_grad():
        if operator(x).abs().max() == 0:
            raise _fail(operator, "after zero_output_() one optimiser step leaves the output zero")


def _check_bfloat16(operator: NeuralOperator, x: torch.Tensor) -> None:
    """Under ``torch.autocast`` to bfloat16 the operator answers within 5 % of float32, and
    its gradients (training's ``precision = "bfloat16"``) reach every parameter in the
    parameter's dtype, finite and within 25 % of float32's."""
    with torch.no_grad():
        single = operator(x)
    reference = _gradients(operator, x, autocast=False)
    try:
        with torch.no_grad(), torch.autocast(x.device.type, dtype=torch.bfloat16):
            low = operator(x).float()
        gradients = _gradients(operator, x, autocast=True)
    except Exception as error:
        message = f"fails under torch.autocast to bfloat16: {type(error).__name__}: {error}"
        raise _fail(operator, message) from error
    if low.shape != single.shape or not (low - single).norm() <= 0.05 * single.norm():
        raise _fail(operator, "under torch.autocast to bfloat16 the output strays from float32's")
    for (name, parameter), grad in zip(operator.named_parameters(), gradients, strict=True):
        if grad is None or grad.dtype != parameter.dtype or not torch.isfinite(grad).all():
            raise _fail(operator, f"under bfloat16 autocast, {name} gets no finite gradient")
    exact_all = torch.cat([g.flatten() for g in reference])
    low_all = torch.cat([g.flatten() for g in gradients])
    if not (low_all - exact_all).norm() <= 0.25 * exact_all.norm():
        raise _fail(operator, "under bfloat16 autocast the gradients stray from float32's")


def _gradients(operator: NeuralOperator, x: torch.Tensor, autocast: bool) -> list:
    """Gradients of a fixed loss of the operator's output, with or without bfloat16
    autocast."""
    operator.zero_grad(set_to_none=True)
    with torch.autocast(x.device.type, dtype=torch.bfloat16, enabled=autocast):
        y = operator(x)
    y.float().square().mean().backward()
    gradients = [p.grad for p in operator.parameters()]
    operator.zero_grad(set_to_none=True)
    return gradients


def check_refiner(refiner: Refiner) -> None:
    """Not usable before ``fit``; ``(mean, std)`` of the input shape with std >= 0; a
    state-dict round trip into a fresh instance reproduces the prediction; deterministic
    under the same rng."""
    rng = np.random.default_rng(0)
    z = rng.standard_normal((6, 80, 2))
    u_hat = z + 0.1 * rng.standard_normal(z.shape)
    u = 0.5 * z + 0.5 * u_hat + 0.05 * rng.standard_normal(z.shape)
    fresh = copy.deepcopy(refiner)
    _expect(refiner, NotFittedError, fresh.predict, z, u_hat)
    if fresh.fit(z, u_hat, u, np.random.default_rng(1)) is not fresh:
        raise _fail(refiner, "fit must return the refiner itself")
    mean, std = fresh.predict(z, u_hat)
    for what, values in (("mean", mean), ("std", std)):
        _check_response(refiner, np.asarray(values), z.shape, what)
    if (np.asarray(std) < 0).any():
        raise _fail(refiner, "std must be >= 0")
    twin = copy.deepcopy(refiner)
    twin.load_state_dict(fresh.state_dict())
    if not np.array_equal(twin.predict(z, u_hat)[0], mean):
        raise _fail(refiner, "a state_dict round trip changes the prediction")
    again = copy.deepcopy(refiner).fit(z, u_hat, u, np.random.default_rng(1))
    if not np.array_equal(again.predict(z, u_hat)[0], mean):
        raise _fail(refiner, "fit is not deterministic under the same rng")
