"""Keep freed blocks in the process instead of handing them back to the kernel.

Training and prediction on the CPU allocate and free tensors of tens of MB at every layer
(``[3001, 20, 64]`` float32 is 15 MB, ``[4001, 20, 128]`` 41 MB). glibc's ``malloc``
serves blocks that large by ``mmap`` and unmaps them on ``free``, so the next tensor of
the same size starts on fresh pages and pays a page fault for every 4 KiB it touches: on
the two cores here that was a quarter of an Example 1 training epoch and 40 % of an
Example 3 one. :func:`retain_freed_memory` turns ``mmap`` off for ``malloc`` (every block
comes from the heap, whatever its size; glibc's ``mmap`` threshold cannot be raised above
32 MiB) and keeps up to 2 GiB of free heap, so freed blocks are reused at once. The
``cphysfno`` command, its study workers and the benchmarks call it at start; the resident
size then stays at its high-water mark instead of falling back between batches (Example
3's training: 1.9 GB instead of 1.4 GB).
"""

from __future__ import annotations

import ctypes

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
