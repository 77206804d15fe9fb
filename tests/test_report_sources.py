"""What a report draws from the parts themselves: the ground-motion source's target
spectrum under the records' spectra, the structure's own artifacts, and the paper's table
named by ``paper_reference``."""

import json
import types

import numpy as np
import pytest
import toy_components
from toy_experiment import toy_experiment

import cphysfno_core as cp
from cphysfno_core.app.cli import main
from cphysfno_core.plugin import hookimpl
from cphysfno_core.reporting import figures
from cphysfno_core.reporting.paper_tables import PAPER_TABLES, paper_table
from cphysfno_core.signals.intensity import SpectrumBand


class BandedSource(toy_components.ToySource):
    """The toy source with a flat target spectrum."""

    name = "banded-source"

    def target_spectrum(self):
        periods = np.geomspace(0.1, 2.0, 5)
        return SpectrumBand(periods, np.full(5, 2.0), np.full(5, 1.0), np.full(5, 4.0))


class PushedStructure(toy_components.ToyStructure):
    """The toy structure with a curve it writes beside the report."""

    name = "pushed-structure"

    def write_artifacts(self, directory):
        directory.mkdir(parents=True, exist_ok=True)
        data = directory / "curve.json"
        data.write_text(json.dumps({"drift": [0.0, 0.01], "shear": [0.0, 1.0]}))
        figure = directory / "curve.png"
        figure.write_bytes(b"\x89PNG not really")
        return [data, figure]


@pytest.fixture
def registry():
    plugin = types.ModuleType("extras")
    plugin.cphysfno_ground_motions = hookimpl(lambda: [BandedSource])
    plugin.cphysfno_structures = hookimpl(lambda: [PushedStructure])
    with toy_components.registered(plugin) as registry:
        yield registry


CONFIG = toy_experiment(
    structure={"name": "pushed-structure"},
    ground_motion="banded-source",
    n_steps=100,
    operator={"width": 4},
    data={"n_train": 6, "n_val": 2, "n_test": 2},
    training={"epochs": 1, "batch_size": 3},
    output={"baseline": False, "paper_reference": "example1"},
)


def test_report_draws_the_target_spectrum_and_embeds_the_structures_figures(registry, tmp_path):
    config = tmp_path / "run.toml"
    config.write_text(CONFIG)
    out = tmp_path / "out"
    assert main(["run", str(config), "--out", str(out)]) == 0
    report = (out / "report.md").read_text()
    assert (out / "figures" / "motion_spectra.png").stat().st_size > 1000
    assert "figures/motion_spectra.png" in report
    assert (out / "structure" / "curve.json").exists()
    assert "structure/curve.png" in report and "curve.json" not in report
    saved = out / "models" / "c-phystoy-operator-toy-linear" / "structure" / "curve.json"
    assert json.loads(saved.read_text())["shear"] == [0.0, 1.0]
    # two outputs: the paper's five-story Table 1 does not fit, so no value in parentheses
    assert "paper's Table 1" in report and "(0." not in report.split("## Figures")[0]


def test_paper_tables_have_one_value_per_output():
    outputs = {"example1": 5, "example2": 10, "example3": 9}
    for reference, table in PAPER_TABLES.items():
        for rmse, rel_l2 in table.rows.values():
            assert len(rmse) == len(rel_l2) == outputs[reference]
    assert "Table 1" in PAPER_TABLES["example1"].caption
    assert "Table 3" in PAPER_TABLES["example2"].caption
    assert "Table 5" in PAPER_TABLES["example3"].caption
    assert paper_table("none") is None


def test_paper_values_stand_beside_ours_only_where_the_row_fits():
    table = paper_table("example3")
    ours = [f"{v:.4f}" for v in np.linspace(0.1, 0.9, 9)]
    beside = table.beside("c-physfno-els", "rel_l2", ours, 4)
    assert beside[0] == "0.1000 (0.2055)" and beside[-1] == "0.9000 (0.1749)"
    assert table.beside("refined-c-physfno-els", "rmse", ours, 4)[6] == "0.7000 (0.0035)"
    assert table.beside("c-physfno-modal", "rel_l2", ours, 4) == ours
    assert table.beside("fno", "rel_l2", ours[:5], 4) == ours[:5]


def test_spectrum_band_checks_its_shapes():
    with pytest.raises(cp.InputError, match="lower must have one value per period"):
        SpectrumBand(np.array([0.1, 1.0]), np.ones(2), np.ones(3), np.ones(2))
    with pytest.raises(cp.InputError, match="periods"):
        SpectrumBand(np.array([0.0, 1.0]), np.ones(2), np.ones(2), np.ones(2))


def test_motion_spectra_are_drawn_with_and_without_a_target(tmp_path):
    acceleration = np.random.default_rng(0).standard_normal((30, 500))
    band = BandedSource().target_spectrum()
    for target in (None, band):
        path = figures.motion_spectra(acceleration, 0.01, tmp_path / "a" / "s.png", target=target)
        assert path.stat().st_size > 1000


def test_fourteen_models_each_get_their_own_style(tmp_path):
    from cphysfno_core.reporting import figures

    styles = figures.model_styles(14)
    assert len({tuple(sorted(s.items())) for s in styles}) == 14
    rng = np.random.default_rng(0)
    truth = rng.uniform(0.01, 0.05, 30)
    predicted = {f"model-{k}": truth * rng.uniform(0.8, 1.2, 30) for k in range(14)}
    path = figures.peaks(truth, predicted, "roof", tmp_path / "peaks.png")
    assert path.stat().st_size > 20_000
