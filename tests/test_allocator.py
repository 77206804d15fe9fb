"""The allocator setting: freed tensor-sized blocks are reused instead of faulted in again."""

import subprocess
import sys

import pytest

PROGRAM = """
import resource, sys
import numpy as np
from cphysfno_core.allocator import retain_freed_memory
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
