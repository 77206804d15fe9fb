"""The own-building example runs end to end through the command line at tiny size."""

import json
import re
from pathlib import Path

from cphysfno_core.app.cli import main

EXAMPLE = Path(__file__).parents[1] / "examples" / "shear-building.toml"


def test_the_shear_building_example_runs_end_to_end(tmp_path, capsys):
    text = EXAMPLE.read_text()
    tiny = {
        "n_train": 8,
        "n_val": 4,
        "n_test": 4,
        "chunk_size": 8,
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
    path = tmp_path / "tiny.toml"
    path.write_text(text.replace("chunk_size = 8", 'chunk_size = 8\nexecutor = "serial"'))
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 0
    assert "story-4" in capsys.readouterr().out
    models = json.loads((out / "metrics.json").read_text())["models"]
    assert {"fno", "c-physfno-els", "c-physfno-modal", "c-physfno-relaxed"} <= set(models)
    assert all(len(row["rel_l2"]) == 4 for row in models.values())
