"""Named responses of ``opensees-model`` (a base shear from the support's reaction, a
story spring's force) against the hand computation of a shear building of zeroLength
springs, through the dataset (with units) and the report; bad names refused early."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
import script_models as sm

import cphysfno_core as cp
from cphysfno_core import edp
from cphysfno_core.app import pipeline

K1 = 4.0e7  # N/m
OUTPUTS = [[1, 1], [2, 1]]
BASE_SHEAR = {"name": "base_shear", "kind": "nodeReaction", "nodes": [0], "dof": 1, "unit": "kN",
              "scale": -1e-3, "pelicun_type": "VB", "pelicun_location": 0}  # fmt: skip
SPRING_2 = {"name": "spring_2", "kind": "eleResponse", "elements": [2], "args": ["basicForce"],
            "unit": "N", "description": "force in the second story's spring"}  # fmt: skip


@pytest.fixture(scope="module")
def springs(tmp_path_factory):
    """Two stories of Steel01 springs, 4e7 and 3e7 N/m yielding at 0.01 m, 2e4 kg floors."""
    return sm.springs(
        tmp_path_factory.mktemp("springs"),
        stiffness=(K1, 3.0e7), yield_force=(K1 * 0.01, 3.0e5), masses=(2.0e4, 2.0e4),
    )  # fmt: skip


def _model(springs, *responses, **more):
    return cp.create(
        "structure", "opensees-model", script=str(springs), outputs=OUTPUTS,
        story_heights=[3.0, 3.0], responses=list(responses), **more,
    )  # fmt: skip


def test_a_base_shear_is_the_first_springs_force_and_a_spring_force_its_own(springs):
    model = _model(springs, BASE_SHEAR, SPRING_2)
    assert [c.name for c in model.response_channels()] == ["base_shear", "spring_2"]
    weak = sm.records(n=1, n_steps=301, peak=0.5)  # both springs stay elastic
    strong = sm.records(n=1, n_steps=301, peak=15.0, seed=2)  # both yield
    responses = model.simulate(weak)
    u = responses.displacement[0]
    assert np.abs(u[:, 0]).max() < 0.01  # below the first spring's yield drift
    shear = responses.extras["base_shear"][0, :, 0]
    # reaction at the support = -(spring force) = -k1 u1, scaled by -1e-3 to kN
    np.testing.assert_allclose(shear, 1e-3 * K1 * u[:, 0], rtol=1e-9, atol=1e-9)
    found = edp.compute(responses, model, weak)
    np.testing.assert_allclose(found["PR"][0, 0], np.abs(shear).max())
    assert found.units["PR"] == ("kN", "N") and found.columns["PR"] == ("base_shear", "spring_2")
    yielded = model.simulate(strong)
    drift = np.diff(np.concatenate([np.zeros((301, 1)), yielded.displacement[0]], axis=1), axis=1)
    assert np.abs(drift).max(axis=0).min() > 0.01  # past yield: no longer k u
    force = yielded.extras["spring_2"][0, :, 0]
    assert np.abs(force).max() < 3.0e7 * 0.01 * (1 + 0.05 * (np.abs(drift[:, 1]).max() / 0.01))
    assert np.corrcoef(force, drift[:, 1])[0, 1] > 0.9  # the spring's force follows its drift


def test_a_run_stores_the_responses_with_their_units_and_reports_their_peaks(springs, tmp_path):
    config = sm.tiny_run(
        {
            "name": "opensees-model", "script": str(springs), "outputs": OUTPUTS,
            "story_heights": [3.0, 3.0], "responses": [BASE_SHEAR, SPRING_2],
        }
    )  # fmt: skip
    pipeline.run(config, tmp_path)
    with h5py.File(tmp_path / "dataset.h5") as f:
        assert f["extras/base_shear"].shape == (8, 301, 1)
        assert f["extras/base_shear"].attrs["units"] == "kN"
        assert f["extras/spring_2"].attrs["units"] == "N"
        assert "second story" in f["extras/spring_2"].attrs["description"]
    data = cp.load_dataset(tmp_path / "dataset.h5")
    assert [c.pelicun_type for c in data.response_channels] == ["VB", None]
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["edp"]["edps"]["PR"]["scored_at"] == ["base_shear", "spring_2"]
    assert set(metrics["edp"]["edps"]) == {"PID", "RID", "PFA", "PFV", "PD", "PR"}
    row = next(iter(v for k, v in metrics["models"].items() if not k.startswith("physics")))
    assert set(row["edp"]) == {"PID", "PFA", "PFV", "PD"}  # it does not learn them
    assert "PR" in metrics["baselines"]["baseline-gp"]["edp"]
    report = (tmp_path / "report.md").read_text()
    assert "Named responses, simulated median peak" in report and "base_shear" in report
    assert "### Peak absolute floor velocity (PFV, m/s)" in report


@pytest.mark.parametrize(
    ("response", "message"),
    [
        (BASE_SHEAR | {"nodes": [7]}, "'base_shear' names node 7, which the model"),
        (BASE_SHEAR | {"dof": 4}, "node 0 has DOFs 1 to 3, not 4"),
        (SPRING_2 | {"elements": [9]}, "'spring_2' names element 9"),
        (SPRING_2 | {"component": 3}, "gives 1 values, not component 3"),
    ],
)
def test_a_response_the_model_cannot_give_is_refused_when_the_model_is_built(
    springs, response, message
):
    with pytest.raises(cp.ConfigError, match=message):
        _model(springs, response).periods()


@pytest.mark.parametrize(
    ("responses", "message"),
    [
        ([BASE_SHEAR, BASE_SHEAR], "the names base_shear are taken"),
        ([BASE_SHEAR | {"name": "absolute_acceleration"}], "absolute_acceleration are taken"),
        ([BASE_SHEAR | {"name": "displacement"}], "displacement are taken"),
        ([{k: v for k, v in BASE_SHEAR.items() if k != "dof"}], "nodeReaction needs nodes"),
        ([SPRING_2 | {"nodes": [1]}], "eleResponse needs elements"),
        ([BASE_SHEAR | {"pelicun_type": "vb"}], "pelicun_type"),
    ],
)
def test_response_settings_are_checked_with_the_config(springs, responses, message):
    with pytest.raises(cp.ConfigError, match=message):
        _model(springs, *responses)


def test_a_run_with_an_isolation_level_and_a_base_shear_gives_demands_pelicun_loads(tmp_path):
    """The isolated building of examples/models/isolated_building.py, its stories over the
    base (the isolation level, a floor no story ends at) and the isolators' shear and the
    middle isolator's deformation recorded: `cphysfno demands` writes the surrogate's
    demands, and the simulated EDPs with the named responses, both load in pelicun."""
    pelicun = pytest.importorskip("pelicun.assessment")
    from cphysfno_core.app.cli import main
    from cphysfno_core.reporting.demands import write_pelicun_demands

    shear = {"name": "base_shear", "kind": "nodeReaction", "nodes": [1, 2, 3], "dof": 1,
             "scale": -1.0, "unit": "kN", "pelicun_type": "VB", "pelicun_location": 0}
    isolator = {"name": "isolator", "kind": "eleResponse", "elements": [2],
                "args": ["basicDeformation"], "unit": "m", "pelicun_type": "BRD"}  # fmt: skip
    structure = {
        "name": "opensees-model", "script": str(sm.EXAMPLES / "models" / "isolated_building.py"),
        "outputs": [[11, 1], [21, 1], [31, 1], [41, 1]], "gravity": "gravity",
        "drift_pairs": [[11, 21], [21, 31], [31, 41]], "responses": [shear, isolator],
    }  # fmt: skip
    pipeline.run(sm.tiny_run(structure), tmp_path)
    assert main(["demands", str(tmp_path)]) == 0
    written = tmp_path / "demands" / "demands.csv"
    header = written.read_text().splitlines()[0].split(",")
    assert [c for c in header if "-PFA-" in c] == [f"1-PFA-{k}-1" for k in range(5)]
    assert [c for c in header if "-PID-" in c] == [f"1-PID-{s}-1" for s in range(1, 4)]
    run = pelicun.Assessment({"PrintLog": False})
    run.demand.load_sample(str(written))
    assert len(run.demand.sample) == 2  # the two test records

    data = cp.load_dataset(tmp_path / "dataset.h5")
    model = cp.create("structure", **structure)
    rows = data.rows("test")
    simulated = edp.compute(
        cp.Responses(data.u[rows], data.dt, extras={k: data.extras[k][rows] for k in
                     ("base_shear", "isolator", edp.ACCELERATION_EXTRA)}),
        model, cp.GroundMotions(data.ag[rows], data.dt),
    )  # fmt: skip
    both = write_pelicun_demands(tmp_path / "simulated.csv", simulated)
    assert both.columns[-2:] == ("1-VB-0-1", "1-BRD-1-1") and both.units[-2:] == ("kN", "m")
    run = pelicun.Assessment({"PrintLog": False})
    run.demand.load_sample(str(both.path))
    np.testing.assert_allclose(
        run.demand.sample[("VB", "0", "1")], 1000.0 * simulated["PR"][:, 0], rtol=1e-6
    )  # kN in the file, N in pelicun
