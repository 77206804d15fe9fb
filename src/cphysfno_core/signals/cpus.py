"""How many CPUs this process may use, and a kernel run over records on all of them."""

from __future__ import annotations

import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor


def usable_cpus() -> int:
    """CPUs this process may run on: its affinity set where the platform has one (a
    container's or ``taskset``'s limit), else every CPU of the machine; at least one."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def record_slices(n_records: int, granule: int, workers: int | None = None) -> list[slice]:
    """Contiguous slices covering ``range(n_records)``, one per worker, as even as whole
    granules allow.

    Args:
        n_records: how many records there are.
        granule: every slice but the last starts and ends on a multiple of this (a compiled
            kernel's SIMD block).
        workers: at most this many slices (default :func:`usable_cpus`); fewer when there
            are fewer granules than workers. No slice is empty.
    """
    blocks = -(-n_records // granule)
    count = max(1, min(workers or usable_cpus(), blocks))
    bounds = [min(n_records, granule * (blocks * i // count)) for i in range(count + 1)]
    return [slice(lo, hi) for lo, hi in zip(bounds[:-1], bounds[1:], strict=True) if hi > lo]


def run_in_slices(kernel: Callable[[slice], None], n_records: int, granule: int) -> None:
    """Call ``kernel(records)`` on the :func:`record_slices` of ``range(n_records)``, one
    thread each (none started for a single slice, nothing called for no records).

    Args:
        kernel: works on the records of one slice; it must release the GIL (a compiled
            ``nogil`` kernel) for the threads to run side by side.
        n_records: how many records there are.
        granule: slice lengths are multiples of this (the kernel's SIMD block).
    """
    slices = record_slices(n_records, granule)
    if len(slices) <= 1:
        for records in slices:
            kernel(records)
        return
    with ThreadPoolExecutor(max_workers=len(slices)) as pool:
        list(pool.map(kernel, slices))
