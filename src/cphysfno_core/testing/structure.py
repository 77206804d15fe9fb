"""The conformance checks of a structure: its contract (shapes and units of ``simulate``,
rest, determinism, periods, declared capabilities) and the physics its capabilities
describe (:mod:`.physics`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..api.interfaces import Structure
from ..signals import GroundMotions, LinearSystem, Responses, Stories, StoryPushover
from ..signals.errors import CapabilityError, InputError
from ..signals.pushover import cyclic_protocol
from .helpers import check_array, expect, fail, small_motions
from .physics import physics_checks

CAPABILITY_METHODS = {
    "linear_system": "linear_system",
    "restoring_force": "restoring_force",
    "projected_simulation": "simulate_projected",
    "stories": "stories",
    "pushover": "story_pushover",
}
"""Capabilities provided by overriding one method of :class:`Structure`."""


def check_outputs_are_named(structure: Structure) -> None:
    """``output_names`` names every output."""
    names = structure.output_names
    if not names or len(names) != structure.n_outputs:
        raise fail(structure, "output_names must name every output")


def check_simulate_shape(structure: Structure) -> None:
    """``simulate`` returns :class:`~cphysfno_core.signals.Responses` on the motions' own
    grid at any T: displacement ``[n, T, n_outputs]``, finite float64 (m)."""
    for n_steps in (201, 333):
        motions = small_motions(n_steps=n_steps)
        responses = structure.simulate(motions)
        if not isinstance(responses, Responses):
            raise fail(structure, "simulate must return cphysfno_core.Responses")
        if responses.dt != motions.dt:
            raise fail(structure, f"response dt {responses.dt} s != motion dt {motions.dt} s")
        shape = (motions.n_records, n_steps, structure.n_outputs)
        check_array(structure, responses.displacement, shape, "displacement")


def check_simulate_is_deterministic(structure: Structure) -> None:
    """Two simulations of the same motions give the same displacements."""
    motions = small_motions(n_steps=101)
    first = structure.simulate(motions).displacement
    if not np.array_equal(structure.simulate(motions).displacement, first):
        raise fail(structure, "simulate is not deterministic")


def check_rest_stays_at_rest(structure: Structure) -> None:
    """Under zero ground motion the structure does not move."""
    rest = structure.simulate(GroundMotions(np.zeros((1, 101)), 0.01)).displacement
    if np.max(np.abs(rest)) != 0.0:
        raise fail(structure, "a structure at rest under zero ground motion must stay at rest")


def check_periods(structure: Structure) -> None:
    """``periods(n)`` gives up to ``n`` positive elastic periods (s), the longest first."""
    periods = np.asarray(structure.periods(2))
    if periods.shape != (min(2, len(structure.periods())),) or not (periods > 0).all():
        raise fail(structure, f"periods(2) must be positive seconds, got {periods}")
    if (np.diff(structure.periods()) > 0).any():
        raise fail(structure, "periods() must list the longest period first")


def check_declared_capabilities(structure: Structure) -> None:
    """A capability is declared in ``capabilities`` exactly where its method is defined."""
    declared = structure.capabilities
    for capability, method in CAPABILITY_METHODS.items():
        defined = getattr(type(structure), method) is not getattr(Structure, method)
        if defined and capability not in declared:
            raise fail(
                structure,
                f"defines {method}() but does not declare '{capability}' in its capabilities",
            )
        if capability in declared and not defined:
            raise fail(structure, f"declares '{capability}' but does not define {method}()")
    own = type(structure).equivalent_linear_system is not Structure.equivalent_linear_system
    if "equivalent_linear_system" in declared and "linear_system" not in declared and not own:
        raise fail(
            structure,
            "declares 'equivalent_linear_system' but defines neither linear_system() nor "
            "equivalent_linear_system()",
        )


def check_undeclared_capabilities_refuse(structure: Structure) -> None:
    """``linear_system``, ``stories`` and ``story_pushover`` raise
    :class:`~cphysfno_core.CapabilityError` where their capability is not declared."""
    for capability, call, args in (
        ("linear_system", structure.linear_system, ()),
        ("stories", structure.stories, ()),
        ("pushover", structure.story_pushover, (np.zeros(2),)),
    ):
        if capability not in structure.capabilities:
            expect(structure, CapabilityError, call, *args)


def check_linear_system(structure: Structure) -> None:
    """``linear_system()`` is a :class:`~cphysfno_core.signals.LinearSystem` with one
    output row per output."""
    system = structure.linear_system()
    if not isinstance(system, LinearSystem):
        raise fail(structure, "linear_system() must return cphysfno_core.LinearSystem")
    if system.output_map.shape[0] != structure.n_outputs:
        raise fail(structure, "linear_system().output_map must have one row per output")


def check_stories(structure: Structure) -> None:
    """``stories()`` returns :class:`~cphysfno_core.signals.Stories` whose indices name the
    structure's outputs and whose heights are finite and > 0 m (or ``nan``, a story without
    height), the same on every call."""
    stories = structure.stories()
    if not isinstance(stories, Stories):
        raise fail(structure, "stories() must return cphysfno_core.Stories")
    try:  # a Stories built by hand past its constructor's checks is checked again here
        Stories(stories.lower, stories.upper, stories.heights_m)
        stories.check_outputs(structure.n_outputs)
    except InputError as error:
        raise fail(structure, f"stories(): {error}") from None
    again = structure.stories()
    same_heights = np.array_equal(again.heights_m, stories.heights_m, equal_nan=True)
    if (again.lower, again.upper) != (stories.lower, stories.upper) or not same_heights:
        raise fail(structure, "stories() must return the same stories on every call")


def check_pushover(structure: Structure) -> None:
    """``story_pushover`` over a small cyclic protocol returns a
    :class:`~cphysfno_core.signals.StoryPushover` of one curve per story, the stories'
    heights, positive masses and a pattern summing to 1; it starts at zero shear and drift,
    its story drifts add up to the roof's displacement, and every story's initial slope is
    positive. A structure whose stories have no heights is not checked: a pushover by
    drift ratio needs them."""
    if not structure.stories().has_heights:
        return
    protocol = cyclic_protocol([1e-4, 2e-4], points_per_cycle=8)
    curves = structure.story_pushover(protocol)
    if not isinstance(curves, StoryPushover):
        raise fail(structure, "story_pushover must return cphysfno_core.StoryPushover")
    heights = np.asarray(structure.stories().heights_m)
    if curves.n_stories != heights.size or not np.allclose(curves.heights, heights):
        raise fail(structure, "story_pushover must give every story of stories() its height")
    if curves.stopped or curves.roof_drift_ratio.shape != protocol.shape:
        raise fail(structure, f"story_pushover stopped at small drifts: {curves.stopped}")
    if not (np.all(curves.masses > 0) and np.isclose(curves.pattern.sum(), 1.0)):
        raise fail(structure, "story_pushover: masses must be > 0 kg and the pattern sum to 1")
    for what, values in (("story_drift", curves.story_drift), ("story_shear", curves.story_shear)):
        if not np.all(np.isfinite(values)) or np.any(values[0] != 0.0):
            raise fail(structure, f"story_pushover: {what} must be finite and start at 0")
    roof = curves.story_drift.sum(axis=1)
    if not np.allclose(roof, protocol * heights.sum(), rtol=1e-6, atol=1e-9 * heights.sum()):
        raise fail(structure, "story_pushover: the story drifts do not add up to the roof's")
    if not np.all(curves.initial_stiffness > 0):
        raise fail(structure, "story_pushover: every story's initial slope must be > 0 N/m")


def check_coarse_simulation_shape(structure: Structure) -> None:
    """``simulate(motions, dt=3 dt)`` answers on the coarse grid that spans the motions."""
    motions = small_motions(n_steps=333)
    coarse = structure.simulate(motions, dt=3 * motions.dt)
    n_coarse = int(np.ceil(motions.duration / (3 * motions.dt) - 1e-9)) + 1
    shape = (motions.n_records, n_coarse, structure.n_outputs)
    check_array(structure, coarse.displacement, shape, "coarse displacement")


_CAPABILITY_CHECKS = {
    "linear_system": check_linear_system,
    "stories": check_stories,
    "pushover": check_pushover,
    "coarse_simulation": check_coarse_simulation_shape,
}
"""The checks of a capability the structure declares."""


def structure_checks(structure: Structure) -> list[Callable[[Structure], None]]:
    """The checks of ``structure``, in order: those every structure passes, those of each
    capability it declares, and the physics checks its capabilities call for
    (:func:`~cphysfno_core.testing.physics.physics_checks`)."""
    checks: list[Callable[[Structure], None]] = [
        check_outputs_are_named,
        check_simulate_shape,
        check_simulate_is_deterministic,
        check_rest_stays_at_rest,
        check_periods,
        check_declared_capabilities,
        check_undeclared_capabilities_refuse,
    ]
    checks += [
        check
        for capability, check in _CAPABILITY_CHECKS.items()
        if capability in structure.capabilities
    ]
    return checks + physics_checks(structure)


def check_structure(structure: Structure) -> None:
    """Run every check of :func:`structure_checks` on ``structure``: shapes and units of
    ``simulate``, any T, at rest stays at rest, determinism, elastic periods, declared
    stories (indices in range, heights > 0), and each capability it claims, including that
    the capabilities describe the physics of ``simulate``."""
    for check in structure_checks(structure):
        check(structure)
