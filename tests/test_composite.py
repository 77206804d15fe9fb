import json

import numpy as np
import pytest
import torch
from cphysfno_refiners import LinearRegressionRefiner

import cphysfno_core as cp


@pytest.fixture
def toy_data(toy_registry):
    source = cp.create("ground_motion", "toy-source", n_steps=120, dt=0.02, scale=0.5)
    structure = cp.create("structure", "toy-structure", cubic=50.0)
    gm = source.sample(24, np.random.default_rng(1))
    u = structure.simulate(gm).displacement
    return structure, gm, u


def test_compose_mixes_names_pairs_and_instances(toy_data):
    structure, gm, u = toy_data
    model = cp.compose(
        structure=structure,
        preprocessor="toy-linear",
        operator=("toy-operator", {"width": 6}),
        refiner="toy-refiner",
    )
    assert model.label == "refined-c-physfno-toy-linear" or model.label.startswith("refined-")
    assert not hasattr(model.preprocessor, "structure_")  # stored, fitted by fit()


def test_missing_capability_fails_at_compose_naming_both(toy_data):
    structure, _, _ = toy_data
    with pytest.raises(
        cp.CapabilityError,
        match="preprocessor 'needs-linear-system' needs structure "
        "'toy-structure' to provide linear_system",
    ):
        cp.compose(structure=structure, preprocessor="needs-linear-system", operator="toy-operator")


def test_bad_operator_parameters_fail_at_compose(toy_data):
    structure, _, _ = toy_data
    with pytest.raises(cp.ConfigError, match="operator.width"):
        cp.compose(structure=structure, operator=("toy-operator", {"width": -1}))


def test_fit_learns_and_save_load_round_trips(toy_data, tmp_path):
    structure, gm, u = toy_data
    model = cp.compose(
        structure=structure,
        preprocessor="toy-linear",
        operator=("toy-operator", {"width": 8}),
        refiner="toy-refiner",
        training={"batch_size": 4, "learning_rate": 1e-2, "seed": 3},
    )
    with pytest.raises(cp.NotFittedError):
        model.predict(gm[:2])
    model.fit(gm[:16], u[:16], validation=(gm[16:20], u[16:20]), epochs=30, progress=None)
    assert hasattr(model.preprocessor, "structure_")
    history = model.history_
    assert len(history.train_loss) == 30
    assert history.train_loss[-1] < 0.6 * history.train_loss[0]
    assert history.val_loss[history.best_epoch - 1] == min(history.val_loss)

    mean, std = model.predict(gm[20:])
    assert mean.shape == std.shape == (4, 120, 2)
    model.save(tmp_path / "m")
    loaded = cp.CompositeModel.load(tmp_path / "m")
    mean2, std2 = loaded.predict(gm[20:])
    np.testing.assert_allclose(mean2, mean, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(std2, std)
    assert loaded.label == model.label


def test_fit_is_repeatable_under_a_seed(toy_data):
    structure, gm, u = toy_data

    def train():
        m = cp.compose(
            structure=structure, operator="toy-operator", training={"batch_size": 4, "seed": 7}
        )
        m.fit(gm[:8], u[:8], validation=(gm[8:12], u[8:12]), epochs=3, progress=None)
        return m.predict(gm[12:14])[0]

    np.testing.assert_array_equal(train(), train())


def test_unrefined_std_is_the_validation_rmse(toy_data):
    structure, gm, u = toy_data
    model = cp.compose(structure=structure, preprocessor="toy-linear", operator="toy-operator")
    model.fit(gm[:8], u[:8], validation=(gm[8:16], u[8:16]), epochs=2, batch_size=4, progress=None)
    val_mean, _ = model.predict(gm[8:16])
    _, std = model.predict(gm[:1])
    expected = np.sqrt(np.mean((val_mean - u[8:16]) ** 2, axis=(0, 1)))
    np.testing.assert_allclose(std[0, 0], expected, rtol=1e-6)


def test_targets_of_the_wrong_shape_are_refused(toy_data):
    structure, gm, u = toy_data
    model = cp.compose(structure=structure, operator="toy-operator")
    with pytest.raises(cp.InputError, match="must be \\[n_records, n_steps, dof\\]"):
        model.fit(gm[:4], u[:3], validation=(gm[4:6], u[4:6]), progress=None)
    with pytest.raises(cp.InputError, match="has 1 outputs but structure 'toy-structure' has 2"):
        model.fit(gm[:4], u[:4, :, :1], validation=(gm[4:6], u[4:6, :, :1]), progress=None)


def test_loading_a_folder_without_a_model_is_a_clear_error(tmp_path, toy_registry):
    with pytest.raises(cp.DatasetError, match="no readable model.json"):
        cp.CompositeModel.load(tmp_path)


@pytest.mark.parametrize("residual", [False, True])
@pytest.mark.parametrize("ground_motion_input", [False, True])
def test_the_formulation_sets_the_operators_inputs_and_target(
    toy_data, tmp_path, residual, ground_motion_input
):
    structure, gm, u = toy_data
    model = cp.compose(
        structure=structure,
        preprocessor="toy-linear",
        operator=("toy-operator", {"width": 4}),
        training={"batch_size": 4, "seed": 1},
        formulation={"residual": residual, "ground_motion_input": ground_motion_input},
    )
    model.fit(gm[:12], u[:12], validation=(gm[12:16], u[12:16]), epochs=2, progress=None)
    n_dof = u.shape[2]
    assert model.operator_.in_channels == n_dof + 1 + ground_motion_input
    stages = model.predict_stages(gm[16:])
    expected_inputs = [stages.z]
    if ground_motion_input:
        expected_inputs.append(gm[16:].acceleration[:, :, None])
    expected_inputs.append(np.broadcast_to(gm.time[None, :, None], (8, gm.n_steps, 1)))
    x = torch.from_numpy(model.input_normalizer_.encode(np.concatenate(expected_inputs, axis=2)))
    with torch.no_grad():
        raw = model.output_normalizer_.decode_torch(model.operator_(x)).double().numpy()
    expected = raw + stages.z if residual else raw
    np.testing.assert_allclose(stages.operator_output, expected, rtol=1e-5, atol=1e-9)
    target = u[:12] - model.physics(gm[:12]) if residual else u[:12]
    np.testing.assert_allclose(model.output_normalizer_.mean, target.mean(axis=(0, 1)))
    loaded = cp.CompositeModel.load(model.save(tmp_path / "model"))
    assert loaded.formulation == model.formulation
    np.testing.assert_array_equal(loaded.predict(gm[16:])[0], stages.mean)


def test_the_baseline_refuses_a_formulation_on_z(toy_data):
    structure, _, _ = toy_data
    with pytest.raises(cp.ConfigError, match="the baseline operator has none"):
        cp.compose(structure=structure, operator="toy-operator", formulation={"residual": True})


def test_a_refiner_calibrated_on_validation_is_fitted_on_the_validation_split(toy_data):
    structure, gm, u = toy_data
    model = cp.compose(
        structure=structure,
        preprocessor="toy-linear",
        operator=("toy-operator", {"width": 4}),
        refiner="toy-calibrated-refiner",
        training={"batch_size": 4},
    )
    model.fit(gm[:12], u[:12], validation=(gm[12:17], u[12:17]), epochs=1, progress=None)
    assert model.refiner.fitted_on == 5
    refined = model.refine("toy-calibrated-refiner", gm[12:15], u[12:15])
    assert refined.refiner.fitted_on == 3


@pytest.mark.parametrize(
    ("split", "records"), [("training", slice(0, 12)), ("validation", slice(12, 17))]
)
def test_linear_regression_fits_on_the_split_it_names(toy_data, split, records):
    structure, gm, u = toy_data
    model = cp.compose(
        structure=structure,
        preprocessor="toy-linear",
        operator=("toy-operator", {"width": 4}),
        refiner=LinearRegressionRefiner(n_points=10**6, calibration_split=split),
        training={"batch_size": 4},
    )
    model.fit(gm[:12], u[:12], validation=(gm[12:17], u[12:17]), epochs=1, progress=None)
    stages = model.predict_stages(gm[records])
    expected = LinearRegressionRefiner(n_points=10**6).fit(
        stages.z, stages.operator_output, u[records], np.random.default_rng(0)
    )
    np.testing.assert_allclose(model.refiner.weights_, expected.weights_, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(model.refiner.sigma_, expected.sigma_, rtol=1e-9)


def test_without_normalisation_the_operator_sees_raw_si_values(toy_data, tmp_path):
    """normalize = false: the operator's inputs are z in m and t in s, and its output is
    the displacement in m, as in the authors' published code."""
    structure, gm, u = toy_data
    model = cp.compose(
        structure=structure,
        preprocessor="toy-linear",
        operator="toy-operator",
        training={"batch_size": 4, "seed": 3, "normalize": False},
    )
    seen = []
    model.fit(gm[:8], u[:8], validation=(gm[8:12], u[8:12]), epochs=1, progress=None)
    model.operator_.register_forward_hook(lambda _m, args, out: seen.append((args[0], out)))
    stages = model.predict_stages(gm[20:])
    x, y = seen[0]
    z = model.physics(gm[20:])
    np.testing.assert_allclose(x[..., :-1].numpy(), z[: x.shape[0]], rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(x[0, :, -1].numpy(), gm.time, rtol=1e-6)
    np.testing.assert_allclose(stages.operator_output[: y.shape[0]], y.numpy(), rtol=1e-6)
    model.save(tmp_path / "raw")
    loaded = cp.CompositeModel.load(tmp_path / "raw")
    assert loaded.training.normalize is False
    np.testing.assert_allclose(loaded.predict(gm[20:])[0], stages.mean, rtol=1e-6, atol=1e-9)


def test_the_residual_form_starts_from_the_physics_response(toy_data):
    """Residual formulation: the operator's output layer starts at zero, so before it has
    learned anything the prediction is z plus the training mean of u - z."""
    structure, gm, u = toy_data
    model = cp.compose(
        structure=structure,
        preprocessor="toy-linear",
        operator="toy-operator",
        training={"batch_size": 4, "learning_rate": 1e-12},
        formulation={"residual": True},
    )
    assert model.label == "c-phystoy-operator-toy-linear-residual"
    model.fit(gm[:8], u[:8], validation=(gm[8:12], u[8:12]), epochs=1, progress=None)
    stages = model.predict_stages(gm[20:])
    shift = model.output_normalizer_.mean
    np.testing.assert_allclose(stages.operator_output, stages.z + shift, rtol=0, atol=1e-9)


def test_predict_takes_a_numpy_array_with_its_dt(toy_data):
    structure, gm, u = toy_data
    model = cp.compose(structure=structure, preprocessor="toy-linear", operator="toy-operator")
    model.fit(gm[:8], u[:8], validation=(gm[8:12], u[8:12]), epochs=1, progress=None)
    mean, _ = model.predict(gm[20:])
    from_array, _ = model.predict(gm.acceleration[20:], dt=gm.dt)
    np.testing.assert_array_equal(from_array, mean)
    one, _ = model.predict(gm.acceleration[20], dt=gm.dt)
    np.testing.assert_array_equal(one, mean[:1])
    with pytest.raises(cp.InputError, match="needs its time step: predict\\(accelerations, dt="):
        model.predict(gm.acceleration[20:])
    with pytest.raises(cp.InputError, match="GroundMotions or a NumPy array .* not str"):
        model.predict("record.AT2")


def test_loading_a_model_whose_plugin_is_missing_names_the_distribution(toy_data, tmp_path):
    structure, gm, u = toy_data
    model = cp.compose(structure=structure, preprocessor="toy-linear", operator="toy-operator")
    model.fit(gm[:8], u[:8], validation=(gm[8:12], u[8:12]), epochs=1, progress=None)
    model.save(tmp_path / "m")
    saved = json.loads((tmp_path / "m" / "model.json").read_text())
    assert saved["providers"]["structure"] == "(registered in code)"
    saved["providers"]["structure"] = "cphysfno-toys 1.2.0"
    saved["structure"]["name"] = "retired-building"
    (tmp_path / "m" / "model.json").write_text(json.dumps(saved))
    with pytest.raises(
        cp.PluginError,
        match="structure 'retired-building' of cphysfno-toys "
        "1.2.0, which is not installed here: pip install cphysfno-toys",
    ):
        cp.CompositeModel.load(tmp_path / "m")


def test_weight_decay_is_decoupled_from_the_gradient(toy_data, toy_registry):
    """Weight decay is decoupled (AdamW): a tiny decay changes the weights only tinily. As
    an L2 term under Adam, any decay would move every weight without a loss gradient by
    about the learning rate a step (Adam divides the term by its own size); in a residual
    model that is every hidden layer at the start, whose output layer is zero, and the
    hidden layers of a full-size FNO die before the network learns anything."""
    structure, gm, u = toy_data
    toy_registry.register("cphysfno_fno.plugin")
    weights = []
    for decay in (0.0, 1e-8):
        model = cp.compose(
            structure=structure,
            preprocessor="toy-linear",
            operator=("fno", {"layers": 2, "modes": 8, "width": 16, "projection_width": 8}),
            training={"batch_size": 4, "weight_decay": decay},
            formulation={"residual": True},
        )
        model.fit(gm[:16], u[:16], validation=(gm[16:20], u[16:20]), epochs=2, progress=None)
        weights.append([p.detach().clone() for p in model.operator_.parameters()])
    for no_decay, tiny_decay in zip(*weights, strict=True):
        torch.testing.assert_close(tiny_decay, no_decay, rtol=1e-5, atol=1e-7)
