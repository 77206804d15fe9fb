"""The allocator settings: freed tensor-sized blocks are reused instead of faulted in again,
and NumPy gives no huge-page advice here or in the processes started from here."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

PROGRAM = """
import resource, sys
import numpy as np
from cphysfno_core.config.allocator import retain_freed_memory
if sys.argv[1] == "retain":
    assert retain_freed_memory()
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for megafloats in tuple(map(int, sys.argv[2].split(","))) * 3:
    a = np.ones(megafloats * 1_000_000, np.float32)
    b = np.ones(megafloats * 1_000_000, np.float32)
    del a, b
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def _page_faults(mode: str, megafloats: str) -> int:
    run = subprocess.run(
        [sys.executable, "-c", PROGRAM, mode, megafloats],
        capture_output=True,
        text=True,
        check=True,
    )
    return int(run.stdout)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc malloc only")
@pytest.mark.parametrize(
    "megafloats",
    ["1,2,3,4,5,6,7", "9,10,11,12"],
    ids=["4-28 MB", "36-48 MB, above glibc's largest mmap threshold"],
)
def test_retained_blocks_are_reused_without_page_faults(megafloats):
    default, retained = _page_faults("default", megafloats), _page_faults("retain", megafloats)
    assert retained < default / 2, (default, retained)


HUGE_PAGE_PROGRAM = """
import subprocess, sys
from numpy._core.multiarray import _get_madvise_hugepage
from cphysfno_core.config.allocator import skip_huge_page_advice
assert skip_huge_page_advice()
child = "from numpy._core.multiarray import _get_madvise_hugepage as g; print(g())"
started = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True)
print(_get_madvise_hugepage(), started.stdout.strip())
"""


def test_huge_page_advice_is_off_here_and_in_started_processes():
    run = subprocess.run(
        [sys.executable, "-c", HUGE_PAGE_PROGRAM], capture_output=True, text=True, check=True
    )
    assert run.stdout.split() == ["False", "False"]


LIBRARY_TUNES_PROGRAM = """
import os, sys
import numpy as np
import cphysfno_core as cp
from cphysfno_core.plugin import get_registry
from numpy._core.multiarray import _get_madvise_hugepage
sys.path.insert(0, sys.argv[1])
import toy_components
registry = get_registry()
registry.register(toy_components, "toys")
source = cp.create("ground_motion", "toy-source", n_steps=40, dt=0.02)
structure = cp.create("structure", "toy-structure")
gm = source.sample(6, np.random.default_rng(0))
u = structure.simulate(gm).displacement
model = cp.compose(structure=structure, preprocessor="toy-linear", operator="toy-operator",
                   training={"batch_size": 2})
print(_get_madvise_hugepage(), os.environ.get("NUMPY_MADVISE_HUGEPAGE"))
model.fit(gm[:4], u[:4], validation=(gm[4:], u[4:]), epochs=1, progress=None)
print(_get_madvise_hugepage(), os.environ.get("NUMPY_MADVISE_HUGEPAGE"))
"""


@pytest.mark.parametrize(("opt_out", "after"), [(None, ["False", "0"]), ("0", ["True", "None"])])
def test_the_library_tunes_memory_when_it_trains_unless_told_not_to(opt_out, after):
    """A script that only calls the library gets the tuned allocator; CPHYSFNO_TUNE_MEMORY=0
    leaves it as it was."""
    env = {k: v for k, v in os.environ.items() if k != "NUMPY_MADVISE_HUGEPAGE"}
    env.pop("CPHYSFNO_TUNE_MEMORY", None)
    if opt_out is not None:
        env["CPHYSFNO_TUNE_MEMORY"] = opt_out
    tests = str(Path(__file__).parent)
    run = subprocess.run(
        [sys.executable, "-c", LIBRARY_TUNES_PROGRAM, tests],
        capture_output=True,
        text=True,
        env=env,
    )
    assert run.returncode == 0, run.stderr
    before, trained = run.stdout.strip().splitlines()[-2:]
    assert before.split() == ["True", "None"]
    assert trained.split() == after
