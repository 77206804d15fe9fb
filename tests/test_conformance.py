"""Every registered component passes the conformance checks of its kind, and the checks
catch components that break their contract."""

import copy
from pathlib import Path

import numpy as np
import pytest
import torch
import toy_components

import cphysfno_core as cp
from cphysfno_core import testing
from cphysfno_core.plugin import LinearSystem, NeuralOperator, Registry

REGISTRY = Registry()


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
    ("story_law", "cracked-pinching"): {"yield_displacement": 0.01, "crack_displacement": 0.002},
}
"""Parameters for the components that have required ones."""


def _names(kind):
    return REGISTRY.names(kind)


def _create(kind, name):
    return REGISTRY.create(kind, name, **EXAMPLE_PARAMS.get((kind, name), {}))


STRUCTURES = [_create("structure", name) for name in _names("structure")]
PREPROCESSORS = [REGISTRY.create("preprocessor", name) for name in _names("preprocessor")]


def _works_on(preprocessor, structure):
    try:
        preprocessor.check(structure)
    except cp.CapabilityError:
        return False
    return True


REGISTERED = [
    *STRUCTURES,
    *(_create("story_law", name) for name in _names("story_law")),
    *(REGISTRY.create("ground_motion", name) for name in _names("ground_motion")),
    *((p, s) for p in PREPROCESSORS for s in STRUCTURES if _works_on(p, s)),
    *(REGISTRY.get("operator", name) for name in _names("operator")),
    *(REGISTRY.create("refiner", name) for name in _names("refiner")),
]
"""Every registered component; a preprocessor with each structure it works on."""


@testing.parametrize_with_checks(REGISTERED)
def test_registered_components_conform(component, check):
    check(component)


@pytest.mark.parametrize(
    "preprocessor, structure",
    [
        pytest.param(p, s, id=f"{p.name}-on-{s.name}")
        for p in PREPROCESSORS
        for s in STRUCTURES
        if not _works_on(p, s)
    ],
)
def test_registered_preprocessors_refuse_what_they_do_not_work_on(preprocessor, structure):
    with pytest.raises(cp.CapabilityError) as refusal:
        copy.deepcopy(preprocessor).fit(structure)
    assert structure.name in str(refusal.value) and preprocessor.name in str(refusal.value)


TOY_STRUCTURE = toy_components.ToyStructure(cubic=3.0)


@testing.parametrize_with_checks(
    [
        TOY_STRUCTURE,
        toy_components.ToySource(),
        (toy_components.ToyPreprocessor(), TOY_STRUCTURE),
        toy_components.ToyRefiner(),
    ]
)
def test_the_toy_components_conform(component, check):
    check(component)


class DriftingStructure(toy_components.ToyStructure):
    """Moves although the ground is still."""

    name = "drifting"

    def simulate(self, motions, *, dt=None):
        responses = super().simulate(motions)
        return cp.Responses(responses.displacement + 1e-3, responses.dt)


def _oscillators(structure):
    """The toy structure's two independent unit-mass oscillators as a linear system."""
    w = 2 * np.pi * np.asarray(structure.params.frequencies_hz)
    return LinearSystem(np.eye(2), np.diag(0.04 * w), np.diag(w**2), [1.0, 1.0], np.eye(2))


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


def test_each_check_of_each_component_is_a_case_named_after_both():
    mark = testing.parametrize_with_checks(
        [
            TOY_STRUCTURE,
            (toy_components.ToyPreprocessor(), TOY_STRUCTURE),
            toy_components.ToyOperator,
            (toy_components.ToyOperator, {"width": 4}),
        ]
    )
    assert mark.args[0] == "component, check"
    ids = [case.id for case in mark.args[1]]
    assert ids[0] == "toy-structure-check_outputs_are_named"
    assert "toy-structure-check_simulate_shape" in ids
    assert "toy-linear-on-toy-structure-check_z_shape" in ids
    assert ids.count("toy-operator-check_output_shape") == 2
    for case in mark.args[1]:
        subject, check = case.values
        if case.id.startswith("toy-linear-on-"):
            assert isinstance(subject, toy_components.ToyPreprocessor)
            assert check.keywords == {"structure": TOY_STRUCTURE}


@pytest.mark.parametrize(
    "component, broken",
    [
        (ForgetfulRefiner(), "forgetful-check_state_dict_round_trip"),
        (DriftingStructure(), "drifting-check_rest_stays_at_rest"),
        (DeclaredRestoringForce(), "declared-only-check_declared_capabilities"),
    ],
)
def test_a_broken_component_fails_the_check_of_what_it_breaks_alone(component, broken):
    failed = []
    for subject, check, case_id in testing.component_checks(component):
        try:
            check(subject)
        except AssertionError:
            failed.append(case_id)
    assert failed == [broken]


def test_what_is_not_a_component_is_refused():
    with pytest.raises(TypeError, match="not a component to check"):
        testing.parametrize_with_checks([toy_components.ToyPreprocessor()])


def test_operator_check_wants_the_packages_error_for_bad_input():
    class Silent(toy_components.ToyOperator):
        name = "silent"

        def forward(self, x):
            return super().forward(x[..., :3])

    with pytest.raises(AssertionError, match="silent: expected CphysfnoError"):
        testing.check_operator(Silent)
    assert torch.is_tensor(Silent(3, 2)(torch.zeros(1, 4, 3)))


def test_an_operator_without_a_linear_layer_cannot_start_at_zero():
    class Spectral(NeuralOperator):
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
