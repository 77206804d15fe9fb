"""The allocator settings: freed tensor-sized blocks are reused instead of faulted in again,
and NumPy gives no huge-page advice here or in the processes started from here."""

import subprocess
import sys

import pytest

PROGRAM = """
import resource, sys
import numpy as np
from cphysfno_core.model.allocator import retain_freed_memory
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
from cphysfno_core.model.allocator import skip_huge_page_advice
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
