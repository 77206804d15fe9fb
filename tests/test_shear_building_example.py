"""The own-building example runs end to end through the command line at tiny size, and its
run gives fragility curves and a pelicun demand sample."""

import json
import re
from pathlib import Path

import numpy as np
import pytest

from cphysfno_core import edp, load_dataset
from cphysfno_core.app.cli import main

EXAMPLE = Path(__file__).parents[1] / "examples" / "shear-building.toml"


@pytest.fixture(scope="module")
def run(tmp_path_factory) -> Path:
    text = EXAMPLE.read_text()
    tiny = {
        "n_train": 8,
        "n_val": 4,
        "n_test": 12,
        "chunk_size": 12,
        "epochs": 2,
        "batch_size": 4,
        "layers": 2,
        "width": 8,
        "projection_width": 16,
    }
    for key, value in tiny.items():
        text = re.sub(rf"(?m)^{key} = .*$", f"{key} = {value}", text)
    text = text.replace("modes = 16", "modes = 8")
    text = text.replace('name = "white-noise"', 'name = "white-noise"\nduration = 5.0')
    folder = tmp_path_factory.mktemp("shear-building")
    path = folder / "tiny.toml"
    path.write_text(text.replace("chunk_size = 12", 'chunk_size = 12\nexecutor = "serial"'))
    out = folder / "out"
    assert main(["-q", "run", str(path), "--out", str(out)]) == 0
    return out


def test_the_shear_building_example_runs_end_to_end(run):
    models = json.loads((run / "metrics.json").read_text())["models"]
    assert {"fno", "c-physfno-els", "c-physfno-modal", "c-physfno-relaxed"} <= set(models)
    assert all(len(row["rel_l2"]) == 4 for row in models.values())


def _median_peak_drift(run: Path) -> float:
    from cphysfno_core import create
    from cphysfno_core.config.experiment import parse_config

    config = parse_config(json.loads((run / "config.json").read_text()))
    structure = create("structure", config.structure.name, **config.structure.params)
    data = load_dataset(run / "dataset.h5")
    demands = edp.compute(data.targets("test"), structure, data.motions("test"))
    return float(np.median(demands.pid.max(axis=1)))


def test_fragility_fits_simulation_and_surrogate_side_by_side(run, capsys):
    threshold = _median_peak_drift(run)  # half the test records exceed it
    arguments = ["fragility", str(run), "--records", "40", "--bootstrap", "10"]
    assert main([*arguments, "--limit-states", f"pid={threshold:.6g}"]) == 0
    printed = capsys.readouterr().out
    assert "simulation | surrogate | surrogate-large" in printed
    document = json.loads((run / "fragility" / "fragility.json").read_text())
    assert document["large_records"] == 40 and document["test_records"] == 12
    assert document["intensity_measure"]["name"] == "sa-t1"
    (fits,) = document["limit_states"].values()
    assert set(fits) == {"simulation", "surrogate", "surrogate-large"}
    simulation = fits["simulation"]
    assert simulation["n_exceeded"] == 6 and simulation["median"] > 0
    low, high = simulation["median_interval"]
    assert low <= simulation["median"] <= high
    assert (run / "fragility" / "fragility.png").stat().st_size > 0
    assert (run / "fragility" / "edp-im.png").stat().st_size > 0


def test_fragility_writes_where_it_is_told(run, tmp_path):
    threshold = _median_peak_drift(run)
    other = tmp_path / "elsewhere"
    arguments = ["fragility", str(run), "--records", "10", "--bootstrap", "5", "--out", str(other)]
    assert main([*arguments, "--limit-states", f"pid={threshold:.6g}"]) == 0
    document = json.loads((other / "fragility.json").read_text())
    assert document["large_records"] == 10 and (other / "fragility.png").is_file()


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--im", "arias"], "unknown intensity measure 'arias'"),
        (["--im", "sa:-1"], "periods must be numbers of s > 0"),
        (["--config", "nowhere.toml"], "nowhere.toml"),
        (["--limit-states", "drift=0.01"], "unknown EDP 'drift': the EDPs are PID"),
        (["--limit-states", "pr=10"], "(PR) need a model that learns them"),
        (["--limit-states", "pd:roof=0.1"], "'roof' is not a column of pd; its columns are"),
        (["--model", "nothing"], "no saved model 'nothing'"),
    ],
)
def test_fragility_refuses_what_it_cannot_fit(run, capsys, arguments, message):
    assert main(["fragility", str(run), "--records", "10", *arguments]) == 2
    assert message in capsys.readouterr().err


def test_fragility_on_floor_velocity_and_one_outputs_displacement(run, tmp_path):
    from cphysfno_core import create
    from cphysfno_core.config.experiment import parse_config

    config = parse_config(json.loads((run / "config.json").read_text()))
    structure = create("structure", config.structure.name, **config.structure.params)
    data = load_dataset(run / "dataset.h5")
    truth = edp.compute(data.targets("test"), structure, data.motions("test"))
    roof = structure.output_names[-1]
    pfv = float(np.median(truth["PFV"][:, 1:].max(axis=1)))
    pd = float(np.median(truth["PD"][:, -1]))
    states = f"pfv={pfv:.6g};pd:{roof}={pd:.6g}"
    arguments = ["fragility", str(run), "--records", "10", "--bootstrap", "5"]
    assert main([*arguments, "--limit-states", states, "--out", str(tmp_path)]) == 0
    document = json.loads((tmp_path / "fragility.json").read_text())
    fits = document["limit_states"]
    assert list(fits) == [f"pfv > {pfv:.6g}", f"pd:{roof} > {pd:.6g}"]
    for fit in fits.values():  # about half the test records exceed each median
        assert 4 <= fit["simulation"]["n_exceeded"] <= 8


def test_demands_writes_the_sample_pelicun_reads(run, capsys):
    assert main(["demands", str(run)]) == 0
    lines = (run / "demands" / "demands.csv").read_text().splitlines()
    header, units = lines[0].split(","), lines[1].split(",")
    assert header[1:5] == [f"1-PID-{s}-1" for s in range(1, 5)]
    assert "1-PFA-0-1" in header and units[header.index("1-PFA-0-1")] == "g"
    assert "1-PFV-4-1" in header and units[header.index("1-PFV-4-1")] == "mps"
    assert len(lines) == 2 + 12


def test_fragility_goes_on_past_a_failed_record_and_an_unreached_limit_state(
    run, capsys, monkeypatch
):
    from cphysfno_core import CompositeModel, InputError

    data = load_dataset(run / "dataset.h5")
    strongest = float(np.abs(data.motions("test").acceleration).max())
    predict = CompositeModel.predict_stages

    def failing(self, motions, *args, **kwargs):  # as physics that diverges on one record
        if np.isclose(np.abs(motions.acceleration).max(axis=1), strongest).any():
            raise InputError("z holds NaN or Inf (first in record 0)")
        return predict(self, motions, *args, **kwargs)

    monkeypatch.setattr(CompositeModel, "predict_stages", failing)
    threshold = _median_peak_drift(run)
    arguments = ["fragility", str(run), "--records", "10", "--bootstrap", "5", "--im", "sa:0.4"]
    assert main([*arguments, "--limit-states", f"pid=5.0,{threshold:.6g}"]) == 0
    printed = capsys.readouterr().out
    assert "1 test records could not be predicted" in printed and "not reached" in printed
    document = json.loads((run / "fragility" / "fragility.json").read_text())
    assert document["skipped_records"]["test"]["count"] == 1
    assert "z holds NaN" in next(iter(document["skipped_records"]["test"]["first"].values()))
    assert document["intensity_measure"]["description"] == "Sa(0.4 s), 5 % damped"
    unreached, reached = document["limit_states"].values()
    assert unreached["simulation"]["median"] is None
    assert "no record exceeds it" in unreached["simulation"]["note"]
    assert reached["simulation"]["median"] > 0 and reached["surrogate"]["n_records"] == 11


def test_fragility_flags_a_fit_of_too_few_exceedances(run, capsys):
    data = load_dataset(run / "dataset.h5")
    from cphysfno_core import create
    from cphysfno_core.config.experiment import parse_config

    config = parse_config(json.loads((run / "config.json").read_text()))
    structure = create("structure", config.structure.name, **config.structure.params)
    pid = edp.compute(data.targets("test"), structure, data.motions("test")).pid.max(axis=1)
    threshold = float(np.sort(pid)[-3:-1].mean())  # two of the twelve records exceed it
    arguments = ["fragility", str(run), "--records", "10", "--bootstrap", "5", "--im", "sa-avg"]
    assert main([*arguments, "--limit-states", f"pid={threshold:.8g}"]) == 0
    printed = capsys.readouterr().out
    document = json.loads((run / "fragility" / "fragility.json").read_text())
    (fits,) = document["limit_states"].values()
    assert "only 2 of 12 records exceed it" in fits["simulation"]["flags"]
    assert "only 2 of 12 records exceed it" in printed and "*" in printed
    assert document["intensity_measure"]["name"] == "sa-avg"


def test_fragility_reads_an_edited_config(run, tmp_path):
    threshold = _median_peak_drift(run)
    edited = tmp_path / "taller.toml"
    text = (run.parent / "tiny.toml").read_text()
    edited.write_text(
        text.replace("story_heights = [4.0, 3.2, 3.2, 3.2]", "story_heights = [8.0, 6.4, 6.4, 6.4]")
    )
    arguments = ["fragility", str(run), "--records", "10", "--bootstrap", "5", "--out"]
    limit = ["--limit-states", f"pid={threshold:.6g}"]
    assert main([*arguments, str(tmp_path / "saved"), *limit]) == 0
    assert main([*arguments, str(tmp_path / "edited"), "--config", str(edited), *limit]) == 0
    saved, taller = (
        json.loads((tmp_path / name / "fragility.json").read_text())["limit_states"]
        for name in ("saved", "edited")
    )
    # twice the heights, half the drift ratios: fewer records exceed the same threshold
    (saved_fit,), (taller_fit,) = saved.values(), taller.values()
    assert taller_fit["simulation"]["n_exceeded"] < saved_fit["simulation"]["n_exceeded"]
