"""Datasets of a structure with random parameters: every record simulated, and its physics
fitted, on its own draw; the draws kept, reproducible and resumable; a fixed structure's
dataset unchanged."""

import tomllib

import numpy as np
import pytest

import cphysfno_core as cp
from cphysfno_core.app.inspection import describe_file
from cphysfno_core.data import Dataset, generation
from cphysfno_core.data.simulation import simulate_chunk
from cphysfno_core.plugin import Structure

MASSES = [4.0e4, 3.0e4, 3.0e4]
STIFFNESSES = [3e7, 2e7]  # stories 2 and 3; story 1 is drawn in most tests
YIELD = 0.01
RANDOM = {
    "stiffness": '{ dist = "lognormal", median = 4e7, beta = 0.3, unit = "N/m" }',
    "yield": '{ dist = "normal", mean = 0.01, std = 0.002, lower = 0.004, unit = "m" }',
}

CORRELATED = '[["stiffnesses.0", "story_law.yield_displacement", 0.5]]'


def _toml(stiffness: str, yield_displacement: str, seed: int = 0, chunk_size: int = 2) -> str:
    return f"""
preprocessor = [{{ name = "els" }}, {{ name = "modal", modes = 2 }}]

[structure]
name = "shear-building"
masses = {MASSES}
stiffnesses = [{stiffness}, {STIFFNESSES[0]}, {STIFFNESSES[1]}]
story_law = {{ name = "bilinear", alpha = 0.05, yield_displacement = {yield_displacement} }}

[uncertainty]
correlations = {CORRELATED if "dist" in stiffness and "dist" in yield_displacement else []}

[ground_motion]
name = "white-noise"
duration = 2.0
spectral_intensity = 0.3

[operator]
name = "fno"

[data]
n_train = 3
n_val = 1
n_test = 1
seed = {seed}
chunk_size = {chunk_size}
executor = "serial"
"""


def _generate(path, **fields) -> Dataset:
    text = _toml(
        fields.pop("stiffness", RANDOM["stiffness"]), fields.pop("law", RANDOM["yield"]), **fields
    )
    cp.generate_dataset(cp.parse_config(tomllib.loads(text)), path, progress=False)
    return cp.load_dataset(path)


def _fixed(stiffness: float, yield_displacement: float) -> Structure:
    return cp.create(
        "structure",
        "shear-building",
        masses=MASSES,
        stiffnesses=[stiffness, *STIFFNESSES],
        story_law={"name": "bilinear", "alpha": 0.05, "yield_displacement": yield_displacement},
    )


@pytest.fixture(scope="module")
def drawn_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("drawn") / "data.h5"
    _generate(path)
    return path


@pytest.fixture
def drawn(drawn_path) -> Dataset:
    return cp.load_dataset(drawn_path)


def test_each_record_is_its_own_structure_simulated_with_its_own_physics(drawn):
    assert drawn.param_names == ("stiffnesses.0", "story_law.yield_displacement")
    assert drawn.param_units == ("N/m", "m")
    assert drawn.params.shape == (5, 2) and len(np.unique(drawn.params, axis=0)) == 5
    motions = cp.GroundMotions(drawn.ag, drawn.dt)
    for i, (stiffness, yield_displacement) in enumerate(drawn.params):
        structure = _fixed(stiffness, yield_displacement)
        record = motions[i]
        np.testing.assert_array_equal(drawn.u[i], structure.simulate(record).displacement[0])
        els = cp.create("preprocessor", "els").fit(structure)
        np.testing.assert_array_equal(drawn.z["els"][i], els.transform(record)[0])
        modal = cp.create("preprocessor", "modal", modes=2).fit(structure)
        np.testing.assert_allclose(
            drawn.z["modal"][i], modal.transform(record)[0], rtol=0, atol=1e-12
        )
    nominal = cp.create("preprocessor", "els").fit(_fixed(4e7, 0.01)).transform(motions)
    assert not np.allclose(drawn.z["els"], nominal)


def test_draws_are_those_of_the_seed_for_any_chunk_size(drawn, tmp_path):
    other = _generate(tmp_path / "other.h5", chunk_size=5)
    np.testing.assert_array_equal(other.params, drawn.params)
    np.testing.assert_array_equal(other.u, drawn.u)
    np.testing.assert_array_equal(other.z["els"], drawn.z["els"])
    reseeded = _generate(tmp_path / "reseeded.h5", seed=1)
    assert not np.array_equal(reseeded.params, drawn.params)


def test_a_killed_generation_resumed_gives_the_same_draws_and_records(drawn, tmp_path, monkeypatch):
    calls = []

    def killed_after_one_chunk(*arguments):
        if calls:
            raise KeyboardInterrupt
        calls.append(arguments)
        return simulate_chunk(*arguments)

    monkeypatch.setattr(generation, "simulate_chunk", killed_after_one_chunk)
    with pytest.raises(KeyboardInterrupt):
        _generate(tmp_path / "data.h5")
    monkeypatch.setattr(
        generation, "simulate_chunk", lambda *a: calls.append(a) or simulate_chunk(*a)
    )
    resumed = _generate(tmp_path / "data.h5")
    assert len(calls) == 3  # 3 chunks of at most 2 records: the first was kept
    np.testing.assert_array_equal(resumed.params, drawn.params)
    np.testing.assert_array_equal(resumed.u, drawn.u)
    np.testing.assert_array_equal(resumed.z["modal"], drawn.z["modal"])


def test_a_family_of_one_is_the_fixed_structure(tmp_path):
    fixed = _generate(tmp_path / "fixed.h5", stiffness="4e7", law=str(YIELD))
    one = '{{ dist = "uniform", low = {0}, high = {0}, unit = "{1}" }}'
    family = _generate(
        tmp_path / "family.h5", stiffness=one.format(4e7, "N/m"), law=one.format(YIELD, "m")
    )
    np.testing.assert_array_equal(family.params, np.tile([4e7, YIELD], (5, 1)))
    np.testing.assert_array_equal(family.ag, fixed.ag)
    np.testing.assert_allclose(family.u, fixed.u, rtol=0, atol=1e-12)
    for name in ("els", "modal"):
        np.testing.assert_allclose(family.z[name], fixed.z[name], rtol=0, atol=1e-12)


def test_a_fixed_structure_dataset_is_its_simulation_and_keeps_no_draws(tmp_path):
    dataset = _generate(tmp_path / "fixed.h5", stiffness="4e7", law=str(YIELD))
    structure = _fixed(4e7, YIELD)
    motions = cp.GroundMotions(dataset.ag, dataset.dt)
    np.testing.assert_array_equal(dataset.u, structure.simulate(motions).displacement)
    els = cp.create("preprocessor", "els").fit(structure)
    np.testing.assert_array_equal(dataset.z["els"], els.transform(motions))
    assert dataset.params.shape == (5, 0) and dataset.param_names == ()
    assert "random structural parameters" not in describe_file(tmp_path / "fixed.h5")


def test_inspect_names_the_parameters_with_their_units_and_spread(drawn, drawn_path):
    text = describe_file(drawn_path)
    assert "random structural parameters (5 draws, one a record):" in text
    for j, (name, unit) in enumerate(zip(drawn.param_names, drawn.param_units, strict=True)):
        column = np.sort(drawn.params[:, j])
        low, median, high = column[0], column[2], column[4]
        line = f"{name:<30} [{unit}] min {low:.6g}, median {median:.6g}, max {high:.6g}"
        assert line in text


def test_a_draw_that_makes_no_structure_stops_generation_before_any_simulation(tmp_path):
    wide = '{ dist = "normal", mean = 4e7, std = 4e8 }'
    text = _toml(wide, str(YIELD))
    with pytest.raises(
        cp.ConfigError,
        match=r"record \d+ draws a structure that is not valid "
        r"\(stiffnesses.0 = -.*\): .*bound the distributions",
    ):
        cp.generate_dataset(cp.parse_config(tomllib.loads(text)), tmp_path / "d.h5", progress=False)
    assert not (tmp_path / "d.h5.parts").exists()
