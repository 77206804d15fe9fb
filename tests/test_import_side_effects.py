"""Importing the package changes nothing process-wide: matplotlib's backend and the
memory allocator stay as the user's process set them."""

import os
import subprocess
import sys

PROGRAM = """
import os
import matplotlib
import cphysfno_core
from cphysfno_core.reporting import figures, report
from cphysfno_core.app import cli, pipeline
from numpy._core.multiarray import _get_madvise_hugepage
print(matplotlib.get_backend(), _get_madvise_hugepage(), os.environ.get("NUMPY_MADVISE_HUGEPAGE"))
"""


def test_importing_leaves_the_backend_and_the_allocator_alone():
    env = {k: v for k, v in os.environ.items() if k != "NUMPY_MADVISE_HUGEPAGE"}
    env["MPLBACKEND"] = "svg"
    run = subprocess.run(
        [sys.executable, "-c", PROGRAM], capture_output=True, text=True, env=env, check=True
    )
    assert run.stdout.split() == ["svg", "True", "None"]
