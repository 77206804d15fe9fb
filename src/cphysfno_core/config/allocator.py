"""How the process gets its memory: freed blocks kept for reuse, fresh pages without
huge-page advice.

Training and prediction on the CPU allocate and free tensors of tens of MB at every layer
(``[3001, 20, 64]`` float32 is 15 MB, ``[4001, 20, 128]`` 41 MB). glibc's ``malloc``
serves blocks that large by ``mmap`` and unmaps them on ``free``, so the next tensor of
the same size starts on fresh pages and pays a page fault for every 4 KiB it touches: on
the two cores here that was a quarter of an Example 1 training epoch and 40 % of an
Example 3 one. :func:`retain_freed_memory` turns ``mmap`` off for ``malloc`` (every block
comes from the heap, whatever its size; glibc's ``mmap`` threshold cannot be raised above
32 MiB) and keeps up to 2 GiB of free heap, so freed blocks are reused at once. The
resident size then stays at its high-water mark instead of falling back between batches
(Example 3's training: 1.9 GB instead of 1.4 GB).

NumPy advises the kernel to back every array of 4 MB or more with transparent huge pages.
Where the kernel finds no free huge page (a virtual machine's fragmented memory, as here),
each fault in such an array first tries to compact memory and then falls back to 4 KiB
pages: the first write to a fresh output array ran 5-7 times slower, and simulating 1000
Bouc-Wen records once took 0.5 s instead of 0.15-0.2 s. The arrays here are written once,
streamed and freed, where huge pages save little; :func:`skip_huge_page_advice` turns the
advice off.

:func:`tune_memory` does both, once per process: the library calls it where it starts
to allocate (training, prediction, data generation), so no script has to. Set the
environment variable ``CPHYSFNO_TUNE_MEMORY=0`` to leave the process's allocator as it is.
"""

from __future__ import annotations

import ctypes
import os

M_TRIM_THRESHOLD = -1
M_MMAP_MAX = -4
TRIM_THRESHOLD = 2**31 - 1
"""Free memory at the top of the heap kept before any is returned (bytes; the largest
value ``mallopt`` takes)."""


def retain_freed_memory() -> bool:
    """Ask glibc ``malloc`` to serve every block from the heap and keep up to 2 GiB of free
    memory at its top.

    Affects the whole process from the call on. Where the heap cannot grow, glibc still
    falls back to ``mmap``.

    Returns:
        Whether the setting took: False where the C library is not glibc (``mallopt``
        missing) or refused a value.
    """
    try:
        mallopt = ctypes.CDLL(None).mallopt  # the C library the process already runs on
    except AttributeError:
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    return bool(mallopt(M_MMAP_MAX, 0)) and bool(mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD))


def skip_huge_page_advice() -> bool:
    """Stop NumPy from advising transparent huge pages for large arrays, in this process
    and in the processes it starts (through ``NUMPY_MADVISE_HUGEPAGE=0``, which NumPy reads
    when it is imported).

    Returns:
        Whether this process's NumPy took the setting: False where it has no switch for
        it (only the processes started later are then affected).
    """
    os.environ["NUMPY_MADVISE_HUGEPAGE"] = "0"
    try:
        from numpy._core.multiarray import _set_madvise_hugepage
    except ImportError:
        return False
    _set_madvise_hugepage(False)
    return True


OPT_OUT = "CPHYSFNO_TUNE_MEMORY"
"""Environment variable: ``0`` leaves the process's allocator as it is."""

_tuned: list[bool] = []
"""Holds ``True`` once :func:`tune_memory` has run in this process."""


def tune_memory() -> bool:
    """:func:`retain_freed_memory` and :func:`skip_huge_page_advice`, the first time it is
    called in a process (later calls do nothing), unless ``CPHYSFNO_TUNE_MEMORY=0``.

    Returns:
        Whether this call changed the settings.
    """
    if _tuned or os.environ.get(OPT_OUT) == "0":
        return False
    _tuned.append(True)
    retain_freed_memory()
    skip_huge_page_advice()
    return True
