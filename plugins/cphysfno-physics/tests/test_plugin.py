"""Registration, parameters, capabilities and the fit-before-transform contract."""

from __future__ import annotations

import numpy as np
import pytest
from cphysfno_physics import EquivalentLinear, ModalReduction, RelaxedSolver, Stick

from cphysfno_core import CapabilityError, ConfigError, NotFittedError, create
from cphysfno_core.plugin import PhysicsPreprocessor, Registry

CLASSES = {"els": EquivalentLinear, "modal": ModalReduction, "relaxed": RelaxedSolver}


@pytest.mark.parametrize("name", sorted(CLASSES))
def test_registry_creates_each_by_name(name):
    component = create("preprocessor", name)
    assert type(component) is CLASSES[name]
    assert isinstance(component, PhysicsPreprocessor)
    assert component.name == name


def test_entry_point_module_registers_the_six():
    registry = Registry(autoload=False, plugins=("cphysfno_physics.plugin",))
    names = ["els", "els-exact", "els-secant", "modal", "relaxed", "stick"]
    assert registry.names("preprocessor") == names
    assert registry.create("preprocessor", "els-exact").params.system == "exact"
    assert registry.create("preprocessor", "els-secant").params.stiffness == "secant"
    assert registry.get("preprocessor", "stick") is Stick
    assert registry.broken == []


@pytest.mark.parametrize(
    ("name", "params", "field"),
    [
        ("els", {"stiffness_scale": 0.0}, "els.stiffness_scale"),
        ("modal", {"modes": 0}, "modal.modes"),
        ("modal", {"substeps": 0}, "modal.substeps"),
        ("relaxed", {"factor": 0}, "relaxed.factor"),
        ("relaxed", {"factor": 2.5}, "relaxed.factor"),
        ("relaxed", {"factr": 3}, "relaxed.factr"),
    ],
)
def test_bad_params_name_the_field(name, params, field):
    with pytest.raises(ConfigError, match=field.replace(".", r"\.")):
        create("preprocessor", name, **params)


@pytest.mark.parametrize("name", sorted(CLASSES))
def test_transform_before_fit_is_not_fitted(name, toy_motions):
    with pytest.raises(NotFittedError, match=f"'{name}' is not fitted"):
        create("preprocessor", name).transform(toy_motions)


@pytest.mark.parametrize(
    ("name", "structure", "capability"),
    [
        ("relaxed", "toy_without_restoring_force", "coarse_simulation"),
        ("els", "toy_without_linear_system", "linear_system"),
        ("modal", "toy_without_linear_system", "linear_system"),
    ],
)
def test_missing_capability_fails_at_fit(name, structure, capability, request):
    lacking = request.getfixturevalue(structure)
    with pytest.raises(CapabilityError) as error:
        create("preprocessor", name).fit(lacking)
    message = str(error.value)
    assert f"preprocessor '{name}'" in message
    assert f"'{lacking.name}'" in message
    assert capability in message


@pytest.mark.parametrize("name", sorted(CLASSES))
def test_fit_returns_the_preprocessor_and_keeps_params(name, toy):
    component = create("preprocessor", name)
    assert component.fit(toy) is component
    assert create("preprocessor", name, **component.get_params()).get_params() == (
        component.get_params()
    )


@pytest.mark.parametrize("name", sorted(CLASSES))
def test_output_is_float64_on_the_motion_grid(name, toy, toy_motions):
    short = toy_motions[:1]
    z = create("preprocessor", name).fit(toy).transform(short)
    assert z.shape == (1, short.n_steps, toy.n_outputs)
    assert z.dtype == np.float64 and np.all(np.isfinite(z))
