"""A model of a family of structures: each record's structural parameters rebuild its
physics response and, with ``formulation.parameter_input``, enter the operator as constant
channels; saved and loaded with the model; refused or warned about where they do not
fit."""

import dataclasses
import warnings

import numpy as np
import pytest
from tiny_family_run import tiny_config

import cphysfno_core as cp
from cphysfno_core.plugin import Structure

MASSES = [4.0e4, 3.0e4]
NOMINAL = {"stiffnesses.0": 4e7, "story_law.yield_displacement": 0.01}
FNO = ("fno", {"layers": 1, "modes": 4, "width": 6})
TRAINING = {"batch_size": 4, "seed": 2, "epochs": 2}


def _structure(stiffness: float, yield_displacement: float) -> Structure:
    return cp.create(
        "structure",
        "shear-building",
        masses=MASSES,
        stiffnesses=[stiffness, 3e7],
        story_law={"name": "bilinear", "alpha": 0.05, "yield_displacement": yield_displacement},
    )


@pytest.fixture(scope="module")
def family():
    """``(motions, u, params)``: 12 records, each on its own drawn structure."""
    rng = np.random.default_rng(0)
    motions = cp.create("ground_motion", "white-noise", duration=2.0).sample(12, rng)
    params = {
        "stiffnesses.0": 4e7 * np.exp(0.3 * rng.standard_normal(12)),
        "story_law.yield_displacement": rng.uniform(0.006, 0.014, 12),
    }
    u = np.concatenate(
        [
            _structure(k, y).simulate(motions[i : i + 1]).displacement
            for i, (k, y) in enumerate(zip(*params.values(), strict=True))
        ]
    )
    return motions, u, params


def _split(params, rows):
    return {name: values[rows] for name, values in params.items()}


def _fit(family, parameter_input=False, preprocessor="els", params=True):
    motions, u, drawn = family
    model = cp.compose(
        structure=_structure(*NOMINAL.values()),
        preprocessor=preprocessor,
        operator=FNO,
        training=TRAINING,
        formulation={"parameter_input": parameter_input},
    )
    given = {}
    if params:
        given = {
            "params": _split(drawn, slice(8)),
            "validation_params": _split(drawn, slice(8, 12)),
            "param_units": {"stiffnesses.0": "N/m"},
        }
    return model.fit(motions[:8], u[:8], validation=(motions[8:], u[8:]), progress=None, **given)


def test_each_record_gets_the_physics_of_its_own_structure(family):
    motions, _, drawn = family
    model = _fit(family)
    z = model.physics(motions, params=drawn)
    for i, (k, y) in enumerate(zip(*drawn.values(), strict=True)):
        own = cp.create("preprocessor", "els").fit(_structure(k, y)).transform(motions[i : i + 1])
        np.testing.assert_allclose(z[i], own[0], rtol=1e-12, atol=1e-15)
    nominal = cp.create("preprocessor", "els").fit(_structure(*NOMINAL.values()))
    np.testing.assert_array_equal(model.physics(motions), nominal.transform(motions))


def test_a_parameter_left_out_takes_the_structures_own_value(family):
    motions, _, drawn = family
    model = _fit(family)
    partial = {"stiffnesses.0": drawn["stiffnesses.0"]}
    full = {**partial, "story_law.yield_displacement": np.full(12, 0.01)}
    np.testing.assert_array_equal(
        model.physics(motions, params=partial), model.physics(motions, params=full)
    )


def test_parameter_channels_enter_the_operator(family):
    motions, _, drawn = family
    with_channels, without = _fit(family, parameter_input=True), _fit(family)
    assert with_channels.label == "c-physfno-els-params"
    assert with_channels.operator_.in_channels == without.operator_.in_channels + 2
    z = without.physics(motions, params=drawn)
    moved = {**drawn, "stiffnesses.0": drawn["stiffnesses.0"] * 1.1}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cp.ExtrapolationWarning)
        for model, changes in ((with_channels, True), (without, False)):
            first = model.predict_stages(motions, z=z, params=drawn).mean
            second = model.predict_stages(motions, z=z, params=moved).mean
            assert (not np.array_equal(first, second)) is changes


def test_the_channels_are_standardised_by_the_training_draws(family):
    _, _, drawn = family
    model = _fit(family, parameter_input=True)
    train = np.column_stack([v[:8] for v in drawn.values()])
    encoded = model.parameters.encode(train)
    np.testing.assert_allclose(encoded.mean(axis=0), 0.0, atol=1e-12)
    np.testing.assert_allclose(encoded.std(axis=0), 1.0, rtol=1e-12)
    assert model.parameters.units == ("N/m", "")


def test_a_family_of_one_equals_the_fixed_structure(family):
    motions, u, _ = family
    one = {name: np.full(8, value) for name, value in NOMINAL.items()}
    model = cp.compose(
        structure=_structure(*NOMINAL.values()), preprocessor="els", operator=FNO, training=TRAINING
    )
    model.fit(
        motions[:8],
        u[:8],
        validation=(motions[8:], u[8:]),
        params=one,
        validation_params={name: v[:4] for name, v in one.items()},
        progress=None,
    )
    fixed = _fit(family, params=False)
    np.testing.assert_allclose(
        model.predict(motions, params=NOMINAL)[0], fixed.predict(motions)[0], rtol=0, atol=1e-12
    )


def test_save_and_load_keep_the_parameters(family, tmp_path):
    motions, _, drawn = family
    model = _fit(family, parameter_input=True)
    model.save(tmp_path / "m")
    loaded = cp.CompositeModel.load(tmp_path / "m")
    assert loaded.parameters.names == model.parameters.names
    assert loaded.parameters.units == model.parameters.units
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cp.ExtrapolationWarning)
        np.testing.assert_allclose(
            loaded.predict(motions, params=drawn)[0], model.predict(motions, params=drawn)[0]
        )


def test_parameters_the_model_cannot_take_are_refused(family):
    motions, _, drawn = family
    with pytest.raises(cp.InputError, match="trained on one structure"):
        _fit(family, params=False).predict(motions, params=drawn)
    model = _fit(family)
    with pytest.raises(cp.InputError, match="unknown structural parameters damping.*knows"):
        model.predict(motions, params={"damping": 0.05})
    with pytest.raises(cp.InputError, match="give one value or 12"):
        model.predict(motions, params={"stiffnesses.0": [4e7, 5e7]})
    with pytest.raises(cp.ConfigError, match="parameter_input"):
        _fit(family, parameter_input=True, params=False)


def test_values_beyond_the_training_draws_are_flagged(family):
    motions, _, drawn = family
    model = _fit(family)
    high = float(drawn["stiffnesses.0"][:8].max())
    with pytest.warns(cp.ExtrapolationWarning, match="1 of 1 records.*stiffnesses.0"):
        model.predict(motions[:1], params={"stiffnesses.0": 1.5 * high})


RUN = """
preprocessor = { name = "els" }

[structure]
name = "shear-building"
masses = [4.0e4, 3.0e4]
stiffnesses = [{ dist = "lognormal", median = 4e7, beta = 0.3, unit = "N/m" }, 3e7]
story_law = { name = "bilinear", alpha = 0.05, yield_displacement = 0.01 }
story_heights = [3.0, 3.0]

[refiner]
name = "linear-regression"

[formulation]
parameter_input = "both"
"""


@pytest.fixture(scope="module")
def family_run(tmp_path_factory):
    """``(folder, evaluation)`` of a run of :data:`RUN`."""
    from cphysfno_core.app import pipeline

    folder = tmp_path_factory.mktemp("family-run")
    return folder, pipeline.run(tiny_config(RUN), folder)


def test_a_run_trains_every_model_with_and_without_the_parameters(family_run):
    tmp_path, evaluation = family_run
    labels = set(evaluation.metrics)
    assert {"fno", "fno-params", "c-physfno-els", "c-physfno-els-params"} <= labels
    assert {"refined-c-physfno-els", "refined-c-physfno-els-params"} <= labels
    loaded = cp.CompositeModel.load(tmp_path / "models" / "refined-c-physfno-els-params")
    assert loaded.parameters.names == ("stiffnesses.0",)
    assert loaded.parameters.units == ("N/m",)
    data = cp.load_dataset(tmp_path / "dataset.h5")
    drawn = data.parameter_draws("test")
    stages = loaded.predict_stages(data.motions("test"), params=drawn)
    np.testing.assert_allclose(stages.z, data.physics("els", "test"), rtol=1e-9, atol=1e-12)
    report = (tmp_path / "report.md").read_text()
    low, median, high = (
        np.min(drawn["stiffnesses.0"]),
        np.median(drawn["stiffnesses.0"]),
        np.max(drawn["stiffnesses.0"]),
    )
    row = next(line for line in report.splitlines() if line.startswith("| `stiffnesses.0`"))
    assert "| N/m | lognormal, median 4e+07, β 0.3 |" in row
    assert row.endswith(f"| {low:.4g} / {median:.4g} / {high:.4g} |")
    assert (tmp_path / "figures" / "parameter_draws.png").stat().st_size > 0


def test_predict_reads_each_records_parameters_from_a_csv(family, tmp_path, capsys):
    from cphysfno_core.app.cli import main

    motions, _, drawn = family
    model = _fit(family, parameter_input=True)
    folder = model.save(tmp_path / "model")
    np.savez(tmp_path / "m.npz", acceleration=motions.acceleration[:3], dt=motions.dt, units="g")
    table = "story_law.yield_displacement,stiffnesses.0\n"
    stiffness, yield_displacement = drawn["stiffnesses.0"], drawn["story_law.yield_displacement"]
    table += "".join(
        f"{float(yield_displacement[i])!r},{float(stiffness[i])!r}\n" for i in range(3)
    )
    (tmp_path / "p.csv").write_text(table)
    out = tmp_path / "out.npz"
    argv = ["predict", str(folder), str(tmp_path / "m.npz"), "--out", str(out), "--units", "g"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cp.ExtrapolationWarning)
        assert main([*argv, "--params", str(tmp_path / "p.csv")]) == 0
        in_g = cp.GroundMotions(motions.acceleration[:3] * 9.80665, motions.dt)
        expected = model.predict(in_g, params=_split(drawn, slice(3)))[0]
    with np.load(out) as written:
        np.testing.assert_allclose(written["mean"], expected, rtol=1e-5, atol=1e-9)
        assert list(written["param_names"]) == ["story_law.yield_displacement", "stiffnesses.0"]
    (tmp_path / "p.csv").write_text("stiffnesses.0\n4e7\n5e7\n")
    assert main([*argv, "--params", str(tmp_path / "p.csv")]) == 2
    assert "give one value or 3" in capsys.readouterr().err
    (tmp_path / "p.csv").write_text("stiffnesses.0\nstiff\n")
    assert main([*argv, "--params", str(tmp_path / "p.csv")]) == 2
    assert "line 2: a value is not a number" in capsys.readouterr().err


def test_both_forms_are_for_a_run_and_a_model_takes_one():
    from cphysfno_core.config import FormulationConfig

    forms = FormulationConfig(residual="choose", parameter_input="both").forms()
    assert [(f.residual, f.parameter_input) for f in forms] == [
        (False, False),
        (True, False),
        (False, True),
        (True, True),
    ]
    with pytest.raises(cp.ConfigError, match="parameter_input = 'both' is for a run"):
        cp.compose(operator=FNO, formulation={"parameter_input": "both"})


def test_parameter_inputs_need_random_parameters():
    fixed = RUN.replace('{ dist = "lognormal", median = 4e7, beta = 0.3, unit = "N/m" }', "4e7")
    with pytest.raises(cp.ConfigError, match="no random parameter to take as input"):
        tiny_config(fixed)


def test_fragility_of_a_family_splits_record_to_record_and_modelling_dispersion(family_run):
    from cphysfno_core.app.fragility_study import parse_limit_states, run_fragility

    folder, _ = family_run
    document = run_fragility(
        folder,
        limit_states=parse_limit_states("pid=0.0005,0.001,0.002"),
        records=60,
        model_label="c-physfno-els-params",
        n_bootstrap=5,
        progress=False,
    )
    assert document["modelling_uncertainty"] == {"parameters": ["stiffnesses.0"], "units": ["N/m"]}
    split = [fits["dispersion"] for fits in document["limit_states"].values()]
    fitted = [s for s in split if s["beta_modelling"] is not None]
    assert fitted, split
    for found in fitted:
        total, record = found["beta_total"], found["beta_record_to_record"]
        assert found["beta_modelling"] == pytest.approx(np.sqrt(max(total**2 - record**2, 0)))
    drawn = [fits["surrogate-large"]["median"] for fits in document["limit_states"].values()]
    medians = [
        fits["surrogate-large-medians"]["median"] for fits in document["limit_states"].values()
    ]
    assert drawn != medians


def test_records_the_median_pass_cannot_predict_are_counted(family_run, monkeypatch):
    from cphysfno_core.app import fragility_study
    from cphysfno_core.app.fragility_study import parse_limit_states, run_fragility

    own = fragility_study.predict_skipping_failures

    def failing_at_medians(model, motions, params=None):
        responses, failures = own(model, motions, params)
        if params is None:
            responses.displacement[0] = np.nan
            failures = {0: "no physics at the medians", **failures}
        return responses, failures

    monkeypatch.setattr(fragility_study, "predict_skipping_failures", failing_at_medians)
    document = run_fragility(
        family_run[0],
        limit_states=parse_limit_states("pid=0.0005,0.001"),
        records=30,
        model_label="c-physfno-els-params",
        n_bootstrap=5,
        progress=False,
    )
    skipped = document["skipped_records"]
    assert skipped["large"]["count"] == 0
    assert skipped["large-medians"] == {"count": 1, "first": {"0": "no physics at the medians"}}


def test_records_whose_physics_collapses_count_as_exceeding(family_run, monkeypatch, tmp_path):
    """The first record of every prediction made to collapse its physics: fitted as an
    exceedance in each surrogate curve (none left out), written collapsed in demands."""
    from cphysfno_core.app import demand_sample, fragility_study
    from cphysfno_core.app.fragility_study import parse_limit_states, run_fragility

    own = fragility_study.predict_skipping_failures

    def first_collapses(model, motions, params=None):
        responses, failures = own(model, motions, params)
        collapsed, displacement = responses.collapsed.copy(), responses.displacement.copy()
        collapsed[0], displacement[0] = True, np.nan
        return dataclasses.replace(
            responses, displacement=displacement, collapsed=collapsed, extras={}
        ), failures

    for module in (fragility_study, demand_sample):
        monkeypatch.setattr(module, "predict_skipping_failures", first_collapses)
    document = run_fragility(
        family_run[0],
        limit_states=parse_limit_states("pid=0.0005,0.5"),
        records=30,
        model_label="c-physfno-els-params",
        n_bootstrap=5,
        progress=False,
    )
    assert document["surrogate_collapses"] == {"test": 1, "large": 1, "large-medians": 1}
    assert document["skipped_records"]["large"]["count"] == 0
    never = document["limit_states"]["pid > 0.5"]  # only the collapse reaches it
    assert never["surrogate-large"]["n_records"] == 30
    assert never["surrogate-large"]["n_exceeded"] == 1
    written, _ = demand_sample.write_demand_sample(
        family_run[0], model_label="c-physfno-els-params", out=tmp_path / "d.csv"
    )
    assert written.n_collapsed == 1


def test_the_dispersion_split_adds_by_the_square_root_of_the_sum_of_squares():
    from cphysfno_core.app.fragility_study import dispersion_split

    found = dispersion_split({"median": 0.6, "beta": 0.5}, {"median": 0.5, "beta": 0.4})
    assert found["beta_modelling"] == pytest.approx(0.3)
    assert found["median_shift"] == pytest.approx(1.2)
    assert "note" not in found
    smaller = dispersion_split({"median": 0.5, "beta": 0.3}, {"median": 0.5, "beta": 0.4})
    assert smaller["beta_modelling"] == 0.0 and "within the fits' scatter" in smaller["note"]
    missing = dispersion_split({"median": None, "beta": None}, {"median": 0.5, "beta": 0.4})
    assert missing["beta_modelling"] is None


def test_demands_of_a_family_predict_each_record_on_its_own_structure(family_run, tmp_path):
    from cphysfno_core.app.demand_sample import write_demand_sample
    from cphysfno_core.model.skipping import predict_skipping_failures

    folder, _ = family_run
    label = "c-physfno-els-params"
    written, _ = write_demand_sample(folder, model_label=label, out=tmp_path / "test.csv")
    data = cp.load_dataset(folder / "dataset.h5")
    model = cp.CompositeModel.load(folder / "models" / label)
    test = data.motions("test")
    responses, _ = predict_skipping_failures(model, test, data.parameter_draws("test"))
    drift = np.abs(np.diff(responses.displacement, axis=2, prepend=0.0)).max(axis=1) / 3.0
    table = np.genfromtxt(tmp_path / "test.csv", delimiter=",", skip_header=2)
    columns = (tmp_path / "test.csv").read_text().splitlines()[0].split(",")
    first = columns.index("1-PID-1-1")
    np.testing.assert_allclose(table[:, first : first + 2], drift, rtol=1e-6)
    np.savez(tmp_path / "m.npz", acceleration=test.acceleration, dt=test.dt, units="m/s^2")
    (tmp_path / "p.csv").write_text("stiffnesses.0\n2e7\n")
    soft, _ = write_demand_sample(
        folder, motions_file=tmp_path / "m.npz", model_label=label, out=tmp_path / "soft.csv",
        params_file=tmp_path / "p.csv",
    )  # fmt: skip
    drawn, _ = write_demand_sample(
        folder, motions_file=tmp_path / "m.npz", model_label=label, out=tmp_path / "drawn.csv"
    )
    soft_table = np.genfromtxt(tmp_path / "soft.csv", delimiter=",", skip_header=2)
    drawn_table = np.genfromtxt(tmp_path / "drawn.csv", delimiter=",", skip_header=2)
    assert not np.allclose(soft_table[:, first], drawn_table[:, first])


def test_a_physics_response_given_to_the_baseline_is_refused(family):
    motions, u, _ = family
    baseline = cp.compose(operator=FNO, training=TRAINING)
    z = np.zeros_like(u)
    with pytest.raises(cp.InputError, match="no physics preprocessor"):
        baseline.fit(motions[:8], u[:8], validation=(motions[8:], u[8:]), z=z[:8], progress=None)
    baseline.fit(motions[:8], u[:8], validation=(motions[8:], u[8:]), progress=None)
    with pytest.raises(cp.InputError, match="no physics preprocessor"):
        baseline.predict_stages(motions, z=z)


def test_a_study_run_finds_the_studys_dataset_and_config(family_run, tmp_path):
    from cphysfno_core.data.layout import run_file

    folder, _ = family_run
    study = tmp_path / "study"
    run = study / "runs" / "table" / "seed-0"
    run.mkdir(parents=True)
    (study / "study.json").write_text("{}")
    (study / "dataset.h5").write_bytes((folder / "dataset.h5").read_bytes())
    (study / "config.json").write_text((folder / "config.json").read_text())
    (run / "metrics.json").write_text((folder / "metrics.json").read_text())
    assert run_file(run, "dataset.h5") == study / "dataset.h5"
    assert run_file(run, "metrics.json") == run / "metrics.json"
    assert run_file(tmp_path, "dataset.h5") == tmp_path / "dataset.h5"  # no study: its own


def test_a_physics_response_of_another_shape_is_refused(family):
    motions, _, _ = family
    model = _fit(family, params=False)
    with pytest.raises(cp.InputError, match=r"physics response \(12, 50, 2\) does not match"):
        model.predict_stages(motions, z=np.zeros((12, 50, 2)))


def test_a_parameter_the_structure_does_not_have_is_refused_at_fit(family):
    motions, u, _ = family
    model = cp.compose(
        structure=_structure(*NOMINAL.values()), preprocessor="els", operator=FNO, training=TRAINING
    )
    wrong = {"stiffnesses.7": np.full(8, 4e7)}
    with pytest.raises(cp.ConfigError, match="no number at stiffnesses.7"):
        model.fit(
            motions[:8], u[:8], validation=(motions[8:], u[8:]), params=wrong,
            validation_params={"stiffnesses.7": np.full(4, 4e7)}, progress=None,
        )  # fmt: skip


def test_a_draw_seen_before_is_not_fitted_again(family, monkeypatch):
    from cphysfno_core.model import composite

    model = _fit(family)
    motions, _, params = family
    model._members.clear()  # the fit kept the draws it saw
    first = {k: v[:3] for k, v in params.items()}
    z = model.physics(motions[:3], params=first)
    kept = dict(model._members)
    assert len(kept) == 3
    again = model.physics(motions[:3], params=first)
    assert np.array_equal(z, again)
    assert all(model._members[row] is member for row, member in kept.items())
    monkeypatch.setattr(composite, "MEMBERS_KEPT", 1)
    model.physics(motions[3:5], params={k: v[3:5] for k, v in params.items()})
    assert list(model._members) == [tuple(np.column_stack(list(params.values()))[4])]
