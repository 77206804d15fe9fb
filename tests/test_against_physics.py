"""C-Phys models against their physics input, and the choice between formulations."""

import pytest

from cphysfno_core.reporting import against_physics

NAMES = ["story-1", "story-2"]


def _models():
    return {
        "physics-els": {"rel_l2": [0.50, 0.40], "validation_rel_l2": [0.45, 0.42]},
        "fno": {"rel_l2": [0.9, 0.9]},
        "c-physfno-els": {
            "physics_input": "physics-els",
            "rel_l2": [0.55, 0.30],
            "validation_rel_l2": [0.40, 0.43],
        },
        "c-physfno-els-residual": {
            "physics_input": "physics-els",
            "rel_l2": [0.35, 0.30],
            "validation_rel_l2": [0.38, 0.41],
        },
    }


def test_shortfalls_name_each_output_worse_than_z_on_each_split():
    found = against_physics.shortfalls(_models(), NAMES)
    assert found == {
        "c-physfno-els": {
            "validation": [("story-2", 0.43, 0.42)],
            "test": [("story-1", 0.55, 0.50)],
        }
    }
    (line,) = against_physics.describe_shortfalls(found)
    assert line.startswith("c-physfno-els is worse than its physics input z alone")
    assert "on validation at story-2 (0.430 against 0.420)" in line
    assert "on test at story-1 (0.550 against 0.500)" in line
    assert "residual = true" in line
    residual = {"c-physfno-els-residual": found["c-physfno-els"]}
    (line,) = against_physics.describe_shortfalls(residual)
    assert line.endswith("z alone is the better answer there")


def test_a_model_level_with_its_physics_is_not_worse():
    models = _models()
    models["c-physfno-els"]["validation_rel_l2"] = [0.45, 0.42]
    models["c-physfno-els"]["rel_l2"] = [0.50, 0.40]
    assert "c-physfno-els" not in against_physics.shortfalls(models, NAMES)


@pytest.mark.parametrize(
    ("residual_validation", "chosen"),
    [([0.38, 0.41], "c-physfno-els-residual"), ([0.44, 0.41], "c-physfno-els")],
)
def test_the_form_with_the_lower_mean_validation_error_is_chosen(residual_validation, chosen):
    models = _models()  # paper form: mean validation 0.415
    models["c-physfno-els-residual"]["validation_rel_l2"] = residual_validation
    assert against_physics.chosen_forms(models) == {"c-physfno-els": chosen}


def test_nothing_is_chosen_where_one_form_was_trained():
    models = _models()
    del models["c-physfno-els-residual"]
    assert against_physics.chosen_forms(models) == {}


def test_a_physics_input_worse_than_zero_is_named_in_the_report():
    from cphysfno_core.reporting.report import _physics_past_zero

    models = {
        "physics-stick": {"rel_l2": [1.09, 0.71]},
        "physics-relaxed": {"rel_l2": [0.35, 0.37]},
        "c-physfno-stick": {"rel_l2": [1.2, 0.4]},  # trained: not a physics input
    }
    lines = _physics_past_zero(models, ["floor-2", "roof"])
    assert len([line for line in lines if line]) == 1
    assert "`physics-stick` is farther from the simulation than predicting zero" in lines[1]
    assert "floor-2 (1.09)" in lines[1] and "roof" not in lines[1]
    assert _physics_past_zero({"physics-els": {"rel_l2": [0.5]}}, ["roof"]) == []
