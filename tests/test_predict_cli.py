"""``cphysfno predict``: a saved model's predictions for motions in a file, equal to the
Python API's, and every bad input refused with one line saying what to do."""

import numpy as np
import pytest

import cphysfno_core as cp
from cphysfno_core.app.cli import main
from cphysfno_core.plugin import TimeGrid


@pytest.fixture
def saved(trained_toy, tmp_path):
    model, gm = trained_toy
    return model, model.save(tmp_path / "model"), gm[8:]


def test_predictions_are_the_models_and_the_summary_is_printed(saved, tmp_path, capsys):
    model, folder, gm = saved
    motions = tmp_path / "motions.npz"
    np.savez(motions, acceleration=gm.acceleration, dt=gm.dt, units="m/s^2")
    out = tmp_path / "pred" / "out.npz"
    assert main(["predict", str(folder), str(motions), "--out", str(out)]) == 0
    stages = model.predict_stages(gm)
    with np.load(out) as written:
        np.testing.assert_allclose(written["mean"], stages.mean, rtol=1e-6)
        np.testing.assert_allclose(written["std"], stages.std, rtol=1e-6)
        np.testing.assert_allclose(written["z"], stages.z)
        assert float(written["dt"]) == 0.02
        assert list(written["output_names"]) == list(model.structure.output_names)
    printed = capsys.readouterr().out
    assert "4 records predicted in" in printed and "ms per record" in printed
    peak = np.median(np.abs(stages.mean[:, :, 0]).max(axis=1))
    assert f"{peak:.4g}" in printed
    assert main(["inspect", str(out)]) == 0
    described = capsys.readouterr().out
    assert f"predictions of model '{model.label}'" in described
    mean_row = next(line for line in described.splitlines() if line.strip().startswith("mean "))
    assert str(stages.mean.shape) in mean_row
    assert "[m] predicted displacement" in described and "[s] time step" in described


def test_a_bare_array_with_its_step_and_records_on_another_grid_with_on_grid(
    saved, tmp_path, capsys
):
    model, folder, gm = saved
    fine = gm.on_grid(TimeGrid(0.01, 200))
    array = tmp_path / "fine.npy"
    np.save(array, fine.acceleration)
    out = tmp_path / "fine-pred.npz"
    command = [
        "predict",
        str(folder),
        str(array),
        "--out",
        str(out),
        "--dt",
        "0.01",
        "--units",
        "m/s2",
    ]
    assert main(command) == 2
    error = capsys.readouterr().err
    assert "these have 200 samples at dt = 0.01 s" in error and "--on-grid" in error
    assert not out.exists()
    assert main([*command, "--on-grid"]) == 0
    with np.load(out) as written:
        expected = model.predict(fine.on_grid(model.grid))[0]
        np.testing.assert_allclose(written["mean"], expected, rtol=1e-6)


@pytest.mark.parametrize(
    ("content", "extra", "message"),
    [
        ({"acceleration": np.ones((2, 80))}, [], "lacks dt: it needs 'acceleration'"),
        ({"acceleration": np.ones((2, 80)), "dt": 0.02}, ["--dt", "0.02"], "holds its own dt"),
        ({"acceleration": np.full((2, 80), np.nan), "dt": 0.02}, [], "NaN or Inf"),
        (None, [], "no such file of ground motions"),
    ],
)
def test_bad_motion_files_are_refused(saved, tmp_path, capsys, content, extra, message):
    _, folder, _ = saved
    path = tmp_path / "m.npz"
    if content is not None:
        np.savez(path, **content)
    out = tmp_path / "o.npz"
    assert main(["predict", str(folder), str(path), "--out", str(out), *extra]) == 2
    error = capsys.readouterr().err
    assert message in error and "not a readable NumPy file" not in error
    assert not out.exists()


def test_motions_carry_their_unit(saved, tmp_path, capsys):
    model, folder, gm = saved
    in_g = tmp_path / "g.npz"
    np.savez(in_g, acceleration=gm.acceleration / 9.80665, dt=gm.dt, units="g")
    out = tmp_path / "g-pred.npz"
    assert main(["predict", str(folder), str(in_g), "--out", str(out)]) == 0
    with np.load(out) as written:
        np.testing.assert_allclose(written["mean"], model.predict(gm)[0], rtol=1e-6)
    bare = tmp_path / "cm.npy"
    np.save(bare, 100.0 * gm.acceleration)
    command = ["predict", str(folder), str(bare), "--dt", "0.02", "--out", str(out)]
    assert main([*command, "--units", "cm/s^2"]) == 0
    with np.load(out) as written:
        np.testing.assert_allclose(written["mean"], model.predict(gm)[0], rtol=1e-6)
    assert main([*command, "--units", "furlong/s2"]) == 2
    assert "--units furlong/s2: give one of m/s2, g, cm/s2" in capsys.readouterr().err
    assert main(["predict", str(folder), str(in_g), "--units", "m/s2", "--out", str(out)]) == 2
    assert "holds motions in g: do not give --units m/s2" in capsys.readouterr().err
    unsaid = tmp_path / "unsaid.npz"
    np.savez(unsaid, acceleration=gm.acceleration, dt=gm.dt)
    with pytest.warns(cp.CphysfnoWarning, match="taken as m/s\\^2"):
        assert main(["predict", str(folder), str(unsaid), "--out", str(out)]) == 0


def test_a_bare_array_needs_its_step_and_the_output_an_npz_name(saved, tmp_path, capsys):
    _, folder, gm = saved
    array = tmp_path / "m.npy"
    np.save(array, gm.acceleration)
    assert main(["predict", str(folder), str(array), "--out", str(tmp_path / "o.npz")]) == 2
    assert "is a bare array: give its time step (--dt, s)" in capsys.readouterr().err
    command = ["predict", str(folder), str(array), "--dt", "0.02", "--out", "o.csv"]
    assert main(command) == 2
    assert "--out o.csv: name an .npz file" in capsys.readouterr().err
    assert main(["predict", str(tmp_path), str(array), "--dt", "0.02", "--out", "o.npz"]) == 2
    assert "holds no readable model.json" in capsys.readouterr().err


def test_bfloat16_precision_is_passed_through(saved, tmp_path):
    model, folder, gm = saved
    motions = tmp_path / "motions.npz"
    np.savez(motions, acceleration=gm.acceleration, dt=gm.dt, units="m/s2")
    out = tmp_path / "low.npz"
    assert (
        main(["predict", str(folder), str(motions), "--out", str(out), "--precision", "bfloat16"])
        == 0
    )
    with np.load(out) as written:
        np.testing.assert_allclose(
            written["operator_output"],
            model.predict_stages(gm, precision="bfloat16").operator_output,
        )
        single = model.predict_stages(gm).operator_output
        change = np.linalg.norm(written["operator_output"] - single) / np.linalg.norm(single)
    assert 1e-5 < change < 1e-2


def _at2(path, values_g, dt):
    """A PEER NGA-West2 AT2 file of ``values_g`` (g) at ``dt`` (s)."""
    lines = [
        "PEER NGA STRONG MOTION DATABASE RECORD",
        "Imperial Valley-06, 10/15/1979, El Centro Array #6, 230",
        "ACCELERATION TIME SERIES IN UNITS OF G",
        f"NPTS=  {len(values_g)}, DT=   {dt:.4f} SEC",
    ]
    lines += [
        "".join(f"  {v: .7E}" for v in values_g[i : i + 5]) for i in range(0, len(values_g), 5)
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_at2_files_and_folders_are_predicted(saved, tmp_path, capsys):
    """PEER AT2 input: one file, or a folder whose records are zero-padded to the longest;
    records of another time step need --on-grid."""
    model, folder, gm = saved
    g = 9.80665
    records = tmp_path / "records"
    records.mkdir()
    first = gm.acceleration[0] / g
    _at2(records / "A.AT2", first, gm.dt)
    _at2(records / "B.at2", gm.acceleration[1][:40] / g, gm.dt)
    out = tmp_path / "at2.npz"
    assert main(["predict", str(folder), str(records / "A.AT2"), "--out", str(out)]) == 0
    with np.load(out) as written:
        expected = model.predict(gm[:1])[0]
        np.testing.assert_allclose(written["mean"], expected, rtol=1e-5, atol=1e-9)
    assert main(["predict", str(folder), str(records), "--out", str(out)]) == 0
    padded = gm.acceleration[:2].copy()
    padded[1, 40:] = 0.0
    with np.load(out) as written:
        expected = model.predict(padded, dt=gm.dt)[0]
        np.testing.assert_allclose(written["mean"], expected, rtol=1e-5, atol=1e-9)
    _at2(records / "C.AT2", first, gm.dt / 2)
    capsys.readouterr()
    assert main(["predict", str(folder), str(records), "--out", str(out)]) == 2
    assert "different time steps" in capsys.readouterr().err
    assert main(["predict", str(folder), str(records), "--out", str(out), "--on-grid"]) == 0
    with np.load(out) as written:
        assert written["mean"].shape == (3, *model.predict(gm[:1])[0].shape[1:])
