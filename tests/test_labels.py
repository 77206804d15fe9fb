"""Model labels: what ``train`` names a model is what the readers of its rows parse back."""

import itertools

import pytest
import toy_components

import cphysfno_core as cp
from cphysfno_core.model import ModelLabel
from cphysfno_core.plugin import Registry

REGISTRY = Registry()


def _every_label():
    """Every label a run of the registered components can make."""
    for operator in REGISTRY.names("operator"):
        yield ModelLabel(operator)
        yield ModelLabel(operator, parameters=True)
        for preprocessor, refined, residual, parameters in itertools.product(
            REGISTRY.names("preprocessor"), (False, True), (False, True), (False, True)
        ):
            yield ModelLabel(operator, preprocessor, refined, residual, parameters)
    for preprocessor in REGISTRY.names("preprocessor"):
        yield ModelLabel.physics(preprocessor)


@pytest.mark.parametrize("label", list(_every_label()), ids=str)
def test_every_label_reads_back_as_itself(label):
    text = str(label)
    assert ModelLabel.parse(text, REGISTRY.names("operator")) == label
    assert str(ModelLabel.parse(text, REGISTRY.names("operator"))) == text


def test_a_model_that_takes_the_structures_parameters_says_so_last():
    label = ModelLabel.parse("refined-c-physfno-els-residual-params", ["fno"])
    assert (label.operator, label.preprocessor) == ("fno", "els")
    assert label.refined and label.residual and label.parameters
    assert ModelLabel.parse("fno-params", ["fno"]) == ModelLabel("fno", parameters=True)
    with pytest.raises(ValueError, match="parameter inputs"):
        ModelLabel.parse("physics-els-params")


@pytest.mark.parametrize(
    "text, operator, preprocessor, refined, residual",
    [
        ("fno", "fno", None, False, False),
        ("c-physfno-els", "fno", "els", False, False),
        ("c-physfno-modal-residual", "fno", "modal", False, True),
        ("refined-c-physfno-relaxed", "fno", "relaxed", True, False),
        ("refined-c-physneuralop-fno-els-exact-residual", "neuralop-fno", "els-exact", True, True),
        ("physics-els", None, "els", False, False),
    ],
)
def test_a_label_says_what_the_model_is(text, operator, preprocessor, refined, residual):
    label = ModelLabel.parse(text, ["fno", "neuralop-fno"])
    assert (label.operator, label.preprocessor) == (operator, preprocessor)
    assert (label.refined, label.residual) == (refined, residual)
    assert label.is_physics == (operator is None)
    assert label.is_trained == (operator is not None)
    assert label.is_composite == (operator is not None and preprocessor is not None)


def test_the_registered_operators_split_a_label_by_default(toy_registry):
    model = cp.compose(
        structure=toy_components.ToyStructure(),
        preprocessor="toy-linear",
        operator="other-toy-operator",
    )
    assert ModelLabel.parse(model.label) == ModelLabel("other-toy-operator", "toy-linear")


def test_an_unknown_operator_ends_at_the_first_hyphen_and_the_text_is_kept():
    label = ModelLabel.parse("c-physmy-net-els-residual", operators=[])
    assert (label.operator, label.preprocessor, label.residual) == ("my", "net-els", True)
    assert str(label) == "c-physmy-net-els-residual"


def test_the_residual_twin_of_a_model():
    assert str(ModelLabel.parse("refined-c-physfno-els", ["fno"]).residual_twin) == (
        "refined-c-physfno-els-residual"
    )


@pytest.mark.parametrize(
    "text", ["", "c-phys", "c-physfno", "c-physfno-", "physics-", "physics-els-residual"]
)
def test_what_is_no_label_is_refused(text):
    with pytest.raises(ValueError):
        ModelLabel.parse(text, ["fno"])
