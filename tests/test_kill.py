"""`cphysfno generate` killed with SIGKILL and started again finishes the same dataset,
without recomputing finished chunks."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from toy_experiment import toy_experiment

import cphysfno_core as cp


def _config(delay_s: float) -> str:
    """The toy experiment whose every simulation waits ``delay_s`` seconds: 11 chunks of 2."""
    return toy_experiment(
        structure={"cubic": 20.0, "delay_s": delay_s},
        n_steps=80,
        data={"n_train": 14, "n_val": 4, "n_test": 4, "chunk_size": 2},
    )


def _environment() -> dict[str, str]:
    here = str(Path(__file__).parent)
    return {
        **os.environ,
        "CPHYSFNO_DISABLE_PLUGIN_AUTOLOAD": "1",
        "CPHYSFNO_PLUGINS": "toy_components",
        "PYTHONPATH": os.pathsep.join([here, os.environ.get("PYTHONPATH", "")]),
    }


def _done(parts: Path) -> int:
    return len(list(parts.glob("chunk-*.npz"))) if parts.exists() else 0


def test_sigkill_at_any_point_then_the_same_command_finishes(toy_registry, tmp_path):
    config = tmp_path / "slow.toml"
    config.write_text(_config(0.25))
    out = tmp_path / "out"
    command = [
        sys.executable,
        "-m",
        "cphysfno_core.app.cli",
        "generate",
        str(config),
        "--out",
        str(out),
    ]
    parts = out / "dataset.h5.parts"
    rng = np.random.default_rng(3)
    seen = []
    for target in (1, 4, 7):  # kill once at least `target` chunks are done, at a random moment
        process = subprocess.Popen(command, env=_environment(), stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 120
        while _done(parts) < target and time.monotonic() < deadline:
            time.sleep(0.02)
        time.sleep(rng.uniform(0.0, 0.25))
        process.send_signal(signal.SIGKILL)
        process.wait()
        seen.append(_done(parts))
    assert all(0 < n < 11 for n in seen), f"a kill did not land mid-run: chunks seen {seen}"
    assert seen == sorted(seen), "a restart lost chunks that were already done"
    finished = subprocess.run(command, env=_environment(), capture_output=True, text=True)
    assert finished.returncode == 0, finished.stderr
    assert f"resuming: {seen[-1]} of 11 chunks already done" in finished.stderr

    reference_config = tmp_path / "fast.toml"
    reference_config.write_text(_config(0.0))
    reference = cp.generate_dataset(
        cp.load_config(reference_config), tmp_path / "ref.h5", progress=False
    )
    killed, clean = cp.load_dataset(out / "dataset.h5"), cp.load_dataset(reference)
    np.testing.assert_array_equal(killed.ag, clean.ag)
    np.testing.assert_array_equal(killed.u, clean.u)
    np.testing.assert_array_equal(killed.z["toy-linear"], clean.z["toy-linear"])
    assert not parts.exists()
