"""Every registered component passes the conformance checks of its kind, and the checks
catch components that break their contract."""

from pathlib import Path

import numpy as np
import pytest
import torch
import toy_components

import cphysfno_core as cp
from cphysfno_core import testing

REGISTRY = cp.Registry()


EXAMPLE_PARAMS = {
    ("structure", "shear-building"): {
        "masses": (2.0e4, 2.0e4, 1.5e4),
        "stiffnesses": (4.0e7, 3.0e7, 2.0e7),
        "story_law": {"name": "bilinear", "yield_displacement": 0.01},
    },
    ("structure", "opensees-model"): {
        "script": str(Path(__file__).parents[1] / "examples" / "models" / "two_story_frame.py"),
        "outputs": [[11, 1], [21, 1]],
        "gravity": "gravity",
        "workers": 1,
    },
    ("story_law", "bilinear"): {"yield_displacement": 0.01},
    ("story_law", "peak-oriented"): {"yield_displacement": 0.01},
    ("story_law", "pinching"): {"yield_displacement": 0.01},
}
"""Parameters for the components that have required ones."""


def _names(kind):
    return REGISTRY.names(kind)


def _create(kind, name):
    return REGISTRY.create(kind, name, **EXAMPLE_PARAMS.get((kind, name), {}))


@pytest.mark.parametrize("name", _names("structure"))
def test_registered_structures_conform(name):
    testing.check_structure(_create("structure", name))


@pytest.mark.parametrize("name", _names("story_law"))
def test_registered_story_laws_conform(name):
    testing.check_story_law(_create("story_law", name))


@pytest.mark.parametrize("name", _names("ground_motion"))
def test_registered_ground_motion_sources_conform(name):
    testing.check_ground_motion_source(REGISTRY.create("ground_motion", name))


@pytest.mark.parametrize("name", _names("preprocessor"))
@pytest.mark.parametrize("structure_name", _names("structure"))
def test_registered_preprocessors_conform_or_refuse(name, structure_name):
    structure = _create("structure", structure_name)
    preprocessor = REGISTRY.create("preprocessor", name)
    try:
        preprocessor.fit(structure)
    except cp.CapabilityError as error:
        assert structure_name in str(error) and name in str(error)
        return
    testing.check_preprocessor(REGISTRY.create("preprocessor", name), structure)


@pytest.mark.parametrize("name", _names("operator"))
def test_registered_operators_conform(name):
    testing.check_operator(REGISTRY.get("operator", name))


@pytest.mark.parametrize("name", _names("refiner"))
def test_registered_refiners_conform(name):
    testing.check_refiner(REGISTRY.create("refiner", name))


def test_the_toy_components_conform():
    structure = toy_components.ToyStructure(cubic=3.0)
    testing.check_structure(structure)
    testing.check_ground_motion_source(toy_components.ToySource())
    testing.check_preprocessor(toy_components.ToyPreprocessor(), structure)
    testing.check_refiner(toy_components.ToyRefiner())


class DriftingStructure(toy_components.ToyStructure):
    """Moves although the ground is still."""

    name = "drifting"

    def simulate(self, motions, *, dt=None):
        responses = super().simulate(motions)
        return cp.Responses(responses.displacement + 1e-3, responses.dt)


def _oscillators(structure):
    """The toy structure's two independent unit-mass oscillators as a linear system."""
    w = 2 * np.pi * np.asarray(structure.params.frequencies_hz)
    return cp.LinearSystem(np.eye(2), np.diag(0.04 * w), np.diag(w**2), [1.0, 1.0], np.eye(2))


class UndeclaredLinearSystem(toy_components.ToyStructure):
    """Defines linear_system() without declaring it."""

    name = "undeclared"

    def linear_system(self):
        return _oscillators(self)


class DeclaredRestoringForce(toy_components.ToyStructure):
    """Declares restoring_force without defining it."""

    name = "declared-only"
    capabilities = frozenset({"restoring_force"})


class ForgetfulRefiner(toy_components.ToyRefiner):
    """Saves nothing of what it learned."""

    name = "forgetful"

    def state_dict(self):
        return {"offset": np.zeros_like(self.offset_), "sigma": self.sigma_}


class FixedLengthOperator(toy_components.ToyOperator):
    """Ignores the time axis length: always answers 10 steps."""

    name = "fixed-length"

    def forward(self, x):
        return super().forward(x)[:, :10]


class Float32OnlyOperator(toy_components.ToyOperator):
    """Refuses autocast, as an operator with a float32-only kernel of its own would."""

    name = "float32-only"

    def forward(self, x):
        if torch.is_autocast_enabled("cpu"):
            raise NotImplementedError("kernel not implemented for 'BFloat16'")
        return super().forward(x)


class CoarseOperator(toy_components.ToyOperator):
    """Rounds its output to integers under autocast."""

    name = "coarse"

    def forward(self, x):
        out = super().forward(x)
        return out.round() if torch.is_autocast_enabled("cpu") else out


class SteepOperator(toy_components.ToyOperator):
    """Answers correctly under autocast, but with twice the gradient."""

    name = "steep"

    def forward(self, x):
        out = super().forward(x)
        if torch.is_autocast_enabled("cpu"):
            return out.detach() + 2.0 * (out - out.detach())
        return out


class OffsetOperator(toy_components.ToyOperator):
    """Adds a constant after its output layer, so zeroing that layer leaves the offset."""

    name = "offset"

    def forward(self, x):
        return super().forward(x) + 0.5


class FrozenZeroOperator(toy_components.ToyOperator):
    """Zeroes its output by a constant factor of zero, through which nothing can learn."""

    name = "frozen-zero"

    def __init__(self, in_channels, out_channels, **hyper):
        super().__init__(in_channels, out_channels, **hyper)
        self.register_buffer("gate", torch.tensor(1.0))

    def zero_output_(self):
        self.gate.zero_()

    def forward(self, x):
        return super().forward(x) * self.gate


@pytest.mark.parametrize(
    "check, component, message",
    [
        (testing.check_structure, DriftingStructure(), "drifting: a structure at rest"),
        (
            testing.check_structure,
            UndeclaredLinearSystem(),
            "undeclared: defines linear_system\\(\\) but does not declare 'linear_system'",
        ),
        (
            testing.check_structure,
            DeclaredRestoringForce(),
            "declared-only: declares 'restoring_force' but does not define restoring_force",
        ),
        (testing.check_refiner, ForgetfulRefiner(), "forgetful: a state_dict round trip"),
        (testing.check_operator, FixedLengthOperator, "fixed-length: output shape"),
        (testing.check_operator, Float32OnlyOperator, "float32-only: fails under torch.autocast"),
        (testing.check_operator, CoarseOperator, "coarse: under torch.autocast to bfloat16"),
        (testing.check_operator, SteepOperator, "steep: under bfloat16 autocast the gradients"),
        (testing.check_operator, OffsetOperator, "offset: after zero_output_\\(\\) the output"),
        (testing.check_operator, FrozenZeroOperator, "frozen-zero: after zero_output_.*step"),
    ],
)
def test_checks_catch_broken_contracts(check, component, message):
    with pytest.raises(AssertionError, match=message):
        check(component)


def test_operator_check_wants_the_packages_error_for_bad_input():
    class Silent(toy_components.ToyOperator):
        name = "silent"

        def forward(self, x):
            return super().forward(x[..., :3])

    with pytest.raises(AssertionError, match="silent: expected CphysfnoError"):
        testing.check_operator(Silent)
    assert torch.is_tensor(Silent(3, 2)(torch.zeros(1, 4, 3)))


def test_an_operator_without_a_linear_layer_cannot_start_at_zero():
    class Spectral(cp.NeuralOperator):
        name = "spectral-only"

        def forward(self, x):
            return x[..., :1]

    with pytest.raises(cp.CapabilityError, match="spectral-only.*override"):
        Spectral(3, 1).zero_output_()


def test_an_unknown_capability_fails_when_the_class_is_made():
    with pytest.raises(TypeError, match="unknown capabilities \\['linear_systems'\\]"):

        class Misspelt(toy_components.ToyStructure):
            capabilities = frozenset({"linear_systems"})


def test_a_linear_system_brings_an_equivalent_one():
    class Declared(toy_components.ToyStructure):
        name = "declared"
        capabilities = frozenset({"linear_system"})

        def linear_system(self):
            return _oscillators(self)

    structure = Declared()
    assert structure.capabilities == {"linear_system", "equivalent_linear_system"}
    assert structure.equivalent_linear_system() is not None
    with pytest.raises(cp.CapabilityError, match="equivalent_linear_system"):
        toy_components.ToyStructure().equivalent_linear_system()
