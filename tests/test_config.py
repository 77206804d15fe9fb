import math
import tomllib
from pathlib import PurePosixPath

import pytest

import cphysfno_core as cp
from cphysfno_core.config.toml_writer import dumps

BASE = {
    "structure": {"name": "toy-structure", "cubic": 5.0},
    "ground_motion": {"name": "toy-source"},
    "preprocessor": {"name": "toy-linear"},
    "operator": {"name": "toy-operator", "width": 4},
    "data": {"n_train": 4, "n_val": 2, "n_test": 2},
}


def _with(section, **fields):
    data = {k: (dict(v) if isinstance(v, dict) else v) for k, v in BASE.items()}
    data[section] = {**data.get(section, {}), **fields}
    return data


def test_a_valid_config_parses_with_component_fields(toy_registry):
    config = cp.parse_config(BASE)
    assert config.structure.params == {"cubic": 5.0}
    assert [p.name for p in config.preprocessor] == ["toy-linear"]
    assert config.training.learning_rate == 1e-3 and config.training.decay_factor == 0.5


@pytest.mark.parametrize(
    "data, message",
    [
        (_with("operator", width=0), r"^operator\.width: Input should be greater than 0"),
        (_with("operator", widht=3), r"^operator\.widht: unknown field"),
        (
            _with("structure", name="tower"),
            r"^structure\.name: unknown structure 'tower'.*"
            r"known structure names: .*toy-structure",
        ),
        (_with("data", n_train=0), r"^data\.n_train: Input should be greater than 0"),
        (_with("training", epochs="many"), r"^training\.epochs: Input should be a valid"),
        (_with("training", lr=1.0), r"^training\.lr: unknown field"),
        ({k: v for k, v in BASE.items() if k != "operator"}, r"^operator: Field required"),
        (_with("refiner", name="nope"), r"^refiner\.name: unknown refiner 'nope'"),
    ],
)
def test_a_wrong_field_names_its_path(toy_registry, data, message):
    with pytest.raises(cp.ConfigError, match=message):
        cp.parse_config(data)


def test_preprocessors_may_be_a_list_and_must_be_distinct(toy_registry):
    data = dict(BASE, preprocessor=[{"name": "toy-linear"}, {"name": "needs-linear-system"}])
    assert len(cp.parse_config(data).preprocessor) == 2
    twice = dict(BASE, preprocessor=[{"name": "toy-linear"}, {"name": "toy-linear"}])
    with pytest.raises(cp.ConfigError, match="each preprocessor may appear once"):
        cp.parse_config(twice)


def test_load_config_reports_the_file_and_bad_toml(toy_registry, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("[structure\nname = 1")
    with pytest.raises(cp.ConfigError, match="bad.toml is not valid TOML"):
        cp.load_config(path)
    with pytest.raises(cp.ConfigError, match="cannot read config"):
        cp.load_config(tmp_path / "missing.toml")


def test_relative_paths_in_a_config_file_are_taken_from_its_folder(tmp_path, monkeypatch):
    """The script and the records' folder resolve beside the config, from any directory."""
    folder = tmp_path / "study"
    (folder / "records").mkdir(parents=True)
    (folder / "config.toml").write_text(
        '[structure]\nname = "opensees-model"\nscript = "models/frame.py"\n'
        "outputs = [[2, 1]]\n"
        '[ground_motion]\nname = "recorded"\nfolder = "records"\n'
        '[[preprocessor]]\nname = "els"\n[operator]\nname = "fno"\n'
    )
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    config = cp.load_config(folder / "config.toml")
    assert config.structure.params["script"] == str(folder / "models" / "frame.py")
    assert config.ground_motion.params["folder"] == str(folder / "records")
    assert config.structure.params["outputs"] == [[2, 1]]


def test_absolute_paths_and_paths_in_a_mapping_are_kept(tmp_path):
    script = tmp_path / "frame.py"
    data = {
        "structure": {"name": "opensees-model", "script": str(script), "outputs": [[2, 1]]},
        "ground_motion": {"name": "white-noise"},
        "preprocessor": {"name": "els"},
        "operator": {"name": "fno"},
    }
    (tmp_path / "absolute.toml").write_text(
        f'[structure]\nname = "opensees-model"\nscript = "{script}"\noutputs = [[2, 1]]\n'
        '[ground_motion]\nname = "white-noise"\n[[preprocessor]]\nname = "els"\n'
        '[operator]\nname = "fno"\n'
    )
    assert cp.load_config(tmp_path / "absolute.toml").structure.params["script"] == str(script)
    relative = {**data, "structure": {**data["structure"], "script": "frame.py"}}
    assert cp.parse_config(relative).structure.params["script"] == "frame.py"


def test_the_toml_writer_reads_back_what_it_wrote():
    data = {
        "title": 'a "quoted"\nname é\t\x7f \U0001f30b',
        "path": PurePosixPath("/records/RSN1.AT2"),
        "ratio": 1e-05,
        "limits": [-math.inf, math.inf],
        "flag": False,
        "empty": [],
        "grid": [[1, 2], [3]],
        "points": [{"x": 1.0}, 2],
        "dotted.key": 3,
        "missing": None,
        "table": {"n": 1, "inner": {"deep": "yes"}, "rows": [{"a": 1, "sub": {"b": 2}}]},
        "layer": [{"kind": "fno", "widths": [8, 16]}, {"kind": "deeponet"}],
    }
    back = tomllib.loads(dumps(data))
    assert math.isnan(tomllib.loads(dumps({"nan": math.nan}))["nan"])
    expected = {k: v for k, v in data.items() if v is not None}
    expected["path"] = "/records/RSN1.AT2"
    assert back == expected


def test_the_toml_writer_names_a_value_it_cannot_write():
    with pytest.raises(TypeError, match="no TOML form for complex"):
        dumps({"z": 1j})


def test_a_config_reads_back_from_its_toml(toy_registry):
    config = cp.parse_config(_with("training", epochs=3, learning_rate=2.5e-4))
    assert cp.parse_config(tomllib.loads(config.to_toml())) == config


def test_check_validates_a_config_and_its_structure_before_any_work(toy_registry, tmp_path, capsys):
    from cphysfno_core.app.cli import main

    path = tmp_path / "ok.toml"
    path.write_text(
        '[structure]\nname = "toy-storied"\n\n[ground_motion]\nname = "toy-source"\n\n'
        '[[preprocessor]]\nname = "toy-linear"\n\n[operator]\nname = "toy-operator"\n'
    )
    assert main(["check", str(path)]) == 0
    printed = capsys.readouterr().out
    assert "check out" in printed and "toy-storied: 2 outputs (dof-1, dof-2), T1 = 1 s" in printed
    assert "2 stories, heights 3, 2.5 m" in printed
    bad = tmp_path / "bad.toml"
    bad.write_text(path.read_text().replace("toy-storied", "toy-structure").replace(
        'name = "toy-linear"', 'name = "needs-linear-system"'))  # fmt: skip
    assert main(["check", str(bad)]) == 2
    error = capsys.readouterr().err
    assert "needs-linear-system" in error and "linear_system" in error
