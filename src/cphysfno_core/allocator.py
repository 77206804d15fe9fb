"""Keep large freed blocks in the process instead of handing them back to the kernel.

Training and prediction on the CPU allocate and free tensors of tens of MB at every layer
(e.g. ``[3001, 20, 64]`` float32, 15 MB). glibc's ``malloc`` serves blocks that large by
``mmap`` and unmaps them on ``free``, so the next tensor of the same size starts on fresh
pages and pays a page fault for every 4 KiB it touches: on the two cores here that was
a quarter of a training epoch's time. :func:`retain_freed_memory` raises the ``mmap``
threshold to its maximum and keeps up to 2 GiB of free heap, so freed blocks are reused at once.
The ``cphysfno`` command and the benchmarks call it at start; the resident size then stays
at its high-water mark instead of falling back between batches.
"""

from __future__ import annotations

import ctypes

M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
LARGEST_HEAP_BLOCK = 32 * 1024 * 1024
"""glibc's ceiling for the ``mmap`` threshold on 64-bit systems (bytes)."""
TRIM_THRESHOLD = 2**31 - 1
"""Free memory at the top of the heap kept before any is returned (bytes; the largest
value ``mallopt`` takes)."""


def retain_freed_memory() -> bool:
    """Ask glibc ``malloc`` to serve blocks up to 32 MiB from the heap and keep up to 2 GiB of free
    memory at its top.

    Affects the whole process from the call on; blocks over 32 MiB are still ``mmap``-ed.

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
    return bool(mallopt(M_MMAP_THRESHOLD, LARGEST_HEAP_BLOCK)) and bool(
        mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD)
    )
