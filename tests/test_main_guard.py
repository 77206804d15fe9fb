"""Worker processes asked for from a script's top-level code fail at once with the fix in
the message, not in multiprocessing's internals."""

import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = """
import sys
sys.path.insert(0, {tests!r})
import cphysfno_core as cp
from cphysfno_core.plugin import get_registry
import toy_components
import toy_experiment
get_registry().register(toy_components, "toys")
text = toy_experiment.toy_experiment(
    n_steps=50, data=dict(n_train=4, n_val=2, n_test=2, chunk_size=2)
).replace('executor = "serial"', 'executor = "processes"\\nworkers = 2')
config = cp.parse_config(__import__("tomllib").loads(text))
{call}
"""

TOP_LEVEL = "cp.generate_dataset(config, {out!r}, progress=False)"
GUARDED = 'if __name__ == "__main__":\n    ' + TOP_LEVEL


@pytest.mark.parametrize("guarded", [False, True], ids=["top level", "guarded"])
def test_workers_from_a_scripts_top_level_fail_with_the_fix(tmp_path, guarded):
    tests = str(Path(__file__).parent)
    call = (GUARDED if guarded else TOP_LEVEL).format(out=str(tmp_path / "data.h5"))
    script = tmp_path / "make_data.py"
    script.write_text(SCRIPT.format(tests=tests, call=call))
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True)
    if guarded:
        assert run.returncode == 0, run.stderr
        assert (tmp_path / "data.h5").exists()
        return
    assert run.returncode != 0
    assert "MainGuardError" in run.stderr
    assert f"called from the top level of {script} (line" in run.stderr
    assert 'if __name__ == "__main__":' in run.stderr
    assert "bootstrapping phase" not in run.stderr
